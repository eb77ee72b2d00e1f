//! The Look section: sprite, blend, size and colour over life, intensity, exposure.

use egui::{Color32, DragValue, Rgba, RichText, Sense, Ui};

use crate::effect::{
    BlendMode, ColorStop, DrawPath, Effect, Look, MAX_COLOR_STOPS, SPLAT_BELOW_PX, Sprite,
};

use super::panel::{blend_label, sprite_label};
use super::state::ViewSettings;

/// The selected emitter's look and the viewport exposure.
pub fn look_ui(ui: &mut Ui, effect: &mut Effect, selected: usize, view: &mut ViewSettings) {
    egui::Grid::new("exposure_grid")
        .num_columns(2)
        .spacing([10.0, 5.0])
        .min_col_width(96.0)
        .show(ui, |ui| {
            let label = ui.label("Exposure").on_hover_text(
                "Viewport exposure: multiplies the HDR image before the ACES tonemap (a view setting, not part of the preset)",
            );
            ui.add(
                egui::Slider::new(&mut view.exposure, 0.05..=8.0)
                    .logarithmic(true)
                    .fixed_decimals(2),
            )
            .labelled_by(label.id);
            ui.end_row();
        });
    let Some(e) = effect.emitters.get_mut(selected) else {
        return;
    };
    look_fields_ui(ui, &mut e.look);
}

/// Sprite, blend, sizes, intensity and the colour gradient of one look.
pub fn look_fields_ui(ui: &mut Ui, look: &mut Look) {
    egui::Grid::new("look_grid")
        .num_columns(2)
        .spacing([10.0, 5.0])
        .min_col_width(96.0)
        .show(ui, |ui| {
            let label = ui.label("Sprite").on_hover_text("Procedural sprite of each billboard");
            egui::ComboBox::from_id_salt("sprite")
                .selected_text(sprite_label(look.sprite))
                .show_ui(ui, |ui| {
                    for s in [Sprite::SoftDisc, Sprite::Point, Sprite::Spark] {
                        ui.selectable_value(&mut look.sprite, s, sprite_label(s));
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            let label_tip = "Additive: light adds up, order-independent (fire, sparks). Alpha: premultiplied over, darkens what is behind (smoke); alpha layers are drawn first";
            ui.label("Blend").on_hover_text(label_tip);
            ui.horizontal(|ui| {
                for b in [BlendMode::Additive, BlendMode::Alpha] {
                    ui.radio_value(&mut look.blend, b, blend_label(b))
                        .on_hover_text(label_tip);
                }
            });
            ui.end_row();
            let label = ui.label("Draw path").on_hover_text(format!(
                "auto: compute splat when particles project below {SPLAT_BELOW_PX} px and blend additively, billboards otherwise. billboard: instanced quads. splat: compute splat (additive only; alpha falls back to billboards)"
            ));
            egui::ComboBox::from_id_salt("draw_path")
                .selected_text(draw_path_label(look.draw_path))
                .show_ui(ui, |ui| {
                    for d in [DrawPath::Auto, DrawPath::Billboard, DrawPath::Splat] {
                        ui.selectable_value(&mut look.draw_path, d, draw_path_label(d));
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            let label = ui
                .label("Size")
                .on_hover_text("Billboard diameter at birth and at death, metres (linear in between)");
            ui.horizontal(|ui| {
                ui.add(
                    DragValue::new(&mut look.size_start_m)
                        .range(0.0..=100.0)
                        .speed(0.002)
                        .prefix("start ")
                        .suffix(" m")
                        .min_decimals(3),
                )
                .labelled_by(label.id);
                ui.add(
                    DragValue::new(&mut look.size_end_m)
                        .range(0.0..=100.0)
                        .speed(0.002)
                        .prefix("end ")
                        .suffix(" m")
                        .min_decimals(3),
                )
                .labelled_by(label.id);
            });
            ui.end_row();
            let label = ui
                .label("Intensity")
                .on_hover_text("Multiplies the colour: HDR brightness before exposure and tonemap");
            ui.add(
                DragValue::new(&mut look.intensity)
                    .range(0.0..=1000.0)
                    .speed(0.01)
                    .min_decimals(2),
            )
            .labelled_by(label.id);
            ui.end_row();
        });
    ui.add_space(4.0);
    ui.label("Colour over life").on_hover_text(
        "Colour (linear RGB) and alpha over the normalised age: 0 = birth, 1 = death",
    );
    gradient_preview_ui(ui, &look.color_over_life);
    color_stops_ui(ui, &mut look.color_over_life);
}

fn draw_path_label(d: DrawPath) -> &'static str {
    match d {
        DrawPath::Auto => "auto",
        DrawPath::Billboard => "billboard",
        DrawPath::Splat => "splat",
    }
}

/// Linear RGBA → egui colour (egui's `Rgba` is linear, premultiplied).
fn to_color32(rgba: [f32; 4]) -> Color32 {
    let [r, g, b, a] = rgba.map(|v| v.clamp(0.0, 1.0));
    Color32::from(Rgba::from_rgba_unmultiplied(r, g, b, a))
}

/// The gradient as a strip: the upper half shows the colour over a dark checkerboard with
/// its alpha, the lower half the opaque colour.
fn gradient_preview_ui(ui: &mut Ui, stops: &[ColorStop]) {
    let width = ui.available_width().min(330.0);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 26.0), Sense::hover());
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
    for s in stops {
        let x = rect.left() + s.t.clamp(0.0, 1.0) * rect.width();
        painter.line_segment(
            [
                egui::pos2(x, rect.bottom() - 5.0),
                egui::pos2(x, rect.bottom()),
            ],
            egui::Stroke::new(1.5, Color32::WHITE),
        );
    }
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
            ui.color_edit_button_rgba_unmultiplied(&mut stop.rgba)
                .labelled_by(label.id)
                .on_hover_text("Colour (linear RGB) and alpha");
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
            "Insert a stop in the widest gap, coloured as the gradient there (at most {MAX_COLOR_STOPS})"
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

/// The gradient's value at `t` (linear interpolation, clamped at the ends), as the
/// billboard shader evaluates it.
pub fn sample_gradient(stops: &[ColorStop], t: f32) -> [f32; 4] {
    let Some(first) = stops.first() else {
        return [1.0; 4];
    };
    if t <= first.t {
        return first.rgba;
    }
    for pair in stops.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if t <= b.t {
            let f = if b.t > a.t {
                (t - a.t) / (b.t - a.t)
            } else {
                1.0
            };
            let mut out = [0.0; 4];
            for (k, o) in out.iter_mut().enumerate() {
                *o = a.rgba[k] + (b.rgba[k] - a.rgba[k]) * f;
            }
            return out;
        }
    }
    stops.last().map_or([1.0; 4], |s| s.rgba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn add_stop_keeps_the_list_sorted_and_the_colour() {
        let mut stops = vec![
            ColorStop {
                t: 0.0,
                rgba: [1.0, 0.0, 0.0, 1.0],
            },
            ColorStop {
                t: 1.0,
                rgba: [0.0, 0.0, 1.0, 0.0],
            },
        ];
        add_stop(&mut stops);
        assert_eq!(stops.len(), 3);
        assert_eq!(stops[1].t, 0.5);
        assert_eq!(stops[1].rgba, [0.5, 0.0, 0.5, 0.5]);
        add_stop(&mut stops);
        assert!(stops.windows(2).all(|w| w[0].t <= w[1].t));
    }
}
