//! `ignis export`'s arguments and its run with a progress bar.

use std::path::PathBuf;

use super::{AlphaMode, CameraMode, ExportSettings, Format, Layout, Passes};

/// `ignis export PRESET`: a flipbook or an image sequence for game engines.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Preset file (default: the embedded campfire).
    pub preset: Option<PathBuf>,
    /// One atlas of COLSxROWS frames, row-major from the top left (the default, 8x8).
    #[arg(long, value_parser = parse_grid, conflicts_with = "sequence")]
    pub flipbook: Option<(u32, u32)>,
    /// One file per frame instead of an atlas.
    #[arg(long)]
    pub sequence: bool,
    /// One frame's size, WxH.
    #[arg(long, default_value = "256x256", value_parser = parse_grid)]
    pub frame_size: (u32, u32),
    /// Effect time of the first frame, seconds (a loop starts past the longest lifetime).
    #[arg(long, default_value_t = 0.0)]
    pub start: f64,
    /// The time the frames span, seconds (default: frames / fps).
    #[arg(long)]
    pub duration: Option<f64>,
    /// How many frames (default: the flipbook's cells, or duration × fps).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Frames per second when --duration or --frames is not given.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// A seamless loop: the last frame flows into the first.
    #[arg(long = "loop")]
    pub looped: bool,
    /// png (8-bit sRGB), png16 (16-bit sRGB) or exr (half-float linear).
    #[arg(long, default_value = "png", value_parser = ["png", "png16", "exr"])]
    pub format: String,
    /// straight or premultiplied.
    #[arg(long, default_value = "premultiplied", value_parser = ["straight", "premultiplied"])]
    pub alpha: String,
    /// Passes, comma-separated: color, emissive, motion.
    #[arg(long, default_value = "color", value_delimiter = ',')]
    pub passes: Vec<String>,
    /// The instance's seed (default: the preset's).
    #[arg(long)]
    pub seed: Option<u32>,
    /// fit (the preset's view, backed off to fit the whole span), preset or ortho.
    #[arg(long, default_value = "fit", value_parser = ["fit", "preset", "ortho"])]
    pub camera: String,
    /// Render over this opaque linear colour R,G,B (0..1) instead of transparency.
    #[arg(long, value_delimiter = ',')]
    pub background: Option<Vec<f32>>,
    /// Output folder.
    #[arg(long, default_value = "export")]
    pub out: PathBuf,
}

fn parse_grid(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected AxB like 8x8, got {s:?}"))?;
    let n = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("bad number in {s:?}"))
    };
    Ok((n(a)?, n(b)?))
}

impl ExportArgs {
    /// The settings these arguments ask for (refused with the option named).
    pub fn settings(&self) -> Result<ExportSettings, String> {
        let mut s = ExportSettings::new(self.out.clone());
        s.layout = match (self.sequence, self.flipbook) {
            (true, _) => Layout::Sequence,
            (false, Some((cols, rows))) => Layout::Flipbook { cols, rows },
            (false, None) => Layout::Flipbook { cols: 8, rows: 8 },
        };
        s.frame_size = self.frame_size;
        s.start_secs = self.start;
        s.duration_secs = self.duration;
        s.frames = self.frames;
        s.fps = self.fps;
        s.looped = self.looped;
        s.format = match self.format.as_str() {
            "png16" => Format::Png16,
            "exr" => Format::Exr,
            _ => Format::Png8,
        };
        s.alpha = match self.alpha.as_str() {
            "straight" => AlphaMode::Straight,
            _ => AlphaMode::Premultiplied,
        };
        let mut passes = Passes {
            color: false,
            emissive: false,
            motion: false,
        };
        for p in &self.passes {
            match p.trim() {
                "color" => passes.color = true,
                "emissive" => passes.emissive = true,
                "motion" => passes.motion = true,
                other => {
                    return Err(format!(
                        "--passes: unknown pass {other:?} (color, emissive, motion)"
                    ));
                }
            }
        }
        s.passes = passes;
        s.seed = self.seed;
        s.camera = match self.camera.as_str() {
            "preset" => CameraMode::Preset,
            "ortho" => CameraMode::Ortho,
            _ => CameraMode::Fit,
        };
        s.background = match self.background.as_deref() {
            Some(&[r, g, b]) => Some([r, g, b]),
            Some(other) => return Err(format!("--background wants R,G,B, got {other:?}")),
            None => None,
        };
        Ok(s)
    }
}
