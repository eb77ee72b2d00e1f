//! The look's data as the GPU sees it, with CPU mirrors of the shader functions in
//! `shaders/look.wgsl` (colour ramps, flipbook frame selection) for tests and tools.

use crate::effect::{CURVE_WIDTH, ColorStop, Flipbook, FlipbookMode, Look, Param, bake_rows};

/// Texels per colour ramp row (keep in sync with `RAMP_WIDTH` in `shaders/look.wgsl`).
pub const RAMP_WIDTH: u32 = 1024;

/// Rows of the ramp texture per emitter: its colour ramp, then its curve rows A and B
/// (`look_curves` in look.wgsl).
pub const ROWS_PER_EMITTER: u32 = 3;

const _: () = assert!(
    CURVE_WIDTH == RAMP_WIDTH,
    "curve rows share the ramp texture"
);

/// The look's curves, the channels of its curve rows: size (m), opacity, spin (deg/s,
/// baked as the angle integral in radians), flipbook frame (0 unless the frame is a curve).
pub fn look_curve_params(look: &Look) -> [&Param; 4] {
    const ZERO: &Param = &Param::Constant(0.0);
    let frame = match look.flipbook.as_ref().map(|f| &f.mode) {
        Some(FlipbookMode::Frames(p)) => p,
        _ => ZERO,
    };
    [&look.size_m, &look.opacity, &look.spin_deg_per_s, frame]
}

/// The look's curve rows A and B: channel z holds `∫₀ᵗ spin` in radians per second of
/// lifetime, so the angle a particle has turned is its lifetime times the row's value.
pub fn bake_look_curves(look: &Look) -> [Vec<[f32; 4]>; 2] {
    bake_rows(
        look_curve_params(look),
        [false, false, true, false],
        [1.0, 1.0, 1f64.to_radians(), 1.0],
    )
}

/// The gradient's value at `t`: linear between stops, clamped at the ends.
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
            // (1 − f)·a + f·b: exactly a at f = 0 and exactly b at f = 1.
            return std::array::from_fn(|k| a.rgba[k] * (1.0 - f) + b.rgba[k] * f);
        }
    }
    stops.last().map_or([1.0; 4], |s| s.rgba)
}

/// One ramp row: the gradient evaluated exactly at t = i / (RAMP_WIDTH − 1). Any number
/// of stops bakes to the same 16 KiB; the shader does two loads and a lerp per vertex
/// instead of a loop over the stops.
pub fn bake_ramp(stops: &[ColorStop]) -> Vec<[f32; 4]> {
    (0..RAMP_WIDTH)
        .map(|i| sample_gradient(stops, i as f32 / (RAMP_WIDTH - 1) as f32))
        .collect()
}

/// A flipbook frame choice: `frame`, the `next` frame and the weight of `next`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameChoice {
    /// The frame shown.
    pub frame: u32,
    /// The frame blended in.
    pub next: u32,
    /// Weight of `next` (0 without frame blending).
    pub weight: f32,
}

/// `flipbook_frames` of look.wgsl: `start01` is the particle's random number for its
/// start frame, `curve_frame` the frame curve's value (read in the frame curve mode).
pub fn flipbook_frame(
    f: &Flipbook,
    age: f32,
    life: f32,
    start01: f32,
    curve_frame: f32,
) -> FrameChoice {
    let count = (f.rows * f.cols).max(1);
    let n = count as f32;
    let start = if f.random_start {
        ((start01 * n) as u32).min(count - 1)
    } else {
        0
    };
    match f.mode {
        FlipbookMode::Frames(_) => {
            let pos = curve_frame.clamp(0.0, n - 1.0);
            let f0 = (pos as u32).min(count - 1);
            let f1 = (f0 + 1).min(count - 1);
            FrameChoice {
                frame: (f0 + start) % count,
                next: (f1 + start) % count,
                weight: if f.blend_frames { pos - f0 as f32 } else { 0.0 },
            }
        }
        FlipbookMode::OverLife => {
            let t = (age / life).clamp(0.0, 1.0);
            if f.blend_frames {
                let pos = t * (n - 1.0);
                let f0 = (pos as u32).min(count - 1);
                let f1 = (f0 + 1).min(count - 1);
                FrameChoice {
                    frame: (f0 + start) % count,
                    next: (f1 + start) % count,
                    weight: pos - f0 as f32,
                }
            } else {
                let fr = ((t * n) as u32).min(count - 1);
                FrameChoice {
                    frame: (fr + start) % count,
                    next: (fr + start) % count,
                    weight: 0.0,
                }
            }
        }
        FlipbookMode::FrameRate { fps } => {
            let pos = age.max(0.0) * fps;
            let whole = pos.floor();
            let f0 = (whole as u32 + start) % count;
            FrameChoice {
                frame: f0,
                next: (f0 + 1) % count,
                weight: if f.blend_frames { pos - whole } else { 0.0 },
            }
        }
    }
}

/// A key of what a ramp row holds (rows are re-uploaded only when it changes).
pub fn gradient_key(look: &Look) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for s in &look.color_over_life {
        s.t.to_bits().hash(&mut h);
        for c in s.rgba {
            c.to_bits().hash(&mut h);
        }
    }
    h.finish()
}
