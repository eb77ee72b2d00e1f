//! Stats ▸ Cost per emitter (adapters with GPU timestamps): which layer of an effect is
//! expensive. The effect is played with every emitter off, then with each emitter alone,
//! for a few frames each; the editor's per-pass timestamps (update, sort + splat, draw +
//! composite) of each run, less those of the run with none, are that emitter's cost. The
//! disabled emitters' clocks stand still meanwhile (their particles freeze), and the
//! effect is back as it was when the measurement ends.

use crate::effect::Effect;

/// Frames each run lasts.
const FRAMES_PER_RUN: u32 = 16;

/// Frames at the start of each run whose timings are left out (the timestamps of earlier
/// frames arrive a few frames late, and the first frames build pipelines).
const SETTLE_FRAMES: u32 = 6;

/// The passes timed, as the editor's pass timer labels them.
pub const PASSES: [&str; 3] = ["update", "sort + splat", "draw + composite"];

/// One emitter's GPU time per frame, ms.
#[derive(Clone, Debug, PartialEq)]
pub struct EmitterCost {
    /// The emitter's name.
    pub name: String,
    /// Update, sort + splat, draw (ms), each less the empty effect's.
    pub ms: [f64; 3],
}

/// A measurement in progress.
#[derive(Clone, Debug, PartialEq)]
pub struct CostProbe {
    /// The effect as it was (restored at the end).
    original: Effect,
    /// The run now: `None` with every emitter off, then `Some(i)` with emitter `i` alone.
    run: Option<usize>,
    frames: u32,
    /// This run's samples of each pass (ms).
    samples: [Vec<f64>; 3],
    /// The empty effect's medians.
    baseline: [f64; 3],
    results: Vec<EmitterCost>,
}

/// What a frame of the probe asks the editor to do.
#[derive(Clone, Debug, PartialEq)]
pub enum ProbeStep {
    /// Play this effect this frame.
    Play(Effect),
    /// Done: play the original again; here are the costs.
    Done(Effect, Vec<EmitterCost>),
}

impl CostProbe {
    /// Starts measuring `effect`.
    pub fn new(effect: &Effect) -> Self {
        Self {
            original: effect.clone(),
            run: None,
            frames: 0,
            samples: Default::default(),
            baseline: [0.0; 3],
            results: Vec::new(),
        }
    }

    /// Which run it is in, for the panel: (emitter being measured or none, of how many).
    pub fn progress(&self) -> (Option<usize>, usize) {
        (self.run, self.original.emitters.len())
    }

    /// The effect with only emitter `run` on (none: all off).
    fn solo(&self) -> Effect {
        let mut e = self.original.clone();
        for (i, em) in e.emitters.iter_mut().enumerate() {
            em.enabled = Some(i) == self.run;
        }
        e
    }

    /// One frame: `latest` is the pass timer's latest timings. Returns what to play.
    pub fn frame(&mut self, latest: &[(&'static str, f64)]) -> ProbeStep {
        self.frames += 1;
        if self.frames > SETTLE_FRAMES {
            for (samples, pass) in self.samples.iter_mut().zip(PASSES) {
                if let Some((_, ms)) = latest.iter().find(|(l, _)| *l == pass) {
                    samples.push(*ms);
                }
            }
        }
        if self.frames < FRAMES_PER_RUN {
            return ProbeStep::Play(self.solo());
        }
        let medians = self.samples.each_ref().map(|s| median(s));
        match self.run {
            None => self.baseline = medians,
            Some(i) => self.results.push(EmitterCost {
                name: self.original.emitters[i].name.clone(),
                ms: std::array::from_fn(|k| (medians[k] - self.baseline[k]).max(0.0)),
            }),
        }
        self.samples = Default::default();
        self.frames = 0;
        let next = self.run.map_or(0, |i| i + 1);
        if next >= self.original.emitters.len() {
            return ProbeStep::Done(self.original.clone(), std::mem::take(&mut self.results));
        }
        self.run = Some(next);
        ProbeStep::Play(self.solo())
    }
}

/// The median of a run's samples (0 when no timing arrived).
fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    crate::gpu::timer::median(&mut v.to_vec())
}

/// The Stats section's block: a button that starts a measurement, its progress, and the
/// last results (`probe` and `results` live in the editor's state).
pub fn emitter_cost_ui(
    ui: &mut egui::Ui,
    probe: &mut Option<CostProbe>,
    results: &[EmitterCost],
    effect: &Effect,
    has_timestamps: bool,
) {
    ui.horizontal(|ui| {
        let button = ui
            .add_enabled(
                has_timestamps && probe.is_none(),
                egui::Button::new("Measure cost per emitter"),
            )
            .on_hover_text(
                "Plays the effect with every emitter off, then each emitter alone, a few \
                 frames each, and reports each one's GPU time (timestamps) less the empty \
                 effect's. Needs an adapter with trustworthy GPU timestamps.",
            );
        if button.clicked() {
            *probe = Some(CostProbe::new(effect));
        }
        if let Some(p) = probe {
            let (run, n) = p.progress();
            ui.label(match run {
                None => "measuring the empty effect…".to_owned(),
                Some(i) => format!("measuring emitter {} of {n}…", i + 1),
            });
        }
    });
    if results.is_empty() {
        return;
    }
    egui::Grid::new("emitter_costs")
        .striped(true)
        .show(ui, |ui| {
            ui.label("emitter");
            for pass in PASSES {
                ui.label(format!("{pass} ms"));
            }
            ui.end_row();
            for r in results {
                ui.label(&r.name);
                for ms in r.ms {
                    ui.label(format!("{ms:.3}"));
                }
                ui.end_row();
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic timings: the empty effect costs (0.1, 0.2, 1.0) ms, and each emitter adds
    /// its own; the probe plays none, then each alone, and reports each one's share.
    #[test]
    fn each_emitter_alone_less_the_empty_effect() {
        let effect = Effect::default_campfire();
        let names: Vec<String> = effect.emitters.iter().map(|e| e.name.clone()).collect();
        let own = |i: usize| [0.5 * (i + 1) as f64, 0.25, 2.0 * (i + 1) as f64];
        let mut probe = CostProbe::new(&effect);
        let mut playing = probe.solo();
        let results = loop {
            let on: Vec<usize> = (0..playing.emitters.len())
                .filter(|&i| playing.emitters[i].enabled)
                .collect();
            assert!(on.len() <= 1, "one emitter at a time: {on:?}");
            let mut ms = [0.1, 0.2, 1.0];
            if let Some(&i) = on.first() {
                for (m, o) in ms.iter_mut().zip(own(i)) {
                    *m += o;
                }
            }
            let latest: Vec<(&'static str, f64)> = PASSES.iter().copied().zip(ms).collect();
            match probe.frame(&latest) {
                ProbeStep::Play(e) => playing = e,
                ProbeStep::Done(original, results) => {
                    assert_eq!(original, effect, "the effect comes back as it was");
                    break results;
                }
            }
        };
        assert_eq!(results.len(), names.len());
        for (i, r) in results.iter().enumerate() {
            assert_eq!(r.name, names[i]);
            for (got, want) in r.ms.iter().zip(own(i)) {
                assert!((got - want).abs() < 1e-9, "{}: {:?}", r.name, r.ms);
            }
        }
    }
}
