//! The sweep: the effect as authored and every candidate, each played over the span and
//! compared frame by frame with the reference at a sixteenth of its step (played once per
//! step the candidates use, before the first candidate that needs it), then timed — one
//! frame of work per [`Sweep::step`], so that a window can run it a slice at a time and
//! stay interactive.

use std::collections::VecDeque;
use std::path::PathBuf;

use serde::Serialize;

use super::TuneError;
use super::candidate::{self, Candidate, Change};
use super::image_error::{ErrorAccumulator, ImageError, Rgb, rgb_of};
use crate::effect::Effect;
use crate::gpu::GpuContext;
use crate::gpu::timer::{GpuTimer, median};
use crate::headless::Headless;
use crate::render::Camera;
use crate::shaders::ShaderLibrary;

/// What a sweep measures.
#[derive(Clone, Debug, Serialize)]
pub struct SweepOptions {
    /// The span played from the start, seconds.
    pub span_secs: f64,
    /// The image size, pixels.
    pub size: (u32, u32),
    /// Frames per simulated second (each one rendered and compared).
    pub fps: f64,
    /// Frames timed after the span (the median is the cost).
    pub cost_frames: usize,
    /// Also play the finest reference at half its step, to show it has converged.
    pub check_reference: bool,
    /// The folder the preset's sprite paths are relative to.
    pub asset_dir: Option<PathBuf>,
    /// The fixed steps tried, in steps per second (default [`super::RATES`]: 30, 60, 120
    /// and 240). Each one's reference runs at a sixteenth of its step: the finest sets
    /// most of the sweep's time.
    pub rates: Vec<u32>,
}

impl SweepOptions {
    /// Options for `effect`: its natural span (its last burst plus its longest lifetime,
    /// 1 to 8 s), 960×540 at 30 frames a second, 10 timed frames, the reference checked.
    pub fn for_effect(effect: &Effect) -> Self {
        let natural = effect.last_burst_secs() + effect.longest_lifetime_secs();
        Self {
            span_secs: natural.clamp(1.0, 8.0),
            size: (960, 540),
            fps: 30.0,
            cost_frames: 10,
            check_reference: true,
            asset_dir: None,
            rates: super::RATES.to_vec(),
        }
    }

    /// The frames of the span.
    pub fn frames(&self) -> usize {
        (self.span_secs * self.fps).ceil().max(1.0) as usize
    }

    /// Refuses impossible options, naming the option.
    pub fn check(&self) -> Result<(), TuneError> {
        let bad = |option: &str, message: String| {
            Err(TuneError::Option {
                option: option.into(),
                message,
            })
        };
        if !(self.span_secs.is_finite() && self.span_secs > 0.0 && self.span_secs <= 600.0) {
            return bad(
                "--span",
                format!("{} s must be in (0, 600]", self.span_secs),
            );
        }
        if self.size.0 == 0 || self.size.1 == 0 || self.size.0 > 8192 || self.size.1 > 8192 {
            let (w, h) = self.size;
            return bad("--size", format!("{w}x{h} must be 1x1 to 8192x8192"));
        }
        if !(self.fps.is_finite() && self.fps >= 1.0 && self.fps <= 1000.0) {
            return bad("--fps", format!("{} must be in 1..=1000", self.fps));
        }
        if self.rates.is_empty() || self.rates.iter().any(|r| !(1..=2000).contains(r)) {
            return bad(
                "--rates",
                format!("{:?} must be steps per second, each 1..=2000", self.rates),
            );
        }
        Ok(())
    }
}

/// One candidate measured.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    /// What it changes.
    pub candidate: Candidate,
    /// Its name in the tables.
    pub label: String,
    /// Its frames against the reference's.
    pub error: ImageError,
    /// Its frames against the effect as authored (what switching its changes on shows).
    pub vs_authored: ImageError,
    /// The median update time of a frame, ms.
    pub update_ms: f64,
    /// The median frame time (update, sort, draw, composite), ms.
    pub frame_ms: f64,
    /// 1: one axis from the effect as authored; 2: a combination along the frontier.
    pub round: u8,
}

/// What a run is for.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    /// The reference at this step.
    Reference(f32),
    /// The reference at half this step, compared with the reference at it.
    ReferenceCheck(f32),
    /// A candidate of this round, compared with the reference at this step.
    Candidate(u8, f32),
}

/// A run in progress: its player, its frames so far, its timings.
struct Running {
    role: Role,
    candidate: Candidate,
    run: Headless,
    camera: Camera,
    frame: usize,
    error: ErrorAccumulator,
    vs_authored: ErrorAccumulator,
    times: Vec<[f64; 4]>,
}

/// Frames run untimed before the timed ones (the GPU's clocks, first use of pipelines).
const UNTIMED_COST_FRAMES: usize = 3;

/// The sweep over one effect (see the module's documentation).
pub struct Sweep {
    ctx: GpuContext,
    effect: Effect,
    opts: SweepOptions,
    timer: GpuTimer,
    /// The references' frames, by step (f32 bits).
    references: Vec<(u32, Vec<Rgb>)>,
    authored: Vec<Rgb>,
    check: ErrorAccumulator,
    queue: VecDeque<(Role, Candidate)>,
    running: Option<Running>,
    /// The player of the last run, kept for the next one: an edit to the next candidate's
    /// effect and a restart build only the pipelines it lacks (a new player per candidate
    /// compiled every pipeline again: most of the sweep's time).
    spare: Option<Headless>,
    /// Every candidate measured so far, the effect as authored first.
    pub results: Vec<Measured>,
    /// Candidates that could not run, and why.
    pub skipped: Vec<(String, String)>,
    combined: bool,
    units_done: usize,
}

impl Sweep {
    /// A sweep of `effect` (valid) with `opts` (checked).
    pub fn new(ctx: &GpuContext, effect: &Effect, opts: SweepOptions) -> Result<Self, TuneError> {
        opts.check()?;
        effect.validate().map_err(crate::PlayerError::Invalid)?;
        let mut queue = VecDeque::new();
        let mut finest = f32::INFINITY;
        for c in candidate::axes(effect, &opts.rates) {
            let applied = c.apply(effect);
            if candidate::worth_measuring(&applied, effect, c.changes.is_empty()) {
                let step = candidate::reference_step(&applied);
                finest = finest.min(step);
                queue.push_back((Role::Candidate(1, step), c));
            }
        }
        if opts.check_reference {
            queue.push_front((Role::ReferenceCheck(finest), Candidate::authored()));
        }
        Ok(Self {
            ctx: ctx.clone(),
            effect: effect.clone(),
            timer: GpuTimer::new(ctx),
            opts,
            references: Vec::new(),
            authored: Vec::new(),
            check: ErrorAccumulator::default(),
            queue,
            running: None,
            spare: None,
            results: Vec::new(),
            skipped: Vec::new(),
            combined: false,
            units_done: 0,
        })
    }

    /// The effect swept.
    pub fn effect(&self) -> &Effect {
        &self.effect
    }

    /// The options.
    pub fn options(&self) -> &SweepOptions {
        &self.opts
    }

    /// The finest reference at half its step against it (`None`: not checked, or not
    /// yet).
    pub fn reference_check(&self) -> Option<ImageError> {
        (self.opts.check_reference && self.check.frames() == self.opts.frames())
            .then(|| self.check.finish())
    }

    /// Work done and (estimated) in all, in frames.
    pub fn progress(&self) -> (usize, usize) {
        let per_candidate = self.opts.frames() + self.opts.cost_frames + UNTIMED_COST_FRAMES;
        let pending = self.queue.len() + usize::from(self.running.is_some());
        // The combinations are not known until the first round ends: about four.
        let later = if self.combined { 0 } else { 4 };
        let left = (pending + later) * per_candidate
            - self
                .running
                .as_ref()
                .map_or(0, |r| r.frame.min(per_candidate));
        (self.units_done, self.units_done + left)
    }

    /// Whether every run is done.
    pub fn is_done(&self) -> bool {
        self.running.is_none() && self.queue.is_empty() && self.combined
    }

    /// Does one frame of work (starting the next run when needed). Returns whether the
    /// sweep is done. A candidate whose player cannot be made is skipped and listed.
    pub fn step(&mut self) -> Result<bool, TuneError> {
        if self.running.is_none() && !self.start_next()? {
            return Ok(true);
        }
        let Some(mut r) = self.running.take() else {
            return Ok(self.is_done());
        };
        self.units_done += 1;
        let frames = self.opts.frames();
        if r.frame < frames {
            self.play_frame(&mut r)?;
        } else {
            let t = r
                .run
                .timed_frame(&self.timer, 1.0 / self.opts.fps, &r.camera);
            if r.frame >= frames + UNTIMED_COST_FRAMES {
                r.times.push(t);
            }
        }
        r.frame += 1;
        let timed = matches!(r.role, Role::Candidate(..));
        let end = frames
            + if timed {
                self.opts.cost_frames + UNTIMED_COST_FRAMES
            } else {
                0
            };
        if r.frame >= end {
            self.finish(r);
        } else {
            self.running = Some(r);
        }
        Ok(self.is_done())
    }

    /// The frames of the reference at `step`, once played.
    fn reference(&self, step: f32) -> Option<&Vec<Rgb>> {
        frames_at(&self.references, step)
    }

    /// Starts the next run of the queue (the combinations once the first round is done; a
    /// reference before the first run that needs it); false when nothing is left.
    fn start_next(&mut self) -> Result<bool, TuneError> {
        loop {
            let Some((role, candidate)) = self.queue.pop_front() else {
                if self.combined {
                    return Ok(false);
                }
                self.combined = true;
                for c in self.combinations() {
                    let step = candidate::reference_step(&c.apply(&self.effect));
                    self.queue.push_back((Role::Candidate(2, step), c));
                }
                continue;
            };
            let needs = match role {
                Role::Candidate(_, step) | Role::ReferenceCheck(step) => Some(step),
                Role::Reference(_) => None,
            };
            if let Some(step) = needs.filter(|&s| self.reference(s).is_none()) {
                self.queue.push_front((role, candidate));
                self.queue
                    .push_front((Role::Reference(step), Candidate::authored()));
                continue;
            }
            let frame_secs = 1.0 / self.opts.fps;
            let effect = match role {
                Role::Reference(step) => candidate::reference(&self.effect, frame_secs, step),
                Role::ReferenceCheck(step) => {
                    candidate::reference(&self.effect, frame_secs, step / 2.0)
                }
                Role::Candidate(..) => runnable(candidate.apply(&self.effect), frame_secs),
            };
            match self.start(role, candidate.clone(), effect) {
                Ok(r) => {
                    self.running = Some(r);
                    return Ok(true);
                }
                // A reference must run; a candidate the device cannot play is skipped.
                Err(e) if matches!(role, Role::Candidate(..)) => {
                    let label = candidate.label(&self.effect);
                    self.skipped.push((label, e.to_string()));
                }
                Err(e) => return Err(e),
            }
        }
    }

    fn start(
        &mut self,
        role: Role,
        candidate: Candidate,
        effect: Effect,
    ) -> Result<Running, TuneError> {
        let run = match self.spare.take() {
            // The same frames as a new player's: the edit keeps nothing of the last run
            // once restarted (tests/tune.rs measures a tuned preset again on a new one).
            Some(mut run) => {
                run.player.set_effect(&effect)?;
                run.player.restart();
                run
            }
            None => {
                let settings = crate::PlayerSettings {
                    asset_dir: self.opts.asset_dir.clone(),
                    ..crate::composite::Composite::player_settings()
                };
                let lib = ShaderLibrary::discover(None);
                Headless::with_settings(&self.ctx, effect, lib, settings)?
            }
        };
        let camera = run.camera.view(self.opts.size);
        Ok(Running {
            role,
            candidate,
            run,
            camera,
            frame: 0,
            error: ErrorAccumulator::default(),
            vs_authored: ErrorAccumulator::default(),
            times: Vec::new(),
        })
    }

    /// Plays and renders one frame of `r`, keeping or comparing it as its role says.
    fn play_frame(&mut self, r: &mut Running) -> Result<(), TuneError> {
        r.run.advance(1.0 / self.opts.fps);
        let image = rgb_of(&r.run.render(self.opts.size)?);
        let k = r.frame;
        match r.role {
            Role::Reference(step) => {
                match self.references.iter_mut().find(|x| x.0 == step.to_bits()) {
                    Some(frames) => frames.1.push(image),
                    None => self.references.push((step.to_bits(), vec![image])),
                }
            }
            Role::ReferenceCheck(step) => {
                if let Some(reference) = frames_at(&self.references, step).and_then(|f| f.get(k)) {
                    self.check.add(&image, reference);
                }
            }
            Role::Candidate(_, step) => {
                if let Some(reference) = self.reference(step).and_then(|f| f.get(k)) {
                    r.error.add(&image, reference);
                }
                if r.candidate.changes.is_empty() {
                    self.authored.push(image);
                } else if let Some(a) = self.authored.get(k) {
                    r.vs_authored.add(&image, a);
                }
            }
        }
        Ok(())
    }

    /// Records a finished run's result.
    fn finish(&mut self, r: Running) {
        let Role::Candidate(round, _) = r.role else {
            return;
        };
        let mut parts: [Vec<f64>; 2] = Default::default();
        for t in &r.times {
            parts[0].push(t[0]);
            parts[1].push(t.iter().sum());
        }
        let [update_ms, frame_ms] = parts.map(|mut p| median(&mut p));
        self.results.push(Measured {
            label: r.candidate.label(&self.effect),
            candidate: r.candidate,
            error: r.error.finish(),
            vs_authored: r.vs_authored.finish(),
            update_ms,
            frame_ms,
            round,
        });
    }

    /// The second round: the first round's changes that save time, most accurate first,
    /// combined one after another (one change per kind: time, state, draw path, or an
    /// emitter's module), each combination a candidate.
    fn combinations(&self) -> Vec<Candidate> {
        let Some(authored) = self.results.iter().find(|m| m.candidate.changes.is_empty()) else {
            return Vec::new();
        };
        let mut cheaper: Vec<&Measured> = self
            .results
            .iter()
            .filter(|m| m.round == 1 && !m.candidate.changes.is_empty())
            .filter(|m| m.frame_ms < authored.frame_ms)
            .collect();
        cheaper.sort_by(|a, b| a.error.mean.total_cmp(&b.error.mean));
        let mut combined: Vec<Change> = Vec::new();
        let mut out = Vec::new();
        for m in cheaper {
            if m.candidate.changes.iter().any(|c| conflicts(c, &combined)) {
                continue;
            }
            combined.extend(m.candidate.changes.iter().cloned());
            if combined.len() > m.candidate.changes.len() {
                let c = Candidate {
                    changes: combined.clone(),
                };
                if candidate::worth_measuring(&c.apply(&self.effect), &self.effect, false) {
                    out.push(c);
                }
            }
            if out.len() == 6 {
                break;
            }
        }
        out
    }
}

/// The frames of the reference at `step` among `references`.
fn frames_at(references: &[(u32, Vec<Rgb>)], step: f32) -> Option<&Vec<Rgb>> {
    references
        .iter()
        .find(|r| r.0 == step.to_bits())
        .map(|r| &r.1)
}

/// Whether `c` changes what one of `taken` already changes.
fn conflicts(c: &Change, taken: &[Change]) -> bool {
    use std::mem::discriminant;
    taken.iter().any(|t| match (c, t) {
        (Change::ModuleOff { emitter: a, .. }, Change::ModuleOff { emitter: b, .. }) => {
            // Two modules of one emitter combine, but not the turbulence twice.
            let turbulence = |c: &Change| {
                matches!(
                    c,
                    Change::ModuleOff {
                        module: super::Module::Turbulence | super::Module::Octaves(_),
                        ..
                    }
                )
            };
            a == b && (c == t || (turbulence(c) && turbulence(t)))
        }
        _ => discriminant(c) == discriminant(t),
    })
}

/// A candidate's effect made playable at frames of `frame_secs`: enough substeps for
/// its step.
fn runnable(mut effect: Effect, frame_secs: f64) -> Effect {
    let needed = candidate::steps_per_frame(frame_secs, effect.time.step_secs);
    effect.time.max_substeps = effect.time.max_substeps.max(needed);
    effect
}

/// The error of one run of `effect` against the reference of `authored` at a sixteenth of
/// `effect`'s step, over the span of `opts`, played independently of any sweep (what a
/// tuned preset is checked with).
pub fn measure_against_reference(
    ctx: &GpuContext,
    authored: &Effect,
    effect: &Effect,
    opts: &SweepOptions,
) -> Result<ImageError, TuneError> {
    let step = candidate::reference_step(effect);
    let reference = candidate::reference(authored, 1.0 / opts.fps, step);
    measure_pair(ctx, &reference, effect, opts)
}

/// The error of `effect`'s frames against `reference`'s over the span of `opts` (the two
/// played side by side, each at steps it can keep up with).
pub fn measure_pair(
    ctx: &GpuContext,
    reference: &Effect,
    effect: &Effect,
    opts: &SweepOptions,
) -> Result<ImageError, TuneError> {
    let frame_secs = 1.0 / opts.fps;
    let play = |e: &Effect| {
        let settings = crate::PlayerSettings {
            asset_dir: opts.asset_dir.clone(),
            ..crate::composite::Composite::player_settings()
        };
        let e = runnable(e.clone(), frame_secs);
        Headless::with_settings(ctx, e, ShaderLibrary::discover(None), settings)
    };
    let (mut a, mut b) = (play(reference)?, play(effect)?);
    let mut acc = ErrorAccumulator::default();
    for _ in 0..opts.frames() {
        a.advance(frame_secs);
        b.advance(frame_secs);
        acc.add(
            &rgb_of(&b.render(opts.size)?),
            &rgb_of(&a.render(opts.size)?),
        );
    }
    Ok(acc.finish())
}
