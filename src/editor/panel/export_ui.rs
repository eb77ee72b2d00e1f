//! The editor's Export section: the settings of `ignis export`, a progress bar, cancel,
//! and a live preview of the atlas. The export runs inside the editor's frame loop
//! ([`drive`], a time budget a frame) through the same [`Export`] as the command line.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::Ui;

use crate::effect::Effect;
use crate::export::{AlphaMode, CameraMode, Export, ExportSettings, Format, Layout};
use crate::gpu::GpuContext;

/// How often the preview is rebuilt while an export runs.
const PREVIEW_EVERY: Duration = Duration::from_millis(250);

/// The Export section's settings and the state of the export it started.
pub struct ExportPanel {
    /// What the next export writes (the layout from `sequence`, `cols`, `rows`).
    pub settings: ExportSettings,
    /// One file per frame instead of an atlas.
    pub sequence: bool,
    /// The flipbook's grid.
    pub cols: u32,
    /// The flipbook's grid.
    pub rows: u32,
    /// The output folder, as typed.
    pub out_dir: String,
    /// Export pressed: the frame loop starts an export of the running effect.
    pub start_requested: bool,
    /// Cancel pressed: the frame loop drops the export (its files are not written).
    pub cancel_requested: bool,
    /// Steps done and in all, while an export runs.
    pub progress: Option<(u32, u32)>,
    /// The outcome of the last export.
    pub message: Option<Result<String, String>>,
    /// The colour atlas so far, and whether it changed since the texture was made.
    preview: Option<(image::RgbaImage, bool)>,
    texture: Option<egui::TextureHandle>,
    last_preview: Option<Instant>,
}

impl Default for ExportPanel {
    fn default() -> Self {
        Self {
            settings: ExportSettings::new("export".into()),
            sequence: false,
            cols: 8,
            rows: 8,
            out_dir: "export".into(),
            start_requested: false,
            cancel_requested: false,
            progress: None,
            message: None,
            preview: None,
            texture: None,
            last_preview: None,
        }
    }
}

impl ExportPanel {
    /// The settings the next export runs with.
    pub fn export_settings(&self) -> ExportSettings {
        ExportSettings {
            layout: if self.sequence {
                Layout::Sequence
            } else {
                Layout::Flipbook {
                    cols: self.cols,
                    rows: self.rows,
                }
            },
            out_dir: PathBuf::from(self.out_dir.trim()),
            ..self.settings.clone()
        }
    }

    /// Whether an export is running.
    pub fn is_running(&self) -> bool {
        self.progress.is_some()
    }
}

/// Starts, steps (for up to `budget`), cancels and finishes the export `running` of
/// `effect` as `panel` asks; call once per editor frame.
pub fn drive(
    ctx: &GpuContext,
    effect: &Effect,
    asset_dir: Option<PathBuf>,
    panel: &mut ExportPanel,
    running: &mut Option<Export>,
    budget: Duration,
) {
    if std::mem::take(&mut panel.cancel_requested) && running.take().is_some() {
        panel.progress = None;
        panel.message = Some(Err("export cancelled: nothing was written".into()));
    }
    if std::mem::take(&mut panel.start_requested) && running.is_none() {
        match Export::new(ctx, effect, asset_dir, panel.export_settings()) {
            Ok(e) => {
                *running = Some(e);
                panel.progress = Some((0, 1));
                panel.message = None;
                panel.preview = None;
            }
            Err(e) => panel.message = Some(Err(e.to_string())),
        }
    }
    let Some(export) = running.as_mut() else {
        return;
    };
    let start = Instant::now();
    loop {
        match export.step() {
            Ok(Some(p)) => panel.progress = Some((p.done, p.total)),
            Ok(None) => {
                let files = export.summary().map_or(0, |s| s.files.len());
                panel.message = Some(Ok(format!(
                    "wrote {files} files to {}",
                    panel.out_dir.trim()
                )));
                panel.preview = export.preview().map(|p| (p, true));
                panel.progress = None;
                *running = None;
                return;
            }
            Err(e) => {
                panel.message = Some(Err(e.to_string()));
                panel.progress = None;
                *running = None;
                return;
            }
        }
        if start.elapsed() >= budget {
            break;
        }
    }
    if panel
        .last_preview
        .is_none_or(|t| t.elapsed() >= PREVIEW_EVERY)
    {
        panel.last_preview = Some(Instant::now());
        if let Some(p) = export.preview() {
            panel.preview = Some((p, true));
        }
    }
}

/// The Export section.
pub fn export_ui(ui: &mut Ui, panel: &mut ExportPanel) {
    let running = panel.is_running();
    ui.add_enabled_ui(!running, |ui| settings_ui(ui, panel));
    ui.horizontal(|ui| {
        if running {
            if ui.button("Cancel").clicked() {
                panel.cancel_requested = true;
            }
        } else if ui
            .button("Start export")
            .on_hover_text("Export the running effect with these settings")
            .clicked()
        {
            panel.start_requested = true;
        }
        crate::editor::panel::progress_ui(
            ui,
            panel.progress.map(|(d, t)| (d as usize, t as usize)),
        );
    });
    crate::editor::panel::outcome_ui(ui, panel.message.as_ref());
    preview_ui(ui, panel);
}

/// A whole-number drag value from 1 to `max`.
fn drag(v: &mut u32, max: u32) -> egui::DragValue<'_> {
    egui::DragValue::new(v).range(1..=max)
}

fn settings_ui(ui: &mut Ui, panel: &mut ExportPanel) {
    egui::Grid::new("export_grid")
        .num_columns(2)
        .show(ui, |ui| {
            layout_rows(ui, panel);
            output_rows(ui, panel);
        });
}

/// The export's layout and span (rows of an open grid): atlas or sequence, frames, size,
/// start, rate, loop.
fn layout_rows(ui: &mut Ui, panel: &mut ExportPanel) {
    use crate::editor::panel::row_ui as row;
    let s = &mut panel.settings;
    row(
        ui,
        "Sequence",
        "One file per frame instead of one atlas",
        |ui| ui.checkbox(&mut panel.sequence, ""),
    );
    if !panel.sequence {
        row(ui, "Columns", "Frames per atlas row", |ui| {
            ui.add(drag(&mut panel.cols, 64))
        });
        row(
            ui,
            "Rows",
            "Atlas rows; frames run row-major from the top left",
            |ui| ui.add(drag(&mut panel.rows, 64)),
        );
    }
    if panel.sequence {
        let frames = s.frames.get_or_insert(60);
        row(ui, "Frames", "How many frames the sequence holds", |ui| {
            ui.add(drag(frames, 100_000))
        });
    } else {
        // A flipbook holds as many frames as it has cells.
        s.frames = None;
    }
    row(ui, "Width", "One frame's width in pixels", |ui| {
        ui.add(drag(&mut s.frame_size.0, 4096))
    });
    row(ui, "Height", "One frame's height in pixels", |ui| {
        ui.add(drag(&mut s.frame_size.1, 4096))
    });
    row(ui, "Start", "Effect time of the first frame", |ui| {
        ui.add(
            egui::DragValue::new(&mut s.start_secs)
                .range(0.0..=600.0)
                .speed(0.05)
                .suffix(" s"),
        )
    });
    row(ui, "Frame rate", "Frames per second of effect time", |ui| {
        ui.add(
            egui::DragValue::new(&mut s.fps)
                .range(1.0..=240.0)
                .suffix(" fps"),
        )
    });
    row(
        ui,
        "Seamless loop",
        "The last frame flows into the first",
        |ui| ui.checkbox(&mut s.looped, ""),
    );
}

/// The export's output (rows of an open grid): format, alpha, passes, camera, folder.
fn output_rows(ui: &mut Ui, panel: &mut ExportPanel) {
    use crate::editor::panel::row_ui as row;
    let s = &mut panel.settings;
    row(
        ui,
        "Format",
        "8-bit or 16-bit sRGB PNG, or half-float linear EXR",
        |ui| {
            choice(
                ui,
                "export_format",
                &mut s.format,
                &[Format::Png8, Format::Png16, Format::Exr],
                Format::name,
            )
        },
    );
    row(
        ui,
        "Alpha",
        "Premultiplied composites exactly: C + B·(1 − A)",
        |ui| {
            choice(
                ui,
                "export_alpha",
                &mut s.alpha,
                &[AlphaMode::Premultiplied, AlphaMode::Straight],
                AlphaMode::name,
            )
        },
    );
    row(ui, "Color pass", "Light and coverage (RGBA)", |ui| {
        ui.checkbox(&mut s.passes.color, "")
    });
    row(ui, "Emissive pass", "The additive light alone", |ui| {
        ui.checkbox(&mut s.passes.emissive, "")
    });
    row(
        ui,
        "Motion pass",
        "Screen motion to the next frame in RG",
        |ui| ui.checkbox(&mut s.passes.motion, ""),
    );
    row(
        ui,
        "Six-way passes",
        "The lit smoke's six-way lightmaps (RTBA and LBFE, Unity's packing), for an engine to \
            relight the flipbook",
        |ui| ui.checkbox(&mut s.passes.sixway, ""),
    );
    row(
        ui,
        "Distortion pass",
        "The heat haze's screen offsets in RG, centred at 0.5, for an engine's distortion \
            material (the scale is in the sidecar)",
        |ui| ui.checkbox(&mut s.passes.distortion, ""),
    );
    row(
        ui,
        "Camera",
        "Fitted to the whole span, orthographic, or the preset's",
        |ui| {
            choice(
                ui,
                "export_camera",
                &mut s.camera,
                &[CameraMode::Fit, CameraMode::Ortho, CameraMode::Preset],
                CameraMode::name,
            )
        },
    );
    row(
        ui,
        "Folder",
        "Where the files go (created if missing)",
        |ui| ui.text_edit_singleline(&mut panel.out_dir),
    );
}

/// A combo box over `options`, named by `name`.
fn choice<T: Copy + PartialEq>(
    ui: &mut Ui,
    id: &str,
    value: &mut T,
    options: &[T],
    name: fn(T) -> &'static str,
) -> egui::Response {
    let mut changed = false;
    let mut response = egui::ComboBox::from_id_salt(id)
        .selected_text(name(*value))
        .show_ui(ui, |ui| {
            for &o in options {
                changed |= ui.selectable_value(value, o, name(o)).changed();
            }
        })
        .response;
    if changed {
        response.mark_changed();
    }
    response
}

/// The atlas so far (over a dark background: premultiplied light shows as it adds).
fn preview_ui(ui: &mut Ui, panel: &mut ExportPanel) {
    if let Some((img, changed)) = panel.preview.as_mut()
        && std::mem::take(changed)
    {
        let size = [img.width() as usize, img.height() as usize];
        let color = egui::ColorImage::from_rgba_premultiplied(size, img.as_raw());
        panel.texture = Some(
            ui.ctx()
                .load_texture("export preview", color, Default::default()),
        );
    }
    if let Some(t) = &panel.texture {
        let width = ui.available_width().min(360.0);
        let size = t.size_vec2() * (width / t.size_vec2().x.max(1.0));
        egui::Frame::new()
            .fill(egui::Color32::from_gray(12))
            .show(ui, |ui| ui.image((t.id(), size)));
    }
}
