//! Image error, as a designer sees it: the 8-bit sRGB channels (red, green, blue) of a
//! candidate's frames against the reference's, over every pixel of every frame — the mean
//! absolute difference, its 99th percentile, and the worst frame.

use serde::Serialize;

/// One frame's displayed colour: 8-bit sRGB, three bytes a pixel.
pub type Rgb = Vec<u8>;

/// The display image's colour channels (the alpha channel is dropped).
pub fn rgb_of(image: &image::RgbaImage) -> Rgb {
    image
        .as_raw()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// The error of a run of frames against another, in 8-bit levels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ImageError {
    /// Mean absolute difference over every channel of every pixel and frame.
    pub mean: f64,
    /// The 99th percentile of those differences (a whole level: they are integers).
    pub p99: u8,
    /// The largest difference.
    pub max: u8,
    /// The frame whose mean difference is largest (from 0).
    pub worst_frame: usize,
    /// That frame's mean difference.
    pub worst_frame_mean: f64,
}

/// Accumulates the differences of frames, one pair at a time (nothing is kept but a
/// histogram and each frame's mean).
#[derive(Clone, Debug)]
pub struct ErrorAccumulator {
    histogram: [u64; 256],
    frame_means: Vec<f64>,
}

impl Default for ErrorAccumulator {
    fn default() -> Self {
        Self {
            histogram: [0; 256],
            frame_means: Vec::new(),
        }
    }
}

impl ErrorAccumulator {
    /// Adds a frame: `a` against `b` (the same size).
    pub fn add(&mut self, a: &[u8], b: &[u8]) {
        let mut frame = [0u64; 256];
        for (x, y) in a.iter().zip(b) {
            frame[usize::from(x.abs_diff(*y))] += 1;
        }
        let (sum, n) = frame
            .iter()
            .enumerate()
            .fold((0u64, 0u64), |(s, n), (d, &c)| (s + d as u64 * c, n + c));
        self.frame_means.push(sum as f64 / n.max(1) as f64);
        for (h, c) in self.histogram.iter_mut().zip(frame) {
            *h += c;
        }
    }

    /// The frames added so far.
    pub fn frames(&self) -> usize {
        self.frame_means.len()
    }

    /// The error of the frames added.
    pub fn finish(&self) -> ImageError {
        let n: u64 = self.histogram.iter().sum();
        let sum: u64 = self
            .histogram
            .iter()
            .enumerate()
            .map(|(d, &c)| d as u64 * c)
            .sum();
        // The smallest difference at or below which 99 % of them lie.
        let target = (n as f64 * 0.99).ceil() as u64;
        let mut seen = 0u64;
        let p99 = self
            .histogram
            .iter()
            .position(|&c| {
                seen += c;
                seen >= target
            })
            .unwrap_or(0) as u8;
        let max = self.histogram.iter().rposition(|&c| c > 0).unwrap_or(0) as u8;
        let (worst_frame, worst_frame_mean) = self
            .frame_means
            .iter()
            .copied()
            .enumerate()
            .fold((0, 0.0), |w, f| if f.1 > w.1 { f } else { w });
        ImageError {
            mean: sum as f64 / n.max(1) as f64,
            p99,
            max,
            worst_frame,
            worst_frame_mean,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_of_known_differences() {
        let mut acc = ErrorAccumulator::default();
        // 100 channels: 98 equal, one off by 10, one by 200; then an equal frame.
        let a = vec![50u8; 100];
        let mut b = a.clone();
        b[3] = 60;
        b[7] = 250;
        acc.add(&a, &b);
        acc.add(&a, &a);
        let e = acc.finish();
        assert_eq!(e.mean, 210.0 / 200.0);
        assert_eq!((e.p99, e.max), (0, 200));
        assert_eq!((e.worst_frame, e.worst_frame_mean), (0, 2.1));
    }
}
