//! Rendering one export frame: the player's layers into targets of the export's own —
//! the colour (transparent, or over an opaque background), the additive light alone,
//! and the motion pass — read back as linear floats.

use crate::gpu::{GpuContext, TextureReadback};
use crate::render::{Camera, begin_hdr_pass};
use crate::runtime::{Layers, Player};
use crate::sim::gpu_sim::map_read;

use super::ExportError;
use super::export_settings::ExportSettings;

/// One rendered frame, linear and premultiplied, exposure applied.
#[derive(Clone, Debug, Default)]
pub(super) struct RawFrame {
    /// Light and coverage (RGBA).
    pub color: Vec<[f32; 4]>,
    /// The additive layers' light alone (RGB; empty when the pass is off).
    pub emissive: Vec<[f32; 4]>,
    /// Weighted mean motion in pixels over the frame interval (empty when off).
    pub motion: Vec<[f32; 2]>,
    /// The six-way lightmaps of the alpha-blended layers, straight: RTBA and LBFE
    /// (empty when off; `sixway_pass.rs`).
    pub sixway: [Vec<[f32; 4]>; 2],
    /// The heat haze's summed screen offsets in frame UV (empty when off).
    pub distortion: Vec<[f32; 2]>,
}

impl RawFrame {
    /// Moves every pass a fraction `t` of the way towards `other` (a loop's fade).
    pub fn blend_towards(&mut self, other: &RawFrame, t: f32) {
        let mix = |a: &mut f32, b: f32| *a += (b - *a) * t;
        for (a, b) in self.color.iter_mut().zip(&other.color) {
            (0..4).for_each(|k| mix(&mut a[k], b[k]));
        }
        for (a, b) in self.emissive.iter_mut().zip(&other.emissive) {
            (0..4).for_each(|k| mix(&mut a[k], b[k]));
        }
        for (a, b) in (self.motion.iter_mut().chain(&mut self.distortion))
            .zip(other.motion.iter().chain(&other.distortion))
        {
            (0..2).for_each(|k| mix(&mut a[k], b[k]));
        }
        for (mine, theirs) in self.sixway.iter_mut().zip(&other.sixway) {
            for (a, b) in mine.iter_mut().zip(theirs) {
                (0..4).for_each(|k| mix(&mut a[k], b[k]));
            }
        }
    }
}

/// The export's targets and camera.
pub(super) struct FrameRenderer {
    camera: Camera,
    size: (u32, u32),
    background: Option<[f32; 3]>,
    color: wgpu::Texture,
    emissive: Option<wgpu::Texture>,
    motion: Option<wgpu::Texture>,
    /// The six-way passes' target (each of its renders read back in turn).
    sixway: Option<wgpu::Texture>,
    /// The distortion pass is on (the player's own target is read back).
    distortion: bool,
}

impl FrameRenderer {
    /// Targets of the settings' frame size for the passes they ask for.
    pub fn new(ctx: &GpuContext, camera: Camera, settings: &ExportSettings) -> Self {
        let size = settings.frame_size;
        let texture = |label| {
            crate::gpu::texture_2d(
                &ctx.device,
                label,
                size,
                1,
                target_format(&ctx.device),
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            )
        };
        let target = |on: bool, label| on.then(|| texture(label));
        Self {
            camera,
            size,
            background: settings.background,
            color: texture("Export::color"),
            emissive: target(settings.passes.emissive, "Export::emissive"),
            motion: target(settings.passes.motion, "Export::motion"),
            sixway: target(settings.passes.sixway, "Export::sixway"),
            distortion: settings.passes.distortion,
        }
    }

    /// Draws the haze layers into the player's distortion target at the frame size and
    /// records its readback (`None`: the effect has no haze this frame).
    fn record_distortion(
        &self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        player: &mut Player,
    ) -> Result<Option<TextureReadback>, ExportError> {
        let drawn = player
            .draw_distortion(enc, (self.size, 1))
            .map_err(|e| ExportError::Invalid(format!("the distortion pass: {e}")))?;
        Ok(drawn
            .then(|| player.distortion())
            .flatten()
            .map(|t| TextureReadback::record(&ctx.device, enc, t, "Export::distortion")))
    }

    /// The frame size.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Renders the player's current state and reads it back (blocking). A GPU error (a
    /// device limit, say) fails the frame rather than writing an empty one.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        player: &mut Player,
    ) -> Result<RawFrame, ExportError> {
        let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let frame = self.render_unchecked(ctx, player);
        if let Some(err) = pollster::block_on(scope.pop()) {
            return Err(ExportError::Invalid(format!(
                "the GPU refused an export frame: {err}"
            )));
        }
        frame
    }

    fn render_unchecked(
        &mut self,
        ctx: &GpuContext,
        player: &mut Player,
    ) -> Result<RawFrame, ExportError> {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        player.record_sampling(&mut enc, &self.camera, None);
        let view = self.color.create_view(&Default::default());
        {
            let mut pass = match self.background {
                Some(b) => begin_clear_pass(&mut enc, &view, b),
                None => begin_hdr_pass(&mut enc, &view),
            };
            player.draw(&mut pass);
        }
        if let Some(t) = &self.emissive {
            let view = t.create_view(&Default::default());
            player.draw_layers(
                &mut begin_hdr_pass(&mut enc, &view),
                Layers::LIGHT | Layers::GLOW,
            );
        }
        if let Some(t) = &self.motion {
            let view = t.create_view(&Default::default());
            player.draw_motion(&mut begin_hdr_pass(&mut enc, &view));
        }
        let read = |enc: &mut wgpu::CommandEncoder, t: &wgpu::Texture| {
            TextureReadback::record(&ctx.device, enc, t, "Export::readback")
        };
        let color = read(&mut enc, &self.color);
        let emissive = self.emissive.as_ref().map(|t| read(&mut enc, t));
        let motion = self.motion.as_ref().map(|t| read(&mut enc, t));
        let sixway = (self.sixway.as_ref())
            .map(|t| super::sixway_pass::record(ctx, &mut enc, player, &self.camera, t));
        let distortion = self
            .distortion
            .then(|| self.record_distortion(ctx, &mut enc, player));
        ctx.queue.submit([enc.finish()]);
        let exposure = player.effect().post.exposure;
        let lit = |p: [f32; 4]| [p[0] * exposure, p[1] * exposure, p[2] * exposure, p[3]];
        // Over an opaque background the image is already composited: exposure scales the
        // whole of it, as the editor's tonemap does.
        let opaque = self.background.is_some();
        let mut frame = RawFrame {
            color: texels(ctx, &color)?
                .into_iter()
                .map(|p| {
                    let p = lit(p);
                    if opaque { [p[0], p[1], p[2], 1.0] } else { p }
                })
                .collect(),
            ..RawFrame::default()
        };
        if let Some(e) = &emissive {
            frame.emissive = texels(ctx, e)?.into_iter().map(lit).collect();
        }
        if let Some(readbacks) = &sixway {
            let renders = readbacks
                .iter()
                .map(|r| texels(ctx, r))
                .collect::<Result<Vec<_>, _>>()?;
            frame.sixway = super::sixway_pass::pack(&renders);
        }
        if let Some(d) = distortion.transpose()?.flatten() {
            frame.distortion = texels(ctx, &d)?.into_iter().map(|p| [p[0], p[1]]).collect();
        } else if self.distortion {
            // No haze: no offset anywhere.
            frame.distortion = vec![[0.0; 2]; (self.size.0 * self.size.1) as usize];
        }
        if let Some(m) = &motion {
            frame.motion = texels(ctx, m)?
                .into_iter()
                .map(|p| {
                    if p[3] > 1e-6 {
                        [p[0] / p[3], p[1] / p[3]]
                    } else {
                        [0.0; 2]
                    }
                })
                .collect();
        }
        Ok(frame)
    }
}

/// The export's target format: 32-bit float where the device blends it (bright light
/// adds up without f16's rounding), else `Rgba16Float`.
pub(super) fn target_format(device: &wgpu::Device) -> wgpu::TextureFormat {
    if device
        .features()
        .contains(wgpu::Features::FLOAT32_BLENDABLE)
    {
        wgpu::TextureFormat::Rgba32Float
    } else {
        crate::render::HDR_FORMAT
    }
}

/// A pass over `view` cleared to the opaque linear colour `b`.
fn begin_clear_pass<'a>(
    enc: &'a mut wgpu::CommandEncoder,
    view: &'a wgpu::TextureView,
    b: [f32; 3],
) -> wgpu::RenderPass<'a> {
    let [r, g, b] = b.map(f64::from);
    let clear = wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 });
    crate::gpu::color_pass(enc, view, clear, "Export::background")
}

/// An `Rgba16Float` or `Rgba32Float` readback's texels as f32.
pub(super) fn texels(
    ctx: &GpuContext,
    copy: &TextureReadback,
) -> Result<Vec<[f32; 4]>, ExportError> {
    let bytes = map_read(ctx, &copy.buffer)?;
    let rows = copy
        .rows(&bytes)
        .ok_or_else(|| ExportError::Invalid("the frame readback is too short".into()))?;
    if copy.texel_bytes == 16 {
        return Ok(rows
            .iter()
            .flat_map(|row| bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(row))
            .collect());
    }
    Ok(rows
        .iter()
        .flat_map(|row| {
            row.chunks_exact(8).map(|t| {
                let v = |i: usize| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32();
                [v(0), v(1), v(2), v(3)]
            })
        })
        .collect())
}

/// Advances `player` from `*now` to `t` seconds of effect time in chunks of at most a
/// 60th of a second (a long frame interval must not trip the hitch guard), simulating
/// each; `*now` becomes `t`.
pub(super) fn advance_to(ctx: &GpuContext, player: &mut Player, now: &mut f64, t: f64) {
    let remaining = t - *now;
    if remaining > 1e-12 {
        let n = (remaining * 60.0).ceil().max(1.0) as u32;
        let dt = remaining / f64::from(n);
        for _ in 0..n {
            player.advance(dt);
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            player.simulate(&mut enc);
            ctx.queue.submit([enc.finish()]);
        }
    }
    *now = t;
}
