//! The camera a frame is drawn with ([`Camera`]: any view and projection, the runtime's
//! and every host's), and the editor's orbit camera around a target, as in the 2006
//! thesis (rotate, zoom, pan), which produces one.

use glam::{DMat4, Mat4, Vec3};

use super::matrix::IntoMat4;

use crate::effect::CameraHint;
use crate::gpu::types::CameraUniform;

/// A camera orbiting `target` at `distance`.
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitCamera {
    /// Orbit centre, world metres.
    pub target: Vec3,
    /// Distance to the target, metres.
    pub distance: f32,
    /// Rotation around +Y, radians.
    pub yaw: f32,
    /// Elevation, radians.
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
}

impl OrbitCamera {
    /// The camera a preset asks for.
    pub fn from_hint(h: &CameraHint) -> Self {
        Self {
            target: h.target_m.into(),
            distance: h.distance_m,
            yaw: h.yaw_deg.to_radians(),
            pitch: h.pitch_deg.to_radians(),
            fov_y: h.fov_y_deg.to_radians(),
        }
    }

    /// Eye position in world space.
    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * sy, sp, cp * cy)
    }

    /// World → view.
    pub fn view_from_world(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye(), self.target, Vec3::Y)
    }

    /// World → clip for an aspect ratio (width / height).
    pub fn clip_from_world(&self, aspect: f32) -> Mat4 {
        let near = (self.distance * 0.01).max(1e-3);
        let far = self.distance * 100.0 + 100.0;
        // wgpu clip space: z in [0, 1], y up (the "directx" convention).
        glam::camera::rh::proj::directx::perspective(self.fov_y, aspect.max(1e-3), near, far)
            * self.view_from_world()
    }

    /// World → view in f64.
    fn view_from_world_f64(&self) -> DMat4 {
        let eye = self.eye().as_dvec3();
        glam::dcamera::rh::view::look_at_mat4(eye, self.target.as_dvec3(), glam::DVec3::Y)
    }

    /// View → clip in f64: right-handed, depth 0..1 (wgpu), like `clip_from_world`.
    fn clip_from_view_f64(&self, aspect: f32) -> DMat4 {
        let near = (self.distance as f64 * 0.01).max(1e-3);
        let far = self.distance as f64 * 100.0 + 100.0;
        let f = 1.0 / (0.5 * self.fov_y as f64).tan();
        let aspect = aspect.max(1e-3) as f64;
        let r = far / (near - far);
        DMat4::from_cols(
            glam::DVec4::new(f / aspect, 0.0, 0.0, 0.0),
            glam::DVec4::new(0.0, f, 0.0, 0.0),
            glam::DVec4::new(0.0, 0.0, r, -1.0),
            glam::DVec4::new(0.0, 0.0, r * near, 0.0),
        )
    }

    /// World → clip in f64, for composing with far-away simulation origins.
    pub fn clip_from_world_f64(&self, aspect: f32) -> DMat4 {
        self.clip_from_view_f64(aspect) * self.view_from_world_f64()
    }

    /// Simulation space with origin `origin` → clip, composed in f64 and rounded once.
    pub fn clip_from_sim(&self, aspect: f32, origin: glam::DVec3) -> Mat4 {
        (self.clip_from_world_f64(aspect) * glam::DMat4::from_translation(origin)).as_mat4()
    }

    /// The camera of a frame of `size` pixels.
    pub fn view(&self, size: (u32, u32)) -> Camera {
        let aspect = size.0 as f32 / size.1.max(1) as f32;
        Camera::from_parts(
            self.view_from_world_f64(),
            self.clip_from_view_f64(aspect),
            size,
        )
    }

    /// The uniform block for the billboard pass.
    pub fn uniform(&self, size: (u32, u32), alpha: f32) -> CameraUniform {
        self.view(size).uniform(alpha)
    }

    /// Rotates by screen-space drag deltas (radians).
    pub fn orbit(&mut self, d_yaw: f32, d_pitch: f32) {
        self.yaw -= d_yaw;
        self.pitch = (self.pitch + d_pitch).clamp(-1.55, 1.55);
    }

    /// Zooms by a factor (>1 moves away).
    pub fn zoom(&mut self, factor: f32) {
        self.distance = (self.distance * factor).clamp(0.05, 1e5);
    }

    /// Pans the target in the view plane by a fraction of the distance.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let view = self.view_from_world();
        let right = Vec3::new(view.x_axis.x, view.y_axis.x, view.z_axis.x);
        let up = Vec3::new(view.x_axis.y, view.y_axis.y, view.z_axis.y);
        self.target += (-right * dx + up * dy) * self.distance;
    }

    /// Frames a sphere: centres on it and backs off to see all of it.
    pub fn frame(&mut self, center: Vec3, radius: f32) {
        self.target = center;
        self.distance = (radius.max(0.05) / (0.5 * self.fov_y).sin()) * 1.1;
    }
}

/// Where a frame is seen from: the host's view and projection matrices and the size of
/// the target in pixels. Any projection wgpu accepts works (perspective or orthographic,
/// reversed Z included): depth in clip space runs 0..1, and the player's soft edges read
/// view-space distances back from the host's depth buffer through the projection's
/// inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    view_from_world: DMat4,
    clip_from_view: DMat4,
    size: (u32, u32),
    /// Derived once (every instance and emitter of a frame reads them).
    clip_from_world: DMat4,
    eye: glam::DVec3,
    /// The interval a motion pass measures motion over, seconds.
    motion_secs: f32,
}

impl Camera {
    /// A camera from the host's `view_from_world` (world → view, right-handed: the camera
    /// looks down −z, as `glam`'s `look_at_rh` makes it; the sort and the soft edges read
    /// depth along −z) and
    /// `clip_from_view` (view → wgpu clip space, depth 0..1) matrices, drawing into a
    /// target of `size_px` pixels.
    ///
    /// Both accept a `glam::Mat4` (`ignis::glam`) or a plain column-major
    /// `[[f32; 4]; 4]`, as another math library's `to_cols_array_2d` gives it.
    pub fn new(
        view_from_world: impl IntoMat4,
        clip_from_view: impl IntoMat4,
        size_px: (u32, u32),
    ) -> Self {
        Self::from_parts(
            view_from_world.into_mat4().as_dmat4(),
            clip_from_view.into_mat4().as_dmat4(),
            size_px,
        )
    }

    /// A camera from the host's combined `clip_from_world` (projection × view, wgpu clip
    /// space, depth 0..1, reversed Z included) and the eye's position in world space, for
    /// hosts that keep only the product. The view is rebuilt from the matrix's rows (the
    /// camera's right and up axes, and its forward axis from the perspective row, or for
    /// an orthographic projection from right × up) and the projection is what remains:
    /// the result draws exactly as [`Camera::new`] with the two apart.
    pub fn from_view_proj(
        clip_from_world: impl IntoMat4,
        eye: impl Into<Vec3>,
        size_px: (u32, u32),
    ) -> Self {
        let clip_from_world = clip_from_world.into_mat4().as_dmat4();
        let eye = eye.into().as_dvec3();
        let row = |i: usize| clip_from_world.row(i).truncate();
        let right = row(0).normalize_or(glam::DVec3::X);
        let up = row(1).normalize_or(glam::DVec3::Y);
        let perspective = row(3).length() > 1e-9 * row(0).length().max(1e-30);
        let forward = if perspective {
            row(3).normalize()
        } else {
            up.cross(right).normalize_or(glam::DVec3::NEG_Z)
        };
        // Orthonormal, right-handed: x right, y up, z back (the view looks down −z).
        let back = -forward;
        let up = back.cross(right).normalize_or(up);
        let right = up.cross(back);
        let view_from_world = DMat4::from_cols(
            glam::DVec4::new(right.x, up.x, back.x, 0.0),
            glam::DVec4::new(right.y, up.y, back.y, 0.0),
            glam::DVec4::new(right.z, up.z, back.z, 0.0),
            glam::DVec4::new(-right.dot(eye), -up.dot(eye), -back.dot(eye), 1.0),
        );
        let clip_from_view = clip_from_world * view_from_world.inverse();
        Self::from_parts(view_from_world, clip_from_view, size_px)
    }

    fn from_parts(view_from_world: DMat4, clip_from_view: DMat4, size: (u32, u32)) -> Self {
        Self {
            view_from_world,
            clip_from_view,
            size: (size.0.max(1), size.1.max(1)),
            clip_from_world: clip_from_view * view_from_world,
            eye: view_from_world.inverse().w_axis.truncate(),
            motion_secs: 0.0,
        }
    }

    /// The same camera over a world placed by `host_from_world` in this camera's world
    /// (a rotation: the presets' y-up world inside a z-up host).
    pub(crate) fn with_world_from(self, host_from_world: DMat4) -> Self {
        Self {
            motion_secs: self.motion_secs,
            ..Self::from_parts(
                self.view_from_world * host_from_world,
                self.clip_from_view,
                self.size,
            )
        }
    }

    /// The same camera, for a motion pass that measures the motion of `secs` seconds
    /// (the export's frame interval).
    #[doc(hidden)]
    pub fn with_motion_secs(self, secs: f32) -> Self {
        Self {
            motion_secs: secs,
            ..self
        }
    }

    /// World → view, rounded to f32.
    #[doc(hidden)]
    pub fn view_from_world_mat4(&self) -> Mat4 {
        self.view_from_world.as_mat4()
    }

    /// View → clip, rounded to f32.
    #[doc(hidden)]
    pub fn clip_from_view_mat4(&self) -> Mat4 {
        self.clip_from_view.as_mat4()
    }

    /// World → clip, rounded to f32 (projecting points on the CPU).
    #[doc(hidden)]
    pub fn clip_from_world_mat4(&self) -> Mat4 {
        self.clip_from_world.as_mat4()
    }

    /// The target size in pixels.
    pub fn size_px(&self) -> (u32, u32) {
        self.size
    }

    /// The eye position in world space.
    pub fn eye(&self) -> Vec3 {
        self.eye.as_vec3()
    }

    /// The eye position in world space, f64.
    pub(crate) fn eye_f64(&self) -> glam::DVec3 {
        self.eye
    }

    /// The viewing direction in world space.
    pub fn forward(&self) -> Vec3 {
        let v = self.view_from_world;
        -glam::DVec3::new(v.x_axis.z, v.y_axis.z, v.z_axis.z)
            .as_vec3()
            .normalize_or(Vec3::Z)
    }

    /// World → clip, f64.
    pub(crate) fn clip_from_world(&self) -> DMat4 {
        self.clip_from_world
    }

    /// Whether depth shrinks away from the camera (reversed Z; the clear value is 0): the
    /// projection's depth 2 m ahead against 1 m ahead (the projection is monotonic along
    /// the view, so this holds wherever the near plane is).
    pub(crate) fn reversed_z(&self) -> bool {
        let depth = |z: f64| {
            let c = self.clip_from_view * glam::DVec4::new(0.0, 0.0, z, 1.0);
            c.z / c.w
        };
        depth(-2.0) < depth(-1.0)
    }

    /// Simulation space with origin `origin` → clip, composed in f64 and rounded once.
    pub(crate) fn clip_from_sim(&self, origin: glam::DVec3) -> Mat4 {
        (self.clip_from_world() * DMat4::from_translation(origin)).as_mat4()
    }

    /// Pixels per (metre / clip w): half the height times the projection's vertical
    /// focal factor.
    pub(crate) fn pixels_per_unit(&self) -> f32 {
        (0.5 * self.size.1 as f64 * self.clip_from_view.y_axis.y.abs()) as f32
    }

    /// The uniform block of both draw paths, with the interpolation `alpha` between the
    /// last two steps.
    pub(crate) fn uniform(&self, alpha: f32) -> CameraUniform {
        let view = self.view_from_world.as_mat4();
        // The camera's right and up axes in world space are the rows of the view rotation.
        let right = Vec3::new(view.x_axis.x, view.y_axis.x, view.z_axis.x).normalize_or(Vec3::X);
        let up = Vec3::new(view.x_axis.y, view.y_axis.y, view.z_axis.y).normalize_or(Vec3::Y);
        // View-space z from a depth d is (a·d + b) / (c·d + e): the z and w rows of the
        // projection's inverse (a projection has no x or y terms there).
        let inv = self.clip_from_view.inverse();
        let depth_to_view =
            [inv.z_axis.z, inv.w_axis.z, inv.z_axis.w, inv.w_axis.w].map(|v| v as f32);
        CameraUniform {
            clip_from_world: self.clip_from_world().as_mat4().to_cols_array_2d(),
            right_alpha: [right.x, right.y, right.z, alpha],
            up: [up.x, up.y, up.z, self.motion_secs],
            viewport: [
                self.size.0 as f32,
                self.size.1 as f32,
                self.pixels_per_unit(),
                0.0,
            ],
            depth_to_view,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A host's `proj * view` and eye give the camera its view and projection apart:
    /// perspective, reversed-Z and orthographic, any orientation.
    #[test]
    fn a_view_projection_and_eye_give_the_same_camera() {
        let eye = Vec3::new(1.5, 2.0, -3.0);
        let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::new(0.2, 0.5, 0.4), Vec3::Z);
        let projections = [
            glam::camera::rh::proj::directx::perspective(0.9, 1.5, 0.1, 80.0),
            glam::camera::rh::proj::directx::perspective(0.9, 1.5, 80.0, 0.1),
            glam::camera::rh::proj::directx::orthographic(-4.0, 4.0, -3.0, 3.0, 0.5, 20.0),
        ];
        for proj in projections {
            let apart = Camera::new(view, proj, (640, 480));
            let product = Camera::from_view_proj((proj * view).to_cols_array_2d(), eye, (640, 480));
            let close = |a: Mat4, b: Mat4| a.abs_diff_eq(b, 1e-4);
            assert!(close(
                apart.view_from_world_mat4(),
                product.view_from_world_mat4()
            ));
            assert!(close(
                apart.clip_from_view_mat4(),
                product.clip_from_view_mat4()
            ));
            assert!(apart.eye().abs_diff_eq(product.eye(), 1e-4));
            assert!(apart.forward().abs_diff_eq(product.forward(), 1e-5));
        }
    }
}
