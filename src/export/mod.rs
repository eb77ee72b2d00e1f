//! `ignis export`: flipbooks (one atlas, frames row-major from the top left) and image
//! sequences of an effect for game engines — real alpha, an emissive and a motion-vector
//! pass, a camera framed on the whole span, seamless loops, and a JSON sidecar.
//!
//! An [`Export`] is another client of the [`Player`]: it plays one instance and draws it
//! into targets of its own (billboards only, full resolution, no bloom or tonemap), one
//! frame per [`Export::step`], so that the command line and the editor's Export window
//! drive the same code (the editor a few steps per UI frame, with a preview and cancel).
//!
//! **Compositing.** The colour pass holds the effect's light in linear units (times the
//! preset's exposure), premultiplied: alpha-blended layers add their coverage to alpha,
//! additive ones add light and no coverage. Over a background `B` (linear) the in-editor
//! image before its tonemap is exactly `C + B·(1 − A)`: decode the PNG's sRGB colour to
//! linear first (EXR is linear already). `--alpha straight` divides by a coverage that
//! also counts the light (`A' = max(A, min(1, max(C.rgb)))`): `rgb·A' + B·(1 − A')` then
//! dims the background behind bright light slightly, for engines without premultiplied
//! blending.

pub mod cli;
mod encode;
mod export_settings;
mod frames;
mod framing;
mod sidecar;
mod sixway_pass;
mod writer;

use std::path::PathBuf;

use crate::effect::{DrawPath, Effect};
use crate::gpu::GpuContext;
use crate::runtime::{InstanceId, Player, PlayerError, PlayerSettings};

pub use encode::{decode_motion, linear_to_srgb, srgb_to_linear};
pub use export_settings::{
    AlphaMode, CameraMode, DISTORTION_SCALE, ExportSettings, Format, Layout, Passes, SIXWAY_PACKING,
};
pub use sidecar::Sidecar;

use frames::{FrameRenderer, RawFrame};
use writer::Writer;

/// Why an export could not run or finish.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// A setting is impossible (the message names it and the fix).
    #[error("{0}")]
    Invalid(String),
    /// The player could not be created or read back.
    #[error(transparent)]
    Player(#[from] PlayerError),
    /// A file could not be written (nothing is left half-written).
    #[error("could not write {path}: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl From<crate::sim::SimError> for ExportError {
    fn from(e: crate::sim::SimError) -> Self {
        Self::Player(e.into())
    }
}

/// How far an export is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Steps done.
    pub done: u32,
    /// Steps in all (framing the span, then rendering it).
    pub total: u32,
}

/// What an export wrote.
#[derive(Clone, Debug)]
pub struct Summary {
    /// Every file written (images, then the sidecar).
    pub files: Vec<PathBuf>,
    /// The sidecar's contents.
    pub sidecar: Sidecar,
}

/// The frames' times: `frames` output frames `interval` apart from `start`. A loop
/// renders `fade` more on each side (from `start − fade·interval`): the last `fade`
/// output frames fade towards the frames before the start, the first `fade` towards
/// the frames after the end, half and half at the seam.
#[derive(Clone, Copy, Debug)]
struct Timeline {
    start_secs: f64,
    interval_secs: f64,
    frames: u32,
    fade: u32,
}

impl Timeline {
    /// Frames rendered.
    fn rendered(&self) -> u32 {
        self.frames + 2 * self.fade
    }

    /// The effect time of rendered frame `r`.
    fn time(&self, r: u32) -> f64 {
        self.start_secs + (f64::from(r) - f64::from(self.fade)) * self.interval_secs
    }

    /// The weight of the frames from the other side of the seam in output frame `j`
    /// (zero outside the fade): ½ at the two frames beside the seam — the seam itself
    /// steps from one half-and-half frame to the next — falling by 1/(2·fade) per frame
    /// away from it.
    fn wrap_weight(&self, j: u32) -> f32 {
        let (n, h) = (self.frames as f32, self.fade as f32);
        let j = j as f32;
        let from_seam = if j < h {
            j
        } else if j >= n - h {
            n - 1.0 - j
        } else {
            return 0.0;
        };
        0.5 - 0.5 * from_seam / h
    }
}

enum Phase {
    /// Simulating the span to sample the particles (a camera that surely sees them all).
    Sampling {
        next: u32,
        samples: framing::Samples,
    },
    /// Rendering the span small through that camera to find what is visible.
    Framing {
        next: u32,
        samples: framing::Samples,
        bounds: framing::Bounds,
        /// The camera that sees every particle of the span.
        wide: framing::Wide,
    },
    /// Rendering frame `next`.
    Rendering {
        next: u32,
    },
    Done,
}

/// An export in progress: call [`Export::step`] until it returns `None`.
pub struct Export {
    ctx: GpuContext,
    settings: ExportSettings,
    player: Player,
    instance: InstanceId,
    timeline: Timeline,
    /// The player's effect time.
    now: f64,
    phase: Phase,
    renderer: Option<FrameRenderer>,
    writer: Writer,
    /// Loop: frames from the other side of the seam, by the output frame they fade
    /// into, kept until that frame is rendered.
    held: std::collections::HashMap<u32, RawFrame>,
    summary: Option<Summary>,
}

impl Export {
    /// Prepares an export of `effect` (PNG sprites relative to `asset_dir`) on `ctx`.
    pub fn new(
        ctx: &GpuContext,
        effect: &Effect,
        asset_dir: Option<PathBuf>,
        settings: ExportSettings,
    ) -> Result<Self, ExportError> {
        settings.validate()?;
        let effect = export_effect(effect);
        let player_settings = PlayerSettings {
            asset_dir,
            adapter_profile: Some(ctx.profile),
            ..PlayerSettings::new(frames::target_format(&ctx.device))
        };
        let mut player = Player::new(&ctx.device, &ctx.queue, &effect, player_settings)?;
        let seed = settings.seed.unwrap_or(effect.seed);
        let instance = player.add_instance(glam::Mat4::IDENTITY, seed)?;
        let timeline = timeline(&effect, &settings);
        let writer = Writer::new(&settings, &effect.name, timeline.frames)?;
        Ok(Self {
            ctx: ctx.clone(),
            player,
            instance,
            timeline,
            now: 0.0,
            phase: Phase::Sampling {
                next: 0,
                samples: framing::Samples::default(),
            },
            renderer: None,
            writer,
            held: std::collections::HashMap::new(),
            summary: None,
            settings,
        })
    }

    /// Steps in all.
    fn total(&self) -> u32 {
        3 * self.timeline.rendered()
    }

    /// Does the next piece of work (one frame framed or rendered, or the files written)
    /// and says how far the export is; `None` once it is finished.
    pub fn step(&mut self) -> Result<Option<Progress>, ExportError> {
        let n = self.timeline.rendered();
        let tl = self.timeline;
        let time = |r: u32| tl.time(r);
        let done = match &mut self.phase {
            Phase::Sampling { next, samples } => {
                frames::advance_to(&self.ctx, &mut self.player, &mut self.now, time(*next));
                samples.add(&self.player.particle_motion(self.instance)?);
                *next += 1;
                let done = *next;
                if done == n {
                    let samples = std::mem::take(samples);
                    self.begin_framing(samples);
                }
                done
            }
            Phase::Framing {
                next,
                samples,
                bounds,
                wide,
            } => {
                frames::advance_to(&self.ctx, &mut self.player, &mut self.now, time(*next));
                if let Some(probe) = self.renderer.as_mut() {
                    bounds.add(&probe.render(&self.ctx, &mut self.player)?, probe.size());
                }
                *next += 1;
                let done = n + *next;
                if *next == n {
                    let camera = match self.settings.camera {
                        CameraMode::Preset => wide.camera(self.settings.frame_size),
                        CameraMode::Fit | CameraMode::Ortho => {
                            wide.cropped(*bounds, self.settings.frame_size)
                        }
                    };
                    let samples = std::mem::take(samples);
                    self.begin_rendering(&samples, camera);
                }
                done
            }
            Phase::Rendering { next } => {
                let k = *next;
                *next += 1;
                self.render_frame(k)?;
                if k + 1 == n {
                    self.finish()?;
                }
                2 * n + k + 1
            }
            Phase::Done => return Ok(None),
        };
        Ok(Some(Progress {
            done,
            total: self.total(),
        }))
    }

    /// A camera that sees every sampled particle whole (or the preset's), and a small
    /// colour-only renderer through it; restarts the player.
    fn begin_framing(&mut self, samples: framing::Samples) {
        let wide = framing::enclosing(self.player.effect(), &samples, self.settings.camera);
        let probe = ExportSettings {
            frame_size: framing::probe_size(self.settings.frame_size),
            passes: Passes::COLOR,
            background: None,
            ..self.settings.clone()
        };
        let camera = wide.camera(probe.frame_size);
        self.renderer = Some(FrameRenderer::new(&self.ctx, camera, &probe));
        self.rewind(false);
        self.phase = Phase::Framing {
            next: 0,
            samples,
            bounds: framing::Bounds::default(),
            wide,
        };
    }

    /// The export's `camera` (for `Fit` and `Ortho`, the wide one cropped to what was
    /// visible, with a margin) and the motion scale; restarts the player.
    fn begin_rendering(&mut self, samples: &framing::Samples, camera: crate::render::Camera) {
        let interval = self.timeline.interval_secs as f32;
        self.writer
            .set_motion_scale(samples.motion_scale(&camera, interval));
        let camera = camera.with_motion_secs(interval);
        self.renderer = Some(FrameRenderer::new(&self.ctx, camera, &self.settings));
        self.rewind(self.settings.passes.motion);
        self.phase = Phase::Rendering { next: 0 };
    }

    /// Back to effect time 0 for the next pass over the span, with or without the
    /// motion pass.
    fn rewind(&mut self, motion: bool) {
        self.player.set_motion_pass(motion);
        self.player.restart();
        self.now = 0.0;
    }

    /// Renders rendered frame `r` and writes the output frame it completes, if any.
    fn render_frame(&mut self, r: u32) -> Result<(), ExportError> {
        let Some(renderer) = self.renderer.as_mut() else {
            return Ok(());
        };
        frames::advance_to(
            &self.ctx,
            &mut self.player,
            &mut self.now,
            self.timeline.time(r),
        );
        let frame = renderer.render(&self.ctx, &mut self.player)?;
        let tl = self.timeline;
        let (n, h) = (tl.frames as i64, tl.fade as i64);
        // The frame's place in the span (negative: before the start).
        let f = i64::from(r) - h;
        // Output frame j, and whether this frame is j's own (else the other side's).
        let (j, own) = if f < 0 {
            (f + n, false)
        } else if f >= n {
            (f - n, false)
        } else {
            (f, true)
        };
        let j = j as u32;
        let w = tl.wrap_weight(j);
        if w == 0.0 {
            return self.output(j, frame);
        }
        // Whichever of the pair comes second completes output frame j.
        let Some(first) = self.held.remove(&j) else {
            self.held.insert(j, frame);
            return Ok(());
        };
        let (mut own_frame, other) = if own { (frame, first) } else { (first, frame) };
        own_frame.blend_towards(&other, w);
        self.output(j, own_frame)
    }

    /// Hands output frame `j` to the writer.
    fn output(&mut self, j: u32, frame: RawFrame) -> Result<(), ExportError> {
        self.writer.write_frame(j, frame)
    }

    /// Writes the atlases and the sidecar. A loop starts after its smallest step
    /// between consecutive frames (every step of a loop is continuous; its seam — last
    /// frame to first — is then its smoothest one).
    fn finish(&mut self) -> Result<(), ExportError> {
        let t = self.writer.drain()?.to_vec();
        let n = t.len();
        // steps[j]: frame j → frame j + 1 (around the loop).
        let steps: Vec<f64> = (0..n)
            .map(|j| encode::mean_difference(&t[j], &t[(j + 1) % n]))
            .collect();
        let first = if self.settings.looped && n > 1 {
            let smallest = (0..n)
                .min_by(|&a, &b| steps[a].total_cmp(&steps[b]))
                .unwrap_or(n - 1);
            (smallest + 1) % n
        } else {
            0
        };
        let seam_step = (first + n - 1) % n.max(1);
        let mut consecutive: Vec<f64> = (0..n.saturating_sub(1))
            .map(|k| steps[(first + k) % n])
            .collect();
        let seam = sidecar::Seam {
            last_to_first: if n > 1 { steps[seam_step] } else { 0.0 },
            median_consecutive: encode::median(&mut consecutive),
        };
        let start_secs = self.timeline.start_secs + first as f64 * self.timeline.interval_secs;
        let effect = self.player.effect();
        let sidecar = Sidecar::new(
            effect,
            &self.settings,
            self.timeline.frames,
            start_secs,
            self.timeline.interval_secs,
            self.writer.motion_scale(),
            self.settings.seed.unwrap_or(effect.seed),
            seam,
        );
        let files = self
            .writer
            .finish(&sidecar, self.timeline.frames, first as u32)?;
        self.summary = Some(Summary { files, sidecar });
        self.phase = Phase::Done;
        Ok(())
    }

    /// What the export wrote, once it is finished.
    pub fn summary(&self) -> Option<&Summary> {
        self.summary.as_ref()
    }

    /// The colour atlas (flipbook) or the last frame (sequence) so far, 8-bit sRGB with
    /// its alpha: the editor's preview.
    pub fn preview(&self) -> Option<image::RgbaImage> {
        self.writer.preview()
    }
}

/// Runs an export to the end, reporting progress after every step.
pub fn run(
    ctx: &GpuContext,
    effect: &Effect,
    asset_dir: Option<PathBuf>,
    settings: ExportSettings,
    mut on_progress: impl FnMut(Progress),
) -> Result<Summary, ExportError> {
    let mut export = Export::new(ctx, effect, asset_dir, settings)?;
    while let Some(p) = export.step()? {
        on_progress(p);
    }
    export
        .summary
        .ok_or_else(|| ExportError::Invalid("the export did not finish".into()))
}

/// The effect as exported: every emitter drawn as billboards (the motion pass draws
/// them; the compute splat has no motion), the blended layer at full resolution, no
/// bloom (a host's post effect, not the particles').
pub fn export_effect(effect: &Effect) -> Effect {
    let mut e = effect.clone();
    for em in &mut e.emitters {
        em.look.draw_path = DrawPath::Billboard;
    }
    e.post.alpha_downscale = 1;
    e.post.glow_downscale = 1;
    e.post.bloom = None;
    e
}

/// Memory a loop's fade may hold in frames waiting for their partners.
const HELD_BYTES: u64 = 1 << 30;

/// The frames' times for `settings`: a loop starts warm (past the longest lifetime,
/// fade frames included) and fades over a quarter of its frames on each side of the
/// seam (at most 16, and as many as [`HELD_BYTES`] hold).
fn timeline(effect: &Effect, settings: &ExportSettings) -> Timeline {
    let frames = settings.frame_count();
    let interval_secs = settings.interval_secs();
    let longest = effect.longest_lifetime_secs();
    // Frames held at once: up to 2·fade, each 16 bytes a pixel and pass.
    let (w, h) = settings.frame_size;
    let passes = settings.passes.names().len().max(1) as u64;
    let frame_bytes = u64::from(w) * u64::from(h) * 16 * passes;
    let by_memory = ((HELD_BYTES / frame_bytes.max(1)) / 2).max(1) as u32;
    let fade = if settings.looped {
        (frames / 4).clamp(1, 16).min(by_memory)
    } else {
        0
    };
    let warm = 1.25 * longest + f64::from(fade) * interval_secs;
    let start_secs = if settings.looped {
        settings.start_secs.max(warm)
    } else {
        settings.start_secs
    };
    Timeline {
        start_secs,
        interval_secs,
        frames,
        fade,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A loop fades over a quarter of its frames on each side of the seam, at most 16,
    /// and no more than `HELD_BYTES` of held frames (16 bytes a pixel and pass, two frames
    /// held per fade frame): 2048² frames of two passes hold 8.
    #[test]
    fn a_loops_fade_is_a_quarter_of_its_frames_within_the_memory_it_may_hold() {
        let effect = Effect::default_campfire();
        let mut settings = ExportSettings::new("out".into());
        settings.looped = true;
        settings.frames = Some(40);
        settings.frame_size = (64, 64);
        assert_eq!(timeline(&effect, &settings).fade, 10);
        settings.frames = Some(200);
        assert_eq!(timeline(&effect, &settings).fade, 16);
        settings.frame_size = (2048, 2048);
        settings.passes.color = true;
        settings.passes.emissive = true;
        settings.passes.motion = false;
        settings.passes.sixway = false;
        settings.passes.distortion = false;
        let held = u64::from(timeline(&effect, &settings).fade) * 2 * 2048 * 2048 * 16 * 2;
        assert_eq!(held, HELD_BYTES, "8 fade frames");
        settings.looped = false;
        assert_eq!(timeline(&effect, &settings).fade, 0);
    }
}
