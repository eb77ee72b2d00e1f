#!/bin/bash
# The lease's second and third runs (one binary, head): `run.sh stages` (the tile-stage
# breakdown, then every preset pipelined in one pass) or `run.sh presets` (every preset
# pipelined over three passes, then the runtime).
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
xz -d .device/h/ignis-head.xz && chmod +x .device/h/ignis-head
B=./.device/h/ignis-head
nvidia-smi > $OUT/smi.txt 2>&1
mkdir -p $OUT/res
if [ "$1" = stages ]; then
  timeout 150 $B bench presets presets/bonfire.ron presets/campfire.ron presets/torch.ron --sizes 3840x2160,1920x1080 --passes 1 --frames 15 --out $OUT/res --name stages > $OUT/res/stages.log 2>&1; echo "stages rc $?"
  timeout 380 $B bench presets --passes 1 --frames 30 --pipelined --out $OUT/res --name presets-pipelined > $OUT/res/pipe.log 2>&1; echo "pipe rc $?"
else
  timeout 420 $B bench presets --passes 3 --frames 30 --pipelined --out $OUT/res --name presets-nvidia-h200 > $OUT/res/presets.log 2>&1; echo "presets rc $?"
  timeout 120 $B bench runtime --size 1920x1080 --frames 21 --out $OUT/res > $OUT/res/runtime.log 2>&1; echo "runtime rc $?"
fi
cd $OUT && tar czf r.tgz res smi.txt && rm -rf res
