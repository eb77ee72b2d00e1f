#!/usr/bin/env bash
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
xz -dk .device/ignis-new.xz && chmod +x .device/ignis-new
mkdir -p $OUT/res
for pass in 1 2; do
for v in presets/torch.ron .device/var/head-tiles.ron; do
  n=$(basename $v .ron)
  timeout 100 ./.device/ignis-new bench runtime --preset $v --counts 1,10,100 --size 1920x1080 --frames 41 \
    --out $OUT/res --name var-$n-$pass > $OUT/res/var-$n-$pass.log 2>&1
  echo "== $n $pass rc=$?"
  grep "^| 1 torches\|^| 10 torches\|^| 100 torches, a grid" $OUT/res/var-$n-$pass.md | cut -d'|' -f2,4-6,9,12
done; done
cd $OUT && tar czf all.tgz res && rm -rf res
