//! A headless session: simulation + renderer + stepper, for `ignis render`, tests and
//! benches.

use crate::effect::Effect;
use crate::gpu::GpuContext;
use crate::render::{OrbitCamera, Renderer};
use crate::shaders::ShaderLibrary;
use crate::sim::{GpuSim, SimError, StepPlan, Stepper};

/// Everything needed to simulate and draw an effect without a window.
pub struct Headless {
    /// The GPU.
    pub ctx: GpuContext,
    /// The effect being simulated.
    pub effect: Effect,
    /// The GPU simulation.
    pub sim: GpuSim,
    /// The renderer.
    pub renderer: Renderer,
    /// Frame time → steps.
    pub stepper: Stepper,
    /// The camera.
    pub camera: OrbitCamera,
    last_alpha: f32,
}

impl Headless {
    /// Sets up `effect` on `ctx` with shaders from `lib`.
    pub fn new(ctx: &GpuContext, effect: Effect, lib: ShaderLibrary) -> Result<Self, SimError> {
        let renderer = Renderer::new(ctx, &lib)?;
        let sim = GpuSim::new(ctx, lib, &effect)?;
        Ok(Self {
            ctx: ctx.clone(),
            camera: OrbitCamera::from_hint(&effect.camera),
            effect,
            sim,
            renderer,
            stepper: Stepper::default(),
            last_alpha: 1.0,
        })
    }

    /// Simulates one frame of `frame_dt_secs` wall-clock time.
    pub fn advance(&mut self, frame_dt_secs: f64) -> Result<StepPlan, SimError> {
        let plan = self.stepper.advance(frame_dt_secs, &self.effect.time);
        self.sim.step(&self.effect, plan.dt_secs, plan.steps)?;
        self.last_alpha = plan.alpha;
        Ok(plan)
    }

    /// Renders the current state to an image.
    pub fn render(&mut self, size: (u32, u32)) -> Result<image::RgbaImage, SimError> {
        self.renderer.render_image(
            &self.ctx,
            &self.sim,
            &self.effect,
            &self.camera,
            self.last_alpha,
            size,
        )
    }

    /// Alive particles over all emitters (blocking readback of the GPU counters).
    pub fn alive(&self) -> Result<u64, SimError> {
        let mut total = 0;
        for i in 0..self.sim.emitter_count() {
            if self.effect.emitters.get(i).is_some_and(|e| e.enabled) {
                total += self.sim.read_counters(i)?[0] as u64;
            }
        }
        Ok(total)
    }
}
