//! A headless host: a [`Player`] with one instance drawn through a [`Composite`], for
//! `ignis render`, tests and benches — a client of the public API like any program that
//! embeds ignis.

use crate::composite::Composite;
use crate::effect::Effect;
use crate::gpu::GpuContext;
use crate::gpu::timer::{GpuTimer, PassTimer};
use crate::render::{Camera, OrbitCamera};
use crate::runtime::{InstanceId, Player, PlayerError, PlayerSettings};
use crate::shaders::{ShaderLibrary, ShaderSourceDir};
use crate::sim::SimError;

/// Everything needed to simulate and draw an effect without a window.
pub struct Headless {
    /// The GPU.
    pub ctx: GpuContext,
    /// The player.
    pub player: Player,
    /// Its one instance, at the origin with the effect's seed.
    pub instance: InstanceId,
    /// The HDR target, bloom and tonemap.
    pub composite: Composite,
    /// The camera.
    pub camera: OrbitCamera,
}

impl Headless {
    /// Sets up `effect` on `ctx` with shaders from `lib`.
    pub fn new(ctx: &GpuContext, effect: Effect, lib: ShaderLibrary) -> Result<Self, PlayerError> {
        Self::with_settings(ctx, effect, lib, Composite::player_settings())
    }

    /// Sets up `effect` with player `settings` (they draw into the composite's HDR
    /// target: its colour format, no depth, one sample).
    pub fn with_settings(
        ctx: &GpuContext,
        effect: Effect,
        lib: ShaderLibrary,
        settings: PlayerSettings,
    ) -> Result<Self, PlayerError> {
        let shader_dir = match lib.source() {
            ShaderSourceDir::Dir(dir) => Some(dir.clone()),
            ShaderSourceDir::Embedded => None,
        };
        let settings = PlayerSettings {
            shader_dir,
            adapter_profile: Some(ctx.profile),
            ..settings
        };
        let mut player = Player::new(&ctx.device, &ctx.queue, &effect, settings)?;
        let instance = player.add_instance(glam::Mat4::IDENTITY, effect.seed)?;
        let composite = Composite::new(ctx, &lib).map_err(SimError::from)?;
        Ok(Self {
            ctx: ctx.clone(),
            camera: OrbitCamera::from_hint(&effect.camera),
            player,
            instance,
            composite,
        })
    }

    /// The effect being played.
    pub fn effect(&self) -> &Effect {
        self.player.effect()
    }

    /// Applies an edit of the effect to the player ([`Player::set_effect`]).
    pub fn edit(&mut self, f: impl FnOnce(&mut Effect)) -> Result<(), PlayerError> {
        let mut effect = self.player.effect().clone();
        f(&mut effect);
        self.player.set_effect(&effect)?;
        self.player.set_seed(self.instance, effect.seed);
        Ok(())
    }

    /// Simulates one frame of `frame_dt_secs` wall-clock time (submitted now).
    pub fn advance(&mut self, frame_dt_secs: f64) {
        self.player.advance(frame_dt_secs);
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        self.player.simulate(&mut enc);
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Plays from the start to `secs` in frames of `frame_dt_secs` ([`Player::seek`]).
    pub fn seek(&mut self, secs: f64, frame_dt_secs: f64) -> u64 {
        self.player.seek(secs, frame_dt_secs)
    }

    /// Renders the current state to an image.
    pub fn render(&mut self, size: (u32, u32)) -> Result<image::RgbaImage, SimError> {
        let camera = self.camera.view(size);
        self.composite
            .render_image(&self.ctx, &mut self.player, &camera)
    }

    /// Simulates and draws one frame of `frame_dt_secs` for `camera` with each part timed
    /// apart by `timer` (GPU timestamps where the adapter has them, else the wall clock
    /// around a drained queue), in milliseconds: update, record (sort, splat, the tiles'
    /// passes), particle draws, composite (heat haze, bloom and tonemap).
    pub fn timed_frame(
        &mut self,
        timer: &GpuTimer,
        frame_dt_secs: f64,
        camera: &Camera,
    ) -> [f64; 4] {
        self.player.advance(frame_dt_secs);
        let Self {
            ctx,
            player,
            composite,
            ..
        } = self;
        let update = timer.time(ctx, |enc| player.simulate(enc));
        let record = timer.time(ctx, |enc| {
            composite.record_player(enc, player, camera, None)
        });
        let mut layered = crate::Layers::NONE;
        let draw = timer.time(ctx, |enc| {
            layered = composite.draw_particles(ctx, enc, player, camera);
        });
        let post = timer.time(ctx, |enc| {
            composite.apply_haze(ctx, enc, player);
            composite.post(ctx, enc, player, layered)
        });
        [update, record, draw, post]
    }

    /// [`Headless::timed_frame`] as a frame loop runs it: the four parts in one encoder
    /// between `timer`'s timestamps ("update", "record", "draw", "composite"), submitted
    /// without waiting, so the GPU stays busy from frame to frame. The parts' times reach
    /// `timer.latest` a frame or two later (frames the timer's ring has no room for are
    /// not timed).
    pub fn pipelined_frame(&mut self, timer: &mut PassTimer, frame_dt_secs: f64, camera: &Camera) {
        self.player.advance(frame_dt_secs);
        let Self {
            ctx,
            player,
            composite,
            ..
        } = self;
        let timing = timer.begin_frame();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        timer.scope(&mut enc, "update", |enc| player.simulate(enc));
        timer.scope(&mut enc, "record", |enc| {
            composite.record_player(enc, player, camera, None)
        });
        let layered = timer.scope(&mut enc, "draw", |enc| {
            composite.draw_particles(ctx, enc, player, camera)
        });
        timer.scope(&mut enc, "composite", |enc| {
            composite.apply_haze(ctx, enc, player);
            composite.post(ctx, enc, player, layered)
        });
        if timing {
            timer.end_frame(&mut enc);
        }
        ctx.queue.submit([enc.finish()]);
        if timing {
            timer.after_submit();
        }
        timer.poll(ctx);
    }

    /// Alive particles over all emitters (blocking readback of the GPU counters).
    pub fn alive(&self) -> Result<u64, PlayerError> {
        let counts = self.player.count_particles(self.instance)?;
        Ok(counts.iter().map(|c| u64::from(c.alive)).sum())
    }
}
