#!/bin/bash
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
xz -d .device/h/ignis-head.xz && chmod +x .device/h/ignis-head
B=./.device/h/ignis-head
nvidia-smi > $OUT/smi.txt 2>&1
mkdir -p $OUT/res
timeout 150 $B bench presets presets/bonfire.ron presets/campfire.ron presets/torch.ron --sizes 3840x2160,1920x1080 --passes 1 --frames 15 --out $OUT/res --name stages > $OUT/res/stages.log 2>&1; echo "stages rc $?"
grep -E "^\| " $OUT/res/stages.md | awk -F'|' '{print $2,$3,$4,"upd",$5,"rec",$6,"draw",$7,"frame",$9,"st",$12}'
timeout 380 $B bench presets --passes 1 --frames 30 --pipelined --out $OUT/res --name presets-pipelined > $OUT/res/pipe.log 2>&1; echo "pipe rc $?"
grep -E "^\| " $OUT/res/presets-pipelined.md | awk -F'|' '{print $2,$3,$4,"upd",$5,"rec",$6,"draw",$7,"frame",$9,"diff",$11,"st",$12}'
cd $OUT && tar czf r2.tgz res smi.txt && rm -rf res
