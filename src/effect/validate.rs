//! Preset validation: every field of an [`Effect`] checked against its range, and every
//! problem reported at once with the field's path (`emitters[1].look.size_m`) and what it
//! must be, so a bad preset names its fix. Events and trails check their own fields
//! (`events.rs`, `trail.rs`) with the same [`Checker`].

use super::{
    BlendMode, CURRENT_VERSION, Collisions, Effect, Emitter, FlipbookMode, Forces, Look,
    MAX_CAPACITY, MAX_COLOR_STOPS, MAX_CURVE_KEYS, MAX_SPHERES, Param, Range, Shape, Sprite,
};

/// A state layout set together with `stateless` (which stores spawn records, not state).
const STATELESS_CONFLICT: &str = concat!(
    "cannot be combined with `stateless` (stateless emitters store spawn records, ",
    "not state); turn one off"
);

/// A validation failure: the field path and what is wrong with its value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path} = {value}: {problem}")]
pub struct ValidationError {
    /// Field path, e.g. `emitters[1].spawn_rate_per_sec`.
    pub path: String,
    /// The offending value, formatted.
    pub value: String,
    /// What it must be instead.
    pub problem: String,
}

/// Collects the problems found, each with its path.
pub(super) struct Checker {
    errors: Vec<ValidationError>,
}

impl Checker {
    /// Records a problem: the field's path, its value and what it must be.
    pub(super) fn push(&mut self, path: String, value: impl std::fmt::Display, problem: &str) {
        self.errors.push(ValidationError {
            path,
            value: value.to_string(),
            problem: problem.to_owned(),
        });
    }

    /// A finite number within `[lo, hi]`.
    pub(super) fn num(&mut self, path: impl Fn() -> String, v: f32, lo: f32, hi: f32) {
        if !v.is_finite() {
            self.push(path(), v, "must be a finite number");
        } else if v < lo {
            self.push(path(), v, &format!("must be ≥ {lo}"));
        } else if v > hi {
            self.push(path(), v, &format!("must be ≤ {hi}"));
        }
    }

    /// Three finite numbers within `[-limit, limit]`.
    pub(super) fn vec3(&mut self, path: impl Fn() -> String, v: [f32; 3], limit: f32) {
        for (i, c) in v.iter().enumerate() {
            self.num(|| format!("{}[{i}]", path()), *c, -limit, limit);
        }
    }

    /// A direction: finite and not the zero vector.
    pub(super) fn nonzero_vec3(&mut self, path: impl Fn() -> String, v: [f32; 3]) {
        self.vec3(&path, v, 1e6);
        if glam::Vec3::from(v).length_squared() < 1e-12 {
            self.push(
                path(),
                format!("{v:?}"),
                "must not be the zero vector (it is a direction)",
            );
        }
    }

    /// A parameter whose values lie in `values` and whose curve keys' times lie in
    /// `[0, t_max]`, strictly increasing.
    pub(super) fn param(
        &mut self,
        path: impl Fn() -> String,
        v: &Param,
        values: (f32, f32),
        t_max: f32,
    ) {
        let (lo, hi) = values;
        match v {
            Param::Constant(x) => self.num(&path, *x, lo, hi),
            Param::Range { min, max } => self.range(&path, Range::new(*min, *max), lo, hi),
            Param::Curve { keys, .. } => {
                self.keys(|| format!("{}.keys", path()), keys, values, t_max)
            }
            Param::TwoCurves { a, b } => {
                self.keys(|| format!("{}.a.keys", path()), &a.keys, values, t_max);
                self.keys(|| format!("{}.b.keys", path()), &b.keys, values, t_max);
            }
        }
    }

    /// A curve's keys: 1..=MAX_CURVE_KEYS of them, finite, times in `[0, t_max]` strictly
    /// increasing, values in `values`.
    pub(super) fn keys(
        &mut self,
        path: impl Fn() -> String,
        keys: &[(f32, f32)],
        values: (f32, f32),
        t_max: f32,
    ) {
        if keys.is_empty() || keys.len() > MAX_CURVE_KEYS {
            self.push(
                path(),
                format!("{} keys", keys.len()),
                &format!("a curve needs 1..={MAX_CURVE_KEYS} keys"),
            );
        }
        let mut last = f32::NEG_INFINITY;
        let (lo, hi) = values;
        for (k, &(t, v)) in keys.iter().enumerate() {
            let problem = if !t.is_finite() || !v.is_finite() {
                "a key's time and value must be finite numbers".to_owned()
            } else if !(0.0..=t_max).contains(&t) {
                format!("a key's time must be in 0..={t_max}")
            } else if v < lo || v > hi {
                format!("a key's value must be in {lo}..={hi}")
            } else if t <= last {
                "keys must be sorted by strictly increasing time".to_owned()
            } else {
                String::new()
            };
            if !problem.is_empty() {
                self.push(format!("{}[{k}]", path()), format!("({t}, {v})"), &problem);
            }
            last = t;
        }
    }

    /// A range whose ends lie in `[lo, hi]`, min ≤ max.
    pub(super) fn range(&mut self, path: impl Fn() -> String, r: Range, lo: f32, hi: f32) {
        self.num(|| format!("{}.min", path()), r.min, lo, hi);
        self.num(|| format!("{}.max", path()), r.max, lo, hi);
        if r.min.is_finite() && r.max.is_finite() && r.min > r.max {
            self.push(
                format!("{}.min", path()),
                r.min,
                &format!("must be ≤ max ({})", r.max),
            );
        }
    }
}

impl Effect {
    /// Checks every field; returns all problems found (empty = valid).
    pub fn validate(&self) -> Result<(), Vec<ValidationError>> {
        let mut c = Checker { errors: Vec::new() };
        self.check_settings(&mut c);
        if self.emitters.is_empty() {
            c.push("emitters".into(), "[]", "must list at least one emitter");
        }
        let mut names = std::collections::HashSet::new();
        for (i, e) in self.emitters.iter().enumerate() {
            let p = |f: &str| format!("emitters[{i}].{f}");
            if !names.insert(e.name.as_str()) {
                c.push(
                    p("name"),
                    format!("{:?}", e.name),
                    "duplicate emitter name; names must be unique",
                );
            }
            e.check(&p, &mut c);
        }
        self.check_events(&mut c);
        if c.errors.is_empty() {
            Ok(())
        } else {
            Err(c.errors)
        }
    }

    /// The version, the time settings, the camera and the post-processing.
    fn check_settings(&self, c: &mut Checker) {
        if self.version > CURRENT_VERSION {
            c.push(
                "version".into(),
                self.version,
                &format!("this build reads versions up to {CURRENT_VERSION}; update ignis"),
            );
        }
        if self.version == 0 {
            c.push("version".into(), 0, "must be ≥ 1");
        }
        let t = &self.time;
        c.num(|| "time.step_secs".into(), t.step_secs, 1e-5, 1.0);
        if t.max_substeps == 0 || t.max_substeps > 1000 {
            c.push(
                "time.max_substeps".into(),
                t.max_substeps,
                "must be in 1..=1000",
            );
        }
        c.num(
            || "time.max_frame_dt_secs".into(),
            t.max_frame_dt_secs,
            1e-5,
            1.0,
        );
        c.num(|| "time.speed".into(), t.speed, 0.0, 100.0);
        let cam = &self.camera;
        c.vec3(|| "camera.target_m".into(), cam.target_m, 1e6);
        c.num(|| "camera.distance_m".into(), cam.distance_m, 0.01, 1e5);
        c.num(|| "camera.yaw_deg".into(), cam.yaw_deg, -3600.0, 3600.0);
        c.num(|| "camera.pitch_deg".into(), cam.pitch_deg, -89.9, 89.9);
        c.num(|| "camera.fov_y_deg".into(), cam.fov_y_deg, 1.0, 170.0);
        c.num(|| "post.exposure".into(), self.post.exposure, 1e-3, 1e3);
        self.lighting.check(c);
        if !(1..=4).contains(&self.post.alpha_downscale) {
            c.push(
                "post.alpha_downscale".into(),
                self.post.alpha_downscale,
                "must be 1..=4 (1 = full resolution)",
            );
        }
        if !(1..=2).contains(&self.post.glow_downscale) {
            c.push(
                "post.glow_downscale".into(),
                self.post.glow_downscale,
                "must be 1 or 2 (1 = full resolution)",
            );
        }
        if let Some(b) = &self.post.bloom {
            c.num(|| "post.bloom.threshold".into(), b.threshold, 0.0, 1e3);
            c.num(|| "post.bloom.intensity".into(), b.intensity, 0.0, 100.0);
            if !(1..=8).contains(&b.levels) {
                c.push("post.bloom.levels".into(), b.levels, "must be 1..=8");
            }
        }
    }
}

impl Emitter {
    /// Every field of this emitter; `p` makes a field's path.
    fn check(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        if self.capacity == 0 || self.capacity > MAX_CAPACITY {
            c.push(
                p("capacity"),
                self.capacity,
                &format!("must be in 1..={MAX_CAPACITY}"),
            );
        }
        c.param(
            || p("spawn_rate_per_sec"),
            &self.spawn_rate_per_sec,
            (0.0, 1e9),
            1e7,
        );
        c.num(|| p("max_spawn_per_sec"), self.max_spawn_per_sec, 0.0, 1e9);
        for (b, burst) in self.bursts.iter().enumerate() {
            c.num(
                || p(&format!("bursts[{b}].time_secs")),
                burst.time_secs,
                0.0,
                1e6,
            );
        }
        c.range(|| p("lifetime_secs"), self.lifetime_secs, 1e-3, 1e4);
        self.check_shape(p, c);
        c.vec3(|| p("transform.position_m"), self.transform.position_m, 1e7);
        c.vec3(
            || p("transform.rotation_deg"),
            self.transform.rotation_deg,
            3600.0,
        );
        c.nonzero_vec3(|| p("direction"), self.direction);
        c.num(|| p("spread_deg"), self.spread_deg, 0.0, 180.0);
        c.range(|| p("speed_m_per_s"), self.speed_m_per_s, 0.0, 1e5);
        self.forces.check(p, c);
        self.check_state(p, c);
        self.collisions.check(p, c);
        let n = &self.spawn_noise;
        c.num(
            || p("spawn_noise.frequency_per_m"),
            n.frequency_per_m,
            0.0,
            1e3,
        );
        c.num(
            || p("spawn_noise.position_amplitude_m"),
            n.position_amplitude_m,
            0.0,
            1e3,
        );
        c.num(
            || p("spawn_noise.direction_amplitude"),
            n.direction_amplitude,
            0.0,
            10.0,
        );
        c.num(
            || p("spawn_noise.scroll_per_sec"),
            n.scroll_per_sec,
            -1e3,
            1e3,
        );
        self.look.check(p, c);
    }

    /// The state options: stateless, packed and tiny state, and what rules them out.
    fn check_state(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        if self.stateless && !self.stateless_blockers().is_empty() {
            c.push(
                p("stateless"),
                "true",
                &format!(
                    "stateless mode needs constant acceleration and linear drag only; turn off: {}",
                    self.stateless_blockers().join(", ")
                ),
            );
        }
        if self.packed_state && self.stateless {
            c.push(p("packed_state"), true, STATELESS_CONFLICT);
        }
        if self.tiny_state && self.stateless {
            c.push(p("tiny_state"), true, STATELESS_CONFLICT);
        }
        if self.tiny_state && self.packed_state {
            c.push(
                p("tiny_state"),
                true,
                "cannot be combined with `packed_state` (one state layout per emitter: 20 or 10 \
                    bytes); turn one off",
            );
        }
    }

    /// The emitter shape's sizes and directions.
    fn check_shape(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        match &self.shape {
            Shape::Point => {}
            Shape::Sphere { radius_m, .. } => c.num(|| p("shape.radius_m"), *radius_m, 0.0, 1e4),
            Shape::Disc { radius_m, normal } => {
                c.num(|| p("shape.radius_m"), *radius_m, 0.0, 1e4);
                c.nonzero_vec3(|| p("shape.normal"), *normal);
            }
            Shape::Box { half_extents_m } => {
                for (k, h) in half_extents_m.iter().enumerate() {
                    c.num(|| p(&format!("shape.half_extents_m[{k}]")), *h, 0.0, 1e4);
                }
            }
            Shape::Cone {
                angle_deg,
                radius_m,
            } => {
                c.num(|| p("shape.angle_deg"), *angle_deg, 0.0, 180.0);
                c.num(|| p("shape.radius_m"), *radius_m, 0.0, 1e4);
            }
            Shape::Line { a_m, b_m } => {
                c.vec3(|| p("shape.a_m"), *a_m, 1e6);
                c.vec3(|| p("shape.b_m"), *b_m, 1e6);
            }
        }
    }
}

impl Forces {
    /// The forces: gravity, buoyancy, drag, wind, gusts and the optional fields.
    fn check(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        c.vec3(|| p("forces.gravity_m_per_s2"), self.gravity_m_per_s2, 1e5);
        c.num(
            || p("forces.buoyancy_m_per_s2"),
            self.buoyancy_m_per_s2,
            -1e5,
            1e5,
        );
        c.num(|| p("forces.drag_per_sec"), self.drag_per_sec, 0.0, 1e4);
        c.param(
            || p("forces.drag_over_life"),
            &self.drag_over_life,
            (0.0, 1e3),
            1.0,
        );
        c.param(
            || p("forces.speed_over_life"),
            &self.speed_over_life,
            (0.0, 1e3),
            1.0,
        );
        c.vec3(|| p("forces.wind_m_per_s"), self.wind_m_per_s, 1e5);
        c.num(
            || p("forces.quadratic_drag_per_m"),
            self.quadratic_drag_per_m,
            0.0,
            1e4,
        );
        if let Some(g) = &self.gusts {
            c.num(|| p("forces.gusts.strength"), g.strength, 0.0, 10.0);
            c.num(
                || p("forces.gusts.frequency_hz"),
                g.frequency_hz,
                0.0,
                100.0,
            );
        }
        self.check_fields(p, c);
    }

    /// The optional force fields: turbulence, vortex, attractor, flame pull.
    fn check_fields(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        if let Some(t) = &self.turbulence {
            c.num(
                || p("forces.turbulence.strength_m_per_s2"),
                t.strength_m_per_s2,
                0.0,
                1e4,
            );
            c.num(
                || p("forces.turbulence.frequency_per_m"),
                t.frequency_per_m,
                0.0,
                1e3,
            );
            c.num(
                || p("forces.turbulence.scroll_m_per_s"),
                t.scroll_m_per_s,
                -1e3,
                1e3,
            );
            c.param(
                || p("forces.turbulence.over_life"),
                &t.over_life,
                (-1e3, 1e3),
                1.0,
            );
            if !(1..=4).contains(&t.octaves) {
                c.push(
                    p("forces.turbulence.octaves"),
                    t.octaves,
                    "must be in 1..=4",
                );
            }
        }
        if let Some(v) = &self.vortex {
            c.vec3(|| p("forces.vortex.center_m"), v.center_m, 1e7);
            c.nonzero_vec3(|| p("forces.vortex.axis"), v.axis);
            c.num(
                || p("forces.vortex.swirl_m_per_s2"),
                v.swirl_m_per_s2,
                -1e4,
                1e4,
            );
            c.num(|| p("forces.vortex.radius_m"), v.radius_m, 1e-3, 1e4);
        }
        if let Some(a) = &self.attractor {
            c.vec3(|| p("forces.attractor.position_m"), a.position_m, 1e7);
            c.num(|| p("forces.attractor.strength"), a.strength, -1e5, 1e5);
            c.num(|| p("forces.attractor.radius_m"), a.radius_m, 1e-3, 1e4);
        }
        if let Some(fp) = &self.flame_pull {
            c.num(
                || p("forces.flame_pull.strength_per_s2"),
                fp.strength_per_s2,
                0.0,
                1e4,
            );
            c.num(|| p("forces.flame_pull.exponent"), fp.exponent, 0.0, 16.0);
            c.param(
                || p("forces.flame_pull.over_life"),
                &fp.over_life,
                (0.0, 1e3),
                1.0,
            );
        }
    }
}

impl Collisions {
    /// The collision response, the ground and the spheres.
    fn check(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        c.num(|| p("collisions.elasticity"), self.elasticity, 0.0, 1.0);
        c.num(|| p("collisions.friction"), self.friction, 0.0, 1.0);
        c.num(
            || p("collisions.rest_speed_m_per_s"),
            self.rest_speed_m_per_s,
            0.0,
            1e3,
        );
        if let Some(g) = &self.ground {
            c.num(|| p("collisions.ground.height_m"), g.height_m, -1e7, 1e7);
        }
        if self.spheres.len() > MAX_SPHERES {
            c.push(
                p("collisions.spheres"),
                format!("{} spheres", self.spheres.len()),
                &format!("at most {MAX_SPHERES}"),
            );
        }
        if let Some(d) = &self.depth_collision {
            c.num(
                || p("collisions.depth_collision.thickness_m"),
                d.thickness_m,
                0.0,
                1e3,
            );
        }
        for (k, sp) in self.spheres.iter().enumerate() {
            c.vec3(
                || p(&format!("collisions.spheres[{k}].center_m")),
                sp.center_m,
                1e7,
            );
            c.num(
                || p(&format!("collisions.spheres[{k}].radius_m")),
                sp.radius_m,
                1e-3,
                1e4,
            );
        }
    }
}

impl Look {
    /// The look: size, opacity, sprite, flipbook, trail, streak and colours.
    fn check(&self, p: &dyn Fn(&str) -> String, c: &mut Checker) {
        c.param(|| p("look.size_m"), &self.size_m, (0.0, 1e3), 1.0);
        c.param(|| p("look.opacity"), &self.opacity, (0.0, 1e3), 1.0);
        c.num(|| p("look.intensity"), self.intensity, 0.0, 1e4);
        c.num(
            || p("look.rotation_random_deg"),
            self.rotation_random_deg,
            0.0,
            360.0,
        );
        c.param(
            || p("look.spin_deg_per_s"),
            &self.spin_deg_per_s,
            (-1e5, 1e5),
            1.0,
        );
        c.num(|| p("look.soft_ground_m"), self.soft_ground_m, 0.0, 100.0);
        if let Sprite::Image(path) = &self.sprite
            && path.trim().is_empty()
        {
            c.push(
                p("look.sprite"),
                "Image(\"\")",
                "needs a PNG path, relative to the preset file",
            );
        }
        if let Some(f) = &self.flipbook {
            for (name, v) in [("rows", f.rows), ("cols", f.cols)] {
                if !(1..=64).contains(&v) {
                    c.push(p(&format!("look.flipbook.{name}")), v, "must be 1..=64");
                }
            }
            match &f.mode {
                FlipbookMode::FrameRate { fps } => {
                    c.num(|| p("look.flipbook.mode.fps"), *fps, 0.0, 1000.0)
                }
                FlipbookMode::Frames(frames) => {
                    c.param(|| p("look.flipbook.mode"), frames, (0.0, 4096.0), 1.0)
                }
                FlipbookMode::OverLife => {}
            }
        }
        if let Some(t) = &self.trail {
            t.check(&p("look.trail"), c);
        }
        if let Some(l) = &self.lit {
            l.check(p, c);
            if self.blend != BlendMode::Alpha {
                c.push(
                    p("look.lit"),
                    "Some(..)",
                    "lights alpha-blended layers only (blend: Alpha)",
                );
            }
            if self.streak.is_some() {
                c.push(
                    p("look.lit"),
                    "Some(..)",
                    "lights camera-facing sprites only: remove the streak",
                );
            }
        }
        if let Some(h) = &self.heat_haze {
            c.num(|| p("look.heat_haze.strength"), h.strength, 0.0, 10.0);
            c.num(|| p("look.heat_haze.frequency"), h.frequency, 0.0, 100.0);
            c.num(|| p("look.heat_haze.speed_hz"), h.speed_hz, -100.0, 100.0);
            for (on, what) in [
                (self.trail.is_some(), "draws sprites only: remove the trail"),
                (self.lit.is_some(), "is not drawn in colour: remove `lit`"),
            ] {
                if on {
                    c.push(p("look.heat_haze"), "Some(..)", what);
                }
            }
        }
        if let Some(s) = &self.streak {
            c.num(|| p("look.streak.length_secs"), s.length_secs, 0.0, 10.0);
            c.num(|| p("look.streak.max_length_m"), s.max_length_m, 0.0, 1e3);
        }
        if self.color_over_life.is_empty() || self.color_over_life.len() > MAX_COLOR_STOPS {
            c.push(
                p("look.color_over_life"),
                format!("{} stops", self.color_over_life.len()),
                &format!("must have 1..={MAX_COLOR_STOPS} stops"),
            );
        }
        let mut last_t = 0.0;
        for (s, stop) in self.color_over_life.iter().enumerate() {
            let sp = || p(&format!("look.color_over_life[{s}]"));
            c.num(|| format!("{}.t", sp()), stop.t, 0.0, 1.0);
            if stop.t < last_t {
                c.push(format!("{}.t", sp()), stop.t, "stops must be sorted by t");
            }
            last_t = stop.t;
            for (k, v) in stop.rgba.iter().enumerate() {
                c.num(|| format!("{}.rgba[{k}]", sp()), *v, 0.0, 1e3);
            }
        }
    }
}
