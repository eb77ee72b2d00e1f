//! The editor for a [`Param`]: its mode (constant, random range, curve, two curves) and,
//! for curves, a plot whose keys are dragged, added (a click away from the keys) and
//! deleted (right-click), with smooth or linear segments, starting shapes and zoom to fit.

use std::ops::RangeInclusive;

use egui::{Color32, DragValue, Pos2, Rect, Sense, Stroke, Ui, pos2, vec2};

use crate::effect::{Curve, MAX_CURVE_KEYS, Param, ParamMode, SHAPES};

/// What a parameter means: its name, unit and limits.
#[derive(Clone, Debug)]
pub struct ParamSpec {
    /// The accessible name of the plot ("Size curve").
    pub name: &'static str,
    /// The value's unit suffix (" m", " /s", "×").
    pub unit: &'static str,
    /// The values it may take.
    pub values: RangeInclusive<f32>,
    /// Drag speed of the number fields.
    pub speed: f64,
    /// Curves run over t ∈ [0, t_max]: 1 for normalised age; seconds for effect time.
    pub t_max: f32,
    /// How the time axis reads ("age" or "s").
    pub t_unit: &'static str,
}

/// The plot's visible window: times `t` and values `v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Time range shown.
    pub t: (f32, f32),
    /// Value range shown.
    pub v: (f32, f32),
}

impl View {
    /// A window holding every key of `p` (with a margin, and zero where values are
    /// non-negative).
    pub fn fit(p: &Param, spec: &ParamSpec) -> View {
        let (lo, hi) = p.bounds();
        let lo = if lo >= 0.0 { 0.0 } else { lo };
        let span = (hi - lo).max(1e-3);
        let last_t = p
            .rows()
            .iter()
            .filter_map(|c| c.keys.last().map(|k| k.0))
            .fold(0.0, f32::max);
        let t1 = if spec.t_max <= 1.0 {
            spec.t_max
        } else {
            (last_t * 1.1).max(1.0)
        };
        View {
            t: (0.0, t1),
            v: (lo - 0.05 * span, hi + 0.1 * span),
        }
    }

    /// Screen position of `(t, v)` in `rect`.
    pub fn to_screen(&self, rect: Rect, (t, v): (f32, f32)) -> Pos2 {
        let x = (t - self.t.0) / (self.t.1 - self.t.0).max(1e-9);
        let y = (v - self.v.0) / (self.v.1 - self.v.0).max(1e-9);
        pos2(
            rect.left() + x * rect.width(),
            rect.bottom() - y * rect.height(),
        )
    }

    /// `(t, v)` at screen position `p` in `rect`.
    pub fn from_screen(&self, rect: Rect, p: Pos2) -> (f32, f32) {
        let x = (p.x - rect.left()) / rect.width().max(1.0);
        let y = (rect.bottom() - p.y) / rect.height().max(1.0);
        (
            self.t.0 + x * (self.t.1 - self.t.0),
            self.v.0 + y * (self.v.1 - self.v.0),
        )
    }
}

/// What the plot remembers between frames.
#[derive(Clone, Debug, Default)]
struct PlotState {
    view: Option<View>,
    /// The key being dragged: (row, index).
    dragging: Option<(usize, usize)>,
}

/// A grid row: the label, then the parameter's editor.
pub fn param_row(ui: &mut Ui, label: &str, tip: &str, p: &mut Param, spec: &ParamSpec) {
    let label = ui.label(label).on_hover_text(tip);
    let id = ui.make_persistent_id(spec.name);
    param_ui(ui, id, p, spec, label.id);
    ui.end_row();
}

/// Height of a curve plot, points.
pub const PLOT_HEIGHT: f32 = 96.0;

/// Where a plot widget of `rect` draws its window: inset so that keys at the ends can be
/// grabbed whole.
pub fn plot_area(rect: Rect) -> Rect {
    rect.shrink2(vec2(7.0, 6.0))
}

/// A parameter's editor: the mode menu and the mode's fields (a plot for curves); the
/// number fields are labelled by `label`.
pub fn param_ui(ui: &mut Ui, id: egui::Id, p: &mut Param, spec: &ParamSpec, label: egui::Id) {
    ui.vertical(|ui| {
        ui.horizontal(|ui| {
            let mut mode = p.mode();
            let menu = egui::ComboBox::from_id_salt(id.with("mode"))
                .selected_text(mode.label())
                .width(86.0)
                .show_ui(ui, |ui| {
                    for m in ParamMode::ALL {
                        ui.selectable_value(&mut mode, m, m.label());
                    }
                });
            let name = format!("{} mode", spec.name.trim_end_matches(" curve"));
            menu.response
                .widget_info(|| egui::WidgetInfo::labeled(egui::Role::ComboBox, true, &name));
            if mode != p.mode() {
                *p = p.to_mode(mode);
                reset_view(ui, id);
            }
            scalar_fields(ui, p, spec, label);
        });
        if matches!(p, Param::Curve { .. } | Param::TwoCurves { .. }) {
            curve_plot(ui, id, p, spec);
            curve_tools(ui, id, p, spec);
        }
    });
}

/// The number fields of the constant and range modes.
fn scalar_fields(ui: &mut Ui, p: &mut Param, spec: &ParamSpec, label: egui::Id) {
    fn field<'a>(v: &'a mut f32, range: RangeInclusive<f32>, spec: &ParamSpec) -> DragValue<'a> {
        DragValue::new(v)
            .range(range)
            .speed(spec.speed)
            .suffix(spec.unit)
            .max_decimals(3)
    }
    match p {
        Param::Constant(v) => {
            ui.add(field(v, spec.values.clone(), spec))
                .labelled_by(label);
        }
        Param::Range { min, max } => {
            let hi = *max;
            ui.add(field(min, *spec.values.start()..=hi, spec).prefix("min "))
                .labelled_by(label);
            let lo = *min;
            ui.add(field(max, lo..=*spec.values.end(), spec).prefix("max "))
                .labelled_by(label);
        }
        _ => {}
    }
}

fn reset_view(ui: &Ui, id: egui::Id) {
    ui.data_mut(|d| d.remove::<PlotState>(id));
}

fn rows_mut(p: &mut Param) -> Vec<&mut Vec<(f32, f32)>> {
    match p {
        Param::Curve { keys, .. } => vec![keys],
        Param::TwoCurves { a, b } => vec![&mut a.keys, &mut b.keys],
        _ => Vec::new(),
    }
}

/// The nearest key to `pos` within `radius` points: (row, index).
fn nearest_key(
    p: &Param,
    view: &View,
    rect: Rect,
    pos: Pos2,
    radius: f32,
) -> Option<(usize, usize)> {
    let mut best = None;
    let mut best_d = radius;
    for (r, row) in p.rows().iter().enumerate().take(rows_in(p)) {
        for (k, key) in row.keys.iter().enumerate() {
            let d = view.to_screen(rect, *key).distance(pos);
            if d <= best_d {
                best_d = d;
                best = Some((r, k));
            }
        }
    }
    best
}

fn rows_in(p: &Param) -> usize {
    if matches!(p, Param::TwoCurves { .. }) {
        2
    } else {
        1
    }
}

/// The plot: both rows drawn (the band between two curves shaded), keys as handles.
fn curve_plot(ui: &mut Ui, id: egui::Id, p: &mut Param, spec: &ParamSpec) {
    // Clear of the panel's scroll bar, which covers the right edge while it is hovered.
    let width = (ui.available_width() - 14.0).clamp(120.0, 420.0);
    let (outer, resp) = ui.allocate_exact_size(vec2(width, PLOT_HEIGHT), Sense::click_and_drag());
    let rect = plot_area(outer);
    let name = spec.name;
    resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, name));
    let mut st: PlotState = ui.data(|d| d.get_temp(id)).unwrap_or_default();
    // Keys outside the window (another emitter's curve, an edit elsewhere, an undo) refit
    // it, except while a key is held.
    let (lo, hi) = p.bounds();
    if st.dragging.is_none() && st.view.is_some_and(|v| lo < v.v.0 || hi > v.v.1) {
        st.view = None;
    }
    let view = *st.view.get_or_insert_with(|| View::fit(p, spec));
    if let Some(pos) = resp.interact_pointer_pos().or(resp.hover_pos()) {
        if resp.drag_started() {
            st.dragging = nearest_key(p, &view, rect, pos, 10.0);
        }
        if resp.dragged()
            && let Some((r, k)) = st.dragging
        {
            let (t, v) = view.from_screen(rect, pos);
            move_key(p, (r, k), (t, v), spec);
        }
        // A click away from every key adds one there (a click on a key only selects it).
        if resp.clicked() && nearest_key(p, &view, rect, pos, 10.0).is_none() {
            let (t, v) = view.from_screen(rect, pos);
            add_key(p, (t, v), spec);
        }
        if resp.secondary_clicked()
            && let Some((r, k)) = nearest_key(p, &view, rect, pos, 10.0)
        {
            let mut rows = rows_mut(p);
            if let Some(row) = rows.get_mut(r)
                && row.len() > 1
            {
                row.remove(k);
            }
        }
    }
    if resp.drag_stopped() {
        st.dragging = None;
        // Keys dragged out of the window: show them all again.
        let (lo, hi) = p.bounds();
        if lo < view.v.0 || hi > view.v.1 {
            st.view = Some(View::fit(p, spec));
        }
    }
    paint_plot(ui, outer, rect, &view, p, spec, resp.hover_pos());
    resp.on_hover_text(format!(
        "{name}: drag a key to move it, click elsewhere to add one, right-click a key to delete \
            it (time: {})",
        spec.t_unit
    ));
    ui.data_mut(|d| d.insert_temp(id, st));
}

/// Moves key `k` of row `r` to `(t, v)`: between its neighbours (times stay strictly
/// increasing) and within the parameter's limits.
fn move_key(p: &mut Param, (r, k): (usize, usize), (t, v): (f32, f32), spec: &ParamSpec) {
    let gap = 1e-3 * spec.t_max.max(1.0);
    let mut rows = rows_mut(p);
    let Some(row) = rows.get_mut(r) else {
        return;
    };
    let lo = if k == 0 { 0.0 } else { row[k - 1].0 + gap };
    let hi = row.get(k + 1).map_or(spec.t_max, |n| n.0 - gap);
    if let Some(key) = row.get_mut(k) {
        key.0 = t.clamp(lo, hi.max(lo));
        key.1 = v.clamp(*spec.values.start(), *spec.values.end());
    }
}

/// Adds a key at `(t, v)` to the row whose curve passes nearest to it.
fn add_key(p: &mut Param, (t, v): (f32, f32), spec: &ParamSpec) {
    let t = t.clamp(0.0, spec.t_max);
    let v = v.clamp(*spec.values.start(), *spec.values.end());
    let curves = p.rows();
    let r = (0..rows_in(p))
        .min_by(|&a, &b| {
            let da = (curves[a].eval(f64::from(t)) - f64::from(v)).abs();
            let db = (curves[b].eval(f64::from(t)) - f64::from(v)).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(0);
    let gap = 1e-3 * spec.t_max.max(1.0);
    let mut rows = rows_mut(p);
    if let Some(row) = rows.get_mut(r)
        && row.len() < MAX_CURVE_KEYS
        && row.iter().all(|k| (k.0 - t).abs() >= gap)
    {
        let at = row.partition_point(|k| k.0 < t);
        row.insert(at, (t, v));
    }
}

fn paint_plot(
    ui: &Ui,
    outer: Rect,
    rect: Rect,
    view: &View,
    p: &Param,
    spec: &ParamSpec,
    hover: Option<Pos2>,
) {
    let painter = ui.painter_at(outer);
    let visuals = ui.visuals();
    painter.rect_filled(outer, 2.0, visuals.extreme_bg_color);
    let grid = Stroke::new(1.0, visuals.faint_bg_color.gamma_multiply(2.0));
    for q in 1..4 {
        let x = rect.left() + rect.width() * q as f32 / 4.0;
        painter.line_segment([pos2(x, rect.top()), pos2(x, rect.bottom())], grid);
    }
    if view.v.0 < 0.0 && view.v.1 > 0.0 {
        let y = view.to_screen(rect, (0.0, 0.0)).y;
        painter.line_segment([pos2(rect.left(), y), pos2(rect.right(), y)], grid);
    }
    let rows = p.rows();
    let n = (rect.width() / 2.0) as usize;
    let sample = |c: &Curve| -> Vec<Pos2> {
        (0..=n)
            .map(|i| {
                let t = view.t.0 + (view.t.1 - view.t.0) * i as f32 / n as f32;
                view.to_screen(rect, (t, c.eval(f64::from(t)) as f32))
            })
            .collect()
    };
    let colors = [
        Color32::from_rgb(255, 170, 60),
        Color32::from_rgb(120, 190, 255),
    ];
    let shown = rows_in(p);
    if shown == 2 {
        let (a, b) = (sample(&rows[0]), sample(&rows[1]));
        for (pa, pb) in a.iter().zip(&b).step_by(2) {
            painter.line_segment([*pa, *pb], Stroke::new(1.0, colors[0].gamma_multiply(0.25)));
        }
    }
    for (r, c) in rows.iter().enumerate().take(shown) {
        painter.add(egui::Shape::line(sample(c), Stroke::new(1.5, colors[r])));
        for key in &c.keys {
            let at = view.to_screen(rect, *key);
            let hot = hover.is_some_and(|h| h.distance(at) <= 10.0);
            painter.circle_filled(at, if hot { 5.0 } else { 3.5 }, colors[r]);
        }
    }
    let text = visuals.weak_text_color();
    let font = egui::FontId::proportional(10.0);
    painter.text(
        rect.left_top() + vec2(3.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{:.3}{}", view.v.1, spec.unit),
        font.clone(),
        text,
    );
    painter.text(
        rect.left_bottom() + vec2(3.0, -2.0),
        egui::Align2::LEFT_BOTTOM,
        format!("{:.3}", view.v.0),
        font.clone(),
        text,
    );
    painter.text(
        rect.right_bottom() + vec2(-3.0, -2.0),
        egui::Align2::RIGHT_BOTTOM,
        format!("{:.2} {}", view.t.1, spec.t_unit),
        font,
        text,
    );
}

/// Smooth or linear, the starting shapes, and zoom to fit.
fn curve_tools(ui: &mut Ui, id: egui::Id, p: &mut Param, spec: &ParamSpec) {
    ui.horizontal(|ui| {
        let mut smooth = p.rows()[0].smooth;
        if ui
            .checkbox(&mut smooth, "smooth")
            .on_hover_text(
                "Monotone cubic segments (never overshoot the keys); off: straight lines",
            )
            .changed()
        {
            match p {
                Param::Curve { smooth: s, .. } => *s = smooth,
                Param::TwoCurves { a, b } => {
                    a.smooth = smooth;
                    b.smooth = smooth;
                }
                _ => {}
            }
        }
        let shapes = egui::ComboBox::from_id_salt(id.with("shape"))
            .selected_text("shape…")
            .width(80.0)
            .show_ui(ui, |ui| {
                for (name, keys, smooth) in SHAPES {
                    if ui.selectable_label(false, name).clicked() {
                        apply_shape(p, keys, smooth, spec);
                        reset_view(ui, id);
                    }
                }
            });
        let name = format!("{} shape", spec.name.trim_end_matches(" curve"));
        shapes
            .response
            .widget_info(|| egui::WidgetInfo::labeled(egui::Role::ComboBox, true, &name));
        if ui
            .button("fit")
            .on_hover_text("Zoom to show every key")
            .clicked()
        {
            reset_view(ui, id);
        }
    });
}

/// Replaces each row by `keys` (values in [0, 1], times in [0, 1]) mapped onto the row's
/// own value range and the parameter's time span.
fn apply_shape(p: &mut Param, keys: &[(f32, f32)], smooth: bool, spec: &ParamSpec) {
    let t_span = if spec.t_max <= 1.0 {
        spec.t_max
    } else {
        p.rows()
            .iter()
            .filter_map(|c| c.keys.last().map(|k| k.0))
            .fold(1.0, f32::max)
    };
    let shaped = |c: &Curve| {
        let (mut lo, mut hi) = c.bounds();
        if hi - lo < 1e-6 {
            lo = lo.min(0.0);
            hi = if hi > 0.0 { hi } else { 1.0 };
        }
        Curve {
            keys: keys
                .iter()
                .map(|&(t, v)| (t * t_span, lo + v * (hi - lo)))
                .collect(),
            smooth,
        }
    };
    match p {
        Param::Curve { keys: k, smooth: s } => {
            let c = shaped(&Curve {
                keys: k.clone(),
                smooth: *s,
            });
            *k = c.keys;
            *s = smooth;
        }
        Param::TwoCurves { a, b } => {
            *a = shaped(a);
            *b = shaped(b);
        }
        _ => {}
    }
}
