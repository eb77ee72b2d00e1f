//! Caps counted per second of simulated time — an emitter's continuous spawns, an event's
//! children — so that the step is a pure accuracy setting: what a cap lets through does
//! not depend on how time is cut into steps.

/// A cap counted per second (an emitter's spawns, an event's children) lets through
/// bursts of up to this much of a second's worth at once.
pub const CAP_BURST_SECS: f32 = 0.1;

/// The burst a cap of `per_sec` lets through at once: [`CAP_BURST_SECS`] of its rate, and
/// at least one.
pub fn cap_burst(per_sec: f32) -> f32 {
    (per_sec * CAP_BURST_SECS).max(1.0)
}

/// A cap of so many per second of simulated time, as a bucket of tokens: it holds at most
/// `cap_burst` tokens (full at the start), each step adds `per_sec · dt` before the step
/// takes what it asks (up to the whole tokens there are), and what is left is kept. What it
/// lets through does not depend on the step: a cap that binds throughout allows
/// `⌊burst + per_sec · T⌋` over any span T at any step size, and one that never binds drops
/// nothing, however many events fall in one short step. `shaders/events.wgsl`'s
/// `take_tokens` does the same arithmetic on the GPU (f32, the same order).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RateCap {
    /// Tokens short of a full bucket (0: full).
    pub deficit: f32,
}

impl RateCap {
    /// Takes up to `asked` from the bucket of a cap of `per_sec` over a step of `dt_secs`;
    /// returns how many are allowed.
    pub fn take(&mut self, asked: u32, per_sec: f32, dt_secs: f32) -> u32 {
        let burst = cap_burst(per_sec);
        let available = (burst - self.deficit) + per_sec * dt_secs;
        let n = asked.min(available.max(0.0).floor().min(u32::MAX as f32) as u32);
        self.deficit = burst - (available - n as f32).min(burst);
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cap_that_binds_allows_the_same_at_any_step() {
        // 2400/s asked 12000/s for 1 s: the full bucket (240) and the rate, at every step.
        for steps in [30u32, 60, 120, 240, 3840] {
            let dt = 1.0 / steps as f32;
            let mut cap = RateCap::default();
            let asked = (12_000.0 * dt).ceil() as u32;
            let total: u32 = (0..steps).map(|_| cap.take(asked, 2400.0, dt)).sum();
            assert_eq!(total, 240 + 2400, "{steps} steps");
        }
    }

    #[test]
    fn a_cap_that_does_not_bind_drops_nothing_however_fine_the_step() {
        // 7680/s (the campfire's smoke), 81 asked a second, now and then two in one step of
        // 1/7680 s: a cap counted per step (1 a step) would drop the second.
        let dt = 1.0 / 7680.0;
        let mut cap = RateCap::default();
        let (mut asked, mut allowed) = (0, 0);
        for k in 0..7680u32 {
            let n = if k % 95 == 0 { 2 } else { 0 };
            asked += n;
            allowed += cap.take(n, 7680.0, dt);
        }
        assert_eq!(allowed, asked);
        assert_eq!(cap_burst(7680.0), 768.0);
        assert_eq!(cap_burst(3.0), 1.0, "at least one");
    }
}
