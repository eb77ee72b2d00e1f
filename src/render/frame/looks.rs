//! The look slots of a frame: each emitter's `LookUniform` (its settings, then each
//! instance's place, ring and sort) and a lit layer's `LitUniform` after it.

use crate::effect::{BlendMode, Effect, FlipbookMode, Look, Streak};
use crate::gpu::types::{LookUniform, PARAMS_STRIDE};
use crate::render::look_bake::ROWS_PER_EMITTER;
use crate::render::scene_lighting::{LitUniform, SceneLighting, write_lit};
use crate::render::sort::SortMember;
use crate::render::sprites::SpriteTexture;
use crate::sim::Modules;

use super::{FrameResources, GroupView};
use crate::render::draw_item::Scene;

/// A lit layer's quads keep texels down to the trim threshold over this gain: its light
/// (sun, flames, host lights) has no bound known when the look is built. The built-in
/// puff ends at its sphere, so the cut does not depend on it.
const LIT_TRIM_GAIN: f32 = 256.0;

/// Emitter `i` across a group's instances (`FrameResources::group_looks`).
pub(super) struct GroupLooks<'s> {
    /// Each instance's look (`None`: the instance has no such emitter or nothing alive).
    pub(super) looks: Vec<Option<LookUniform>>,
    /// Each instance's part of the sort (alpha-blended emitters).
    pub(super) members: Vec<SortMember>,
    /// The pool the instances' segments are in.
    pub(super) pool: Option<crate::sim::gpu_sim::EmitterBuffers<'s>>,
    /// The nearest instance's distance from the camera (m).
    pub(super) distance: f32,
}

/// Emitter `index` as every instance of a group has it (their emitters and events are
/// the player's): whether it is stateless, and the colour ramp row + 1 of the parent it
/// inherits its colour from (0: none).
pub(super) struct GroupEmitter {
    pub(super) index: usize,
    pub(super) stateless: bool,
    color_row: u32,
}

impl GroupEmitter {
    /// Emitter `i` of `effect`.
    pub(super) fn of(effect: &Effect, i: usize) -> Self {
        Self {
            index: i,
            stateless: Modules::in_effect(effect, i).contains(Modules::STATELESS),
            color_row: effect
                .color_parent(i)
                .map_or(0, |p| ROWS_PER_EMITTER * p as u32 + 1),
        }
    }
}

/// Writes the draw's looks into `block` (one per instance, at `PARAMS_STRIDE`), each with
/// the draw's widest window `width`; a missing instance gets an empty segment of its pool
/// of `capacity` slots (no window, nothing drawn).
pub(super) fn write_looks(
    block: &mut [u8],
    looks: &[Option<LookUniform>],
    width: u32,
    capacity: u32,
) {
    for (k, u) in looks.iter().enumerate() {
        let mut u = u.unwrap_or(LookUniform {
            ring_b: [0, 0, capacity, 0],
            ..LookUniform::default()
        });
        u.ring[3] = width;
        block[k * PARAMS_STRIDE as usize..][..size_of::<LookUniform>()]
            .copy_from_slice(bytemuck::bytes_of(&u));
    }
}

/// The look uniform of an emitter (everything but the matrices, the ground height and
/// stateless motion, which depend on the frame). `ramp_row` is the emitter's colour ramp
/// row (its curve rows follow it), `salt` its per-particle random salt, `sprite_integral` the sprite's ∫ brightness.
pub fn look_uniform(look: &Look, ramp_row: u32, salt: u32, sprite_integral: f32) -> LookUniform {
    let (rows, cols, mode, fps, random_start) = match &look.flipbook {
        Some(f) => {
            let (mode, fps) = match f.mode {
                FlipbookMode::OverLife => (0, 0.0),
                FlipbookMode::FrameRate { fps } => (1, fps),
                FlipbookMode::Frames(_) => (2, 0.0),
            };
            (
                f.rows.max(1),
                f.cols.max(1),
                mode,
                fps,
                u32::from(f.random_start),
            )
        }
        None => (1, 1, 0, 0.0, 0),
    };
    let blend = match look.blend {
        BlendMode::Additive => 0,
        BlendMode::Alpha => 1,
    };
    let streak = look.streak.unwrap_or(Streak {
        length_secs: 0.0,
        max_length_m: 0.0,
    });
    let inv_soft = if look.soft_ground_m > 0.0 {
        1.0 / look.soft_ground_m
    } else {
        0.0
    };
    LookUniform {
        // x, y: the trail's width and opacity at its tail (fractions; trail.wgsl).
        size_intensity: [
            look.trail.as_ref().map_or(1.0, |t| t.tail_width),
            look.trail.as_ref().map_or(1.0, |t| t.tail_opacity),
            look.intensity,
            // w: heat haze's strength (billboard.wgsl HAZE).
            look.heat_haze.map_or(0.0, |h| h.strength),
        ],
        ids: [ramp_row, blend, rows, cols],
        flags: [mode, random_start, salt, 0],
        extra: [
            sprite_integral,
            // y: heat haze's ripples per sprite.
            look.heat_haze.map_or(0.0, |h| h.frequency),
            look.rotation_random_deg.to_radians(),
            fps,
        ],
        // x: the trail's width (× the particle's size; trail.wgsl), y: heat haze's speed.
        spin_streak: [
            look.trail.as_ref().map_or(0.0, |t| t.width),
            look.heat_haze.map_or(0.0, |h| h.speed_hz),
            streak.length_secs,
            streak.max_length_m,
        ],
        soft: [0.0, inv_soft, 0.0, 0.0],
        trim: [0.0, 0.0, 1.0, 1.0],
        ..LookUniform::default()
    }
}

impl FrameResources {
    /// Emitter `i`'s look of every instance (its salt, place and ring are set per
    /// instance by `member_look`): the look's settings and the sprite's trim, and the
    /// share of its rectangle the trim's octagon draws (none for a streak, or with
    /// trimming off).
    pub(super) fn base_look(
        &mut self,
        effect: &Effect,
        i: usize,
        sprite: &SpriteTexture,
    ) -> (LookUniform, Option<f32>) {
        let e = &effect.emitters[i];
        let mut u = look_uniform(&e.look, ROWS_PER_EMITTER * i as u32, 0, sprite.integral);
        if !self.trim_sprites || e.look.streak.is_some() {
            return (u, None);
        }
        // Six-way maps hold two images side by side (RTBA | LBFE): every frame of either
        // counts, as frames of a sheet twice as wide.
        let lit = e.look.lit.is_some() && e.look.blend == BlendMode::Alpha;
        let (rows, cols) = e
            .look
            .flipbook
            .as_ref()
            .map_or((1, 1), |f| (f.rows, f.cols));
        let cols = if lit { 2 * cols } else { cols };
        // What is invisible at intensity 1 shows when the light is multiplied; a lit
        // layer's light has no bound known here, so it keeps what is nearly black.
        let gain = (e.look.intensity * effect.post.exposure).max(1.0);
        let gain = if lit { gain * LIT_TRIM_GAIN } else { gain };
        let threshold = crate::render::sprites::TRIM_THRESHOLD / gain;
        let (rect, cuts, share) = *self
            .trims
            .entry((sprite.id, rows, cols, threshold.to_bits()))
            .or_insert_with(|| {
                let t = sprite.trim(rows, cols, threshold);
                (t.rect, t.packed_cuts(), t.octagon_share())
            });
        u.trim = rect;
        u.tiny_c[3] = cuts;
        (u, Some(share))
    }

    /// Writes lit emitter `i`'s `LitUniform` of every instance of the group into `block`
    /// (each in its simulation space; the effect's own light is added on the GPU).
    pub(super) fn write_lit_looks(
        &self,
        view: &GroupView<'_, '_>,
        i: usize,
        lit: &crate::effect::Lit,
        block: &mut [u8],
    ) {
        for (k, scene) in view.group.iter().enumerate() {
            let Some(scene) = scene else {
                continue;
            };
            let own;
            let lighting = match &self.lighting {
                Some(l) => l,
                None => {
                    own = SceneLighting::from(&scene.effect.lighting);
                    &own
                }
            };
            let origin =
                (scene.sim.planner().emitters.get(i)).map_or(glam::DVec3::ZERO, |p| p.origin());
            let u = LitUniform::new(lit, lighting, origin);
            write_lit(
                &mut block[k * PARAMS_STRIDE as usize..][..PARAMS_STRIDE as usize],
                &u,
            );
        }
    }

    /// Emitter `i`'s look uniform of one instance, from the group's `base`, its pool and
    /// its part of the group's sort (`None`: no pool).
    fn member_look<'s>(
        &self,
        view: &GroupView<'_, '_>,
        scene: &Scene<'s>,
        emitter: &GroupEmitter,
        base: &LookUniform,
    ) -> Option<(
        LookUniform,
        crate::sim::gpu_sim::EmitterBuffers<'s>,
        SortMember,
    )> {
        let (sim, effect, i) = (scene.sim, scene.effect, emitter.index);
        let e = effect.emitters.get(i)?;
        let origin = sim
            .planner()
            .emitters
            .get(i)
            .map(|p| p.origin())
            .unwrap_or_default();
        let mut u = *base;
        u.flags[2] = crate::rng::pcg4d([effect.seed, i as u32, e.seed_offset, 0x5EED_100C])[0];
        u.clip_from_sim = view.camera.clip_from_sim(origin).to_cols_array_2d();
        let ground = e.collisions.ground.as_ref().map_or(0.0, |g| g.height_m);
        u.soft[0] = (f64::from(ground) - origin.y) as f32;
        if emitter.stateless {
            // Closed-form evaluation at the render time (between the last two steps).
            let planner = sim.planner();
            let t = planner.time_secs - (1.0 - view.alpha as f64) * planner.last_dt_secs as f64;
            let a = e.forces.constant_acceleration();
            let w = e.forces.wind_m_per_s;
            u.motion_a = [a.x, a.y, a.z, e.forces.drag_per_sec];
            u.motion_b = [w[0], w[1], w[2], t.rem_euclid(4096.0) as f32];
        }
        let mut b = sim.emitter_buffers(i)?;
        if !self.live_window_only {
            b.window = crate::sim::planner::LiveWindow::all(b.capacity);
        }
        // The ring, for packed state's re-derived lifetimes; the capacity and the live
        // window's length (ring_b.zw) place the draws' and the splat's invocations.
        u.soft[2] = b.life_range.0;
        u.soft[3] = b.life_range.1;
        u.ring = [
            (b.spawned_total % u64::from(b.capacity.max(1))) as u32,
            b.spawned_total as u32,
            (b.spawned_total >> 32) as u32,
            0,
        ];
        // w: the live window's length (it ends at the ring's head, ring.x).
        u.ring_b = [b.seed_salt.0, b.seed_salt.1, b.capacity, b.window.len];
        // The octagon's cuts (tiny_c.w) are the sprite's, set in the base look.
        let cuts = u.tiny_c[3];
        [u.tiny, u.tiny_b, u.tiny_c] = b.tiny;
        u.tiny_c[3] = cuts;
        // The trail's newest entries are from before the last step (trail.wgsl).
        u.tiny_c[1] = b.last_step;
        // An emitter that inherits its parent's colour: the parent's ramp row + 1.
        u.tiny_c[2] = emitter.color_row;
        u.flags[3] = b.slot_base;
        // The window ends at the ring's head (u.ring[0]).
        let cap = b.capacity.max(1);
        let sort = SortMember {
            eye: (view.camera.eye_f64() - origin)
                .as_vec3()
                .extend(0.0)
                .to_array(),
            window: [
                (u.ring[0] + cap - b.window.len.min(cap)) % cap,
                b.window.len,
                b.slot_base,
                0,
            ],
        };
        Some((u, b, sort))
    }

    /// Emitter `i`'s look in every instance of the group (from `base`), each instance's
    /// sort member, the pool the instances share and the nearest instance's distance from
    /// the camera (it decides the projected size, and so the path).
    pub(super) fn group_looks<'s>(
        &self,
        view: &GroupView<'_, 's>,
        emitter: &GroupEmitter,
        base: &LookUniform,
    ) -> GroupLooks<'s> {
        let i = emitter.index;
        let mut out = GroupLooks {
            looks: Vec::with_capacity(view.group.len()),
            members: Vec::new(),
            pool: None,
            distance: f32::INFINITY,
        };
        for scene in view.group {
            let Some((scene, (u, b, sort))) = scene
                .as_ref()
                .and_then(|s| Some((s, self.member_look(view, s, emitter, base)?)))
            else {
                out.looks.push(None);
                out.members.push(SortMember::default());
                continue;
            };
            let placed = glam::Vec3::from(scene.effect.emitters[i].transform.position_m);
            out.distance = out.distance.min((view.camera.eye() - placed).length());
            out.members.push(sort);
            out.looks.push(Some(u));
            out.pool.get_or_insert(b);
        }
        out
    }
}
