#!/bin/bash
# 100 torches: the automatic path against billboards everywhere and smoke on billboards.
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
cd .device/rt && xz -dk ignis-new.xz; chmod +x ignis-*; cd ../..
mkdir -p $OUT/res
for round in 1; do
  for v in torch torch-billboards torch-smoke-billboards; do
    p=.device/rt/$v.ron; [ $v = torch ] && p=presets/torch.ron
    timeout 100 ./.device/rt/ignis-new bench runtime --preset $p --counts 1,100 --size 1920x1080 --frames 21 --out $OUT/res --name $v-$round > $OUT/res/$v-$round.log 2>&1
    echo "== $v $round rc $?"; grep -E "^\| (1|100) torches, a" $OUT/res/$v-$round.md | awk -F'|' '{print $2,"rec",$4,"draw",$5,"tot",$6,"cpu",$7,$9,"|",$11}'
  done
done
cd $OUT && tar czf rt3.tgz res && rm -rf res
