//! The light lit layers are drawn in: the preset's sun and ambient (View section), and a
//! lit layer's six-way settings (Look section).

use egui::{DragValue, Ui};

use crate::effect::{BlendMode, Lighting, Lit, Look, SixWayMaps};

use crate::editor::panel::{drag, grid, row_ui};

/// The preset's sun (a direction from its height and bearing, a colour and a strength)
/// and its ambient light.
pub fn lighting_ui(ui: &mut Ui, lighting: &mut Lighting) {
    grid("lighting_grid").show(ui, |ui| {
        let d = lighting.sun_unit();
        let (mut bearing, mut height) = (d.x.atan2(d.z).to_degrees(), d.y.asin().to_degrees());
        let tip = "Where the sun (or the moon) is: its height above the horizon and its bearing \
            around +Y (0° = +Z, towards the default camera). Saved with the preset; a host sets \
            its own";
        let changed = row_ui(ui, "Sun", tip, |ui| {
            ui.horizontal(|ui| {
                let a = ui.add(
                    DragValue::new(&mut height)
                        .range(-90.0..=90.0)
                        .suffix("° up"),
                );
                let b = ui.add(
                    DragValue::new(&mut bearing)
                        .range(-180.0..=180.0)
                        .suffix("°"),
                );
                a | b
            })
            .inner
        })
        .changed();
        if changed {
            let (h, b) = (height.to_radians(), bearing.to_radians());
            lighting.sun_direction = [h.cos() * b.sin(), h.sin(), h.cos() * b.cos()];
        }
        hdr_color_row(
            ui,
            "Sun colour",
            "The sun's colour times its strength (linear; 1 lights \
            a white sprite white)",
            &mut lighting.sun_color,
        );
        hdr_color_row(
            ui,
            "Ambient",
            "Light from every direction (linear): the sky",
            &mut lighting.ambient,
        );
    });
}

/// A colour with a strength: a picker for the hue and a multiplier for HDR values.
fn hdr_color_row(ui: &mut Ui, label: &str, tip: &str, rgb: &mut [f32; 3]) {
    row_ui(ui, label, tip, |ui| {
        ui.horizontal(|ui| {
            let mut strength = rgb.iter().copied().fold(0.0, f32::max);
            let mut hue = if strength > 0.0 {
                rgb.map(|c| c / strength)
            } else {
                [1.0; 3]
            };
            let a = ui.color_edit_button_rgb(&mut hue);
            let b = ui.add(
                DragValue::new(&mut strength)
                    .range(0.0..=100.0)
                    .speed(0.005)
                    .prefix("× "),
            );
            if a.changed() || b.changed() {
                *rgb = hue.map(|c| c * strength);
            }
            a | b
        })
        .inner
    });
}

/// The look's lit-smoke rows (rows of an open grid): on/off for alpha-blended layers,
/// the maps, the albedo, the glow and the effect light's share.
pub fn lit_rows_ui(ui: &mut Ui, look: &mut Look) {
    let alpha = look.blend == BlendMode::Alpha;
    // Switched to additive blending or a streak above: no longer a lit layer.
    if look.lit.is_some() && (!alpha || look.streak.is_some()) {
        look.lit = None;
    }
    let tip = "Shade this alpha-blended layer with six-way lightmaps: lit by the effect's own \
        flames, the sun and ambient (View) and a host's lights; the maps replace the sprite";
    row_ui(ui, "Lit (six-way)", tip, |ui| {
        ui.add_enabled_ui(alpha && look.streak.is_none(), |ui| {
            let mut on = look.lit.is_some();
            let r = ui.checkbox(&mut on, "");
            if r.changed() {
                look.lit = on.then(Lit::default);
            }
            r
        })
        .inner
    });
    let Some(lit) = look.lit.as_mut() else {
        return;
    };
    let tip = "The built-in puff (or its 4 × 4 flipbook, ray-marched by ignis) or a pair of \
        PNGs: RTBA (right, top, back, alpha) and LBFE (left, bottom, front, emissive), linear, \
        as EmberGen and Unity's Six Way shader use";
    row_ui(ui, "Lightmaps", tip, |ui| {
        let text = match &lit.maps {
            SixWayMaps::Puff => "puff",
            SixWayMaps::PuffSheet => "puff sheet (4×4)",
            SixWayMaps::Images { .. } => "PNG pair",
        };
        egui::ComboBox::from_id_salt("sixway_maps")
            .selected_text(text)
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut lit.maps, SixWayMaps::Puff, "puff");
                ui.selectable_value(&mut lit.maps, SixWayMaps::PuffSheet, "puff sheet (4×4)");
                if ui
                    .selectable_label(text == "PNG pair", "PNG pair")
                    .clicked()
                    && text != "PNG pair"
                {
                    lit.maps = SixWayMaps::Images {
                        rtba: "textures/smoke_sixway_rtba.png".into(),
                        lbfe: "textures/smoke_sixway_lbfe.png".into(),
                    };
                }
            })
            .response
    });
    if let SixWayMaps::Images { rtba, lbfe } = &mut lit.maps {
        row_ui(ui, "RTBA path", "Relative to the preset file", |ui| {
            ui.text_edit_singleline(rtba)
        });
        row_ui(ui, "LBFE path", "Relative to the preset file", |ui| {
            ui.text_edit_singleline(lbfe)
        });
    }
    row_ui(
        ui,
        "Albedo",
        "The smoke's colour under white light (linear)",
        |ui| {
            // A copy: egui's colour round trip must not edit the preset by showing it.
            let mut albedo = lit.albedo;
            let r = ui.color_edit_button_rgb(&mut albedo);
            if r.changed() {
                lit.albedo = albedo;
            }
            r
        },
    );
    row_ui(
        ui,
        "Glow",
        "How much of the colour over life the smoke emits itself, where the maps' emissive mask \
            says (embers in the smoke)",
        |ui| ui.add(drag(&mut lit.emission, 0.0..=100.0, 0.01, "")),
    );
    row_ui(
        ui,
        "Fire light",
        "How strongly the effect's own light (its additive layers, measured each frame) lights \
            this layer: 1 = its power over the squared distance",
        |ui| ui.add(drag(&mut lit.self_light, 0.0..=100.0, 0.01, "")),
    );
}
