//! The Pareto frontier of error against cost, and the choice within a budget.

/// A budget the tuner chooses within.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Budget {
    /// The most image error allowed: the mean over every 8-bit channel, pixel and frame.
    /// The cheapest candidate within it is chosen.
    ErrorMean(f64),
    /// The most frame time allowed on this adapter, ms. The most accurate candidate
    /// within it is chosen.
    FrameMs(f64),
}

impl std::fmt::Display for Budget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Budget::ErrorMean(e) => write!(f, "a mean error of {e}/255"),
            Budget::FrameMs(ms) => write!(f, "a frame of {ms} ms"),
        }
    }
}

/// The indices of the points no other point dominates (as accurate or more and as cheap
/// or cheaper, one of them strictly), cheapest first. Of equal points the first is kept.
pub fn pareto(points: &[(f64, f64)]) -> Vec<usize> {
    let dominates = |a: (f64, f64), b: (f64, f64)| a.0 <= b.0 && a.1 <= b.1 && a != b;
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            !points
                .iter()
                .enumerate()
                .any(|(j, &p)| dominates(p, points[i]) || (p == points[i] && j < i))
        })
        .collect();
    front.sort_by(|&a, &b| points[a].1.total_cmp(&points[b].1));
    front
}

/// The candidate `budget` chooses among `points` (error, cost): the cheapest within an
/// error budget, or the most accurate within a cost budget; `None` when none is within it.
pub fn choose(points: &[(f64, f64)], budget: Budget) -> Option<usize> {
    let within = (0..points.len()).filter(|&i| match budget {
        Budget::ErrorMean(e) => points[i].0 <= e,
        Budget::FrameMs(ms) => points[i].1 <= ms,
    });
    match budget {
        Budget::ErrorMean(_) => within.min_by(|&a, &b| {
            points[a]
                .1
                .total_cmp(&points[b].1)
                .then(points[a].0.total_cmp(&points[b].0))
        }),
        Budget::FrameMs(_) => within.min_by(|&a, &b| {
            points[a]
                .0
                .total_cmp(&points[b].0)
                .then(points[a].1.total_cmp(&points[b].1))
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frontier_keeps_only_undominated_points() {
        // (error, cost)
        let pts = [
            (1.0, 1.0),
            (0.5, 2.0),
            (0.6, 3.0),
            (0.1, 5.0),
            (1.0, 1.0),
            (2.0, 0.5),
        ];
        let front = pareto(&pts);
        assert_eq!(front, vec![5, 0, 1, 3]);
        for &i in &front {
            for (j, p) in pts.iter().enumerate() {
                let dominated = p.0 <= pts[i].0 && p.1 <= pts[i].1 && *p != pts[i];
                assert!(!dominated, "{i} dominated by {j}");
            }
        }
        assert_eq!(choose(&pts, Budget::ErrorMean(0.55)), Some(1));
        assert_eq!(choose(&pts, Budget::FrameMs(2.5)), Some(1));
        assert_eq!(choose(&pts, Budget::ErrorMean(0.01)), None);
    }
}
