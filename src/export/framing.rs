//! Framing an export: the particles of the whole span, sampled, fix the camera (nothing
//! cropped at any frame, a margin around) and the motion pass's scale.

use glam::{Mat4, Vec3};

use crate::effect::Effect;
use crate::render::{Camera, OrbitCamera};

use super::export_settings::CameraMode;

/// Particles kept per frame at most (every k-th one beyond).
const PER_FRAME: usize = 20_000;

/// The margin left around the particles, as a fraction of the frame.
const MARGIN: f32 = 0.06;

/// Particles (world position and velocity) seen over the span.
#[derive(Clone, Debug, Default)]
pub(super) struct Samples {
    points: Vec<(Vec3, Vec3)>,
}

impl Samples {
    /// Adds one frame's particles (evenly thinned to `PER_FRAME`).
    pub fn add(&mut self, frame: &[(Vec3, Vec3)]) {
        let step = frame.len().div_ceil(PER_FRAME).max(1);
        self.points.extend(frame.iter().step_by(step).copied());
    }

    /// The largest motion of a sampled particle over `interval` seconds, in frame UV
    /// units, times two and a margin: the motion pass's scale (decoded motion =
    /// (value − 0.5) × scale).
    pub fn motion_scale(&self, camera: &Camera, interval: f32) -> f32 {
        let clip: Mat4 = camera.clip_from_world_mat4();
        let uv = |p: Vec3| {
            let c = clip * p.extend(1.0);
            (c.w > 1e-4).then(|| glam::vec2(c.x / c.w * 0.5, -c.y / c.w * 0.5))
        };
        let largest = self
            .points
            .iter()
            .filter_map(|&(p, v)| Some((uv(p + v * interval)? - uv(p)?).abs().max_element()))
            .fold(0.0f32, f32::max);
        (2.0 * largest * 1.05).max(1e-3)
    }
}

/// The largest distance a particle's drawn quad reaches from its centre, over the
/// effect's emitters (size with its randomness, rotation, streak tails).
fn reach(effect: &Effect) -> f32 {
    effect
        .emitters
        .iter()
        .filter(|e| e.enabled)
        .map(|e| {
            let l = &e.look;
            let size = l.size_m.bounds().1;
            let streak = l.streak.as_ref().map_or(0.0, |s| s.max_length_m);
            0.5 * size * std::f32::consts::SQRT_2 + streak
        })
        .fold(0.0, f32::max)
}

/// A camera that sees every particle of the span whole: the preset's, or one along the
/// preset's view that encloses the sampled particles (each grown by its quad's reach).
#[derive(Clone, Debug)]
pub(super) enum Wide {
    /// The preset's camera as it is.
    Preset(OrbitCamera),
    /// Orthographic: half extents of the particles' box on the view plane about `centre`.
    Ortho {
        centre: Vec3,
        forward: Vec3,
        half: glam::Vec2,
        depth: f32,
    },
    /// The preset's field of view from `eye`, far enough back.
    Perspective {
        eye: Vec3,
        centre: Vec3,
        fov_y: f32,
        distance: f32,
    },
}

/// The enclosing camera for `mode`.
pub(super) fn enclosing(effect: &Effect, samples: &Samples, mode: CameraMode) -> Wide {
    let preset = OrbitCamera::from_hint(&effect.camera);
    if mode == CameraMode::Preset || samples.points.is_empty() {
        return Wide::Preset(preset);
    }
    let forward = (preset.target - preset.eye()).normalize_or(Vec3::NEG_Z);
    let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
    let up = right.cross(forward);
    let r = reach(effect);
    // The particles in the view's basis about the preset's target (z towards the eye).
    let basis: Vec<Vec3> = samples
        .points
        .iter()
        .map(|&(p, _)| {
            let d = p - preset.target;
            Vec3::new(d.dot(right), d.dot(up), -d.dot(forward))
        })
        .collect();
    let lo = basis
        .iter()
        .fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b))
        - r;
    let hi = basis
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b))
        + r;
    let mid = 0.5 * (lo + hi);
    let centre = preset.target + right * mid.x + up * mid.y - forward * mid.z;
    if mode == CameraMode::Ortho {
        let half = 0.5 * (hi - lo);
        return Wide::Ortho {
            centre,
            forward,
            half: glam::vec2(half.x, half.y) * 1.1,
            depth: half.z + 1.0,
        };
    }
    // Back off along the view until every particle's sphere is inside a square frame (the
    // frame's aspect only widens it).
    let t = (0.5 * preset.fov_y).tan() * 0.9;
    let grow = (1.0 + t * t).sqrt();
    let distance = basis
        .iter()
        .map(|b| {
            let b = *b - mid;
            b.z + (b.x.abs().max(b.y.abs()) + r * grow) / t
        })
        .fold(r + 0.05, f32::max);
    Wide::Perspective {
        eye: centre - forward * distance,
        centre,
        fov_y: preset.fov_y,
        distance,
    }
}

impl Wide {
    /// This camera for frames of `size` (a wider frame sees more, never less).
    pub fn camera(&self, size: (u32, u32)) -> Camera {
        let aspect = size.0 as f32 / size.1.max(1) as f32;
        match *self {
            Wide::Preset(ref orbit) => orbit.view(size),
            Wide::Ortho {
                centre,
                forward,
                half,
                depth,
            } => {
                let hx = half.x.max(half.y * aspect);
                let hy = hx / aspect;
                let view =
                    glam::camera::rh::view::look_at_mat4(centre - forward * depth, centre, Vec3::Y);
                let proj = glam::camera::rh::proj::directx::orthographic(
                    -hx,
                    hx,
                    -hy,
                    hy,
                    0.01,
                    2.0 * depth + 1.0,
                );
                Camera::new(view, proj, size)
            }
            Wide::Perspective {
                eye,
                centre,
                fov_y,
                distance,
            } => {
                // Keep the square frame's horizontal reach when the frame is narrower.
                let fov_y = if aspect < 1.0 {
                    2.0 * ((0.5 * fov_y).tan() / aspect).atan()
                } else {
                    fov_y
                };
                let view = glam::camera::rh::view::look_at_mat4(eye, centre, Vec3::Y);
                let near = (distance * 0.01).max(1e-3);
                let proj = glam::camera::rh::proj::directx::perspective(
                    fov_y.min(3.0),
                    aspect,
                    near,
                    distance * 4.0 + 10.0,
                );
                Camera::new(view, proj, size)
            }
        }
    }

    /// This camera for frames of `size`, cropped to `bounds` (what was visible through
    /// it, in its clip space) with a margin: an off-centre crop of the same view.
    pub fn cropped(&self, bounds: Bounds, size: (u32, u32)) -> Camera {
        let wide = self.camera(size);
        let Some((lo, hi)) = bounds.rect() else {
            return wide;
        };
        let c = 0.5 * (lo + hi);
        let s = (0.5 * (hi - lo).max_element() / (1.0 - 2.0 * MARGIN)).clamp(1e-3, 1.0);
        // x' = (x − c.x·w) / s in clip space: the crop as a projection.
        let crop = Mat4::from_cols(
            glam::vec4(1.0 / s, 0.0, 0.0, 0.0),
            glam::vec4(0.0, 1.0 / s, 0.0, 0.0),
            glam::vec4(0.0, 0.0, 1.0, 0.0),
            glam::vec4(-c.x / s, -c.y / s, 0.0, 1.0),
        );
        Camera::new(
            wide.view_from_world_mat4(),
            crop * wide.clip_from_view_mat4(),
            size,
        )
    }
}

/// The probe's frame size: the export's aspect, 256 pixels on the long side.
pub(super) fn probe_size(size: (u32, u32)) -> (u32, u32) {
    let long = size.0.max(size.1).max(1) as f32;
    let k = 256.0 / long;
    (
        ((size.0 as f32 * k).round() as u32).max(8),
        ((size.1 as f32 * k).round() as u32).max(8),
    )
}

/// Where anything was visible over the probe's frames, in clip space (x right, y up).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Bounds {
    rect: Option<(glam::Vec2, glam::Vec2)>,
}

impl Bounds {
    /// Grows by the pixels of `frame` (of `size`) that hold visible light or coverage,
    /// by their whole extent.
    pub fn add(&mut self, frame: &super::frames::RawFrame, size: (u32, u32)) {
        let (w, h) = (size.0 as usize, size.1 as usize);
        for (i, p) in frame.color.iter().enumerate() {
            // What an 8-bit image would show: coverage of half a step, or light whose
            // sRGB encoding reaches half a step (linear 0.5 / 255 / 12.92).
            if p[3] < 0.5 / 255.0 && p[0].max(p[1]).max(p[2]) < 1.5e-4 {
                continue;
            }
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let lo = glam::vec2(2.0 * x / w as f32 - 1.0, 1.0 - 2.0 * (y + 1.0) / h as f32);
            let hi = glam::vec2(2.0 * (x + 1.0) / w as f32 - 1.0, 1.0 - 2.0 * y / h as f32);
            self.rect = Some(match self.rect {
                Some((a, b)) => (a.min(lo), b.max(hi)),
                None => (lo, hi),
            });
        }
    }

    /// The rectangle, if anything was visible.
    pub fn rect(&self) -> Option<(glam::Vec2, glam::Vec2)> {
        self.rect
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effect::Param;

    /// The campfire with every sprite `size_m` wide and no streaks, and still particles
    /// sampled at `points`.
    fn sampled(size_m: f32, points: &[[f32; 3]]) -> (Effect, Samples) {
        let mut effect = Effect::default_campfire();
        for e in &mut effect.emitters {
            e.look.size_m = Param::Constant(size_m);
            e.look.streak = None;
        }
        let mut samples = Samples::default();
        let frame: Vec<(Vec3, Vec3)> = points
            .iter()
            .map(|&p| (Vec3::from(p), Vec3::ZERO))
            .collect();
        samples.add(&frame);
        (effect, samples)
    }

    /// A fitted perspective camera holds every particle's sphere (its quad's reach) inside
    /// the preset's field of view, each checked as a circle against the edges of the
    /// frame's wedge (its distance from each edge plane), with the tightest no farther
    /// back than the margin asks.
    #[test]
    fn a_fitted_camera_holds_every_particles_sphere_in_its_field_of_view() {
        let (mut effect, samples) =
            sampled(1.0, &[[0.3, 1.0, -0.2], [-0.5, 0.2, 0.4], [0.1, -0.3, 0.0]]);
        effect.camera.fov_y_deg = 90.0;
        let r = reach(&effect);
        let Wide::Perspective {
            eye, centre, fov_y, ..
        } = enclosing(&effect, &samples, CameraMode::Fit)
        else {
            panic!("a fitted camera is a perspective one");
        };
        let forward = (centre - eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let t = (0.5 * fov_y).tan();
        let mut tightest = f32::INFINITY;
        for &(p, _) in &samples.points {
            let v = p - eye;
            for lateral in [v.dot(right).abs(), v.dot(up).abs()] {
                let clearance = (t * v.dot(forward) - lateral) / (1.0 + t * t).sqrt();
                assert!(
                    clearance >= r,
                    "{p}: {clearance} m from the edge, reach {r}"
                );
                tightest = tightest.min(clearance);
            }
        }
        assert!(tightest <= 1.3 * r, "{tightest} m from the edge, reach {r}");
    }

    /// A fitted orthographic camera's half extents are the particles' spheres' box on the
    /// view plane, 10 % wider: every sphere inside, the widest touching 1/1.1 of it.
    #[test]
    fn a_fitted_orthographic_camera_holds_the_spheres_box_with_a_tenth_to_spare() {
        let (effect, samples) = sampled(0.2, &[[0.3, 1.0, -0.2], [-0.5, 0.2, 0.4]]);
        let r = reach(&effect);
        let Wide::Ortho {
            centre,
            forward,
            half,
            ..
        } = enclosing(&effect, &samples, CameraMode::Ortho)
        else {
            panic!("an orthographic camera");
        };
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let (mut widest_x, mut widest_y) = (0.0f32, 0.0f32);
        for &(p, _) in &samples.points {
            let v = p - centre;
            widest_x = widest_x.max(v.dot(right).abs() + r);
            widest_y = widest_y.max(v.dot(up).abs() + r);
        }
        assert!(
            (half.x - 1.1 * widest_x).abs() < 1e-4,
            "{half} against {widest_x}"
        );
        assert!(
            (half.y - 1.1 * widest_y).abs() < 1e-4,
            "{half} against {widest_y}"
        );
    }

    /// The probe keeps the export's aspect with 256 pixels on its long side, and at
    /// least 8 on the short one.
    #[test]
    fn the_probe_is_256_pixels_on_its_long_side() {
        assert_eq!(probe_size((1920, 1080)), (256, 144));
        assert_eq!(probe_size((64, 64)), (256, 256));
        assert_eq!(probe_size((100, 1000)), (26, 256));
        assert_eq!(probe_size((4000, 10)), (256, 8));
    }

    /// An orthographic camera frames its box whatever the frame's aspect: on a frame twice
    /// as wide as high, a box twice as high as wide fills the height, its corners on the
    /// frame's top and bottom edges, inside its sides.
    #[test]
    fn an_orthographic_frame_holds_its_box_at_any_aspect() {
        let wide = Wide::Ortho {
            centre: Vec3::ZERO,
            forward: Vec3::NEG_Z,
            half: glam::vec2(1.0, 2.0),
            depth: 5.0,
        };
        for size in [(200, 100), (100, 200), (128, 128)] {
            let clip = wide.camera(size).clip_from_world_mat4();
            let (mut x, mut y) = (0.0f32, 0.0f32);
            for corner in [Vec3::new(1.0, 2.0, 0.0), Vec3::new(-1.0, -2.0, 0.0)] {
                let c = clip.project_point3(corner);
                (x, y) = (x.max(c.x.abs()), y.max(c.y.abs()));
            }
            assert!(x <= 1.0 + 1e-5 && y <= 1.0 + 1e-5, "{size:?}: {x}, {y}");
            assert!(
                (x.max(y) - 1.0).abs() < 1e-5,
                "{size:?}: {x}, {y} (not tight)"
            );
        }
    }

    /// The motion pass's scale is twice the largest sampled motion in frame UV units
    /// (half the clip range) with 5 % to spare, up or across: through an orthographic
    /// frame 2 m high, a particle moving 0.5 m/s up over 1 s moves a quarter of the frame.
    #[test]
    fn the_motion_scale_is_twice_the_largest_motion_in_frame_units() {
        let wide = Wide::Ortho {
            centre: Vec3::ZERO,
            forward: Vec3::NEG_Z,
            half: glam::vec2(1.0, 1.0),
            depth: 5.0,
        };
        let camera = wide.camera((64, 64));
        for v in [Vec3::new(0.0, 0.5, 0.0), Vec3::new(-0.5, 0.0, 0.0)] {
            let mut samples = Samples::default();
            samples.add(&[(Vec3::new(0.1, -0.2, 0.0), v), (Vec3::ZERO, 0.2 * v)]);
            let scale = samples.motion_scale(&camera, 1.0);
            assert!((scale - 2.0 * 0.25 * 1.05).abs() < 1e-5, "{v}: {scale}");
        }
    }
}
