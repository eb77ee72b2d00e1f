#!/bin/bash
# The runtime bench with the record's GPU parts, and every preset, on the new binary.
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
cd .device/rt && xz -d ignis-new.xz; chmod +x ignis-*; cd ../..
mkdir -p $OUT/res
for round in 1 2; do
  timeout 150 ./.device/rt/ignis-new bench runtime --size 1920x1080 --frames 41 --out $OUT/res --name runtime-nvidia-h200-$round > $OUT/res/rt-$round.log 2>&1
  echo "== $round rc $?"; grep -E "^\| [0-9]" $OUT/res/runtime-nvidia-h200-$round.md | awk -F'|' '{print $2,"rec",$4,"draw",$5,"cpu",$7,$8,$9,"|",$11}'
done
timeout 330 ./.device/rt/ignis-new bench presets --passes 2 --frames 30 --pipelined --out $OUT/res --name presets-nvidia-h200 > $OUT/res/presets.log 2>&1; echo "presets rc $?"
grep -E "^\| " $OUT/res/presets-nvidia-h200.md | head -40 | cut -c1-200
cd $OUT && tar czf rt2.tgz res && rm -rf res
