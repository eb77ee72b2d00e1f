//! Each step's parameter block (`SimParams`) from an emitter's settings: what the planner uploads.

use super::*;

/// WGSL's `mix`: `a·(1 − t) + b·t`.
pub fn mix(a: f32, b: f32, t: f32) -> f32 {
    a * (1.0 - t) + b * t
}

impl SimParams {
    /// The fields one step sets: its size, start time (the noise's), and spawns.
    pub(super) fn set_step(
        &mut self,
        dt_secs: f32,
        t0_secs: f64,
        spawn_base: u64,
        spawn_count: u32,
    ) {
        self.dt_secs = dt_secs;
        // Noise time wraps every 4096 s so the f32 never grows large.
        self.wind_time[3] = t0_secs.rem_euclid(4096.0) as f32;
        self.spawn_head = (spawn_base % u64::from(self.capacity.max(1))) as u32;
        self.spawn_count = spawn_count;
        self.spawn_base_lo = spawn_base as u32;
        self.spawn_base_hi = (spawn_base >> 32) as u32;
    }
}

/// The part of an emitter's block that no step changes (its step fields are zero; see
/// `SimParams::set_step`).
pub(super) fn static_params(
    e: &Emitter,
    origin: glam::DVec3,
    seed: u32,
    salt: u32,
    capacity: u32,
) -> SimParams {
    let (shape_a, shape_b) = shape_params(&e.shape);
    let dir = glam::Vec3::from(e.direction).normalize_or(glam::Vec3::Y);
    // Translation relative to the simulation origin, computed in f64.
    let mut world = e.transform.world_from_emitter();
    let rel = (glam::Vec3::from(e.transform.position_m).as_dvec3() - origin).as_vec3();
    world.w_axis = rel.extend(1.0);
    let world_dir = world.transform_vector3(dir).normalize_or(glam::Vec3::Y);
    let accel = e.forces.constant_acceleration();
    let wind = e.forces.wind_m_per_s;
    let n = &e.spawn_noise;
    let mut p = SimParams {
        world_from_emitter: world.to_cols_array_2d(),
        shape_a,
        shape_b,
        direction_spread: [dir.x, dir.y, dir.z, e.spread_deg.to_radians()],
        speed_life: [
            e.speed_m_per_s.min,
            e.speed_m_per_s.max,
            e.lifetime_secs.min,
            e.lifetime_secs.max,
        ],
        accel_drag: [accel.x, accel.y, accel.z, e.forces.drag_per_sec],
        wind_time: [wind[0], wind[1], wind[2], 0.0],
        noise: [
            n.frequency_per_m,
            n.position_amplitude_m,
            n.direction_amplitude,
            n.scroll_per_sec,
        ],
        seed,
        emitter_salt: salt,
        shape_kind: e.shape.kind_index(),
        capacity,
        axis_origin: rel.extend(0.0).to_array(),
        axis_dir: [world_dir.x, world_dir.y, world_dir.z, 0.0],
        update_window: [0, capacity, 0, 0],
        ..SimParams::default()
    };
    set_force_fields(&mut p, &e.forces);
    set_collisions(&mut p, &e.collisions, origin);
    p
}

/// The emitter shape's two parameter rows (`shape_a`, `shape_b`; see spawn.wgsl).
pub(super) fn shape_params(shape: &Shape) -> ([f32; 4], [f32; 4]) {
    match shape {
        Shape::Point => ([0.0; 4], [0.0; 4]),
        Shape::Sphere {
            radius_m,
            surface_only,
        } => (
            [*radius_m, if *surface_only { 1.0 } else { 0.0 }, 0.0, 0.0],
            [0.0; 4],
        ),
        Shape::Disc { radius_m, normal } => {
            let n = glam::Vec3::from(*normal).normalize_or(glam::Vec3::Y);
            ([*radius_m, 0.0, 0.0, 0.0], [n.x, n.y, n.z, 0.0])
        }
        Shape::Box { half_extents_m: h } => ([h[0], h[1], h[2], 0.0], [0.0; 4]),
        Shape::Cone {
            angle_deg,
            radius_m,
        } => ([angle_deg.to_radians(), *radius_m, 0.0, 0.0], [0.0; 4]),
        Shape::Line { a_m, b_m } => ([a_m[0], a_m[1], a_m[2], 0.0], [b_m[0], b_m[1], b_m[2], 0.0]),
    }
}

/// The optional forces' parameters: turbulence, gusts, quadratic drag, flame pull, vortex
/// and attractor (an absent one's parameters leave it without effect).
pub(super) fn set_force_fields(p: &mut SimParams, f: &Forces) {
    p.turbulence = f.turbulence.as_ref().map_or([0.0; 4], |t| {
        [
            t.strength_m_per_s2,
            t.frequency_per_m,
            t.octaves.clamp(1, 4) as f32,
            t.scroll_m_per_s,
        ]
    });
    let (gust_strength, gust_hz) = f
        .gusts
        .as_ref()
        .map_or((0.0, 0.0), |g| (g.strength, g.frequency_hz));
    let (pull, pull_exp) = f
        .flame_pull
        .as_ref()
        .map_or((0.0, 1.0), |fp| (fp.strength_per_s2, fp.exponent));
    p.gusts_qdrag_pull = [gust_strength, gust_hz, f.quadratic_drag_per_m, pull];
    (p.vortex_center, p.vortex_axis) =
        f.vortex
            .as_ref()
            .map_or(([0.0; 4], [0.0, 1.0, 0.0, 0.0]), |v| {
                let a = glam::Vec3::from(v.axis).normalize_or(glam::Vec3::Y);
                (
                    [v.center_m[0], v.center_m[1], v.center_m[2], v.radius_m],
                    [a.x, a.y, a.z, v.swirl_m_per_s2],
                )
            });
    let (attractor, mode, radius) = f.attractor.as_ref().map_or(([0.0; 4], 0.0, 1.0), |a| {
        let at = a.position_m;
        let mode = match a.falloff {
            crate::effect::Falloff::InverseSquare => 0.0,
            crate::effect::Falloff::ConstantWithinRadius => 1.0,
        };
        ([at[0], at[1], at[2], a.strength], mode, a.radius_m)
    });
    p.attractor = attractor;
    p.attractor_b = [radius, mode, pull_exp, 0.0];
}

/// The collision parameters: the ground (its height relative to the simulation `origin`),
/// the response and up to four spheres.
pub(super) fn set_collisions(p: &mut SimParams, col: &Collisions, origin: glam::DVec3) {
    let flag = |on: bool| if on { 1.0 } else { 0.0 };
    for (slot, s) in p.spheres.iter_mut().zip(&col.spheres) {
        let center = (glam::Vec3::from(s.center_m).as_dvec3() - origin).as_vec3();
        *slot = center.extend(s.radius_m).to_array();
    }
    let ground = col.ground.as_ref();
    p.ground = [
        ground.map_or(0.0, |g| (g.height_m as f64 - origin.y) as f32),
        col.elasticity,
        col.friction,
        flag(ground.is_some_and(|g| g.kill_on_contact)),
    ];
    p.collide_b = [
        col.rest_speed_m_per_s,
        col.spheres.len().min(4) as f32,
        flag(col.kill_on_sphere_contact),
        flag(ground.is_some()),
    ];
    let depth = col.depth_collision.as_ref();
    p.collide_c = [
        flag(col.stick_on_contact),
        depth.map_or(0.0, |d| d.thickness_m),
        flag(depth.is_some_and(|d| d.kill_on_contact)),
        0.0,
    ];
}
