//! Candidates: the effect as authored with some of its settings changed — integrator,
//! step, state layout, an optional module switched off, the draw path — and the reference
//! every candidate is compared with.

use serde::Serialize;

use crate::effect::{DrawPath, Effect, Emitter, Integrator, TimeMode};

/// The fixed steps a sweep tries unless asked for others, in steps per second.
pub const RATES: [u32; 4] = [30, 60, 120, 240];

/// A reference's step is this fraction of the step of the candidate it is compared with.
pub const REFERENCE_DIVISOR: f32 = 16.0;

/// How simulated time advances in a candidate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum StepChoice {
    /// A fixed step of this many seconds.
    Fixed(f32),
    /// One step per frame (the frame's delta).
    FrameDelta,
}

/// How the emitters store their particles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum StateChoice {
    /// 32 bytes per particle, f32.
    Full,
    /// 20 bytes (`packed_state`) where an emitter allows it.
    Packed,
    /// 10 bytes (`tiny_state`) where an emitter allows it.
    Tiny,
}

/// An optional module of one emitter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Module {
    /// Curl-noise turbulence, all of it.
    Turbulence,
    /// Turbulence with only this many octaves (the ones above it off).
    Octaves(u32),
    /// The vortex.
    Vortex,
    /// The attractor.
    Attractor,
    /// The flame pull.
    FlamePull,
    /// Wind gusts.
    Gusts,
    /// Quadratic drag.
    QuadraticDrag,
    /// Ground and sphere colliders.
    Collisions,
    /// The emitter's events (and the children only they feed).
    Events,
    /// The trail (or ribbon).
    Trail,
}

impl Module {
    /// What the tables call it.
    pub fn label(self) -> String {
        match self {
            Module::Turbulence => "turbulence".into(),
            Module::Octaves(n) => format!("turbulence octaves above {n}"),
            Module::Vortex => "vortex".into(),
            Module::Attractor => "attractor".into(),
            Module::FlamePull => "flame pull".into(),
            Module::Gusts => "gusts".into(),
            Module::QuadraticDrag => "quadratic drag".into(),
            Module::Collisions => "collisions".into(),
            Module::Events => "events".into(),
            Module::Trail => "trail".into(),
        }
    }

    /// The modules `e` uses, each of which a candidate can switch off (an octave count
    /// for every octave above the first).
    pub fn in_emitter(e: &Emitter) -> Vec<Module> {
        let f = &e.forces;
        let mut v = Vec::new();
        if let Some(t) = &f.turbulence {
            v.push(Module::Turbulence);
            v.extend((1..t.octaves).rev().map(Module::Octaves));
        }
        let present = [
            (f.vortex.is_some(), Module::Vortex),
            (f.attractor.is_some(), Module::Attractor),
            (f.flame_pull.is_some(), Module::FlamePull),
            (f.gusts.is_some(), Module::Gusts),
            (f.quadratic_drag_per_m > 0.0, Module::QuadraticDrag),
            (e.collisions.any(), Module::Collisions),
            (!e.events.is_empty(), Module::Events),
            (e.look.trail.is_some(), Module::Trail),
        ];
        v.extend(present.iter().filter(|p| p.0).map(|p| p.1));
        v
    }
}

/// One change from the effect as authored.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Change {
    /// Every emitter integrates with this method.
    Integrator(Integrator),
    /// The effect's time step.
    Step(StepChoice),
    /// Every emitter that allows it stores this layout.
    State(StateChoice),
    /// One emitter's module off.
    ModuleOff {
        /// The emitter's index.
        emitter: usize,
        /// The module.
        module: Module,
    },
    /// Every emitter draws through this path.
    DrawPath(DrawPath),
}

/// A candidate: the effect as authored with these changes, in order.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Candidate {
    /// The changes (none: the effect as authored).
    pub changes: Vec<Change>,
}

impl Candidate {
    /// The effect as authored.
    pub fn authored() -> Self {
        Self::default()
    }

    /// A candidate of one change.
    pub fn single(change: Change) -> Self {
        Self {
            changes: vec![change],
        }
    }

    /// What the tables call it, with emitter names from `effect`.
    pub fn label(&self, effect: &Effect) -> String {
        if self.changes.is_empty() {
            return "as authored".into();
        }
        self.changes
            .iter()
            .map(|c| change_label(c, effect))
            .collect::<Vec<_>>()
            .join(" + ")
    }

    /// The effect with the changes applied (not validated: a change an emitter cannot take,
    /// e.g. a packed state with events, is skipped for that emitter).
    pub fn apply(&self, effect: &Effect) -> Effect {
        let mut e = effect.clone();
        for c in &self.changes {
            apply_change(&mut e, c);
        }
        e
    }
}

fn change_label(c: &Change, effect: &Effect) -> String {
    match c {
        Change::Integrator(i) => i.label().to_owned(),
        Change::Step(StepChoice::Fixed(s)) => format!("step 1/{:.0} s", 1.0 / s),
        Change::Step(StepChoice::FrameDelta) => "frame delta".into(),
        Change::State(s) => format!("{s:?} state").to_lowercase(),
        Change::ModuleOff { emitter, module } => {
            let name = effect.emitters.get(*emitter).map_or("?", |e| &e.name);
            format!("{name}: {} off", module.label())
        }
        Change::DrawPath(p) => format!("{p:?} draw").to_lowercase(),
    }
}

fn apply_change(effect: &mut Effect, c: &Change) {
    match *c {
        Change::Integrator(i) => effect.emitters.iter_mut().for_each(|e| e.integrator = i),
        Change::Step(StepChoice::Fixed(s)) => {
            effect.time.mode = TimeMode::FixedStep;
            effect.time.step_secs = s;
        }
        Change::Step(StepChoice::FrameDelta) => effect.time.mode = TimeMode::FrameDelta,
        Change::State(s) => set_state(effect, s),
        Change::ModuleOff { emitter, module } => module_off(effect, emitter, module),
        Change::DrawPath(p) => effect
            .emitters
            .iter_mut()
            .for_each(|e| e.look.draw_path = p),
    }
}

/// Sets the state layout of every emitter that can store it (not stateless, no events,
/// not fed by events, no trail).
fn set_state(effect: &mut Effect, s: StateChoice) {
    let fed: Vec<bool> = (0..effect.emitters.len())
        .map(|i| effect.event_fed(i))
        .collect();
    for (e, fed) in effect.emitters.iter_mut().zip(fed) {
        let compact = !fed && !e.stateless && e.events.is_empty() && e.look.trail.is_none();
        e.packed_state = compact && s == StateChoice::Packed;
        e.tiny_state = compact && s == StateChoice::Tiny;
    }
}

fn module_off(effect: &mut Effect, i: usize, module: Module) {
    let was_fed: Vec<bool> = (0..effect.emitters.len())
        .map(|k| effect.event_fed(k))
        .collect();
    let Some(e) = effect.emitters.get_mut(i) else {
        return;
    };
    let f = &mut e.forces;
    match module {
        Module::Turbulence => f.turbulence = None,
        Module::Octaves(n) => {
            if let Some(t) = &mut f.turbulence {
                t.octaves = t.octaves.min(n.max(1));
            }
        }
        Module::Vortex => f.vortex = None,
        Module::Attractor => f.attractor = None,
        Module::FlamePull => f.flame_pull = None,
        Module::Gusts => f.gusts = None,
        Module::QuadraticDrag => f.quadratic_drag_per_m = 0.0,
        Module::Collisions => {
            e.collisions.ground = None;
            e.collisions.spheres.clear();
        }
        Module::Events => e.events.clear(),
        Module::Trail => e.look.trail = None,
    }
    // A child no event feeds any more would spawn at its own rate: it goes dark instead.
    for (k, fed) in was_fed.into_iter().enumerate() {
        if fed && !effect.event_fed(k) {
            effect.emitters[k].enabled = false;
        }
    }
}

/// The step of the reference a candidate is compared with: a sixteenth of its own step
/// (of 1/60 s in frame-delta mode).
pub fn reference_step(candidate: &Effect) -> f32 {
    let own = match candidate.time.mode {
        TimeMode::FixedStep => candidate.time.step_secs,
        TimeMode::FrameDelta => 1.0 / 60.0,
    };
    own / REFERENCE_DIVISOR
}

/// A reference: the effect as authored and its seed, RK4 at a fixed step of `step_secs`
/// ([`reference_step`]), the full f32 state (no stateless shortcut), every module as
/// authored, every emitter drawn as billboards.
pub fn reference(effect: &Effect, frame_secs: f64, step_secs: f32) -> Effect {
    let mut r = effect.clone();
    r.time.mode = TimeMode::FixedStep;
    r.time.step_secs = step_secs;
    r.time.max_substeps = steps_per_frame(frame_secs, r.time.step_secs).max(1);
    for e in &mut r.emitters {
        e.integrator = Integrator::Rk4;
        e.packed_state = false;
        e.tiny_state = false;
        e.stateless = false;
        e.look.draw_path = DrawPath::Billboard;
    }
    r
}

/// The steps a frame of `frame_secs` needs at `step_secs`, and one to spare.
pub fn steps_per_frame(frame_secs: f64, step_secs: f32) -> u32 {
    ((frame_secs / f64::from(step_secs)).ceil() as u32 + 1).min(1000)
}

/// The first sweep: every integrator at every fixed step of `rates` (steps per second;
/// and frame delta where the effect uses it), the other state layouts, each module of
/// each emitter off on its own, and each draw path — one axis at a time from the effect
/// as authored.
pub fn axes(effect: &Effect, rates: &[u32]) -> Vec<Candidate> {
    let mut v = vec![Candidate::authored()];
    let fixed = |&r: &u32| StepChoice::Fixed(1.0 / r as f32);
    let mut steps: Vec<StepChoice> = rates.iter().map(fixed).collect();
    if effect.time.mode == TimeMode::FrameDelta {
        steps.push(StepChoice::FrameDelta);
    }
    for &i in &Integrator::ALL {
        for &s in &steps {
            v.push(Candidate {
                changes: vec![Change::Integrator(i), Change::Step(s)],
            });
        }
    }
    for s in [StateChoice::Full, StateChoice::Packed, StateChoice::Tiny] {
        v.push(Candidate::single(Change::State(s)));
    }
    for (i, e) in effect
        .emitters
        .iter()
        .enumerate()
        .filter(|(_, e)| e.enabled)
    {
        for module in Module::in_emitter(e) {
            v.push(Candidate::single(Change::ModuleOff { emitter: i, module }));
        }
    }
    for p in [DrawPath::Billboard, DrawPath::Splat, DrawPath::Tiles] {
        v.push(Candidate::single(Change::DrawPath(p)));
    }
    v
}

/// Whether a candidate is worth measuring: it validates, and it changes the effect (a
/// state layout no emitter can take, or the integrator and step the effect already has,
/// is the effect as authored again).
pub fn worth_measuring(candidate: &Effect, authored: &Effect, is_authored: bool) -> bool {
    candidate.validate().is_ok() && (is_authored || candidate != authored)
}
