//! How an emitter's particles look: sprite, flipbook, size and opacity over life,
//! streaks, colour over life, blending and the draw path.

use serde::{Deserialize, Serialize};

use super::*;

/// How an emitter's particles look.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Look {
    /// The sprite texture: a built-in procedural one or a PNG.
    pub sprite: Sprite,
    /// Animate the sprite as an atlas of frames (`None`: the whole texture is one sprite).
    pub flipbook: Option<Flipbook>,
    /// Billboard size (diameter) over normalised age, metres.
    pub size_m: Param,
    /// Multiplies each particle's contribution over normalised age: its light when
    /// additive, its coverage (alpha) when alpha-blended (1 = as the colour says).
    pub opacity: Param,
    /// Per-particle random initial rotation, 0..=360 degrees of spread.
    pub rotation_random_deg: f32,
    /// Angular velocity over normalised age, degrees per second (a range: each particle
    /// spins at its own constant rate).
    pub spin_deg_per_s: Param,
    /// Stretch the billboard along the screen-space velocity (sparks).
    pub streak: Option<Streak>,
    /// A ribbon through each particle's last positions (see [`Trail`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trail: Option<Trail>,
    /// Fade the sprite where it meets the ground plane over this distance, metres (0 =
    /// off; the plane is the emitter's ground collider, or y = 0 without one).
    pub soft_ground_m: f32,
    /// Colour and alpha over normalised age (0 = birth, 1 = death); linear RGB.
    pub color_over_life: Vec<ColorStop>,
    /// Multiplies the colour (HDR brightness).
    pub intensity: f32,
    /// How particles are blended.
    pub blend: BlendMode,
    /// Which draw path renders them.
    pub draw_path: DrawPath,
    /// Shade an alpha-blended layer with six-way lightmaps (see [`Lit`]; its maps
    /// replace `sprite`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lit: Option<Lit>,
    /// Heat haze: the emitter is not drawn; its particles bend what is behind them (see
    /// [`HeatHaze`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heat_haze: Option<HeatHaze>,
}

/// A distortion layer: each particle of the emitter writes a screen-space offset — a
/// procedural ripple across its sprite, scaled by its size on screen and weighted by its
/// sprite's coverage and its opacity over life — and the frame's colour is refracted by
/// the sum. The emitter itself is invisible (its colour is not drawn).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HeatHaze {
    /// The largest offset, as a fraction of the particle's size on screen.
    pub strength: f32,
    /// Ripples across a sprite.
    pub frequency: f32,
    /// How fast the ripples move, cycles per second of each particle's age.
    pub speed_hz: f32,
}

impl Default for HeatHaze {
    fn default() -> Self {
        Self {
            strength: 0.03,
            frequency: 1.5,
            speed_hz: 1.2,
        }
    }
}

/// The two draw paths; both render the same look.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum DrawPath {
    /// Splat when the particles project smaller than [`SPLAT_BELOW_PX`] and blend
    /// additively (on GPUs, the adapter profile's `splat_dense_only`, only from
    /// [`SPLAT_PX_PER_QUAD`]); on GPUs (`tile_raster`) the tile rasteriser from
    /// [`TILES_ABOVE_PX`] and [`TILES_MIN_FILL_PX`]; billboards otherwise.
    #[default]
    Auto,
    /// Always instanced billboards (textured quads through the rasteriser).
    Billboard,
    /// Always the compute splat (additive emitters only; alpha emitters fall back to
    /// billboards, which they need for ordering).
    Splat,
    /// Always the compute tile rasteriser: the billboards' quads, binned into screen
    /// tiles and blended per tile on the compute units (the look of the billboards; in a
    /// host's pass only with its depth view). Alpha-blended emitters take it together or
    /// not at all (ribbons aside: they stay billboards, drawn behind the tiles' blended
    /// layers); streaks stay billboards.
    Tiles,
}

/// Auto draw path: below this projected particle size (pixels), splat.
pub const SPLAT_BELOW_PX: f32 = 4.0;

/// Auto draw path on adapters whose profile says `splat_dense_only` (GPUs): small particles
/// splat only when the draw has a quad (its widest live window × its instances) for every
/// this many pixels of the target or more. The splat clears and resolves the whole target:
/// on the H100 at 1920×1080 the thesis preset's 16384 points (one per 127 pixels) took
/// 0.42 ms a frame splatted and 0.20 ms as billboards (`ignis bench presets`) with the
/// splat's resolve drawn, as in a host's pass (resolved by compute: 0.145 against 0.227).
pub const SPLAT_PX_PER_QUAD: f32 = 64.0;

/// Auto draw path on adapters whose profile allows the tile rasteriser: particles that
/// project at least this large (pixels) take it — where the splat stops: on the H100 the
/// tiles beat the billboards from there (`ignis bench perf`: 4M flames of about 6 px,
/// 22.5 ms against 31.4).
pub const TILES_ABOVE_PX: f32 = 4.0;

/// Auto draw path: an emitter takes the tile rasteriser only when its quads (all its
/// instances' live windows) at their largest projected size would cover at least this
/// many pixels, or when it has [`TILES_MIN_QUADS`] of them: light fill costs the
/// billboards little, and the tiles a fixed ~0.1 ms on the H100 (`ignis bench presets`:
/// the spark fountain's 26-sprite glow).
pub const TILES_MIN_FILL_PX: f32 = 1.0e6;

/// Auto draw path: an emitter with at least this many quads (all its instances' live
/// windows) takes the tile rasteriser whatever their fill: many small quads cost the
/// billboards their count, not their pixels. On the H200 at 1920×1080 the torch's heads
/// (0.04 m embers, about 5 px) of 100 torches on a grid, some 30,000 quads, took 0.20 ms
/// as billboards and made the frame 1.378 ms; on the tiles it was 1.290 ms. Ten torches'
/// 3,000 heads were cheaper as billboards (0.650 against 0.685 ms;
/// `bench/results/runtime-heads/`).
pub const TILES_MIN_QUADS: u32 = 16_384;

/// A sprite texture: one of the procedural set generated at start, or a PNG with alpha.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Sprite {
    /// A soft round disc.
    SoftDisc,
    /// A hard-edged point (the thesis's look).
    Point,
    /// A bright core with a soft halo (sparks).
    Spark,
    /// A teardrop flame tongue, brighter at the base.
    FlameWisp,
    /// A lumpy, noisy puff (smoke).
    SmokePuff,
    /// A built-in 4 × 4 flipbook of licking flame tongues (use with a 4 × 4 flipbook).
    FlameSheet,
    /// A PNG (straight alpha) at this path, relative to the preset file.
    Image(String),
}

impl Sprite {
    /// The built-in sprites, in menu order.
    pub const BUILT_IN: [Sprite; 6] = [
        Sprite::SoftDisc,
        Sprite::Point,
        Sprite::Spark,
        Sprite::FlameWisp,
        Sprite::SmokePuff,
        Sprite::FlameSheet,
    ];

    /// A short name for menus and messages.
    pub fn label(&self) -> &str {
        match self {
            Sprite::SoftDisc => "soft disc",
            Sprite::Point => "point",
            Sprite::Spark => "spark",
            Sprite::FlameWisp => "flame wisp",
            Sprite::SmokePuff => "smoke puff",
            Sprite::FlameSheet => "flame sheet (4×4)",
            Sprite::Image(path) => path,
        }
    }
}

/// A sprite atlas of `rows` × `cols` frames (row-major, top-left first), animated.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Flipbook {
    /// Frame rows in the atlas.
    pub rows: u32,
    /// Frame columns in the atlas.
    pub cols: u32,
    /// How the frame advances.
    pub mode: FlipbookMode,
    /// Cross-fade between consecutive frames (two texture samples) instead of cutting.
    pub blend_frames: bool,
    /// Start each particle on a random frame.
    pub random_start: bool,
}

impl Default for Flipbook {
    fn default() -> Self {
        Self {
            rows: 4,
            cols: 4,
            mode: FlipbookMode::OverLife,
            blend_frames: true,
            random_start: false,
        }
    }
}

/// How a flipbook's frame advances.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FlipbookMode {
    /// Frame 0 at birth to the last frame at death.
    OverLife,
    /// A fixed rate, looping.
    FrameRate {
        /// Frames per second.
        fps: f32,
    },
    /// The frame over normalised age (0 = the first frame; a fraction blends toward the
    /// next when `blend_frames`; clamped to the last).
    Frames(Param),
}

/// Spark streaks: the billboard runs from the particle back along its velocity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Streak {
    /// The tail is where the particle was this many seconds ago (at its current
    /// velocity), like the thesis's old-to-new interpolation.
    pub length_secs: f32,
    /// Longest tail, metres (keeps very fast sparks from crossing the screen).
    pub max_length_m: f32,
}

impl Default for Streak {
    fn default() -> Self {
        Self {
            length_secs: 0.03,
            max_length_m: 0.5,
        }
    }
}

/// Blend modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum BlendMode {
    /// Light adds up (fire, sparks): order-independent.
    Additive,
    /// Premultiplied alpha "over" (smoke): darkens what is behind.
    Alpha,
}

/// One stop of a colour gradient.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorStop {
    /// Normalised age, 0..1.
    pub t: f32,
    /// Linear RGB and alpha.
    pub rgba: [f32; 4],
}

/// The most gradient stops a look may have: the ramp baking handles any number, but stops
/// closer than one of its 1024 texels cannot be told apart, so more would be noise.
pub const MAX_COLOR_STOPS: usize = 1024;

impl Default for Look {
    fn default() -> Self {
        Self {
            sprite: Sprite::SoftDisc,
            flipbook: None,
            size_m: Param::Curve {
                keys: vec![(0.0, 0.22), (1.0, 0.06)],
                smooth: false,
            },
            opacity: Param::Constant(1.0),
            rotation_random_deg: 0.0,
            spin_deg_per_s: Param::Constant(0.0),
            streak: None,
            trail: None,
            soft_ground_m: 0.0,
            color_over_life: vec![
                ColorStop {
                    t: 0.0,
                    rgba: [1.0, 0.9, 0.6, 0.0],
                },
                ColorStop {
                    t: 0.08,
                    rgba: [1.0, 0.75, 0.3, 0.9],
                },
                ColorStop {
                    t: 0.35,
                    rgba: [1.0, 0.38, 0.06, 0.7],
                },
                ColorStop {
                    t: 0.7,
                    rgba: [0.7, 0.1, 0.02, 0.35],
                },
                ColorStop {
                    t: 1.0,
                    rgba: [0.08, 0.05, 0.05, 0.0],
                },
            ],
            intensity: 1.6,
            blend: BlendMode::Additive,
            draw_path: DrawPath::Auto,
            lit: None,
            heat_haze: None,
        }
    }
}
