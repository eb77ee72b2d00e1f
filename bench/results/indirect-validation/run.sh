#!/usr/bin/env bash
# The runtime bench with wgpu's indirect-call validation on (its default) and off,
# alternating in one lease.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
xz -dk .device/ignis.xz && chmod +x .device/ignis
mkdir -p $OUT/res
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv > $OUT/res/smi.txt
for pass in 1 2; do
  for v in 1 0; do
    WGPU_VALIDATION_INDIRECT_CALL=$v timeout 170 ./.device/ignis bench runtime --size 1920x1080 --frames 41 \
      --out $OUT/res --name rt-validate$v-$pass > $OUT/res/rt-validate$v-$pass.log 2>&1
    echo "== validate=$v pass=$pass rc=$?"
    grep "^| 1 torches\|^| 100 torches, a grid" $OUT/res/rt-validate$v-$pass.md | cut -d'|' -f2-9
  done
done
cd $OUT && tar czf all.tgz res && rm -rf res
