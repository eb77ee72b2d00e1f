//! [`ExportSettings`]: what an export writes, with the command line's defaults.

use std::path::PathBuf;

/// One atlas or one file per frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// `cols × rows` frames in one image, row-major from the top left (Unreal's SubUV,
    /// Unity's Texture Sheet Animation, Godot's H/V frames).
    Flipbook {
        /// Frames per row.
        cols: u32,
        /// Rows.
        rows: u32,
    },
    /// One file per frame.
    Sequence,
}

/// The image format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// 8-bit sRGB PNG.
    #[value(name = "png")]
    Png8,
    /// 16-bit sRGB PNG.
    Png16,
    /// Half-float linear OpenEXR (light above 1 kept).
    Exr,
}

impl Format {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png8 | Self::Png16 => "png",
            Self::Exr => "exr",
        }
    }

    /// The name the command line and the sidecar use.
    pub fn name(self) -> &'static str {
        match self {
            Self::Png8 => "png",
            Self::Png16 => "png16",
            Self::Exr => "exr",
        }
    }
}

/// How colour and alpha are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AlphaMode {
    /// Colour divided by a coverage that also counts additive light (see the module doc).
    Straight,
    /// Colour multiplied by coverage: composites exactly as `C + B·(1 − A)`.
    Premultiplied,
}

impl AlphaMode {
    /// The name the command line and the sidecar use.
    pub fn name(self) -> &'static str {
        match self {
            Self::Straight => "straight",
            Self::Premultiplied => "premultiplied",
        }
    }
}

/// Where the frames are seen from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CameraMode {
    /// The preset's perspective camera's direction, backed off to fit every particle of
    /// the whole span with a margin.
    Fit,
    /// The preset's camera as it is.
    Preset,
    /// An orthographic camera along the preset's direction, fitted like `Fit`.
    Ortho,
}

impl CameraMode {
    /// The name the command line and the sidecar use.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fit => "fit",
            Self::Preset => "preset",
            Self::Ortho => "ortho",
        }
    }
}

/// Which passes are written, one file (or atlas) per pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Passes {
    /// RGBA: the light and coverage.
    pub color: bool,
    /// The additive light alone (RGB, opaque: add it).
    pub emissive: bool,
    /// Screen-space motion to the next frame in RG, centred at 0.5.
    pub motion: bool,
    /// The alpha-blended (smoke) layers' six-way lightmaps, for an engine to relight:
    /// two files, `sixway_rtba` and `sixway_lbfe` (see [`SIXWAY_PACKING`]).
    pub sixway: bool,
    /// The heat-haze layers' screen offsets in RG, centred at 0.5, for an engine's
    /// distortion material (offset in frame UV = (value − 0.5) × [`DISTORTION_SCALE`]).
    pub distortion: bool,
}

/// The distortion pass's encoding: a stored value v means an offset of
/// (v − 0.5) × this, in frame UV (x right, y down).
pub const DISTORTION_SCALE: f32 = 0.1;

/// The packing of the six-way passes, as the sidecar states it (Unity's Six Way
/// shader's): lit by a unit white light from each axis of the camera's frame.
pub const SIXWAY_PACKING: &str = "sixway_rtba: R lit from the camera's right, G from above \
    (camera up), B from behind (away from the camera), A coverage; sixway_lbfe: R from the \
    left, G from below, B from the front (the camera's side), A emissive (the layers' own \
    glow); linear, straight alpha, the alpha-blended layers only";

impl Passes {
    /// No pass (the start of a list of passes).
    pub const NONE: Passes = Passes {
        color: false,
        emissive: false,
        motion: false,
        sixway: false,
        distortion: false,
    };

    /// The colour pass alone (the default).
    pub const COLOR: Passes = Passes {
        color: true,
        ..Passes::NONE
    };

    /// The names of the passes that are on.
    pub fn names(self) -> Vec<&'static str> {
        [
            (self.color, "color"),
            (self.emissive, "emissive"),
            (self.motion, "motion"),
            (self.sixway, "sixway_rtba"),
            (self.sixway, "sixway_lbfe"),
            (self.distortion, "distortion"),
        ]
        .into_iter()
        .filter_map(|(on, n)| on.then_some(n))
        .collect()
    }
}

/// Everything an export is told.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportSettings {
    /// Flipbook or sequence.
    pub layout: Layout,
    /// One frame's size in pixels.
    pub frame_size: (u32, u32),
    /// The effect time of the first frame (a loop starts warm: past the longest lifetime).
    pub start_secs: f64,
    /// The time the frames span; `None`: `frames / fps`.
    pub duration_secs: Option<f64>,
    /// How many frames; `None`: the flipbook's cells, or `duration × fps` for a sequence.
    pub frames: Option<u32>,
    /// Frames per second when the duration or the count is not given.
    pub fps: f64,
    /// A seamless loop: the last frame flows into the first.
    pub looped: bool,
    /// The image format.
    pub format: Format,
    /// Straight or premultiplied alpha.
    pub alpha: AlphaMode,
    /// The passes written.
    pub passes: Passes,
    /// The instance's seed; `None`: the preset's.
    pub seed: Option<u32>,
    /// The framing.
    pub camera: CameraMode,
    /// Render over this opaque linear colour instead of transparency (to check the
    /// compositing formula, or for engines that want no alpha).
    pub background: Option<[f32; 3]>,
    /// The folder the files go to (created if missing).
    pub out_dir: PathBuf,
}

impl ExportSettings {
    /// An 8×8 flipbook of 256² frames at 30 fps, premultiplied 8-bit PNG colour, framed
    /// to fit, into `out_dir`.
    pub fn new(out_dir: PathBuf) -> Self {
        Self {
            layout: Layout::Flipbook { cols: 8, rows: 8 },
            frame_size: (256, 256),
            start_secs: 0.0,
            duration_secs: None,
            frames: None,
            fps: 30.0,
            looped: false,
            format: Format::Png8,
            alpha: AlphaMode::Premultiplied,
            passes: Passes::COLOR,
            seed: None,
            camera: CameraMode::Fit,
            background: None,
            out_dir,
        }
    }

    /// The number of output frames.
    pub fn frame_count(&self) -> u32 {
        match (self.frames, self.layout, self.duration_secs) {
            (Some(n), _, _) => n,
            (None, Layout::Flipbook { cols, rows }, _) => cols * rows,
            (None, Layout::Sequence, Some(d)) => (d * self.fps).round().max(1.0) as u32,
            (None, Layout::Sequence, None) => 60,
        }
    }

    /// The time between frames.
    pub fn interval_secs(&self) -> f64 {
        match self.duration_secs {
            Some(d) => d / f64::from(self.frame_count().max(1)),
            None => 1.0 / self.fps,
        }
    }

    /// Refuses impossible settings, naming the option and the fix.
    pub fn validate(&self) -> Result<(), super::ExportError> {
        let bad = |m: String| Err(super::ExportError::Invalid(m));
        let (w, h) = self.frame_size;
        if !(1..=8192).contains(&w) || !(1..=8192).contains(&h) {
            return bad(format!(
                "--frame-size {w}x{h}: each side must be 1 to 8192 pixels"
            ));
        }
        let n = self.frame_count();
        if n == 0 || n > 100_000 {
            return bad(format!("--frames {n}: give 1 to 100000 frames"));
        }
        if let Layout::Flipbook { cols, rows } = self.layout {
            if cols == 0 || rows == 0 {
                return bad(format!("--flipbook {cols}x{rows}: both must be at least 1"));
            }
            if n > cols * rows {
                return bad(format!(
                    "--frames {n} does not fit a {cols}x{rows} flipbook: give at most {} frames \
                        or a larger grid",
                    cols * rows
                ));
            }
            if u64::from(cols * w) > 16384 || u64::from(rows * h) > 16384 {
                return bad(format!(
                    "a {cols}x{rows} flipbook of {w}x{h} frames is {}x{} pixels: atlases are at \
                        most 16384 on a side (smaller frames or grid)",
                    cols * w,
                    rows * h
                ));
            }
        }
        if self.looped && n < 2 {
            return bad(format!("--loop needs at least 2 frames, got --frames {n}"));
        }
        if !(self.start_secs.is_finite() && self.start_secs >= 0.0) {
            return bad(format!(
                "--start {}: must be 0 or more seconds",
                self.start_secs
            ));
        }
        if let Some(d) = self.duration_secs
            && !(d.is_finite() && d > 0.0 && d <= 3600.0)
        {
            return bad(format!(
                "--duration {d}: must be above 0 and at most 3600 seconds"
            ));
        }
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= 1000.0) {
            return bad(format!(
                "--fps {}: must be above 0 and at most 1000",
                self.fps
            ));
        }
        let p = self.passes;
        if !(p.color || p.emissive || p.motion || p.sixway || p.distortion) {
            return bad(
                "--passes: name at least one of color, emissive, motion, sixway, distortion".into(),
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Any one pass alone is enough to export, and none is refused with the passes named.
    #[test]
    fn any_one_pass_exports_and_none_is_refused() {
        let none = Passes {
            color: false,
            emissive: false,
            motion: false,
            sixway: false,
            distortion: false,
        };
        let alone: [fn(&mut Passes); 5] = [
            |p| p.color = true,
            |p| p.emissive = true,
            |p| p.motion = true,
            |p| p.sixway = true,
            |p| p.distortion = true,
        ];
        for (k, set) in alone.iter().enumerate() {
            let mut settings = ExportSettings::new("out".into());
            settings.passes = none;
            set(&mut settings.passes);
            assert!(settings.validate().is_ok(), "pass {k} alone refused");
        }
        let mut settings = ExportSettings::new("out".into());
        settings.passes = none;
        let err = settings
            .validate()
            .expect_err("no pass accepted")
            .to_string();
        assert!(err.contains("--passes"), "{err}");
    }
}
