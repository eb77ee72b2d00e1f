//! Values that change: a constant, a random range, a curve, or a random blend of two
//! curves (the four modes of Unity's and Godot's particle curves).
//!
//! A [`Param`] is evaluated at a time `t` and a random number `u ∈ [0, 1)`:
//! `mix(a(t), b(t), u)` where `a` and `b` are its two rows — both the constant, the range's
//! ends (constant in t), the curve twice, or the two curves. Per-particle quantities take
//! `t` as the normalised age (0 at birth, 1 at death) and `u` from the particle's hash; the
//! spawn rate takes the effect's time in seconds and `u` from the instance's seed. The GPU
//! reads baked rows ([`bake_rows`]) the way it reads the colour ramp.
//!
//! Smooth curves are monotone cubics (Fritsch–Carlson tangents, the PCHIP weights): they
//! never overshoot their keys, so a curve's extremes are its keys' extremes and a curve of
//! non-negative keys never goes negative.

use serde::{Deserialize, Serialize};

/// The most keys a curve may have.
pub const MAX_CURVE_KEYS: usize = 64;

/// Texels per baked curve row (the colour ramp's width; keep in sync with
/// `CURVE_WIDTH` in `shaders/curves.wgsl`).
pub const CURVE_WIDTH: u32 = 1024;

/// A curve through keys `(t, value)`, sorted by strictly increasing `t`; constant before
/// the first key and after the last.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Curve {
    /// The keys, `(t, value)`.
    pub keys: Vec<(f32, f32)>,
    /// Monotone cubic segments (no overshoot); straight lines when false.
    pub smooth: bool,
}

/// A quantity in one of four modes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Param {
    /// The same value always.
    Constant(f32),
    /// A value drawn uniformly from `[min, max]`, fixed for a particle's life (or, for the
    /// spawn rate, an instance's).
    Range {
        /// Lower end.
        min: f32,
        /// Upper end (≥ min).
        max: f32,
    },
    /// A curve over time.
    Curve {
        /// The keys, `(t, value)`.
        keys: Vec<(f32, f32)>,
        /// Monotone cubic segments; straight lines when false.
        smooth: bool,
    },
    /// A random blend of two curves: `mix(a(t), b(t), u)`, `u` fixed per particle.
    TwoCurves {
        /// The curve at u = 0.
        a: Curve,
        /// The curve at u = 1.
        b: Curve,
    },
}

/// The four modes, for menus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamMode {
    /// [`Param::Constant`].
    Constant,
    /// [`Param::Range`].
    Range,
    /// [`Param::Curve`].
    Curve,
    /// [`Param::TwoCurves`].
    TwoCurves,
}

impl ParamMode {
    /// Every mode, in menu order.
    pub const ALL: [ParamMode; 4] = [
        ParamMode::Constant,
        ParamMode::Range,
        ParamMode::Curve,
        ParamMode::TwoCurves,
    ];

    /// A short name for menus.
    pub fn label(self) -> &'static str {
        match self {
            ParamMode::Constant => "constant",
            ParamMode::Range => "random range",
            ParamMode::Curve => "curve",
            ParamMode::TwoCurves => "random between two curves",
        }
    }
}

impl From<f32> for Param {
    fn from(v: f32) -> Self {
        Param::Constant(v)
    }
}

impl Curve {
    /// A constant curve (one key).
    pub fn flat(v: f32) -> Self {
        Curve {
            keys: vec![(0.0, v)],
            smooth: true,
        }
    }

    /// A straight line from `(0, a)` to `(1, b)`.
    pub fn line(a: f32, b: f32) -> Self {
        Curve {
            keys: vec![(0.0, a), (1.0, b)],
            smooth: false,
        }
    }

    /// The value at `t` (f64 throughout; the baked rows round once).
    pub fn eval(&self, t: f64) -> f64 {
        let k = &self.keys;
        let Some(&(t0, v0)) = k.first() else {
            return 0.0;
        };
        let &(tn, vn) = k.last().unwrap_or(&(t0, v0));
        if t <= f64::from(t0) {
            return f64::from(v0);
        }
        if t >= f64::from(tn) {
            return f64::from(vn);
        }
        // The segment [keys[s], keys[s + 1]] holding t.
        let s = k.partition_point(|&(kt, _)| f64::from(kt) <= t).max(1) - 1;
        let s = s.min(k.len() - 2);
        let (x0, y0) = (f64::from(k[s].0), f64::from(k[s].1));
        let (x1, y1) = (f64::from(k[s + 1].0), f64::from(k[s + 1].1));
        let h = x1 - x0;
        if h <= 0.0 {
            return y1;
        }
        let f = (t - x0) / h;
        if !self.smooth {
            return y0 * (1.0 - f) + y1 * f;
        }
        let (m0, m1) = (self.tangent(s), self.tangent(s + 1));
        let f2 = f * f;
        let f3 = f2 * f;
        (2.0 * f3 - 3.0 * f2 + 1.0) * y0
            + (f3 - 2.0 * f2 + f) * h * m0
            + (-2.0 * f3 + 3.0 * f2) * y1
            + (f3 - f2) * h * m1
    }

    /// The slope of segment `s` (between keys s and s + 1).
    fn secant(&self, s: usize) -> (f64, f64) {
        let (a, b) = (self.keys[s], self.keys[s + 1]);
        let h = f64::from(b.0) - f64::from(a.0);
        let d = if h > 0.0 {
            (f64::from(b.1) - f64::from(a.1)) / h
        } else {
            0.0
        };
        (h, d)
    }

    /// The monotone tangent at key `k` (Fritsch–Butland weights, as PCHIP): zero at a local
    /// extreme, a weighted harmonic mean of the neighbouring slopes elsewhere, the one-sided
    /// slope at the ends.
    fn tangent(&self, k: usize) -> f64 {
        let n = self.keys.len();
        if k == 0 {
            return self.secant(0).1;
        }
        if k == n - 1 {
            return self.secant(n - 2).1;
        }
        let (h0, d0) = self.secant(k - 1);
        let (h1, d1) = self.secant(k);
        if d0 * d1 <= 0.0 {
            return 0.0;
        }
        let w1 = 2.0 * h1 + h0;
        let w2 = h1 + 2.0 * h0;
        (w1 + w2) / (w1 / d0 + w2 / d1)
    }

    /// `∫ₐᵇ curve(t) dt`: Simpson's rule on each piece between keys, exact for the linear
    /// and cubic segments and the constant ends.
    pub fn integral(&self, a: f64, b: f64) -> f64 {
        if b <= a {
            return 0.0;
        }
        let mut total = 0.0;
        let mut lo = a;
        let inner = self
            .keys
            .iter()
            .map(|k| f64::from(k.0))
            .filter(|&t| t > a && t < b);
        for hi in inner.chain(std::iter::once(b)) {
            let mid = 0.5 * (lo + hi);
            total += (hi - lo) / 6.0 * (self.eval(lo) + 4.0 * self.eval(mid) + self.eval(hi));
            lo = hi;
        }
        total
    }

    /// The smallest and largest value the curve takes (its keys', as it never overshoots).
    pub fn bounds(&self) -> (f32, f32) {
        self.keys
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), k| {
                (lo.min(k.1), hi.max(k.1))
            })
    }
}

impl Param {
    /// The mode.
    pub fn mode(&self) -> ParamMode {
        match self {
            Param::Constant(_) => ParamMode::Constant,
            Param::Range { .. } => ParamMode::Range,
            Param::Curve { .. } => ParamMode::Curve,
            Param::TwoCurves { .. } => ParamMode::TwoCurves,
        }
    }

    /// The two rows blended by the random number (see the module doc).
    pub fn rows(&self) -> [Curve; 2] {
        match self {
            Param::Constant(v) => [Curve::flat(*v), Curve::flat(*v)],
            Param::Range { min, max } => [Curve::flat(*min), Curve::flat(*max)],
            Param::Curve { keys, smooth } => {
                let c = Curve {
                    keys: keys.clone(),
                    smooth: *smooth,
                };
                [c.clone(), c]
            }
            Param::TwoCurves { a, b } => [a.clone(), b.clone()],
        }
    }

    /// The value at `t` for random number `u`.
    pub fn eval(&self, t: f64, u: f64) -> f64 {
        match self {
            Param::Constant(v) => f64::from(*v),
            _ => {
                let [a, b] = self.rows();
                a.eval(t) * (1.0 - u) + b.eval(t) * u
            }
        }
    }

    /// `∫ₐᵇ` of the value for random number `u`.
    pub fn integral(&self, u: f64, a: f64, b: f64) -> f64 {
        match self {
            Param::Constant(v) => f64::from(*v) * (b - a).max(0.0),
            _ => {
                let [ra, rb] = self.rows();
                ra.integral(a, b) * (1.0 - u) + rb.integral(a, b) * u
            }
        }
    }

    /// The smallest and largest value over every `t` and `u`.
    pub fn bounds(&self) -> (f32, f32) {
        let [a, b] = self.rows();
        let (a, b) = (a.bounds(), b.bounds());
        (a.0.min(b.0), a.1.max(b.1))
    }

    /// Every value multiplied by `f` (the times unchanged).
    pub fn scaled(&self, f: f32) -> Param {
        let curve = |c: &Curve| Curve {
            keys: c.keys.iter().map(|&(t, v)| (t, v * f)).collect(),
            smooth: c.smooth,
        };
        match self {
            Param::Constant(v) => Param::Constant(v * f),
            Param::Range { min, max } => Param::Range {
                min: min * f,
                max: max * f,
            },
            Param::Curve { keys, smooth } => Param::Curve {
                keys: keys.iter().map(|&(t, v)| (t, v * f)).collect(),
                smooth: *smooth,
            },
            Param::TwoCurves { a, b } => Param::TwoCurves {
                a: curve(a),
                b: curve(b),
            },
        }
    }

    /// True when this is exactly the constant `v`.
    pub fn is_constant(&self, v: f32) -> bool {
        *self == Param::Constant(v)
    }

    /// This parameter converted to `mode`, keeping its values as far as the mode can: a
    /// constant becomes a range of one value or a flat curve, a curve a range over its
    /// extremes, and so on.
    pub fn to_mode(&self, mode: ParamMode) -> Param {
        let (lo, hi) = self.bounds();
        let [a, b] = self.rows();
        match mode {
            ParamMode::Constant => Param::Constant(self.eval(0.0, 0.5) as f32),
            ParamMode::Range => Param::Range { min: lo, max: hi },
            ParamMode::Curve => match self {
                Param::Range { .. } => Param::Curve {
                    keys: vec![(0.0, lo), (1.0, hi)],
                    smooth: true,
                },
                _ => Param::Curve {
                    keys: a.keys,
                    smooth: a.smooth,
                },
            },
            ParamMode::TwoCurves => match self {
                Param::Constant(v) => Param::TwoCurves {
                    a: Curve::line(*v, *v),
                    b: Curve::line(*v, *v),
                },
                _ => Param::TwoCurves { a, b },
            },
        }
    }
}

/// Bakes up to four parameters into two rows of [`CURVE_WIDTH`] texels (one channel
/// each): row A holds each parameter's `a(tᵢ)`, row B its `b(tᵢ)`, at
/// `tᵢ = i / (CURVE_WIDTH − 1)`. With `integrate[c]`, channel c holds `∫₀^tᵢ` of the row
/// instead, times `scale[c]` (the spin: the angle turned by normalised age t is life ×
/// that).
pub fn bake_rows(params: [&Param; 4], integrate: [bool; 4], scale: [f64; 4]) -> [Vec<[f32; 4]>; 2] {
    let n = CURVE_WIDTH as usize;
    let t_at = |i: usize| i as f64 / (n - 1) as f64;
    let mut rows = [vec![[0.0f32; 4]; n], vec![[0.0f32; 4]; n]];
    for (c, p) in params.iter().enumerate() {
        for (r, curve) in p.rows().iter().enumerate() {
            let mut acc = 0.0;
            for (i, texel) in rows[r].iter_mut().enumerate() {
                let v = if integrate[c] {
                    if i > 0 {
                        acc += curve.integral(t_at(i - 1), t_at(i));
                    }
                    acc
                } else {
                    curve.eval(t_at(i))
                };
                texel[c] = (v * scale[c]) as f32;
            }
        }
    }
    rows
}

/// A baked row read at `t` as the shaders read it (`curve_lookup` in curves.wgsl): the two
/// texels around `t · (CURVE_WIDTH − 1)`, linearly blended.
pub fn lookup(row: &[[f32; 4]], t: f32) -> [f32; 4] {
    let last = row.len().saturating_sub(1);
    let x = t.clamp(0.0, 1.0) * last as f32;
    let i = (x as usize).min(last);
    let j = (i + 1).min(last);
    let f = x - i as f32;
    let (a, b) = (row[i], row[j]);
    std::array::from_fn(|k| a[k] + (b[k] - a[k]) * f)
}

/// `lookup` of both rows, blended by the per-channel random numbers `u`.
pub fn lookup_blend(rows: &[Vec<[f32; 4]>; 2], t: f32, u: [f32; 4]) -> [f32; 4] {
    let (a, b) = (lookup(&rows[0], t), lookup(&rows[1], t));
    std::array::from_fn(|k| a[k] + (b[k] - a[k]) * u[k])
}

/// A key of what baked rows hold (rows are re-uploaded only when it changes).
pub fn rows_key(params: &[&Param]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in params {
        for (r, c) in p.rows().iter().enumerate() {
            (r, c.smooth, c.keys.len()).hash(&mut h);
            for k in &c.keys {
                (k.0.to_bits(), k.1.to_bits()).hash(&mut h);
            }
        }
    }
    h.finish()
}

/// A starting shape for a curve editor: its name, keys and whether it is smooth.
pub type CurveShape = (&'static str, &'static [(f32, f32)], bool);

/// Starting shapes for a curve editor: (name, keys, smooth), over t ∈ [0, 1] and values in
/// [0, 1] (scaled by the caller).
pub const SHAPES: [CurveShape; 5] = [
    ("linear up", &[(0.0, 0.0), (1.0, 1.0)], false),
    ("ease in/out", &[(0.0, 0.0), (0.5, 0.5), (1.0, 1.0)], true),
    ("fade out", &[(0.0, 1.0), (0.6, 0.8), (1.0, 0.0)], true),
    (
        "fade in/out",
        &[(0.0, 0.0), (0.15, 1.0), (0.7, 0.8), (1.0, 0.0)],
        true,
    ),
    (
        "pulse",
        &[(0.0, 0.0), (0.25, 1.0), (0.5, 0.2), (0.75, 1.0), (1.0, 0.0)],
        true,
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(keys: &[(f32, f32)], smooth: bool) -> Curve {
        Curve {
            keys: keys.to_vec(),
            smooth,
        }
    }

    #[test]
    fn curves_pass_through_keys_and_hold_their_ends() {
        for smooth in [false, true] {
            let c = curve(&[(0.1, 2.0), (0.4, 5.0), (0.9, 1.0)], smooth);
            for &(t, v) in &c.keys {
                assert_eq!(c.eval(f64::from(t)), f64::from(v));
            }
            assert_eq!(c.eval(-1.0), 2.0);
            assert_eq!(c.eval(0.0), 2.0);
            assert_eq!(c.eval(1.0), 1.0);
        }
    }

    /// Between keys, a smooth curve is the cubic Hermite segment with PCHIP's
    /// (Fritsch–Butland) tangents, worked out by hand: keys (0, 0), (1, 1), (3, 2) have
    /// slopes 1 and 1/2, the inner tangent 9/13 (weights 5 and 4), the end tangents the
    /// one-sided slopes; at a local extreme the tangent is 0.
    #[test]
    fn smooth_curves_are_pchip_hermite_segments_between_keys() {
        let c = curve(&[(0.0, 0.0), (1.0, 1.0), (3.0, 2.0)], true);
        // t = 0.5: h10·1 + h01·1 + h11·(9/13) with h10 = 1/8, h01 = 1/2, h11 = −1/8.
        assert!((c.eval(0.5) - 7.0 / 13.0).abs() < 1e-12, "{}", c.eval(0.5));
        // t = 2 (h = 2): h00·1 + h10·2·(9/13) + h01·2 + h11·2·(1/2).
        assert!((c.eval(2.0) - 80.5 / 52.0).abs() < 1e-12, "{}", c.eval(2.0));
        // t = 0.25: h00 = 27/32, h10 = 9/64, h01 = 5/32, h11 = −3/64.
        let quarter = 9.0 / 64.0 + 5.0 / 32.0 - 3.0 / 64.0 * 9.0 / 13.0;
        assert!((c.eval(0.25) - quarter).abs() < 1e-12, "{}", c.eval(0.25));
        // Unequal spacings and slopes, none of them 1 or 2 (keys (0, 0), (0.5, 1.5),
        // (2, 2.25): h 0.5 and 1.5, slopes 3 and 1/2): weights 3.5 and 2.5, the inner
        // tangent 6 / (3.5/3 + 2.5/0.5) = 36/37; at t = 0.25, h10·0.5·3 + h01·1.5 +
        // h11·0.5·36/37.
        let uneven = curve(&[(0.0, 0.0), (0.5, 1.5), (2.0, 2.25)], true);
        let want = 0.1875 + 0.75 - 0.0625 * 36.0 / 37.0;
        assert!(
            (uneven.eval(0.25) - want).abs() < 1e-12,
            "{}",
            uneven.eval(0.25)
        );
        let peak = curve(&[(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)], true);
        assert!((peak.eval(0.5) - 0.625).abs() < 1e-12, "{}", peak.eval(0.5));
        assert!((peak.eval(1.5) - 0.625).abs() < 1e-12, "{}", peak.eval(1.5));
    }

    /// Two keys at one time make a jump: its zero-length segment has slope 0, so the
    /// keys beside it are local extremes of their smooth segments (tangent 0). By hand,
    /// at the segments' middles: h10·h·2 + h01·1 = 0.625 and h00·3 + h01·4 + h11·h·2 = 3.375.
    #[test]
    fn a_jump_between_two_keys_at_one_time_flattens_the_segments_beside_it() {
        let c = curve(&[(0.0, 0.0), (0.5, 1.0), (0.5, 3.0), (1.0, 4.0)], true);
        assert!((c.eval(0.25) - 0.625).abs() < 1e-12, "{}", c.eval(0.25));
        assert!((c.eval(0.75) - 3.375).abs() < 1e-12, "{}", c.eval(0.75));
        assert_eq!(c.eval(0.5), 3.0, "the jump's later key holds at its time");
    }

    #[test]
    fn smooth_curves_never_overshoot_their_keys() {
        let c = curve(
            &[(0.0, 0.0), (0.1, 1.0), (0.2, 1.0), (0.5, 0.0), (1.0, 3.0)],
            true,
        );
        for i in 0..=10_000 {
            let t = f64::from(i) / 10_000.0;
            let v = c.eval(t);
            assert!((0.0..=3.0).contains(&v), "{v} at {t}");
            // Flat between the two equal keys (monotone: no bump).
            if (0.1..=0.2).contains(&t) {
                assert!((v - 1.0).abs() < 1e-12, "{v} at {t}");
            }
        }
    }

    #[test]
    fn integrals_match_closed_forms() {
        // A line: ∫₀¹ (1 + 2t) dt = 2; a constant end after the last key.
        let line = curve(&[(0.0, 1.0), (1.0, 3.0)], false);
        assert!((line.integral(0.0, 1.0) - 2.0).abs() < 1e-12);
        assert!((line.integral(1.0, 3.0) - 6.0).abs() < 1e-12);
        // A smooth curve against a fine midpoint sum.
        let c = curve(&[(0.0, 0.0), (0.3, 2.0), (0.7, 0.5), (1.0, 1.0)], true);
        let n = 200_000;
        let mid: f64 = (0..n)
            .map(|i| c.eval((f64::from(i) + 0.5) / f64::from(n)) / f64::from(n))
            .sum();
        assert!((c.integral(0.0, 1.0) - mid).abs() < 1e-9);
        let p = Param::Range { min: 1.0, max: 3.0 };
        assert!((p.integral(0.25, 0.0, 2.0) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn baked_rows_hold_exact_values_at_texels() {
        let p = Param::TwoCurves {
            a: curve(&[(0.0, 1.0), (1.0, 0.0)], false),
            b: curve(&[(0.0, 0.0), (0.5, 2.0), (1.0, 1.0)], true),
        };
        let c = Param::Constant(0.0);
        let rows = bake_rows([&p, &c, &p, &c], [false, false, true, false], [1.0; 4]);
        for i in [0usize, 17, 511, 1023] {
            let t = i as f64 / 1023.0;
            assert_eq!(rows[0][i][0], p.rows()[0].eval(t) as f32);
            assert_eq!(rows[1][i][0], p.rows()[1].eval(t) as f32);
            let w = p.rows()[1].integral(0.0, t);
            assert!((f64::from(rows[1][i][2]) - w).abs() < 1e-6, "{i}");
        }
        // Between texels the lookup is the blend of its two texels.
        let v = lookup_blend(&rows, 0.3, [0.25; 4]);
        let exact = p.eval(0.3, 0.25);
        assert!(
            (f64::from(v[0]) - exact).abs() < 1e-4,
            "{} vs {exact}",
            v[0]
        );
    }

    #[test]
    fn modes_convert_keeping_values() {
        let p = Param::Constant(2.0);
        for m in ParamMode::ALL {
            let q = p.to_mode(m);
            assert_eq!(q.mode(), m);
            assert_eq!(q.eval(0.3, 0.7), 2.0, "{m:?}");
        }
        let r = Param::Range { min: 1.0, max: 4.0 };
        assert_eq!(r.to_mode(ParamMode::Curve).bounds(), (1.0, 4.0));
        // A constant becomes two straight lines with a key at each end to drag, not one
        // flat key.
        assert_eq!(
            p.to_mode(ParamMode::TwoCurves),
            Param::TwoCurves {
                a: Curve::line(2.0, 2.0),
                b: Curve::line(2.0, 2.0),
            }
        );
    }

    /// A parameter's integral and scaling against their closed forms, for every mode: a
    /// constant's integral is v·(b − a) (0 backwards), a range's the mix of its ends'.
    #[test]
    fn params_integrate_and_scale_as_their_closed_forms() {
        let c = Param::Constant(3.0);
        assert_eq!(c.integral(0.7, 0.25, 2.0), 3.0 * 1.75);
        assert_eq!(c.integral(0.7, 2.0, 0.25), 0.0);
        let r = Param::Range { min: 1.0, max: 5.0 };
        assert!((r.integral(0.25, 0.0, 2.0) - 2.0 * 2.0).abs() < 1e-12);
        assert_eq!(c.scaled(0.5), Param::Constant(1.5));
        assert_eq!(
            r.scaled(2.0),
            Param::Range {
                min: 2.0,
                max: 10.0
            }
        );
        let line = Param::Curve {
            keys: vec![(0.0, 1.0), (1.0, 3.0)],
            smooth: false,
        };
        assert_eq!(
            line.scaled(2.0),
            Param::Curve {
                keys: vec![(0.0, 2.0), (1.0, 6.0)],
                smooth: false
            }
        );
        let two = Param::TwoCurves {
            a: Curve::line(1.0, 3.0),
            b: Curve::flat(0.5),
        };
        let want = Param::TwoCurves {
            a: Curve::line(2.0, 6.0),
            b: Curve::flat(1.0),
        };
        assert_eq!(two.scaled(2.0), want);
        // ∫₀¹ (1 + 2t)·2 dt = 4.
        assert!((line.scaled(2.0).integral(0.0, 0.0, 1.0) - 4.0).abs() < 1e-12);
    }

    /// The names the editor's parameter menus show for the modes.
    #[test]
    fn modes_have_their_menu_names() {
        let names = ParamMode::ALL.map(ParamMode::label);
        let want = [
            "constant",
            "random range",
            "curve",
            "random between two curves",
        ];
        assert_eq!(names, want);
    }
}
