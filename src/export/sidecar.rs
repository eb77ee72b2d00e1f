//! The JSON sidecar beside an export's images: everything an engine importer needs.

use serde::Serialize;

use crate::effect::Effect;

use super::export_settings::{ExportSettings, Layout};

/// How well a loop closes: mean colour difference (8-bit steps) of the last frame to the
/// first, next to the median of consecutive frames.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Seam {
    /// Last frame → first frame.
    pub last_to_first: f64,
    /// The median over consecutive frames.
    pub median_consecutive: f64,
}

/// The sidecar's contents.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sidecar {
    /// `"flipbook"` or `"sequence"`.
    pub layout: &'static str,
    /// Frames per atlas row (1 for a sequence).
    pub columns: u32,
    /// Atlas rows (1 for a sequence).
    pub rows: u32,
    /// Frames written.
    pub frame_count: u32,
    /// One frame's size, pixels.
    pub frame_width: u32,
    /// One frame's size, pixels.
    pub frame_height: u32,
    /// Playback rate that reproduces the effect's speed.
    pub frames_per_second: f64,
    /// Where frame k is.
    pub frame_order: &'static str,
    /// The effect time of the first frame, seconds.
    pub start_secs: f64,
    /// Whether the last frame flows into the first.
    #[serde(rename = "loop")]
    pub looped: bool,
    /// The loop's seam (reported with or without a loop).
    pub seam: Seam,
    /// `"straight"` or `"premultiplied"`.
    pub alpha: &'static str,
    /// `"png"`, `"png16"` or `"exr"`.
    pub format: &'static str,
    /// The colour encoding of colour passes.
    pub color_space: &'static str,
    /// How to composite the colour pass over a background.
    pub compositing: &'static str,
    /// The passes written, each a file (or atlas) of its own.
    pub passes: Vec<&'static str>,
    /// What the six-way passes hold (with `--passes sixway`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sixway_packing: Option<&'static str>,
    /// Motion pass: motion in frame UV (x right, y down) to the next frame =
    /// (value − 0.5) × this.
    pub motion_vector_scale: f32,
    /// Distortion pass (with `--passes distortion`): the heat haze's offset in frame UV
    /// (x right, y down) = (value − 0.5) × this, in R and G.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distortion_scale: Option<f32>,
    /// The camera mode.
    pub camera: &'static str,
    /// The preset's name.
    pub preset: String,
    /// The instance's seed.
    pub seed: u32,
    /// The ignis version that wrote it.
    pub ignis_version: &'static str,
}

impl Sidecar {
    /// The sidecar of an export.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        effect: &Effect,
        settings: &ExportSettings,
        frames: u32,
        start_secs: f64,
        interval_secs: f64,
        motion_vector_scale: f32,
        seed: u32,
        seam: Seam,
    ) -> Self {
        let (layout, columns, rows) = match settings.layout {
            Layout::Flipbook { cols, rows } => ("flipbook", cols, rows),
            Layout::Sequence => ("sequence", 1, 1),
        };
        let exr = settings.format == super::Format::Exr;
        let premultiplied = settings.alpha == super::AlphaMode::Premultiplied;
        Self {
            layout,
            columns,
            rows,
            frame_count: frames,
            frame_width: settings.frame_size.0,
            frame_height: settings.frame_size.1,
            frames_per_second: 1.0 / interval_secs,
            frame_order: if columns > 1 || rows > 1 {
                "row-major from the top left: frame k at column k % columns, row k / columns"
            } else {
                "one file per frame, numbered from 0"
            },
            start_secs,
            looped: settings.looped,
            seam,
            alpha: settings.alpha.name(),
            format: settings.format.name(),
            color_space: if exr { "linear" } else { "sRGB" },
            compositing: match (premultiplied, settings.background.is_some()) {
                (_, true) => "opaque: rendered over the background colour",
                (true, _) => "linear: result = color + background * (1 - alpha)",
                (false, _) => "linear: result = color * alpha + background * (1 - alpha)",
            },
            passes: settings.passes.names(),
            sixway_packing: settings
                .passes
                .sixway
                .then_some(super::export_settings::SIXWAY_PACKING),
            motion_vector_scale,
            distortion_scale: (settings.passes.distortion)
                .then_some(super::export_settings::DISTORTION_SCALE),
            camera: settings.camera.name(),
            preset: effect.name.clone(),
            seed,
            ignis_version: env!("CARGO_PKG_VERSION"),
        }
    }

    /// The sidecar as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}
