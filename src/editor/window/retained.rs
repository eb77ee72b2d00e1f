//! The retained window image: on CPU adapters the side panel is repainted only when it
//! changed.
//!
//! egui repaints the whole window every frame. On a GPU that is free; on lavapipe a
//! 1280×720 frame of panel background, text and viewport image costs ~13 ms of the
//! frame's ~65. The viewport changes every frame, the panel rarely. So the UI is painted
//! into a persistent image: when every paint job outside the viewport is the same as last
//! frame (and no egui texture changed), only the jobs over the viewport are drawn again,
//! scissored to it; the image is then copied to the window's frame (a plain copy, ~0.3 ms).

use std::hash::{Hash, Hasher};

use egui::epaint::{Mesh, Primitive, Vertex};
use egui::{ClippedPrimitive, Color32, Rect, TextureId};

/// What to paint this frame.
#[derive(Debug)]
pub enum Repaint {
    /// Everything, over a cleared image.
    Full,
    /// Only these jobs (clipped to the live rectangle), over last frame's image.
    Live(Vec<ClippedPrimitive>),
}

/// The persistent image the UI is painted into, and its view.
#[derive(Clone, Debug)]
pub struct RetainedImage {
    /// The image (copied to the window's frame).
    pub texture: wgpu::Texture,
    /// Its view (painted into).
    pub view: wgpu::TextureView,
}

/// The persistent image and what the panel looked like when it was painted.
#[derive(Debug, Default)]
pub struct RetainedUi {
    image: Option<RetainedImage>,
    key: Option<u64>,
    /// Frames painted in full (start, panel changes, resizes).
    pub full_repaints: u64,
    /// Frames where only the viewport was painted.
    pub live_repaints: u64,
}

impl RetainedUi {
    /// The image to paint into, `size` pixels of `format` (recreated on a resize, which
    /// forces a full repaint).
    pub fn image(
        &mut self,
        device: &wgpu::Device,
        size: (u32, u32),
        format: wgpu::TextureFormat,
    ) -> &RetainedImage {
        let stale = self.image.as_ref().is_none_or(|i| {
            let t = &i.texture;
            (t.width(), t.height()) != size || t.format() != format
        });
        if stale {
            // A new image holds nothing yet: the next plan repaints in full.
            self.key = None;
            self.image = None;
        }
        self.image.get_or_insert_with(|| {
            let texture = crate::gpu::texture_2d(
                device,
                "editor::retained_ui",
                size,
                1,
                format,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            );
            let view = texture.create_view(&Default::default());
            RetainedImage { texture, view }
        })
    }

    /// Decides this frame's repaint. `live` is the rectangle (points) repainted every
    /// frame (the viewport); `textures_changed` is true when egui set or
    /// freed a texture; `background` fills the live rectangle first unless an
    /// `opaque_cover` mesh (a texture drawn opaque) covers it (see [`live_jobs`]).
    #[allow(clippy::too_many_arguments)]
    pub fn plan(
        &mut self,
        jobs: &[ClippedPrimitive],
        live: Rect,
        screen: [u32; 2],
        textures_changed: bool,
        background: Color32,
        opaque_cover: Option<TextureId>,
    ) -> Repaint {
        let key = panel_key(jobs, live, screen);
        let same = key.is_some() && self.key == key && !textures_changed && self.image.is_some();
        self.key = key;
        if same {
            self.live_repaints += 1;
            Repaint::Live(live_jobs(jobs, live, background, opaque_cover))
        } else {
            self.full_repaints += 1;
            Repaint::Full
        }
    }

    /// Forgets the panel: the next frame is painted in full.
    pub fn invalidate(&mut self) {
        self.key = None;
    }
}

/// A hash of everything painted outside `live`: the jobs not wholly inside it (their
/// clip rectangles, textures and meshes), `live` itself and the screen size; `None`
/// when a paint callback is among them (its output cannot be compared).
pub fn panel_key(jobs: &[ClippedPrimitive], live: Rect, screen: [u32; 2]) -> Option<u64> {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    screen.hash(&mut h);
    hash_rect(&mut h, live);
    for job in jobs.iter().filter(|j| !live.contains_rect(j.clip_rect)) {
        hash_rect(&mut h, job.clip_rect);
        match &job.primitive {
            Primitive::Mesh(mesh) => {
                mesh.texture_id.hash(&mut h);
                mesh.indices.hash(&mut h);
                let bytes: &[u8] = bytemuck::cast_slice(&mesh.vertices);
                bytes.hash(&mut h);
            }
            Primitive::Callback(_) => return None,
        }
    }
    Some(h.finish())
}

fn hash_rect(h: &mut impl Hasher, r: Rect) {
    for v in [r.min.x, r.min.y, r.max.x, r.max.y] {
        v.to_bits().hash(h);
    }
}

/// The jobs that touch `live`, clipped to it, after a `background` rectangle over it.
/// When one of them is an `opaque_cover` mesh covering `live`, it is the background: the
/// rectangle and every job before it (hidden under it) are left out.
pub fn live_jobs(
    jobs: &[ClippedPrimitive],
    live: Rect,
    background: Color32,
    opaque_cover: Option<TextureId>,
) -> Vec<ClippedPrimitive> {
    let mut out: Vec<ClippedPrimitive> = jobs
        .iter()
        .filter(|j| j.clip_rect.intersects(live))
        .map(|j| ClippedPrimitive {
            clip_rect: j.clip_rect.intersect(live),
            primitive: j.primitive.clone(),
        })
        .filter(|j| j.clip_rect.is_positive())
        .collect();
    let cover = out.iter().rposition(|j| match &j.primitive {
        Primitive::Mesh(m) => {
            Some(m.texture_id) == opaque_cover && mesh_bounds(m).contains_rect(live)
        }
        Primitive::Callback(_) => false,
    });
    match cover {
        Some(first) => {
            out.drain(..first);
        }
        None => {
            let mut mesh = Mesh::default();
            mesh.add_colored_rect(live, background);
            out.insert(
                0,
                ClippedPrimitive {
                    clip_rect: live,
                    primitive: Primitive::Mesh(mesh),
                },
            );
        }
    }
    out
}

fn mesh_bounds(m: &Mesh) -> Rect {
    m.vertices.iter().fold(Rect::NOTHING, |r, v: &Vertex| {
        r.union(Rect::from_min_max(v.pos, v.pos))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{pos2, vec2};

    fn rect_job(clip: Rect, r: Rect, color: Color32) -> ClippedPrimitive {
        let mut mesh = Mesh::default();
        mesh.add_colored_rect(r, color);
        ClippedPrimitive {
            clip_rect: clip,
            primitive: Primitive::Mesh(mesh),
        }
    }

    fn layout() -> (Rect, Rect) {
        let live = Rect::from_min_size(pos2(0.0, 0.0), vec2(600.0, 400.0));
        let panel = Rect::from_min_size(pos2(600.0, 0.0), vec2(200.0, 400.0));
        (live, panel)
    }

    #[test]
    fn viewport_changes_keep_the_key_and_panel_changes_do_not() {
        let (live, panel) = layout();
        let frame = |hud: Color32, text: Color32| {
            vec![
                rect_job(panel, panel, Color32::from_gray(30)),
                rect_job(panel, panel.shrink(20.0), text),
                rect_job(live, live.shrink(5.0), hud),
            ]
        };
        let a = panel_key(&frame(Color32::RED, Color32::WHITE), live, [800, 400]);
        let b = panel_key(&frame(Color32::GREEN, Color32::WHITE), live, [800, 400]);
        let c = panel_key(&frame(Color32::RED, Color32::BLACK), live, [800, 400]);
        let d = panel_key(&frame(Color32::RED, Color32::WHITE), live, [801, 400]);
        assert_eq!(a, b, "a change inside the viewport needs no panel repaint");
        assert_ne!(a, c, "a panel change must repaint it");
        assert_ne!(a, d, "a resize must repaint everything");
    }

    #[test]
    fn live_jobs_are_clipped_to_the_viewport_behind_a_background() {
        let (live, panel) = layout();
        let whole = Rect::from_min_size(pos2(0.0, 0.0), vec2(800.0, 400.0));
        let jobs = vec![
            rect_job(panel, panel, Color32::from_gray(30)),
            rect_job(live, live, Color32::RED),
            // A popup over both: kept, clipped to the viewport.
            rect_job(
                whole,
                Rect::from_min_max(pos2(500.0, 10.0), pos2(700.0, 50.0)),
                Color32::BLUE,
            ),
        ];
        let out = live_jobs(&jobs, live, Color32::BLACK, None);
        assert_eq!(out.len(), 3, "background, viewport job, popup");
        assert!(out.iter().all(|j| live.contains_rect(j.clip_rect)));
        assert_eq!(out[2].clip_rect.max.x, 600.0);
        // An opaque image covering the viewport needs no background.
        let mut image = Mesh::with_texture(TextureId::User(7));
        image.add_rect_with_uv(
            live,
            Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0)),
            Color32::WHITE,
        );
        // Under it, a panel border's end that reaches into the viewport: hidden.
        let jobs = vec![
            rect_job(
                whole,
                Rect::from_min_max(pos2(595.0, 0.0), pos2(605.0, 400.0)),
                Color32::GRAY,
            ),
            ClippedPrimitive {
                clip_rect: live,
                primitive: Primitive::Mesh(image),
            },
            rect_job(
                live,
                Rect::from_min_max(pos2(10.0, 10.0), pos2(20.0, 20.0)),
                Color32::GREEN,
            ),
        ];
        let covered = live_jobs(&jobs, live, Color32::BLACK, Some(TextureId::User(7)));
        assert_eq!(covered.len(), 2, "the image and the overlay after it");
        assert!(
            matches!(&covered[0].primitive, Primitive::Mesh(m) if m.texture_id == TextureId::User(7))
        );
        assert_eq!(live_jobs(&jobs, live, Color32::BLACK, None).len(), 4);
    }
}
