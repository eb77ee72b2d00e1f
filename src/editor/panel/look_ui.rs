//! The Look section: sprite, blend, size and colour over life, intensity, exposure.

use egui::{Color32, DragValue, Rgba, RichText, Sense, Ui};

use crate::effect::{
    BlendMode, Bloom, ColorStop, DrawPath, Effect, Flipbook, FlipbookMode, Look, MAX_COLOR_STOPS,
    MAX_TRAIL_POINTS, Param, Post, SPLAT_BELOW_PX, Sprite, Streak, TILES_ABOVE_PX, Trail,
    TrailMode,
};
pub use crate::render::look_bake::sample_gradient;

use crate::editor::panel::curve_editor::{ParamSpec, param_row};
use crate::editor::panel::drag;
use crate::editor::state::ViewSettings;

/// The size parameter's editor: metres over normalised age.
pub const SIZE: ParamSpec = ParamSpec {
    name: "Size curve",
    unit: " m",
    values: 0.0..=100.0,
    speed: 0.002,
    t_max: 1.0,
    t_unit: "of life",
};
const OPACITY: ParamSpec = ParamSpec {
    name: "Opacity curve",
    unit: "×",
    values: 0.0..=100.0,
    speed: 0.005,
    t_max: 1.0,
    t_unit: "of life",
};
const SPIN: ParamSpec = ParamSpec {
    name: "Spin curve",
    unit: " °/s",
    values: -3600.0..=3600.0,
    speed: 1.0,
    t_max: 1.0,
    t_unit: "of life",
};
const FRAME: ParamSpec = ParamSpec {
    name: "Frame curve",
    unit: "",
    values: 0.0..=4095.0,
    speed: 0.05,
    t_max: 1.0,
    t_unit: "of life",
};

/// The selected emitter's look, the effect's composite (exposure, bloom) and the
/// viewport exposure. `sprite_error` is the selected emitter's sprite load error.
pub fn look_ui(
    ui: &mut Ui,
    effect: &mut Effect,
    selected: usize,
    view: &mut ViewSettings,
    sprite_error: Option<&str>,
) {
    egui::Grid::new("exposure_grid")
        .num_columns(2)
        .spacing([10.0, 5.0])
        .min_col_width(96.0)
        .show(ui, |ui| {
            let label = ui.label("Exposure").on_hover_text(
                "Viewport exposure: multiplies the HDR image before the ACES tonemap (a view \
                    setting, not part of the preset)",
            );
            ui.add(
                egui::Slider::new(&mut view.exposure, 0.05..=8.0)
                    .logarithmic(true)
                    .fixed_decimals(2),
            )
            .labelled_by(label.id);
            ui.end_row();
            post_ui(ui, &mut effect.post);
        });
    ui.separator();
    let Some(e) = effect.emitters.get_mut(selected) else {
        return;
    };
    look_fields_ui(ui, &mut e.look);
    crate::editor::panel::grid("lit_grid").show(ui, |ui| {
        crate::editor::panel::lighting_ui::lit_rows_ui(ui, &mut e.look)
    });
    if let Some(err) = sprite_error {
        ui.colored_label(Color32::from_rgb(255, 110, 90), err);
    }
}

/// The effect's composite settings (rows of an open grid).
fn post_ui(ui: &mut Ui, post: &mut Post) {
    let label = ui
        .label("Preset exposure")
        .on_hover_text("Saved with the preset: multiplies the HDR image before bloom and tonemap");
    ui.add(
        egui::Slider::new(&mut post.exposure, 0.05..=8.0)
            .logarithmic(true)
            .fixed_decimals(2),
    )
    .labelled_by(label.id);
    ui.end_row();
    ui.label("Bloom").on_hover_text(
        "Light above the threshold is blurred over a mip chain and added back (off: no passes run)",
    );
    let mut on = post.bloom.is_some();
    if ui.checkbox(&mut on, "glow").changed() {
        post.bloom = on.then(Bloom::default);
    }
    ui.end_row();
    let label = ui.label("Resolution").on_hover_text(
        "Smoke: alpha-blended layers drawn at 1/n of the resolution and upsampled in the \
            composite (soft smoke looks the same and costs n² less fill). Flames: large \
            additive sprites (12 px or more on screen) drawn at 1/n into a glow layer the \
            bloom and tonemap add (a quarter of the fill; sparks stay sharp)",
    );
    ui.horizontal(|ui| {
        ui.label("smoke");
        for (n, text) in [(1, "full"), (2, "½"), (4, "¼")] {
            ui.radio_value(&mut post.alpha_downscale, n, text)
                .labelled_by(label.id);
        }
        ui.label("flames");
        for (n, text) in [(1, "full"), (2, "½")] {
            ui.radio_value(&mut post.glow_downscale, n, text)
                .labelled_by(label.id);
        }
    });
    ui.end_row();
    if let Some(b) = &mut post.bloom {
        let label = ui
            .label("Bloom threshold")
            .on_hover_text("HDR brightness where the glow starts");
        ui.add(drag(&mut b.threshold, 0.0..=100.0, 0.01, ""))
            .labelled_by(label.id);
        ui.end_row();
        let label = ui
            .label("Bloom intensity")
            .on_hover_text("How much blurred light is added");
        ui.add(drag(&mut b.intensity, 0.0..=10.0, 0.01, ""))
            .labelled_by(label.id);
        ui.end_row();
        let label = ui
            .label("Bloom levels")
            .on_hover_text("Blur levels: each halves the resolution (more = wider glow)");
        ui.add(DragValue::new(&mut b.levels).range(1..=8))
            .labelled_by(label.id);
        ui.end_row();
    }
}

/// Sprite, flipbook, blend, sizes, randomness, streaks, soft edges, intensity and the
/// colour gradient of one look.
pub fn look_fields_ui(ui: &mut Ui, look: &mut Look) {
    egui::Grid::new("look_grid")
        .num_columns(2)
        .spacing([10.0, 5.0])
        .min_col_width(96.0)
        .show(ui, |ui| {
            sprite_rows_ui(ui, look);
            blend_rows_ui(ui, look);
            param_row(
                ui,
                "Size",
                "Billboard diameter over the particle's life, metres",
                &mut look.size_m,
                &SIZE,
            );
            param_row(
                ui,
                "Opacity",
                "Multiplies the particle's contribution over its life: its light when additive, \
                    its coverage when alpha",
                &mut look.opacity,
                &OPACITY,
            );
            let label = ui
                .label("Rotation")
                .on_hover_text("Random initial rotation spread, degrees");
            ui.add(drag(&mut look.rotation_random_deg, 0.0..=360.0, 1.0, "°").prefix("random "))
                .labelled_by(label.id);
            ui.end_row();
            param_row(
                ui,
                "Spin",
                "Angular velocity over the particle's life, degrees per second (a range: each \
                    particle spins at its own rate)",
                &mut look.spin_deg_per_s,
                &SPIN,
            );
            streak_row_ui(ui, look);
            trail_rows_ui(ui, look);
            brightness_rows_ui(ui, look);
        });
    ui.add_space(4.0);
    ui.label("Colour over life").on_hover_text(
        "Colour (linear RGB) and alpha over the normalised age: 0 = birth, 1 = death. Click the \
            bar to add a stop, drag a handle to move it, right-click a handle to remove it",
    );
    gradient_editor_ui(ui, &mut look.color_over_life);
    color_stops_ui(ui, &mut look.color_over_life);
}

/// Blend mode and draw path (rows of an open grid).
fn blend_rows_ui(ui: &mut Ui, look: &mut Look) {
    let label_tip = "Additive: light adds up, order-independent (fire, sparks). Alpha: \
        premultiplied over, darkens what is behind (smoke); alpha layers are drawn \
        first, sorted back to front";
    ui.label("Blend").on_hover_text(label_tip);
    ui.horizontal(|ui| {
        for b in [BlendMode::Additive, BlendMode::Alpha] {
            ui.radio_value(&mut look.blend, b, blend_label(b))
                .on_hover_text(label_tip);
        }
    });
    ui.end_row();
    let label = ui.label("Draw path").on_hover_text(format!(
        "auto: compute splat when particles project below {SPLAT_BELOW_PX} px, blend \
            additively and have no streak; on GPUs the tile rasteriser from \
            {TILES_ABOVE_PX} px; billboards otherwise. billboard: instanced quads. \
            splat: compute splat (additive only; alpha falls back to billboards). \
            tiles: the compute tile rasteriser (alpha-blended emitters take it together \
            or not at all)"
    ));
    egui::ComboBox::from_id_salt("draw_path")
        .selected_text(draw_path_label(look.draw_path))
        .show_ui(ui, |ui| {
            for d in [
                DrawPath::Auto,
                DrawPath::Billboard,
                DrawPath::Splat,
                DrawPath::Tiles,
            ] {
                ui.selectable_value(&mut look.draw_path, d, draw_path_label(d));
            }
        })
        .response
        .labelled_by(label.id);
    ui.end_row();
}

/// The velocity streak: on/off, length in seconds and its cap (a row of an open grid).
fn streak_row_ui(ui: &mut Ui, look: &mut Look) {
    let label = ui.label("Streak").on_hover_text(
        "Stretch each billboard from where the particle was (length \
            seconds ago) to where it is: spark trails",
    );
    ui.horizontal(|ui| {
        let mut on = look.streak.is_some();
        if ui.checkbox(&mut on, "stretch").changed() {
            look.streak = on.then(Streak::default);
        }
        if let Some(s) = &mut look.streak {
            ui.add(drag(&mut s.length_secs, 0.0..=1.0, 0.001, " s"))
                .labelled_by(label.id);
            ui.add(drag(&mut s.max_length_m, 0.0..=100.0, 0.01, " m").prefix("≤ "))
                .labelled_by(label.id);
        }
    });
    ui.end_row();
}

/// Soft ground and intensity (rows of an open grid).
fn brightness_rows_ui(ui: &mut Ui, look: &mut Look) {
    let label = ui.label("Soft ground").on_hover_text(
        "Fade sprites over this distance above the ground plane (the \
            emitter's ground collider, else y = 0) instead of cutting them: soft \
            particles. 0 = off",
    );
    ui.add(drag(&mut look.soft_ground_m, 0.0..=10.0, 0.002, " m"))
        .labelled_by(label.id);
    ui.end_row();
    let label = ui
        .label("Intensity")
        .on_hover_text("Multiplies the colour: HDR brightness before exposure and tonemap");
    ui.add(drag(&mut look.intensity, 0.0..=1000.0, 0.01, "").min_decimals(2))
        .labelled_by(label.id);
    ui.end_row();
}

/// The trail: on/off, points and spacing; width, tapers and the sprite when on (rows of an
/// open grid).
fn trail_rows_ui(ui: &mut Ui, look: &mut Look) {
    let label = ui.label("Trail").on_hover_text(
        "A ribbon (drawn by the billboards) through each particle's last positions, recorded \
            every few steps, or — an emitter fed by events — one per parent through the \
            particles it spawned, in order; the velocity streak is the cheaper option",
    );
    ui.horizontal(|ui| {
        let mut on = look.trail.is_some();
        if ui.checkbox(&mut on, "ribbon").changed() {
            look.trail = on.then(Trail::default);
        }
        if let Some(t) = &mut look.trail {
            let menu = egui::ComboBox::from_id_salt("trail_mode")
                .selected_text(format!("through {}", t.mode.label()))
                .show_ui(ui, |ui| {
                    for m in TrailMode::ALL {
                        ui.selectable_value(&mut t.mode, m, m.label());
                    }
                });
            menu.response.labelled_by(label.id).widget_info(|| {
                egui::WidgetInfo::labeled(egui::Role::ComboBox, true, "Trail mode")
            });
        }
    });
    ui.end_row();
    if let Some(t) = look.trail.as_mut().filter(|t| t.mode == TrailMode::History) {
        trail_points_row_ui(ui, t);
    }
    trail_width_rows_ui(ui, look);
}

/// The points a trail through a particle's last positions keeps (a row of an open grid).
fn trail_points_row_ui(ui: &mut Ui, t: &mut Trail) {
    let label = ui.label("Trail points").on_hover_text(
        "Positions kept per particle, and how far back they reach in seconds of simulated time \
            (a step coarser than the spacing keeps fewer: one per step)",
    );
    ui.horizontal(|ui| {
        ui.add(
            DragValue::new(&mut t.points)
                .range(2..=MAX_TRAIL_POINTS)
                .prefix("points "),
        )
        .labelled_by(label.id);
        ui.add(drag(&mut t.length_secs, 1e-3..=60.0, 0.005, " s").prefix("over "))
            .labelled_by(label.id);
    });
    ui.end_row();
}

/// The trail's width, tapers and sprite (rows of an open grid; none without a trail).
fn trail_width_rows_ui(ui: &mut Ui, look: &mut Look) {
    let Some(t) = &mut look.trail else {
        return;
    };
    let label = ui.label("Trail width").on_hover_text(
        "Width at the particle (× its size), then the width and opacity at the tail as \
            fractions of it; sprite: draw the particle's sprite too",
    );
    ui.horizontal(|ui| {
        ui.add(drag(&mut t.width, 0.0..=100.0, 0.01, "×"))
            .labelled_by(label.id);
        ui.add(drag(&mut t.tail_width, 0.0..=1.0, 0.01, "").prefix("tail "))
            .labelled_by(label.id);
        ui.add(drag(&mut t.tail_opacity, 0.0..=1.0, 0.01, "").prefix("fade "))
            .labelled_by(label.id);
        ui.checkbox(&mut t.draw_sprite, "sprite");
    });
    ui.end_row();
}

/// The sprite picker, the PNG path and the flipbook (rows of an open grid).
fn sprite_rows_ui(ui: &mut Ui, look: &mut Look) {
    let label = ui.label("Sprite").on_hover_text(
        "Built-in procedural sprites, or a PNG with alpha (path relative to the \
            preset file; reloads when the file changes)",
    );
    let is_image = matches!(look.sprite, Sprite::Image(_));
    egui::ComboBox::from_id_salt("sprite")
        .selected_text(if is_image {
            "PNG file"
        } else {
            look.sprite.label()
        })
        .show_ui(ui, |ui| {
            for s in Sprite::BUILT_IN {
                let text = s.label().to_owned();
                ui.selectable_value(&mut look.sprite, s, text);
            }
            if ui.selectable_label(is_image, "PNG file").clicked() && !is_image {
                look.sprite = Sprite::Image("textures/flame_sheet.png".to_owned());
            }
        })
        .response
        .labelled_by(label.id);
    ui.end_row();
    if let Sprite::Image(path) = &mut look.sprite {
        let label = ui
            .label("PNG path")
            .on_hover_text("Relative to the preset file");
        ui.text_edit_singleline(path).labelled_by(label.id);
        ui.end_row();
    }
    ui.label("Flipbook").on_hover_text(
        "Treat the sprite as an atlas of rows × columns frames (row-major from \
            the top left) and animate it",
    );
    let mut on = look.flipbook.is_some();
    if ui.checkbox(&mut on, "animate").changed() {
        look.flipbook = on.then(|| {
            let mut f = Flipbook::default();
            if look.sprite != Sprite::FlameSheet {
                (f.rows, f.cols) = (1, 1);
            }
            f
        });
    }
    ui.end_row();
    if let Some(f) = &mut look.flipbook {
        flipbook_rows_ui(ui, f);
    }
}

/// A flipbook's rows (of an open grid): its frames, their timing, blending and start.
fn flipbook_rows_ui(ui: &mut Ui, f: &mut Flipbook) {
    let label = ui
        .label("Frames")
        .on_hover_text("Rows × columns of the atlas");
    ui.horizontal(|ui| {
        ui.add(DragValue::new(&mut f.rows).range(1..=64).suffix(" rows"))
            .labelled_by(label.id);
        ui.add(DragValue::new(&mut f.cols).range(1..=64).suffix(" cols"))
            .labelled_by(label.id);
    });
    ui.end_row();
    let label = ui.label("Frame timing").on_hover_text(
        "Over life: first frame at birth, last at death. Frame rate: a fixed rate, looping. \
            Curve: the frame over life, as a parameter",
    );
    let frames = f.rows * f.cols;
    ui.horizontal(|ui| {
        let over_life = matches!(f.mode, FlipbookMode::OverLife);
        if ui
            .radio(over_life, "over life")
            .labelled_by(label.id)
            .clicked()
        {
            f.mode = FlipbookMode::OverLife;
        }
        let rate = matches!(f.mode, FlipbookMode::FrameRate { .. });
        if ui.radio(rate, "fps").labelled_by(label.id).clicked() && !rate {
            f.mode = FlipbookMode::FrameRate { fps: 24.0 };
        }
        if let FlipbookMode::FrameRate { fps } = &mut f.mode {
            ui.add(DragValue::new(fps).range(0.0..=240.0).speed(0.1))
                .labelled_by(label.id);
        }
        let curve = matches!(f.mode, FlipbookMode::Frames(_));
        if ui.radio(curve, "curve").labelled_by(label.id).clicked() && !curve {
            let last = frames.saturating_sub(1) as f32;
            f.mode = FlipbookMode::Frames(Param::Curve {
                keys: vec![(0.0, 0.0), (1.0, last)],
                smooth: false,
            });
        }
    });
    ui.end_row();
    if let FlipbookMode::Frames(p) = &mut f.mode {
        let spec = ParamSpec {
            values: 0.0..=frames.saturating_sub(1) as f32,
            ..FRAME
        };
        param_row(
            ui,
            "Frame",
            "The flipbook frame over the particle's life (0 = first; fractions blend when \
                blending frames)",
            p,
            &spec,
        );
    }
    ui.label("");
    ui.horizontal(|ui| {
        ui.checkbox(&mut f.blend_frames, "blend frames")
            .on_hover_text("Cross-fade consecutive frames (two texture samples)");
        ui.checkbox(&mut f.random_start, "random start")
            .on_hover_text("Each particle starts on a random frame");
    });
    ui.end_row();
}

/// An interactive gradient bar: click to add a stop (coloured as the gradient there),
/// drag a handle to move a stop between its neighbours, right-click a handle to remove it
/// (one stop always remains). Any number of stops.
pub fn gradient_editor_ui(ui: &mut Ui, stops: &mut Vec<ColorStop>) {
    let width = ui.available_width().min(330.0);
    let (rect, bar) = ui.allocate_exact_size(egui::vec2(width, 26.0), Sense::click());
    bar.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::Button, true, "Gradient (click to add a stop)")
    });
    paint_gradient(ui, rect, stops);
    let (handles, _) = ui.allocate_exact_size(egui::vec2(width, 12.0), Sense::hover());
    let id = bar.id;
    let x_of = |t: f32| rect.left() + t.clamp(0.0, 1.0) * rect.width();
    let mut remove = None;
    for k in 0..stops.len() {
        let x = x_of(stops[k].t);
        let hit =
            egui::Rect::from_center_size(egui::pos2(x, handles.center().y), egui::vec2(10.0, 12.0));
        let r = ui
            .interact(hit, id.with(("stop", k)), Sense::click_and_drag())
            .on_hover_text(format!(
                "t {:.3} · drag to move · right-click to remove",
                stops[k].t
            ));
        if r.dragged() {
            let lo = if k == 0 { 0.0 } else { stops[k - 1].t };
            let hi = stops.get(k + 1).map_or(1.0, |s| s.t);
            let t = stops[k].t + r.drag_delta().x / rect.width();
            stops[k].t = t.clamp(lo, hi);
        }
        if r.secondary_clicked() && stops.len() > 1 {
            remove = Some(k);
        }
        let fill = to_color32([stops[k].rgba[0], stops[k].rgba[1], stops[k].rgba[2], 1.0]);
        let stroke = if r.hovered() || r.dragged() {
            egui::Stroke::new(2.0, Color32::WHITE)
        } else {
            egui::Stroke::new(1.0, Color32::GRAY)
        };
        let top = egui::pos2(x, handles.top());
        ui.painter().add(egui::Shape::convex_polygon(
            vec![
                top,
                egui::pos2(x + 5.0, handles.bottom()),
                egui::pos2(x - 5.0, handles.bottom()),
            ],
            fill,
            stroke,
        ));
    }
    if let Some(k) = remove {
        stops.remove(k);
    }
    if bar.clicked()
        && let Some(pos) = bar.interact_pointer_pos()
    {
        let t = ((pos.x - rect.left()) / rect.width()).clamp(0.0, 1.0);
        let rgba = sample_gradient(stops, t);
        let at = stops.iter().position(|s| s.t > t).unwrap_or(stops.len());
        stops.insert(at, ColorStop { t, rgba });
    }
}

fn draw_path_label(d: DrawPath) -> &'static str {
    match d {
        DrawPath::Auto => "auto",
        DrawPath::Billboard => "billboard",
        DrawPath::Splat => "splat",
        DrawPath::Tiles => "tiles",
    }
}

/// Linear RGBA → egui colour (egui's `Rgba` is linear, premultiplied).
fn to_color32(rgba: [f32; 4]) -> Color32 {
    let [r, g, b, a] = rgba.map(|v| v.clamp(0.0, 1.0));
    Color32::from(Rgba::from_rgba_unmultiplied(r, g, b, a))
}

/// The gradient as a strip: the upper half shows the colour over a dark checkerboard with
/// its alpha, the lower half the opaque colour.
fn paint_gradient(ui: &Ui, rect: egui::Rect, stops: &[ColorStop]) {
    let painter = ui.painter_at(rect);
    let cell = 6.5;
    let cols = (rect.width() / cell).ceil() as usize;
    let rows = (rect.height() / cell).ceil() as usize;
    for cy in 0..rows {
        for cx in 0..cols {
            let shade = if (cx + cy) % 2 == 0 { 40 } else { 70 };
            let min = rect.min + egui::vec2(cx as f32 * cell, cy as f32 * cell);
            painter.rect_filled(
                egui::Rect::from_min_size(min, egui::vec2(cell, cell)),
                0.0,
                Color32::from_gray(shade),
            );
        }
    }
    if stops.is_empty() {
        return;
    }
    let mid = rect.center().y;
    let mut mesh = egui::Mesh::default();
    let mut add_band = |top: f32, bottom: f32, opaque: bool| {
        let mut points: Vec<(f32, [f32; 4])> = stops.iter().map(|s| (s.t, s.rgba)).collect();
        if let Some(first) = points.first().copied()
            && first.0 > 0.0
        {
            points.insert(0, (0.0, first.1));
        }
        if let Some(last) = points.last().copied()
            && last.0 < 1.0
        {
            points.push((1.0, last.1));
        }
        for pair in points.windows(2) {
            let (t0, c0) = pair[0];
            let (t1, c1) = pair[1];
            let x0 = rect.left() + t0.clamp(0.0, 1.0) * rect.width();
            let x1 = rect.left() + t1.clamp(0.0, 1.0) * rect.width();
            let color = |c: [f32; 4]| {
                if opaque {
                    to_color32([c[0], c[1], c[2], 1.0])
                } else {
                    to_color32(c)
                }
            };
            let base = mesh.vertices.len() as u32;
            mesh.colored_vertex(egui::pos2(x0, top), color(c0));
            mesh.colored_vertex(egui::pos2(x1, top), color(c1));
            mesh.colored_vertex(egui::pos2(x1, bottom), color(c1));
            mesh.colored_vertex(egui::pos2(x0, bottom), color(c0));
            mesh.add_triangle(base, base + 1, base + 2);
            mesh.add_triangle(base, base + 2, base + 3);
        }
    };
    add_band(rect.top(), mid, false);
    add_band(mid, rect.bottom(), true);
    painter.add(egui::Shape::mesh(mesh));
}

/// One row per stop (t, colour with alpha, remove) and an add button. Each stop's t is
/// clamped between its neighbours, so the list stays sorted.
pub fn color_stops_ui(ui: &mut Ui, stops: &mut Vec<ColorStop>) {
    let mut remove = None;
    let n = stops.len();
    for k in 0..n {
        let lo = if k == 0 { 0.0 } else { stops[k - 1].t };
        let hi = if k + 1 == n { 1.0 } else { stops[k + 1].t };
        ui.horizontal(|ui| {
            let stop = &mut stops[k];
            let label = ui.label(format!("Stop {}", k + 1));
            ui.add(
                DragValue::new(&mut stop.t)
                    .range(lo..=hi)
                    .speed(0.002)
                    .prefix("t ")
                    .fixed_decimals(3),
            )
            .labelled_by(label.id)
            .on_hover_text("Normalised age of this stop (0 = birth, 1 = death)");
            // Edit a copy: egui's colour round trip (through premultiplied alpha) would
            // otherwise rewrite the stop every frame — zeroing the colour of a stop with
            // alpha 0 and marking the preset unsaved by merely showing it.
            let mut rgba = stop.rgba;
            if ui
                .color_edit_button_rgba_unmultiplied(&mut rgba)
                .labelled_by(label.id)
                .on_hover_text("Colour (linear RGB) and alpha")
                .changed()
            {
                stop.rgba = rgba;
            }
            ui.weak(format!("α {:.2}", stop.rgba[3]));
            if ui
                .add_enabled(n > 1, egui::Button::new("x").small())
                .on_hover_text("Remove this stop")
                .clicked()
            {
                remove = Some(k);
            }
        });
    }
    if let Some(k) = remove {
        stops.remove(k);
    }
    let can_add = stops.len() < MAX_COLOR_STOPS;
    if ui
        .add_enabled(can_add, egui::Button::new("Add stop"))
        .on_hover_text(format!(
            "Insert a stop in the widest gap, coloured as the gradient there (at most \
                {MAX_COLOR_STOPS})"
        ))
        .clicked()
    {
        add_stop(stops);
    }
    if !can_add {
        ui.weak(RichText::new(format!("{MAX_COLOR_STOPS} stops is the maximum")).small());
    }
}

/// Inserts a stop in the middle of the widest gap (including the gaps to t = 0 and t = 1),
/// with the colour the gradient already has there.
pub fn add_stop(stops: &mut Vec<ColorStop>) {
    if stops.is_empty() {
        stops.push(ColorStop {
            t: 0.5,
            rgba: [1.0, 0.5, 0.1, 1.0],
        });
        return;
    }
    let mut edges: Vec<f32> = vec![0.0];
    edges.extend(stops.iter().map(|s| s.t));
    edges.push(1.0);
    let (gap, _) = edges
        .windows(2)
        .enumerate()
        .map(|(i, w)| (i, w[1] - w[0]))
        .fold(
            (0, -1.0),
            |best, cur| if cur.1 > best.1 { cur } else { best },
        );
    let t = 0.5 * (edges[gap] + edges[gap + 1]);
    let rgba = sample_gradient(stops, t);
    // `gap` is the index of the first stop after the insertion point.
    stops.insert(gap.min(stops.len()), ColorStop { t, rgba });
}

/// UI name of a blend mode.
pub fn blend_label(b: BlendMode) -> &'static str {
    match b {
        BlendMode::Additive => "additive",
        BlendMode::Alpha => "alpha",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn add_stop_keeps_the_list_sorted_and_the_colour() {
        let stop = |t, rgba| ColorStop { t, rgba };
        let mut stops = vec![
            stop(0.0, [1.0, 0.0, 0.0, 1.0]),
            stop(1.0, [0.0, 0.0, 1.0, 0.0]),
        ];
        add_stop(&mut stops);
        assert_eq!(stops.len(), 3);
        assert_eq!(stops[1].t, 0.5);
        assert_eq!(stops[1].rgba, [0.5, 0.0, 0.5, 0.5]);
        add_stop(&mut stops);
        assert!(stops.windows(2).all(|w| w[0].t <= w[1].t));
    }
}
