//! The 3D viewport: the simulation's image, camera input, the ground grid and the
//! emitter-shape gizmos (drawn with egui's painter from projected 3D points).

use egui::{Color32, Pos2, Rect, Sense, Stroke, Ui};
use glam::{Mat4, Vec3, Vec4};

use crate::effect::{Effect, Emitter, Shape};
use crate::render::OrbitCamera;
use crate::runtime::EffectLight;

use crate::editor::state::EditorState;

/// Radians of orbit per point dragged.
const ORBIT_RAD_PER_POINT: f32 = 0.008;

/// What the frame loop needs from the viewport after the UI ran.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewportOutput {
    /// Size of the render target, physical pixels (render scale applied).
    pub size_px: (u32, u32),
    /// Where the viewport is in the window (points): the part repainted every frame.
    pub rect: Rect,
}

impl Default for ViewportOutput {
    fn default() -> Self {
        Self {
            size_px: (0, 0),
            rect: Rect::NOTHING,
        }
    }
}

/// The central viewport: shows `texture` (the tonemapped simulation image), handles the
/// camera and draws the grid and gizmos.
pub fn viewport_ui(
    ui: &mut Ui,
    camera: &mut OrbitCamera,
    state: &mut EditorState,
    texture: Option<egui::TextureId>,
) -> ViewportOutput {
    let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
    camera_input(ui, &response, rect, camera, state);

    let painter = ui.painter_at(rect);
    // The background is the frame's clear colour: painting it here would shade every
    // viewport pixel once more in egui's pass.
    let aspect = rect.width() / rect.height().max(1.0);
    let projector = Projector::new(camera.clip_from_world(aspect), rect);
    if let Some(id) = texture {
        // Additive over the background: a premultiplied tint with zero alpha adds the
        // texels. (The lean painter draws it opaque: the image then is the background.)
        let additive = Color32::from_rgb_additive(255, 255, 255);
        let uv = Rect::from_min_max(Pos2::ZERO, egui::pos2(1.0, 1.0));
        painter.image(id, rect, uv, additive);
    }
    // The test scene's ground has its own checker (and the grid, drawn over the image,
    // would cross its props).
    if state.view.show_grid && !state.view.test_scene {
        // After the image and additive too, so the sum is the same in either order and
        // an opaque image cannot hide the grid.
        let light = state.fire_light.filter(|_| state.view.fire_lights_grid);
        draw_grid(&painter, &projector, light.as_ref(), state.view.exposure);
    }
    if state.view.show_gizmos {
        for (i, e) in state.effect.emitters.iter().enumerate() {
            if e.enabled || i == state.selected {
                let color = if i == state.selected {
                    Color32::from_rgb(120, 200, 255)
                } else {
                    Color32::from_rgba_unmultiplied(150, 160, 180, 110)
                };
                draw_gizmo(&painter, &projector, e, color, i == state.selected);
            }
        }
    }
    // The mouse collider: a sphere under the pointer, on the plane through the orbit
    // target facing the camera.
    state.mouse_point = None;
    if state.view.mouse_collider
        && let Some(pointer) = response.hover_pos()
    {
        let ndc = glam::Vec2::new(
            (pointer.x - rect.left()) / rect.width().max(1.0) * 2.0 - 1.0,
            1.0 - (pointer.y - rect.top()) / rect.height().max(1.0) * 2.0,
        );
        let inv = camera.clip_from_world(aspect).inverse();
        let near = inv.project_point3(ndc.extend(0.0));
        let far = inv.project_point3(ndc.extend(1.0));
        let dir = (far - near).normalize_or_zero();
        let normal = (camera.target - camera.eye()).normalize_or_zero();
        let denom = dir.dot(normal);
        if denom.abs() > 1e-6 {
            let t = (camera.target - near).dot(normal) / denom;
            let p = near + dir * t;
            state.mouse_point = Some(p);
            let (u, v) = basis(normal);
            projector.polyline(
                &painter,
                &circle(p, u, v, crate::editor::state::MOUSE_COLLIDER_RADIUS_M),
                egui::Stroke::new(1.5, Color32::from_rgb(255, 120, 80)),
            );
        }
    }
    hud_ui(&painter, rect, state);
    if state.view.inspect {
        state.inspect.pointer = response.hover_pos().map(|p| {
            let f = (p - rect.min) / rect.size().max(egui::vec2(1.0, 1.0));
            [f.x, f.y]
        });
        if response.clicked() {
            state.inspect.pin_requested = true;
        }
        if let Some(info) = &state.inspect.shown
            && let Some(at) = projector.point(info.position_m)
        {
            painter.circle_stroke(
                at,
                7.0,
                egui::Stroke::new(1.5, Color32::from_rgb(120, 220, 255)),
            );
        }
        crate::editor::diagnostics::inspector::inspect_overlay(&painter, rect, state);
    }

    let ppp = ui.ctx().pixels_per_point();
    let scale = state.view.render_scale.clamp(0.1, 1.0);
    let w = (rect.width() * ppp * scale).round().max(1.0) as u32;
    let h = (rect.height() * ppp * scale).round().max(1.0) as u32;
    ViewportOutput {
        size_px: (w, h),
        rect,
    }
}

fn camera_input(
    ui: &Ui,
    response: &egui::Response,
    rect: Rect,
    camera: &mut OrbitCamera,
    state: &mut EditorState,
) {
    let (shift, ctrl) = ui.input(|i| (i.modifiers.shift, i.modifiers.command));
    let delta = response.drag_delta();
    // Ctrl+drag moves the selected emitter's sphere collider nearest the pointer, in the
    // plane facing the camera (one drag is one undo step).
    if ctrl && response.dragged_by(egui::PointerButton::Primary) {
        if let Some(pointer) = response.interact_pointer_pos() {
            drag_collider(camera, rect, state, pointer, delta);
        }
        return;
    }
    let is_pan = response.dragged_by(egui::PointerButton::Middle)
        || response.dragged_by(egui::PointerButton::Secondary)
        || (shift && response.dragged_by(egui::PointerButton::Primary));
    if is_pan {
        // One point of drag moves the target by one point's worth of the view at the
        // target's distance, so the scene follows the pointer.
        let per_point = 2.0 * (0.5 * camera.fov_y).tan() / rect.height().max(1.0);
        camera.pan(delta.x * per_point, delta.y * per_point);
    } else if response.dragged_by(egui::PointerButton::Primary) {
        camera.orbit(delta.x * ORBIT_RAD_PER_POINT, delta.y * ORBIT_RAD_PER_POINT);
    }
    if response.hovered() {
        let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        if scroll != 0.0 {
            camera.zoom((-scroll * 0.0015).exp());
        }
        if pinch != 1.0 && pinch > 0.0 {
            camera.zoom(1.0 / pinch);
        }
    }
    if response.double_clicked() {
        state.frame_requested = true;
    }
}

fn drag_collider(
    camera: &OrbitCamera,
    rect: Rect,
    state: &mut EditorState,
    pointer: Pos2,
    delta: egui::Vec2,
) {
    let aspect = rect.width() / rect.height().max(1.0);
    let clip_from_world = camera.clip_from_world(aspect);
    let to_screen = |p: Vec3| -> Option<Pos2> {
        let c = clip_from_world * p.extend(1.0);
        (c.w > 1e-4).then(|| {
            let n = c.truncate() / c.w;
            egui::pos2(
                rect.left() + (n.x * 0.5 + 0.5) * rect.width(),
                rect.top() + (0.5 - n.y * 0.5) * rect.height(),
            )
        })
    };
    let Some(e) = state.effect.emitters.get_mut(state.selected) else {
        return;
    };
    let nearest = e
        .collisions
        .spheres
        .iter_mut()
        .filter_map(|s| to_screen(Vec3::from(s.center_m)).map(|q| (q.distance(pointer), s)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((_, sphere)) = nearest {
        let center = Vec3::from(sphere.center_m);
        let distance = (center - camera.eye()).length();
        let per_point = 2.0 * (0.5 * camera.fov_y).tan() / rect.height().max(1.0) * distance;
        let view = camera.view_from_world();
        let right = Vec3::new(view.x_axis.x, view.y_axis.x, view.z_axis.x);
        let up = Vec3::new(view.x_axis.y, view.y_axis.y, view.z_axis.y);
        sphere.center_m = (center + (right * delta.x - up * delta.y) * per_point).to_array();
    }
}

/// Projects world points into the viewport rectangle.
pub struct Projector {
    clip_from_world: Mat4,
    rect: Rect,
}

impl Projector {
    /// A projector for a camera matrix and the viewport's screen rectangle.
    pub fn new(clip_from_world: Mat4, rect: Rect) -> Self {
        Self {
            clip_from_world,
            rect,
        }
    }

    fn clip(&self, p: Vec3) -> Vec4 {
        self.clip_from_world * p.extend(1.0)
    }

    fn to_screen(&self, c: Vec4) -> Pos2 {
        let ndc = c.truncate() / c.w;
        egui::pos2(
            self.rect.left() + (ndc.x * 0.5 + 0.5) * self.rect.width(),
            self.rect.top() + (0.5 - ndc.y * 0.5) * self.rect.height(),
        )
    }

    /// Where a world point is on screen (`None` behind the camera).
    pub fn point(&self, p: Vec3) -> Option<Pos2> {
        let c = self.clip(p);
        (c.w > 1e-6 && c.z >= 0.0).then(|| self.to_screen(c))
    }

    /// The screen segment of the world segment `a`–`b`, clipped at the near plane
    /// (`None` when it lies entirely behind it).
    pub fn segment(&self, a: Vec3, b: Vec3) -> Option<[Pos2; 2]> {
        let (mut ca, mut cb) = (self.clip(a), self.clip(b));
        // wgpu clip space keeps 0 ≤ z ≤ w; cut what is in front of the near plane.
        if ca.z < 0.0 && cb.z < 0.0 {
            return None;
        }
        if ca.z < 0.0 {
            ca = ca.lerp(cb, ca.z / (ca.z - cb.z));
        } else if cb.z < 0.0 {
            cb = cb.lerp(ca, cb.z / (cb.z - ca.z));
        }
        if ca.w <= 1e-6 || cb.w <= 1e-6 {
            return None;
        }
        Some([self.to_screen(ca), self.to_screen(cb)])
    }

    /// Draws a polyline through world points.
    fn polyline(&self, painter: &egui::Painter, points: &[Vec3], stroke: Stroke) {
        for pair in points.windows(2) {
            if let Some(s) = self.segment(pair[0], pair[1]) {
                painter.line_segment(s, stroke);
            }
        }
    }
}

/// The light on the ground (normal +Y) at `p` from the effect's light `l`: its power
/// over the squared distance (softened by its spread) times the cosine, a grey ground's
/// share, at the viewport's exposure — times the gain the embed example lights its
/// ground with (the effect light's power is in sprite units, not a host's lumens).
fn ground_light(l: &EffectLight, p: Vec3, exposure: f32) -> [f32; 3] {
    const GROUND_ALBEDO: f32 = 0.3 * 7.5;
    let to = l.position - p;
    let d2 = to.length_squared() + l.radius_m * l.radius_m;
    let cos = (to.y / d2.sqrt().max(1e-6)).max(0.0);
    let k = GROUND_ALBEDO * exposure * cos / d2.max(1e-4) / std::f32::consts::PI;
    l.rgb_power.map(|c| c * k)
}

fn draw_grid(
    painter: &egui::Painter,
    projector: &Projector,
    light: Option<&EffectLight>,
    exposure: f32,
) {
    const HALF_EXTENT_M: f32 = 5.0;
    const CELL_M: f32 = 0.5;
    let n = (HALF_EXTENT_M / CELL_M) as i32;
    // Lit by the fire, a line is drawn in pieces, each in the light at its middle.
    let pieces = if light.is_some() { 40 } else { 1 };
    for k in -n..=n {
        let v = k as f32 * CELL_M;
        // Additive (premultiplied, zero alpha): light added over the image.
        let gray = if k == 0 {
            61u8
        } else if k % 2 == 0 {
            33
        } else {
            19
        };
        for (a, b) in [
            (
                Vec3::new(v, 0.0, -HALF_EXTENT_M),
                Vec3::new(v, 0.0, HALF_EXTENT_M),
            ),
            (
                Vec3::new(-HALF_EXTENT_M, 0.0, v),
                Vec3::new(HALF_EXTENT_M, 0.0, v),
            ),
        ] {
            for i in 0..pieces {
                let (p, q) = (
                    a.lerp(b, i as f32 / pieces as f32),
                    a.lerp(b, (i + 1) as f32 / pieces as f32),
                );
                let lit = light.map_or([0.0; 3], |l| ground_light(l, (p + q) * 0.5, exposure));
                let c = lit.map(|e| (f32::from(gray) + e * 255.0).min(255.0) as u8);
                if let Some(s) = projector.segment(p, q) {
                    let color = Color32::from_rgb_additive(c[0], c[1], c[2]);
                    painter.line_segment(s, Stroke::new(1.0, color));
                }
            }
        }
    }
    // Short axis markers: +X red, +Z blue.
    for (dir, color) in [
        (Vec3::X, Color32::from_rgb_additive(141, 51, 51)),
        (Vec3::Z, Color32::from_rgb_additive(51, 71, 151)),
    ] {
        if let Some(s) = projector.segment(Vec3::ZERO, dir * 0.5) {
            painter.line_segment(s, Stroke::new(1.5, color));
        }
    }
}

/// Two unit vectors perpendicular to `n` and to each other.
fn basis(n: Vec3) -> (Vec3, Vec3) {
    let n = n.normalize_or(Vec3::Y);
    let u = n.any_orthonormal_vector();
    (u, n.cross(u))
}

fn circle(center: Vec3, u: Vec3, v: Vec3, radius: f32) -> Vec<Vec3> {
    const SEGMENTS: usize = 48;
    (0..=SEGMENTS)
        .map(|k| {
            let a = k as f32 / SEGMENTS as f32 * std::f32::consts::TAU;
            center + (u * a.cos() + v * a.sin()) * radius
        })
        .collect()
}

/// Wireframe polylines of an emitter's spawn shape, in emitter space.
pub fn shape_wireframe(e: &Emitter) -> Vec<Vec<Vec3>> {
    match &e.shape {
        Shape::Point => {
            let s = 0.05;
            vec![
                vec![Vec3::X * -s, Vec3::X * s],
                vec![Vec3::Y * -s, Vec3::Y * s],
                vec![Vec3::Z * -s, Vec3::Z * s],
            ]
        }
        Shape::Sphere { radius_m, .. } => vec![
            circle(Vec3::ZERO, Vec3::X, Vec3::Y, *radius_m),
            circle(Vec3::ZERO, Vec3::Y, Vec3::Z, *radius_m),
            circle(Vec3::ZERO, Vec3::X, Vec3::Z, *radius_m),
        ],
        Shape::Disc { radius_m, normal } => {
            let (u, v) = basis(Vec3::from(*normal));
            vec![circle(Vec3::ZERO, u, v, *radius_m)]
        }
        Shape::Box { half_extents_m } => {
            let h = Vec3::from(*half_extents_m);
            let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * h;
            let mut lines = vec![
                vec![
                    c(-1., -1., -1.),
                    c(1., -1., -1.),
                    c(1., -1., 1.),
                    c(-1., -1., 1.),
                    c(-1., -1., -1.),
                ],
                vec![
                    c(-1., 1., -1.),
                    c(1., 1., -1.),
                    c(1., 1., 1.),
                    c(-1., 1., 1.),
                    c(-1., 1., -1.),
                ],
            ];
            for (x, z) in [(-1., -1.), (1., -1.), (1., 1.), (-1., 1.)] {
                lines.push(vec![c(x, -1., z), c(x, 1., z)]);
            }
            lines
        }
        Shape::Cone {
            angle_deg,
            radius_m,
        } => {
            let dir = Vec3::from(e.direction).normalize_or(Vec3::Y);
            let (u, v) = basis(dir);
            let mut lines = vec![circle(Vec3::ZERO, u, v, *radius_m)];
            let (sin, cos) = angle_deg.to_radians().sin_cos();
            let length = 0.4;
            for w in [u, v, -u, -v] {
                let rim = w * *radius_m;
                lines.push(vec![rim, rim + (dir * cos + w * sin) * length]);
            }
            lines
        }
        Shape::Line { a_m, b_m } => vec![vec![Vec3::from(*a_m), Vec3::from(*b_m)]],
    }
}

fn draw_gizmo(
    painter: &egui::Painter,
    projector: &Projector,
    e: &Emitter,
    color: Color32,
    is_selected: bool,
) {
    let world_from_emitter = e.transform.world_from_emitter();
    let stroke = Stroke::new(if is_selected { 1.5 } else { 1.0 }, color);
    for line in shape_wireframe(e) {
        let world: Vec<Vec3> = line
            .iter()
            .map(|p| world_from_emitter.transform_point3(*p))
            .collect();
        projector.polyline(painter, &world, stroke);
    }
    if is_selected {
        draw_force_gizmos(painter, projector, e);
        let origin = world_from_emitter.transform_point3(Vec3::ZERO);
        let dir =
            world_from_emitter.transform_vector3(Vec3::from(e.direction).normalize_or(Vec3::Y));
        let tip = origin + dir * 0.3;
        projector.polyline(painter, &[origin, tip], stroke);
        if let Some([_, t]) = projector.segment(origin, tip) {
            painter.circle_filled(t, 2.5, color);
        }
    }
}

/// Colliders, the attractor and the vortex axis of an emitter (all in world space).
fn draw_force_gizmos(painter: &egui::Painter, projector: &Projector, e: &Emitter) {
    let collider = Stroke::new(1.0, Color32::from_rgb(230, 150, 70));
    for sphere in &e.collisions.spheres {
        let c = Vec3::from(sphere.center_m);
        for (u, v) in [(Vec3::X, Vec3::Y), (Vec3::Y, Vec3::Z), (Vec3::X, Vec3::Z)] {
            projector.polyline(painter, &circle(c, u, v, sphere.radius_m), collider);
        }
    }
    if let Some(ground) = &e.collisions.ground {
        let h = ground.height_m;
        let s = 2.0;
        let corners = [
            Vec3::new(-s, h, -s),
            Vec3::new(s, h, -s),
            Vec3::new(s, h, s),
            Vec3::new(-s, h, s),
            Vec3::new(-s, h, -s),
        ];
        projector.polyline(painter, &corners, collider);
    }
    let force = Stroke::new(1.0, Color32::from_rgb(190, 120, 255));
    if let Some(a) = &e.forces.attractor {
        let p = Vec3::from(a.position_m);
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            projector.polyline(painter, &[p - axis * 0.08, p + axis * 0.08], force);
        }
        let (u, v) = basis(Vec3::Y);
        projector.polyline(painter, &circle(p, u, v, a.radius_m), force);
    }
    if let Some(vortex) = &e.forces.vortex {
        let c = Vec3::from(vortex.center_m);
        let axis = Vec3::from(vortex.axis).normalize_or(Vec3::Y);
        projector.polyline(painter, &[c - axis * 1.5, c + axis * 1.5], force);
        let (u, v) = basis(axis);
        projector.polyline(painter, &circle(c, u, v, vortex.radius_m), force);
    }
}

fn hud_ui(painter: &egui::Painter, rect: Rect, state: &EditorState) {
    let s = &state.stats;
    let mut text = format!(
        "{:.0} fps  ·  {:.1} ms  ·  {} particles",
        s.fps(),
        s.mean_frame_secs() * 1e3,
        s.total_alive()
    );
    if state.playback.is_paused {
        text.push_str("  ·  PAUSED");
    }
    let font = egui::FontId::monospace(12.0);
    let pos = rect.left_top() + egui::vec2(10.0, 8.0);
    painter.text(
        pos + egui::vec2(1.0, 1.0),
        egui::Align2::LEFT_TOP,
        &text,
        font.clone(),
        Color32::BLACK,
    );
    painter.text(
        pos,
        egui::Align2::LEFT_TOP,
        text,
        font,
        Color32::from_gray(200),
    );
    // A red badge while a shader fails to build (the last good pipeline keeps running;
    // the panel shows file:line:col and the caret).
    if !state.shader_errors.is_empty() {
        let badge = format!(
            "SHADER ERROR ({}): last good pipeline running, see the panel",
            state.shader_errors.len()
        );
        let at = rect.left_bottom() + egui::vec2(10.0, -28.0);
        let galley = painter.layout_no_wrap(badge, egui::FontId::monospace(12.0), Color32::WHITE);
        let bg = Rect::from_min_size(at, galley.size()).expand(5.0);
        painter.rect_filled(bg, 4.0, Color32::from_rgb(190, 30, 30));
        painter.galley(at, galley, Color32::WHITE);
    }
}

/// A sphere around the bulk of `positions` for framing the camera: the centre of the
/// 5th–95th percentile box and its half diagonal (stray embers do not zoom out the
/// view). `None` when there are no points.
pub fn frame_bounds(positions: &[Vec3]) -> Option<(Vec3, f32)> {
    if positions.is_empty() {
        return None;
    }
    let pick = |axis: usize| {
        let mut v: Vec<f32> = positions
            .iter()
            .map(|p| p[axis])
            .filter(|x| x.is_finite())
            .collect();
        v.sort_by(f32::total_cmp);
        let lo = v.get(v.len() * 5 / 100).copied().unwrap_or(0.0);
        let hi = v
            .get((v.len() * 95 / 100).min(v.len().saturating_sub(1)))
            .copied()
            .unwrap_or(0.0);
        (lo, hi)
    };
    let (x, y, z) = (pick(0), pick(1), pick(2));
    let lo = Vec3::new(x.0, y.0, z.0);
    let hi = Vec3::new(x.1, y.1, z.1);
    let center = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(0.1);
    center.is_finite().then_some((center, radius))
}

/// Where the emitters are, as a fallback frame when no particle is alive.
pub fn emitter_bounds(effect: &Effect) -> (Vec3, f32) {
    let points: Vec<Vec3> = effect
        .emitters
        .iter()
        .filter(|e| e.enabled)
        .map(|e| Vec3::from(e.transform.position_m))
        .collect();
    frame_bounds(&points)
        .map(|(c, r)| (c + Vec3::Y * 0.5, r.max(1.0)))
        .unwrap_or((Vec3::new(0.0, 0.7, 0.0), 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_behind_the_camera_are_clipped() {
        let camera = OrbitCamera::from_hint(&crate::effect::CameraHint::default());
        let rect = Rect::from_min_size(Pos2::ZERO, egui::vec2(200.0, 100.0));
        let p = Projector::new(camera.clip_from_world(2.0), rect);
        // The target projects to the centre of the rectangle.
        let s = p.segment(camera.target, camera.target).expect("visible");
        assert!((s[0].x - 100.0).abs() < 1e-3 && (s[0].y - 50.0).abs() < 1e-3);
        let eye = camera.eye();
        let behind = eye + (eye - camera.target);
        assert!(
            p.segment(behind, eye + (eye - camera.target) * 2.0)
                .is_none()
        );
        assert!(p.segment(behind, camera.target).is_some());
    }

    #[test]
    fn framing_ignores_outliers() {
        let mut pts: Vec<Vec3> = (0..100)
            .map(|i| Vec3::new(0.0, i as f32 * 0.01, 0.0))
            .collect();
        pts.push(Vec3::new(0.0, 1000.0, 0.0));
        let (c, r) = frame_bounds(&pts).expect("points");
        assert!(c.y < 1.0 && r < 1.0, "{c} {r}");
    }
}
