//! View ▸ Inspect: the particle under the pointer (or the one clicked, pinned) — its
//! emitter, slot, age, lifetime, position, velocity and the forces acting on it now — shown
//! over the viewport. The frame loop reads it back after drawing (`Player::pick_particle`,
//! `Player::inspect_particle`); the viewport only says where the pointer is.

use egui::{Align2, Color32, FontId, Painter, Rect, pos2};

use crate::runtime::ParticleInfo;

use super::gfx::Gfx;
use super::state::EditorState;

/// How far from the pointer a particle may be to be picked, in render pixels.
const PICK_RADIUS_PX: f32 = 10.0;

/// What Inspect follows and shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Inspect {
    /// The pointer over the viewport, as a fraction of its size (x right, y down).
    pub pointer: Option<[f32; 2]>,
    /// A click asked to pin the particle under the pointer (or unpin, over none).
    pub pin_requested: bool,
    /// The pinned particle: (emitter, slot).
    pub pinned: Option<(usize, u32)>,
    /// What the last frame found.
    pub shown: Option<ParticleInfo>,
}

impl Gfx {
    /// After the draw: picks or follows the inspected particle (a blocking readback,
    /// only while Inspect is on).
    pub(super) fn update_inspect(
        &mut self,
        state: &mut EditorState,
        camera: &crate::render::OrbitCamera,
    ) {
        let inspect = &mut state.inspect;
        if !state.view.inspect {
            *inspect = Inspect::default();
            return;
        }
        let view = camera.view(self.viewport_px);
        let (w, h) = view.size_px();
        let pick = |gfx: &Self, p: [f32; 2]| {
            let pixel = glam::Vec2::new(p[0] * w as f32, p[1] * h as f32);
            gfx.player
                .pick_particle(gfx.instance, &view, pixel, PICK_RADIUS_PX)
                .unwrap_or_else(|err| {
                    log::warn!("inspecting particles: {err}");
                    None
                })
        };
        if std::mem::take(&mut inspect.pin_requested) {
            inspect.pinned = inspect
                .pointer
                .and_then(|p| pick(self, p))
                .map(|i| (i.emitter, i.slot));
        }
        inspect.shown = match inspect.pinned {
            Some((e, slot)) => self
                .player
                .inspect_particle(self.instance, e, slot)
                .unwrap_or_default(),
            None => inspect.pointer.and_then(|p| pick(self, p)),
        };
    }
}

/// The inspected particle's read-out in the viewport's top-right corner.
pub fn inspect_overlay(painter: &Painter, rect: Rect, state: &EditorState) {
    let Some(info) = &state.inspect.shown else {
        return;
    };
    let name = state
        .running
        .emitters
        .get(info.emitter)
        .map_or("?", |e| e.name.as_str());
    let v3 = |v: glam::Vec3| format!("{:7.3} {:7.3} {:7.3}", v.x, v.y, v.z);
    let mut lines = vec![
        format!(
            "{name} · slot {}{}",
            info.slot,
            if state.inspect.pinned.is_some() {
                " · pinned"
            } else {
                ""
            }
        ),
        format!("age {:.3} s of {:.3} s", info.age_secs, info.lifetime_secs),
        format!("position m    {}", v3(info.position_m)),
        format!("velocity m/s  {}", v3(info.velocity_m_per_s)),
        "forces m/s²".to_owned(),
    ];
    lines.extend(
        info.forces
            .iter()
            .map(|(n, a)| format!("  {n:<18} {}", v3(*a))),
    );
    let font = FontId::monospace(11.0);
    let at = pos2(rect.right() - 8.0, rect.top() + 8.0);
    let text = lines.join("\n");
    let galley = painter.layout_no_wrap(text, font, Color32::from_gray(230));
    let r = Align2::RIGHT_TOP.anchor_size(at, galley.size()).expand(6.0);
    painter.rect_filled(r, 4.0, Color32::from_black_alpha(190));
    painter.galley(r.min + egui::vec2(6.0, 6.0), galley, Color32::WHITE);
}
