#!/usr/bin/env bash
# The runtime bench, old binary (batches of 16, 32, 64) and new (one batch that grows),
# alternating in one lease.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
for b in old new; do xz -dk .device/ignis-$b.xz && chmod +x .device/ignis-$b; done
mkdir -p $OUT/res
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv > $OUT/res/smi.txt
for pass in 1 2; do
  for b in old new; do
    timeout 120 ./.device/ignis-$b bench runtime --size 1920x1080 --frames 41 \
      --out $OUT/res --name rt-$b-$pass > $OUT/res/rt-$b-$pass.log 2>&1
    echo "== $b pass=$pass rc=$?"
    grep "^| 1 torches\|^| 10 torches\|^| 100 torches" $OUT/res/rt-$b-$pass.md | cut -d'|' -f2-10
  done
done
cd $OUT && tar czf all.tgz res && rm -rf res
