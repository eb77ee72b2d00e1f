#!/bin/bash
# Lit presets' billboards: old (no lit trim), lit trim, lit trim + octagons; one lease, two rounds.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp WGPU_BACKEND=vulkan
for b in turb littrim oct; do xz -dc .device/ignis-$b.xz > /tmp/$b && chmod +x /tmp/$b; done
R=$PWD; mkdir -p $OUT/r
P="$R/presets/campfire.ron $R/presets/bonfire.ron $R/presets/torch.ron"
for i in 1 2; do
(cd .device/old && timeout 120 /tmp/turb bench presets $P --sizes 1920x1080,3840x2160 --passes 2 --frames 15 --out $OUT/r --name old-$i > $OUT/r/old-$i.log 2>&1; echo old$i $?)
(cd .device/lt && timeout 120 /tmp/littrim bench presets $P --sizes 1920x1080,3840x2160 --passes 2 --frames 15 --out $OUT/r --name littrim-$i > $OUT/r/littrim-$i.log 2>&1; echo littrim$i $?)
timeout 120 /tmp/oct bench presets $P --sizes 1920x1080,3840x2160 --passes 2 --frames 15 --out $OUT/r --name oct-$i > $OUT/r/oct-$i.log 2>&1; echo oct$i $?
done
cp -r $OUT/r/*.md $OUT/ 2>/dev/null
cd $OUT && tar czf all.tgz r && rm -rf r
