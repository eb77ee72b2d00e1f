//! `ignis export`'s arguments and its run with a progress bar.

use std::path::PathBuf;

use super::{AlphaMode, CameraMode, ExportSettings, Format, Layout, Passes};

/// `ignis export PRESET`: a flipbook or an image sequence for game engines.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Preset file (default: the embedded campfire).
    pub preset: Option<PathBuf>,
    /// One atlas of COLSxROWS frames, row-major from the top left (the default, 8x8).
    #[arg(long, value_parser = parse_pair, conflicts_with = "sequence")]
    pub flipbook: Option<(u32, u32)>,
    /// One file per frame instead of an atlas.
    #[arg(long)]
    pub sequence: bool,
    /// One frame's size, WxH.
    #[arg(long, default_value = "256x256", value_parser = parse_pair)]
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
    #[arg(long, value_enum, default_value = "png")]
    pub format: Format,
    /// straight or premultiplied.
    #[arg(long, value_enum, default_value = "premultiplied")]
    pub alpha: AlphaMode,
    /// Passes, comma-separated: color, emissive, motion, distortion (the heat haze's
    /// screen offsets), sixway (the smoke's six-way
    /// lightmaps, two files, for an engine to relight).
    #[arg(long, default_value = "color", value_delimiter = ',')]
    pub passes: Vec<String>,
    /// The instance's seed (default: the preset's).
    #[arg(long)]
    pub seed: Option<u32>,
    /// fit (the preset's view, cropped to the whole span), preset or ortho.
    #[arg(long, value_enum, default_value = "fit")]
    pub camera: CameraMode,
    /// Render over this opaque linear colour R,G,B (0..1) instead of transparency.
    #[arg(long, value_delimiter = ',')]
    pub background: Option<Vec<f32>>,
    /// Output folder.
    #[arg(long, default_value = "export")]
    pub out: PathBuf,
}

/// Two whole numbers written `AxB` (`640x480`, `8x8`), as the command line takes sizes
/// and grids.
pub fn parse_pair(s: &str) -> Result<(u32, u32), String> {
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
        s.format = self.format;
        s.alpha = self.alpha;
        let mut passes = Passes::NONE;
        for p in &self.passes {
            match p.trim() {
                "color" => passes.color = true,
                "emissive" => passes.emissive = true,
                "motion" => passes.motion = true,
                "sixway" => passes.sixway = true,
                "distortion" => passes.distortion = true,
                other => {
                    return Err(format!(
                        "--passes: unknown pass {other:?} (color, emissive, motion, sixway, \
                         distortion)"
                    ));
                }
            }
        }
        s.passes = passes;
        s.seed = self.seed;
        s.camera = self.camera;
        s.background = match self.background.as_deref() {
            Some(&[r, g, b]) => Some([r, g, b]),
            Some(other) => return Err(format!("--background wants R,G,B, got {other:?}")),
            None => None,
        };
        Ok(s)
    }
}
