//! A look inside the particles: the one under a pixel, and what acts on it now — its
//! slot, age, lifetime, position, velocity and each force's share of its acceleration,
//! evaluated with the CPU mirror of the update's force model (`cpu_reference::Forces`).

use glam::{DVec3, Vec2, Vec3};

use crate::gpu::types::Particle;
use crate::render::Camera;
use crate::sim::cpu_reference::Forces;
use crate::sim::modules::Modules;

use super::{InstanceId, Player, PlayerError};

/// One particle, looked at closely.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleInfo {
    /// The emitter (its index in the effect).
    pub emitter: usize,
    /// Its slot in the emitter's pool.
    pub slot: u32,
    /// Age, seconds.
    pub age_secs: f32,
    /// Lifetime, seconds.
    pub lifetime_secs: f32,
    /// Position in the host's world, metres.
    pub position_m: Vec3,
    /// Velocity, m/s.
    pub velocity_m_per_s: Vec3,
    /// Each force's acceleration on it now (m/s²), by name, then their sum (`total`).
    pub forces: Vec<(&'static str, Vec3)>,
}

/// The modules that add a force of their own, and their names.
const FORCE_MODULES: [(Modules, &str); 6] = [
    (Modules::DRAG, "drag"),
    (Modules::QUADRATIC_DRAG, "quadratic drag"),
    (Modules::TURBULENCE, "turbulence"),
    (Modules::VORTEX, "vortex"),
    (Modules::ATTRACTOR, "attractor"),
    (Modules::FLAME_PULL, "flame pull"),
];

impl Player {
    /// The living particle of instance `id` nearest to `pixel` on `camera`'s screen,
    /// within `radius_px` (a blocking readback of its pools).
    pub fn pick_particle(
        &self,
        id: InstanceId,
        camera: &Camera,
        pixel: Vec2,
        radius_px: f32,
    ) -> Result<Option<ParticleInfo>, PlayerError> {
        let clip_from_world = self.preset_camera(camera).clip_from_world_mat4();
        let (w, h) = camera.size_px();
        let size = Vec2::new(w as f32, h as f32);
        let mut best: Option<(f32, usize, u32)> = None;
        for (e, origin) in self.origins(id)?.into_iter().enumerate() {
            if !self.effect.emitters[e].enabled || self.effect.emitters[e].stateless {
                continue;
            }
            for (slot, p) in self.particles(id, e)?.iter().enumerate() {
                if !p.is_alive() {
                    continue;
                }
                let clip = clip_from_world * (p.position() + origin).extend(1.0);
                if clip.w <= 0.0 {
                    continue;
                }
                let ndc = clip.truncate() / clip.w;
                let at = Vec2::new((ndc.x + 1.0) * 0.5, (1.0 - ndc.y) * 0.5) * size;
                let d = at.distance(pixel);
                if d <= radius_px && best.is_none_or(|(b, _, _)| d < b) {
                    best = Some((d, e, slot as u32));
                }
            }
        }
        match best {
            Some((_, e, slot)) => self.inspect_particle(id, e, slot),
            None => Ok(None),
        }
    }

    /// Particle `slot` of emitter `emitter` in instance `id`, if it is alive (`None` also
    /// for an emitter or slot the effect does not have).
    pub fn inspect_particle(
        &self,
        id: InstanceId,
        emitter: usize,
        slot: u32,
    ) -> Result<Option<ParticleInfo>, PlayerError> {
        // The instance's own emitter: its seed, and its place in the world.
        let placed = self.instance_effect(id).ok_or(PlayerError::NoInstance)?;
        let Some(e) = placed.emitters.get(emitter) else {
            return Ok(None);
        };
        let particles = self.particles(id, emitter)?;
        let Some(p) = particles.get(slot as usize).filter(|p| p.is_alive()) else {
            return Ok(None);
        };
        let seed = placed.seed;
        let params = self
            .with_state(id, |s| {
                let planner = s.planner();
                planner
                    .emitters
                    .get(emitter)
                    .map(|ep| ep.params_now(e, seed, emitter as u32, planner.time_secs))
            })
            .flatten()
            .ok_or(PlayerError::NoInstance)?;
        let origin = Vec3::from_slice(&self.origins(id)?[emitter].to_array());
        Ok(Some(ParticleInfo {
            emitter,
            slot,
            age_secs: p.pos_age[3],
            lifetime_secs: p.vel_life[3],
            position_m: self.to_host(p.position() + origin),
            velocity_m_per_s: self.to_host(p.velocity()),
            forces: forces_on(
                p,
                &params,
                Modules::of(e),
                over_life_now(e, p, &params, slot),
            )
            .into_iter()
            .map(|(name, f)| (name, self.to_host(f)))
            .collect(),
        }))
    }

    /// Each emitter's simulation-space origin in instance `id`.
    pub(super) fn origins(&self, id: InstanceId) -> Result<Vec<Vec3>, PlayerError> {
        self.with_state(id, |s| {
            (0..self.effect.emitters.len())
                .map(|i| {
                    let p = s.planner().emitters.get(i);
                    p.map_or(Vec3::ZERO, |p| p.origin().as_vec3())
                })
                .collect()
        })
        .ok_or(PlayerError::NoInstance)
    }
}

/// The particle's over-life multipliers at its age now (as the update's next step reads
/// them), or 1 where the emitter has no curves.
fn over_life_now(
    e: &crate::effect::Emitter,
    p: &Particle,
    params: &crate::gpu::types::SimParams,
    slot: u32,
) -> [f32; 4] {
    if !Modules::of(e).contains(Modules::CURVES) {
        return [1.0; 4];
    }
    let rows = crate::sim::modules::bake_over_life(e);
    let life = p.vel_life[3];
    crate::sim::cpu_reference::over_life_at(&rows, p.pos_age[3] / life, params, slot, life)
}

/// Each force's share of `p`'s acceleration: the constant part (gravity and buoyancy),
/// then every module on (gusts ride on the drag), then the sum; `over_life` scales them
/// as the update does.
fn forces_on(
    p: &Particle,
    params: &crate::gpu::types::SimParams,
    on: Modules,
    over_life: [f32; 4],
) -> Vec<(&'static str, Vec3)> {
    let pos = p.position().as_dvec3();
    let vel = p.velocity().as_dvec3();
    let (age, life) = (f64::from(p.pos_age[3]), f64::from(p.vel_life[3]));
    let time = f64::from(params.wind_time[3]);
    let accel = |modules: Modules| -> DVec3 {
        Forces {
            params,
            modules,
            over_life,
        }
        .acceleration(pos, vel, age, life, time)
    };
    let base = accel(Modules::default());
    let gusts = if on.contains(Modules::GUSTS) {
        Modules::GUSTS
    } else {
        Modules::default()
    };
    let mut out = vec![("gravity + buoyancy", base.as_vec3())];
    for (m, name) in FORCE_MODULES {
        if on.contains(m) {
            out.push((name, (accel(m.with(gusts)) - base).as_vec3()));
        }
    }
    out.push(("total", accel(on).as_vec3()));
    out
}
