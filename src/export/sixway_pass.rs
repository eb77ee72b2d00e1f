//! The export's six-way passes: the alpha-blended (smoke) layers rendered seven more
//! times — lit by a unit white light from each axis of the camera's frame (right, up,
//! behind, left, down, front) with nothing else, then by their own glow alone — and
//! packed as Unity's Six Way shader reads them (RTBA, LBFE: `export_settings::SIXWAY_PACKING`),
//! so an engine relights the exported flipbook with its own lights.

use glam::Vec3;

use crate::gpu::{GpuContext, TextureReadback};
use crate::render::scene_lighting::SceneLighting;
use crate::render::{Camera, begin_hdr_pass};
use crate::runtime::{Layers, Player};

/// Rec. 709 luminance of linear RGB.
const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Records the seven renders into `target`, each copied out after it is drawn; the
/// player's lighting is put back after.
pub(super) fn record(
    ctx: &GpuContext,
    enc: &mut wgpu::CommandEncoder,
    player: &mut Player,
    camera: &Camera,
    target: &wgpu::Texture,
) -> Vec<TextureReadback> {
    let before = player.lighting().cloned();
    let view_from_world = camera.view_from_world_mat4();
    let right = view_from_world.row(0).truncate();
    let up = view_from_world.row(1).truncate();
    let back = camera.forward();
    let axes = [right, up, back, -right, -up, -back];
    let mut out = Vec::with_capacity(7);
    for k in 0..7 {
        let lit = k < 6;
        player.set_lighting(Some(SceneLighting {
            sun_direction: axes.get(k).copied().unwrap_or(Vec3::Y),
            sun_color: if lit { [1.0; 3] } else { [0.0; 3] },
            ambient: [0.0; 3],
            point_lights: Vec::new(),
            own_light: 0.0,
            glow: if lit { 0.0 } else { 1.0 },
        }));
        player.record_sampling(enc, camera, None);
        let view = target.create_view(&Default::default());
        player.draw_layers(&mut begin_hdr_pass(enc, &view), Layers::BLENDED);
        out.push(TextureReadback::record(
            &ctx.device,
            enc,
            target,
            "Export::sixway_readback",
        ));
    }
    player.set_lighting(before);
    out
}

/// The seven renders (premultiplied) as the two straight maps: each channel the
/// luminance of one render over the coverage.
pub(super) fn pack(renders: &[Vec<[f32; 4]>]) -> [Vec<[f32; 4]>; 2] {
    let luma = |p: [f32; 4]| p[0] * LUMA[0] + p[1] * LUMA[1] + p[2] * LUMA[2];
    let texels = renders.first().map_or(0, Vec::len);
    let mut maps = [Vec::with_capacity(texels), Vec::with_capacity(texels)];
    for i in 0..texels {
        let at = |k: usize| {
            renders
                .get(k)
                .and_then(|r| r.get(i))
                .copied()
                .unwrap_or_default()
        };
        let a = at(0)[3];
        let s = |k: usize| if a > 1e-6 { luma(at(k)) / a } else { 0.0 };
        maps[0].push([s(0), s(1), s(2), a]);
        maps[1].push([s(3), s(4), s(5), s(6)]);
    }
    maps
}
