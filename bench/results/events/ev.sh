#!/bin/bash
# The module table at 16.8M: HEAD (cur) and the event scan's early exit (ev), interleaved.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
for b in cur ev; do xz -dc .device/ignis-$b.xz > /tmp/$b && chmod +x /tmp/$b; done
mkdir -p $OUT/r
for i in ${ROUNDS:-1 2}; do for b in ev cur; do
  s=$(date +%s)
  timeout 150 /tmp/$b bench perf --sides 64 --repeats 5 --module-capacity 16777216 --out $OUT/r --name modules-$b-$i > $OUT/r/$b-$i.log 2>&1; echo $b$i $? $(( $(date +%s) - s ))s
done; done
cd $OUT && for f in r/*.md; do grep -h "events on\|bare:\|turbulence on\|trail on\|collisions on" $f | sed "s|^|$(basename $f .md) |"; done > summary.txt; tar czf all.tgz r && rm -rf r
