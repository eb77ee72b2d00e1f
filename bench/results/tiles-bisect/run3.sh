#!/bin/bash
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
xz -d .device/h/ignis-head.xz && chmod +x .device/h/ignis-head
B=./.device/h/ignis-head
nvidia-smi > $OUT/smi.txt 2>&1
mkdir -p $OUT/res
timeout 420 $B bench presets --passes 3 --frames 30 --pipelined --out $OUT/res --name presets-nvidia-h200 > $OUT/res/presets.log 2>&1; echo "presets rc $?"
grep -E "^\| " $OUT/res/presets-nvidia-h200.md | awk -F'|' '{print $2,$3,$4,"frame",$9,"passes",$10,"diff",$11}'
timeout 120 $B bench runtime --size 1920x1080 --frames 21 --out $OUT/res > $OUT/res/runtime.log 2>&1; echo "runtime rc $?"
tail -30 $OUT/res/runtime.log
cd $OUT && tar czf r3.tgz res smi.txt && rm -rf res
