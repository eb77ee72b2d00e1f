//! [`EffectLight`]: the light an instance's fire gives its scene, estimated each frame
//! from the additive particles alive (the GPU sums their emitted light and its
//! luminance-weighted moments; `render::light`) and read back a frame or two later.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use super::{InstanceId, Player};
use crate::gpu::{GpuContext, Uploads};
use crate::render::DrawItem;
use crate::render::Scene;
use crate::render::frame::FrameResources;
use crate::render::light::{LightPass, LightSums};
use crate::render::light_apply::SelfLightPass;
use crate::shaders::{ShaderError, ShaderLibrary};

/// The light of one instance, as a point light a host can place in its scene.
///
/// Estimated from the additive (emissive) particles alive in a recent frame: each
/// particle's emitted light E = colour × alpha × opacity × intensity × its sprite's area
/// (m², the sprite's brightness integrated over the quad); the light sits at the
/// luminance-weighted centroid of the particles, and flickers as they do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EffectLight {
    /// The light-weighted centroid of the particles, in the host's world (metres).
    pub position: Vec3,
    /// The light's colour, linear RGB with its largest channel 1.
    pub color: [f32; 3],
    /// Its power: the summed luminance of the emitted light (HDR colour × m²). A host
    /// scales it to its own light units (Bevy's lumens, a renderer's watts).
    pub power: f32,
    /// The emitted light per channel (linear RGB × m²; `color` × the largest of them).
    pub rgb_power: [f32; 3],
    /// How far the light is spread: the luminance-weighted RMS distance of the particles
    /// from `position` (metres; an area light's radius, or a point light's softening).
    pub radius_m: f32,
}

/// Who a light total belongs to: the instance and the emitter's simulation origin.
pub(super) type LightOwner = (InstanceId, DVec3);

/// The estimate's state in a player: the pass (built on first need) and the latest
/// lights.
#[derive(Default)]
pub(super) struct LightEstimate {
    pub pass: Option<LightPass<LightOwner>>,
    /// The lit layers' share of the light (built with `pass`).
    pub apply: Option<SelfLightPass>,
    /// Why the passes could not be built (logged once; not tried again until a reload of
    /// their shaders).
    pub error: Option<String>,
    pub on: bool,
    pub latest: HashMap<InstanceId, EffectLight>,
}

impl Player {
    /// Estimates each instance's light from now on (`on`), read with
    /// [`Player::effect_light`]: a small compute pass per additive emitter and a readback
    /// that never stalls (the light of a frame arrives one or two frames later). Off by
    /// default.
    pub fn set_light_estimate(&mut self, on: bool) {
        self.light.on = on;
        if !on {
            self.light.latest.clear();
        }
    }

    /// Instance `id`'s light as last read back (see [`EffectLight`]); `None` before the
    /// first readback, with the estimate off, or for an instance with no light alive.
    pub fn effect_light(&self, id: InstanceId) -> Option<EffectLight> {
        self.light.latest.get(&id).copied()
    }

    /// Why the effect light cannot be estimated, naming the file: its passes failed to
    /// build from the player's shaders or on this device (then [`Player::effect_light`] is
    /// `None` and lit layers are drawn without their effect's own light). `None` while
    /// they work or before they are first needed. [`Player::reload_shader`] of
    /// `light.wgsl` or `light_apply.wgsl` builds them again.
    pub fn light_estimate_error(&self) -> Option<&str> {
        self.light.error.as_deref()
    }
}

/// What the light pass reads of a player's frame.
pub(super) struct LightFrame<'a> {
    pub ctx: &'a GpuContext,
    pub library: &'a ShaderLibrary,
    pub frame: &'a FrameResources,
    pub items: &'a [DrawItem],
    /// The host's world from the preset's (`PlayerSettings::world_up`).
    pub host: Option<glam::Quat>,
}

impl LightEstimate {
    /// Records the light pass when the estimate is on or a lit layer is drawn (after
    /// `frame.prepare`, before the draws): collects finished readbacks, asks for the last
    /// record's maps, records this frame's sums and their readback (the estimate), and
    /// hands the lit layers their share on the GPU (`light_apply`).
    pub(super) fn record(
        &mut self,
        f: &LightFrame<'_>,
        enc: &mut wgpu::CommandEncoder,
        uploads: &mut Uploads,
        owners: &[Option<LightOwner>],
    ) {
        let lit = f.items.iter().any(|d| d.variant.lit);
        if (!self.on && !lit) || self.error.is_some() {
            return;
        }
        if self.pass.is_none() || self.apply.is_none() {
            match build(f.ctx, f.library, f.frame) {
                Ok((p, a)) => (self.pass, self.apply) = (Some(p), Some(a)),
                Err(e) => return self.failed_with(&e),
            }
        }
        let Some(pass) = self.pass.as_mut() else {
            return;
        };
        let owner = |slot: usize| owners.get(slot).copied().flatten();
        let readback: Option<&dyn Fn(usize) -> Option<LightOwner>> = match self.on {
            true => Some(&owner),
            false => None,
        };
        if self.on {
            if let Some(sums) = pass.collect(f.ctx) {
                self.latest = lights(&sums, f.host);
            }
            pass.map_recorded();
        }
        // Every upload first, then the sums, their totals and the apply in one pass.
        let totals = pass.prepare(f.ctx, (enc, uploads), f.items);
        let apply = match (lit, self.apply.as_mut(), pass.sums_buffer()) {
            (true, Some(apply), Some(sums)) => apply
                .prepare(f.ctx, (enc, uploads), f.frame, f.items, &totals, sums)
                .then_some(&*apply),
            _ => None,
        };
        if !totals.is_empty() || apply.is_some() {
            let mut compute = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("LightPass"),
                timestamp_writes: None,
            });
            pass.dispatch(&mut compute, f.frame, f.items);
            if let Some(apply) = apply {
                apply.dispatch(&mut compute);
            }
        }
        if let Some(owner) = readback {
            pass.record_readback(enc, f.items, owner);
        }
    }

    /// Whether a frame's light is read back: the estimate is on and its passes built.
    pub(super) fn reads_back(&self) -> bool {
        self.on && self.error.is_none()
    }

    /// Stops the estimate after its passes could not be built, saying why (a reload of
    /// their shaders tries again).
    fn failed_with(&mut self, why: &ShaderError) {
        log::error!(
            "the effect light cannot be estimated (lit layers are drawn without it): {why}"
        );
        self.error = Some(why.to_string());
    }

    /// Rebuilds the pass `entry` names (`light.wgsl` or `light_apply.wgsl`) from `lib`;
    /// after a failure, builds both anew, and the error goes when they build.
    pub(super) fn reload(
        &mut self,
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        frame: &FrameResources,
        entry: &str,
    ) -> Result<(), ShaderError> {
        match (&mut self.pass, &mut self.apply) {
            (Some(pass), _) if entry == "light.wgsl" => pass.rebuild(ctx, lib),
            (_, Some(apply)) if entry == "light_apply.wgsl" => apply.rebuild(ctx, lib),
            _ if self.error.is_some() => {
                let (pass, apply) = build(ctx, lib, frame)?;
                (self.pass, self.apply, self.error) = (Some(pass), Some(apply), None);
                Ok(())
            }
            // Built on first need, from the reloaded shaders.
            _ => Ok(()),
        }
    }
}

/// The light's passes, built in an error scope: whatever the host's device refuses is
/// returned, not a panic in its error handler.
fn build(
    ctx: &GpuContext,
    lib: &ShaderLibrary,
    frame: &FrameResources,
) -> Result<(LightPass<LightOwner>, SelfLightPass), ShaderError> {
    let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let built =
        LightPass::new(ctx, lib, frame).and_then(|p| Ok((p, SelfLightPass::new(ctx, lib)?)));
    let refused = pollster::block_on(scope.pop());
    match (built, refused) {
        (Ok(passes), None) => Ok(passes),
        (Err(e), _) => Err(e),
        (_, Some(e)) => Err(ShaderError::Pipeline {
            file: "light.wgsl, light_apply.wgsl".into(),
            message: e.to_string(),
        }),
    }
}

/// Each instance's light from its emitters' sums.
fn lights(
    sums: &[(LightOwner, LightSums)],
    host: Option<glam::Quat>,
) -> HashMap<InstanceId, EffectLight> {
    // Σ E.rgb, Σ Y, Σ Y·p, Σ Y·|p|² in world space, per instance (f64).
    let mut totals: HashMap<InstanceId, ([f64; 3], f64, DVec3, f64)> = HashMap::new();
    for ((id, origin), s) in sums {
        let t = totals.entry(*id).or_default();
        let y = f64::from(s[3]);
        let yp = DVec3::new(f64::from(s[4]), f64::from(s[5]), f64::from(s[6]));
        for (sum, add) in t.0.iter_mut().zip(s) {
            *sum += f64::from(*add);
        }
        t.1 += y;
        t.2 += yp + *origin * y;
        t.3 += f64::from(s[7]) + 2.0 * origin.dot(yp) + origin.length_squared() * y;
    }
    totals
        .into_iter()
        .filter(|(_, t)| t.1 > 0.0)
        .map(|(id, (rgb, y, yp, ypp))| {
            let centre = yp / y;
            let spread = (ypp / y - centre.length_squared()).max(0.0).sqrt();
            let peak = rgb.iter().copied().fold(0.0, f64::max).max(1e-30);
            let position = centre.as_vec3();
            let light = EffectLight {
                position: host.map_or(position, |q| q * position),
                color: rgb.map(|c| (c / peak) as f32),
                power: y as f32,
                rgb_power: rgb.map(|c| c as f32),
                radius_m: spread as f32,
            };
            (id, light)
        })
        .collect()
}

/// Who each look slot of a frame measures, for the light estimate: the instance and the
/// emitter's simulation origin, in the order `FrameResources::prepare` gives the slots
/// (each group's emitters in turn, each with the group's members).
pub(super) fn light_owners(
    groups: &[Vec<Option<Scene<'_>>>],
    ids: &[Vec<Option<InstanceId>>],
) -> Vec<Option<LightOwner>> {
    let mut owners = Vec::new();
    for (group, ids) in groups.iter().zip(ids) {
        let emitters = group
            .iter()
            .flatten()
            .next()
            .map_or(0, |s| s.effect.emitters.len());
        for e in 0..emitters {
            for (scene, id) in group.iter().zip(ids) {
                owners.push(scene.as_ref().zip(*id).map(|(s, id)| {
                    let origin = s.sim.planner().emitters.get(e).map(|p| p.origin());
                    (id, origin.unwrap_or_default())
                }));
            }
        }
    }
    owners
}
