#!/bin/bash
# One lease: the campfire's frame on the old and the new binary, interleaved ("camp"), or
# every preset on both ("all").
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
(cd .device && for b in old new; do [ -x ignis-$b ] || { xz -dk ignis-$b.xz && chmod +x ignis-$b; }; done)
nvidia-smi > $OUT/smi.txt 2>&1
mkdir -p $OUT/res
if [ "$1" = check ]; then
for b in old new old new; do
  timeout 55 ./.device/ignis-$b bench presets presets/bonfire.ron presets/torch.ron --passes 1 --frames 15 --out $OUT/res --name check-$b > $OUT/res/check-$b.log 2>&1
  echo "== $b"; grep -E "^\| (bonfire|torch)" $OUT/res/check-$b.md | awk -F'|' '{print $2,$3,$4,"upd",$5,"frame",$9}'
done
elif [ "$1" = pipe ]; then
timeout 170 ./.device/ignis-new bench presets presets/campfire.ron --sizes 1920x1080,3840x2160 --passes 3 --frames 60 --pipelined --out $OUT/res --name pipe-campfire > $OUT/res/pipe-campfire.log 2>&1
grep -E "^\| campfire" $OUT/res/pipe-campfire.md | awk -F'|' '{print $3,$4,"upd",$5,"sort",$6,"draw",$7,"comp",$8,"frame",$9,"passes",$10}'
timeout 290 ./.device/ignis-new bench presets --passes 1 --frames 30 --pipelined --out $OUT/res --name pipe-all > $OUT/res/pipe-all.log 2>&1; echo "all rc $?"
grep -E "^\| " $OUT/res/pipe-all.md | awk -F'|' '{print $2,$3,$4,"upd",$5,"frame",$9}' | head -140
elif [ "$1" = camp5 ]; then
for round in 1 2; do
  for size in 3840x2160 1920x1080; do
    timeout 200 ./.device/ignis-new bench presets presets/campfire.ron --sizes $size,$size --passes 4 --frames 15 --out $OUT/res --name camp5-$size-$round > $OUT/res/camp5-$size-$round.log 2>&1
    echo "== $size $round"; grep -E "^\| campfire" $OUT/res/camp5-$size-$round.md | awk -F'|' '{print $3,$4,"upd",$5,"sort",$6,"draw",$7,"comp",$8,"frame",$9,"passes",$10}'
  done
done
elif [ "$1" = camp ]; then
for round in 1 2 3; do
  for b in old new; do
    preset=presets/campfire.ron; [ $b = old ] && preset=.device/campfire-old.ron
    timeout 150 ./.device/ignis-$b bench presets $preset --sizes 3840x2160,1920x1080 --passes 3 --frames 15 --out $OUT/res --name camp-$b-$round > $OUT/res/camp-$b-$round.log 2>&1
    echo "== $b $round"; grep -E "^\| campfire" $OUT/res/camp-$b-$round.md | awk -F'|' '{print $3,$4,"upd",$5,"draw",$7,"frame",$9}'
  done
done
else
for b in new old; do
  timeout 270 ./.device/ignis-$b bench presets --passes 2 --frames 15 --out $OUT/res --name all-$b > $OUT/res/all-$b.log 2>&1; echo "$b rc $?"
done
fi
cd $OUT && tar czf all-$1.tgz res smi.txt && rm -rf res
