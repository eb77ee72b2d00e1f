#!/bin/bash
# Bisect the tiles' slowdown: the same (old) presets on binaries of six commits, interleaved.
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
cd .device/bis && for f in *.xz; do xz -d $f; done; chmod +x ignis-*; cd ../..
nvidia-smi > $OUT/smi.txt 2>&1
mkdir -p $OUT/res
P=.device/oldpresets
for round in 1 2; do
  for b in $BINS; do
    timeout 80 ./.device/bis/ignis-$b bench presets $P/bonfire.ron $P/campfire.ron --sizes 3840x2160 --passes 2 --frames 15 --out $OUT/res --name bis-$b-$round > $OUT/res/bis-$b-$round.log 2>&1
    echo "== $b $round rc $?"; grep -E "^\| (bonfire|campfire)" $OUT/res/bis-$b-$round.md | awk -F'|' '{print $2,$4,"upd",$5,"tiles",$6,"draw",$7,"comp",$8,"frame",$9}'
  done
done
if [ -n "$PIPE" ]; then
  timeout 200 ./.device/bis/ignis-head bench presets --passes 1 --frames 30 --pipelined --out $OUT/res --name pipe-all > $OUT/res/pipe-all.log 2>&1; echo "pipe rc $?"
  grep -E "^\| " $OUT/res/pipe-all.md | awk -F'|' '{print $2,$3,$4,"upd",$5,"tiles",$6,"frame",$9}'
fi
cd $OUT && tar czf bis.tgz res smi.txt && rm -rf res
