#!/bin/bash
# The runtime's CPU and GPU cost, old and new binaries interleaved in one lease.
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
cd .device/rt && for f in *.xz; do xz -d $f; done; chmod +x ignis-*; cd ../..
nvidia-smi -L; lscpu | grep -E "Model name|^CPU\(s\)|MHz"; which perf
mkdir -p $OUT/res
for round in 1 2; do
  for b in old new; do
    timeout 150 ./.device/rt/ignis-$b bench runtime --size 1920x1080 --frames 41 --out $OUT/res --name rt-$b-$round > $OUT/res/rt-$b-$round.log 2>&1
    echo "== $b $round rc $?"; grep -E "^\| [0-9]" $OUT/res/rt-$b-$round.md | awk -F'|' '{print $2,"rec",$4,"draw",$5,"tot",$6,"cpu",$7,$8,$9}'
  done
done
cd $OUT && tar czf rt.tgz res && rm -rf res
