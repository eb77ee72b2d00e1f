//! View ▸ Inspect: the particle under the pointer (or the one clicked, pinned) — its
//! emitter, slot, age, lifetime, position, velocity and the forces acting on it now — shown
//! over the viewport. The frame loop reads it back after drawing (`Player::pick_particle`,
//! `Player::inspect_particle`); the viewport only says where the pointer is.
//!
//! View ▸ State view: the selected emitter's state buffer drawn as images, one texel per
//! slot in slot order — position, velocity and age as colours — refreshed a few times a
//! second: where the ring's head is, which slots live, how velocities spread.

use egui::{Align2, Color32, FontId, Painter, Rect, pos2};

use crate::runtime::{InstanceId, ParticleInfo, Player};

use crate::editor::state::EditorState;

/// How far from the pointer a particle may be to be picked, in render pixels.
const PICK_RADIUS_PX: f32 = 10.0;

/// Frames between two readbacks of the state view.
const STATE_VIEW_EVERY_FRAMES: u64 = 10;

/// An emitter's state as images, one texel per slot (row-major, slot 0 top left).
#[derive(Clone, Debug, PartialEq)]
pub struct StateImages {
    /// The emitter shown.
    pub emitter: usize,
    /// The frame it was read back on (the textures are uploaded once per readback).
    pub frame: u64,
    /// Position (each axis scaled over the living particles' extent), velocity (0.5 + v /
    /// 2·max speed) and age as a fraction of the lifetime; dead slots dark.
    pub images: [egui::ColorImage; 3],
}

/// Dead slots in the state view.
const DEAD: Color32 = Color32::from_rgb(18, 18, 26);

impl StateImages {
    /// The images of `particles` (emitter `emitter`'s pool, in slot order).
    pub fn of(emitter: usize, frame: u64, particles: &[crate::gpu::types::Particle]) -> Self {
        let n = particles.len().max(1);
        let w = (n as f64).sqrt().ceil() as usize;
        let h = n.div_ceil(w);
        let alive: Vec<_> = particles.iter().filter(|p| p.is_alive()).collect();
        let (lo, hi) = alive.iter().fold(
            (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(p.position()), hi.max(p.position())),
        );
        let extent = (hi - lo).max(glam::Vec3::splat(1e-6));
        let top_speed = alive
            .iter()
            .map(|p| p.velocity().abs().max_element())
            .fold(1e-6, f32::max);
        let byte = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
        let colour = |v: glam::Vec3| Color32::from_rgb(byte(v.x), byte(v.y), byte(v.z));
        let mut images = std::array::from_fn(|_| egui::ColorImage::filled([w, h], Color32::BLACK));
        for (k, p) in particles.iter().enumerate() {
            let texels = if p.is_alive() {
                let age = byte(p.pos_age[3] / p.vel_life[3].max(1e-6));
                [
                    colour((p.position() - lo) / extent),
                    colour(p.velocity() / (2.0 * top_speed) + 0.5),
                    Color32::from_rgb(age, age, age),
                ]
            } else {
                [DEAD; 3]
            };
            for (image, t) in images.iter_mut().zip(texels) {
                image.pixels[k] = t;
            }
        }
        Self {
            emitter,
            frame,
            images,
        }
    }
}

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
    /// The state view's images (View ▸ State view).
    pub state_images: Option<StateImages>,
}

/// The player's particles as the Inspect view asks them of the editor's one instance.
pub(crate) struct Inspected<'a> {
    pub player: &'a Player,
    pub instance: InstanceId,
    /// The viewport's render size, pixels.
    pub viewport_px: (u32, u32),
    /// The frame's number (the state view refreshes every few frames).
    pub frame: u64,
}

/// After the draw: picks or follows the inspected particle (a blocking readback, only
/// while Inspect is on), and refreshes the state view.
pub(crate) fn update_inspect(
    gfx: &Inspected<'_>,
    state: &mut EditorState,
    camera: &crate::render::OrbitCamera,
) {
    update_state_view(gfx, state);
    let inspect = &mut state.inspect;
    if !state.view.inspect {
        inspect.pointer = None;
        inspect.pinned = None;
        inspect.shown = None;
        return;
    }
    let view = camera.view(gfx.viewport_px);
    let (w, h) = view.size_px();
    let pick = |p: [f32; 2]| {
        let pixel = glam::Vec2::new(p[0] * w as f32, p[1] * h as f32);
        gfx.player
            .pick_particle(gfx.instance, &view, pixel, PICK_RADIUS_PX)
            .unwrap_or_else(|err| {
                log::warn!("inspecting particles: {err}");
                None
            })
    };
    if std::mem::take(&mut inspect.pin_requested) {
        inspect.pinned = inspect.pointer.and_then(pick).map(|i| (i.emitter, i.slot));
    }
    inspect.shown = match inspect.pinned {
        Some((e, slot)) => gfx
            .player
            .inspect_particle(gfx.instance, e, slot)
            .unwrap_or_default(),
        None => inspect.pointer.and_then(pick),
    };
}

/// The state view's images of the selected emitter, every few frames while it is on.
fn update_state_view(gfx: &Inspected<'_>, state: &mut EditorState) {
    if !state.view.state_view {
        state.inspect.state_images = None;
        return;
    }
    let e = state.selected;
    let stale = state
        .inspect
        .state_images
        .as_ref()
        .is_none_or(|s| s.emitter != e);
    if !stale && !gfx.frame.is_multiple_of(STATE_VIEW_EVERY_FRAMES) {
        return;
    }
    match gfx.player.particles(gfx.instance, e) {
        Ok(particles) => {
            state.inspect.state_images = Some(StateImages::of(e, gfx.frame, &particles));
        }
        Err(err) => log::warn!("reading the state of emitter {e}: {err}"),
    }
}

/// The state view: a window with the selected emitter's state as images.
pub fn state_view_ui(
    ctx: &egui::Context,
    state: &mut EditorState,
    textures: &mut Option<([egui::TextureHandle; 3], u64)>,
) {
    let Some(images) = &state.inspect.state_images else {
        *textures = None;
        return;
    };
    let names = ["position", "velocity", "age"];
    let options = egui::TextureOptions::NEAREST;
    let (handles, uploaded) = textures.get_or_insert_with(|| {
        let handles =
            std::array::from_fn(|i| ctx.load_texture(names[i], images.images[i].clone(), options));
        (handles, images.frame)
    });
    if *uploaded != images.frame {
        for (h, image) in handles.iter_mut().zip(&images.images) {
            h.set(image.clone(), options);
        }
        *uploaded = images.frame;
    }
    let name = state
        .running
        .emitters
        .get(images.emitter)
        .map_or("?", |e| e.name.as_str());
    let mut open = true;
    egui::Window::new(format!("State · {name}"))
        .open(&mut open)
        .default_pos(egui::pos2(16.0, 48.0))
        .resizable(false)
        .show(ctx, |ui| {
            ui.label(format!(
                "{} slots, one texel each (slot 0 top left); dead slots dark",
                images.images[0].pixels.len()
            ));
            ui.horizontal(|ui| {
                for (h, n) in handles.iter().zip(names) {
                    ui.vertical(|ui| {
                        ui.label(n);
                        ui.image((h.id(), egui::vec2(160.0, 160.0)));
                    });
                }
            });
        });
    if !open {
        state.view.state_view = false;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::types::Particle;

    fn particle(pos: [f32; 3], vel: [f32; 3], age: f32, life: f32) -> Particle {
        Particle {
            pos_age: [pos[0], pos[1], pos[2], age],
            vel_life: [vel[0], vel[1], vel[2], life],
        }
    }

    /// One texel per slot in slot order; positions span the living particles' extent,
    /// velocities are centred on grey, ages are the fraction of the lifetime, dead slots
    /// dark.
    #[test]
    fn the_state_view_draws_one_texel_per_slot() {
        let dead = Particle::default();
        let particles = [
            particle([0.0, 0.0, 0.0], [2.0, 0.0, -2.0], 0.5, 1.0),
            dead,
            particle([1.0, 2.0, 4.0], [0.0, 0.0, 0.0], 0.0, 2.0),
            dead,
            particle([0.5, 1.0, 2.0], [0.0, -1.0, 0.0], 1.5, 2.0),
        ];
        let s = StateImages::of(3, 7, &particles);
        let [pos, vel, age] = &s.images;
        assert_eq!((s.emitter, pos.size), (3, [3, 2]));
        assert_eq!(pos.pixels[0], Color32::from_rgb(0, 0, 0));
        assert_eq!(pos.pixels[2], Color32::from_rgb(255, 255, 255));
        assert_eq!(pos.pixels[4], Color32::from_rgb(128, 128, 128));
        assert_eq!(vel.pixels[0], Color32::from_rgb(255, 128, 0));
        assert_eq!(vel.pixels[2], Color32::from_rgb(128, 128, 128));
        assert_eq!(age.pixels[0], Color32::from_rgb(128, 128, 128));
        assert_eq!(age.pixels[4], Color32::from_rgb(191, 191, 191));
        for image in &s.images {
            assert_eq!(image.pixels[1], DEAD);
            assert_eq!(image.pixels[3], DEAD);
        }
    }
}
