//! The editor's GPU side ([`Gfx`]): the device, the window's surface, the player and the
//! composite, egui's painter, and the frame steps that use them — run the UI, simulate,
//! draw the viewport (this file); paint the UI and present (`present.rs`).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context as _, anyhow};
use winit::window::Window;

use crate::composite::Composite;
use crate::effect::Effect;
use crate::gpu::GpuContext;
use crate::hot_reload::{FileWatcher, ShaderReloader, wgsl_names};
use crate::render::OrbitCamera;
use crate::runtime::{InstanceId, Player, PlayerSettings};
use crate::shaders::{ShaderLibrary, ShaderSourceDir};

use crate::editor::diagnostics::stage_profiler::StageProfiler;
use crate::editor::diagnostics::stats::{EmitterStats, ShaderReloadStats};
use crate::editor::panel::viewport::{ViewportOutput, emitter_bounds, frame_bounds, viewport_ui};
use crate::editor::panel::{PANEL_WIDTH, panel_ui};
use crate::editor::state::EditorState;
use crate::editor::window::app::EditOptions;
use crate::editor::window::editor_profile::EditorProfile;
use crate::editor::window::run_report::{FrameLog, RunReport, Tick, WARMUP_FRAMES};
use crate::editor::window::ui_painter::UiPainter;

/// Read the GPU's alive counters every this many frames (a blocking readback).
const COUNTER_INTERVAL_FRAMES: u64 = 15;

/// Simulated time between the timeline's snapshots (a seek replays about this much at
/// most, once the state has been played or replayed since the last edit).
const SEEK_SNAPSHOT_SECS: f64 = 2.0;

/// GPU memory the timeline's snapshots may take.
const SEEK_SNAPSHOT_BYTES: u64 = 256 << 20;

/// Pools at least this large (particle slots in all) leave the device slow for small work
/// once freed (`docs/performance.md`): going back far below them moves to a new device.
const LARGE_POOL_SLOTS: u64 = 4 << 20;

/// Every emitter's slots.
fn total_slots(effect: &Effect) -> u64 {
    effect.emitters.iter().map(|e| u64::from(e.capacity)).sum()
}

/// Whether an effect of `slots` particle slots, after a peak of `peak` on this device,
/// should move to a fresh device: the peak was a large pool and the effect is now a
/// sixteenth of it or less. On the H100 small work on a device that held a large pool
/// runs 2–5× slower; a new device is fast again.
pub(crate) fn wants_fresh_device(peak: u64, slots: u64) -> bool {
    peak >= LARGE_POOL_SLOTS && slots.saturating_mul(16) <= peak
}

/// The time an export may take of each editor frame.
const EXPORT_BUDGET: Duration = Duration::from_millis(40);

/// Wall time a frame gives a measurement in progress (Time ▸ Measure this effect): the
/// editor stays interactive while it runs.
const MEASURE_BUDGET: Duration = Duration::from_millis(30);

/// Everything that exists once the window does.
pub(crate) struct Gfx {
    pub(crate) window: Arc<Window>,
    pub(crate) surface: wgpu::Surface<'static>,
    pub(crate) config: wgpu::SurfaceConfiguration,
    pub(crate) surface_can_copy: bool,
    /// The editor's choices for this adapter (render scale, draft, painter, retained).
    pub(crate) editor_profile: EditorProfile,
    pub(crate) ctx: GpuContext,
    /// Plays the running effect (one instance, at the origin).
    pub(crate) player: Player,
    pub(crate) instance: InstanceId,
    /// The viewport's HDR target, bloom and tonemap around the player.
    pub(crate) composite: Composite,
    /// The running effect the player last accepted (it plays this plus the mouse
    /// collider).
    pub(crate) gpu_effect: Effect,
    pub(crate) egui_ctx: egui::Context,
    pub(crate) egui_state: egui_winit::State,
    pub(crate) ui_painter: UiPainter,
    pub(crate) viewport_texture: Option<egui::TextureId>,
    /// The viewport image egui shows (a gamma-encoded copy of the display image).
    pub(crate) viewport_image: Option<wgpu::Texture>,
    /// The frame clock and the run's timings.
    pub(crate) log: FrameLog,
    pub(crate) viewport_px: (u32, u32),
    /// What changes every frame (points): the viewport and the timeline under it.
    pub(crate) live_rect: egui::Rect,
    /// The retained window image (the adapter profile's choice, and a surface that can be
    /// copied to): the panel is repainted only when it changed.
    pub(crate) retained: Option<crate::editor::window::retained::RetainedUi>,
    pub(crate) profiler: StageProfiler,
    /// Per-pass GPU timestamps (None on CPU adapters: their timestamps are not trusted).
    pub(crate) pass_timer: Option<crate::gpu::timer::PassTimer>,
    /// Hot reload of `shaders/` (absent with the embedded shaders).
    shader_watch: Option<ShaderWatch>,
    /// Watches the folders of the PNG sprites in use: a changed file is reloaded.
    /// (folders, their watcher).
    pub(crate) sprite_watch: Option<(Vec<PathBuf>, Option<FileWatcher>)>,
    /// The most particle slots the effect has had on this device (see
    /// [`wants_fresh_device`]).
    pub(crate) peak_slots: u64,
    /// The effect shrank far below that peak: the frame loop moves to a new device.
    pub(crate) wants_fresh_device: bool,
    /// The state view's textures (View ▸ State view).
    pub(crate) state_textures: Option<([egui::TextureHandle; 3], u64)>,
    /// The export the Export section started, stepped a little every frame.
    pub(crate) export: Option<crate::export::Export>,
    /// Time ▸ Measure this effect: the sweep in progress.
    pub(crate) sweep: Option<crate::tune::Sweep>,
}

/// The shader folder's watcher and the reloader that rebuilds affected pipelines.
struct ShaderWatch {
    dir: PathBuf,
    watcher: FileWatcher,
    reloader: ShaderReloader,
}

impl ShaderWatch {
    /// Watches `lib`'s folder; `None` for embedded shaders or when watching fails.
    fn new(lib: &ShaderLibrary) -> Option<Self> {
        let ShaderSourceDir::Dir(dir) = lib.source() else {
            return None;
        };
        match FileWatcher::new(&[dir.as_path()]) {
            Ok(watcher) => Some(Self {
                dir: dir.clone(),
                watcher,
                reloader: ShaderReloader::new(lib),
            }),
            Err(err) => {
                log::warn!("not watching {} for shader changes: {err}", dir.display());
                None
            }
        }
    }
}

/// The editor's player: the running effect as one instance at the origin, drawn into the
/// composite's HDR target, built from the shader folder when there is one. Not batched:
/// an edit that resizes a pool keeps the particles that fit.
fn editor_player(
    ctx: &GpuContext,
    lib: &ShaderLibrary,
    state: &EditorState,
) -> anyhow::Result<(Player, InstanceId)> {
    let settings = PlayerSettings {
        batch_instances: false,
        shader_dir: match lib.source() {
            ShaderSourceDir::Dir(dir) => Some(dir.clone()),
            ShaderSourceDir::Embedded => None,
        },
        asset_dir: state.asset_dir(),
        adapter_profile: Some(ctx.profile),
        ..Composite::player_settings()
    };
    let mut player = Player::new(&ctx.device, &ctx.queue, &state.running, settings)?;
    // The timeline's seeks start from the snapshot before them.
    player.keep_seek_snapshots(SEEK_SNAPSHOT_SECS, SEEK_SNAPSHOT_BYTES);
    let instance = player.add_instance(glam::Mat4::IDENTITY, state.running.seed)?;
    Ok((player, instance))
}

/// What the window's surface can do besides being drawn to.
struct SurfaceCaps {
    /// Copied from (screenshots read the frame itself).
    can_copy: bool,
    /// Copied into (the retained window).
    can_receive: bool,
}

/// The surface's configuration for `window`: egui's preferred format, copyable when the
/// surface allows, no vsync under automation.
fn surface_config(
    surface: &wgpu::Surface,
    adapter: &wgpu::Adapter,
    window: &Window,
    options: &EditOptions,
) -> anyhow::Result<(wgpu::SurfaceConfiguration, SurfaceCaps)> {
    let size = window.inner_size();
    let caps = surface.get_capabilities(adapter);
    let format = egui_wgpu::preferred_framebuffer_format(&caps.formats)
        .map_err(|e| anyhow!("the window surface offers no usable format: {e:?}"))?;
    let surface_can_copy = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
    let surface_can_receive = caps.usages.contains(wgpu::TextureUsages::COPY_DST);
    let mut config = surface
        .get_default_config(adapter, size.width.max(1), size.height.max(1))
        .ok_or_else(|| anyhow!("the adapter cannot present to this window"))?;
    config.format = format;
    config.usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    if surface_can_copy {
        // Screenshots copy the frame itself; no offscreen re-render needed.
        config.usage |= wgpu::TextureUsages::COPY_SRC;
    }
    // Automation measures throughput, so it does not wait for vertical blanks.
    config.present_mode = if options.frames.is_some() {
        wgpu::PresentMode::AutoNoVsync
    } else {
        wgpu::PresentMode::AutoVsync
    };

    let caps = SurfaceCaps {
        can_copy: surface_can_copy,
        can_receive: surface_can_receive,
    };
    Ok((config, caps))
}

/// egui's window state, with the device's largest texture side.
fn egui_state(egui_ctx: &egui::Context, window: &Window, ctx: &GpuContext) -> egui_winit::State {
    let max_texture_side = ctx.device.limits().max_texture_dimension_2d as usize;
    egui_winit::State::new(
        egui_ctx.clone(),
        egui::ViewportId::ROOT,
        window,
        Some(window.scale_factor() as f32),
        window.theme(),
        Some(max_texture_side),
    )
}

impl Gfx {
    /// The GPU side of the editor in `window`: a device on an adapter that can draw to
    /// it, the surface, the player, the composite and egui's painter. Called at start and
    /// again after the device was lost.
    pub(crate) fn new(
        window: Arc<Window>,
        instance: &wgpu::Instance,
        options: &EditOptions,
        state: &EditorState,
    ) -> anyhow::Result<Self> {
        let surface = instance
            .create_surface(window.clone())
            .context("creating the window's GPU surface")?;
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
            instance,
            Some(&surface),
        ))
        .map_err(|e| anyhow!("no GPU adapter can draw to this window: {e}"))?;
        let ctx = GpuContext::from_adapter(adapter)?.with_request(&options.adapter_profile);
        let adapter = ctx
            .adapter
            .clone()
            .ok_or_else(|| anyhow!("the GPU context lost its adapter"))?;
        let pass_timer = crate::gpu::timer::PassTimer::new(&ctx);

        let (mut config, caps) = surface_config(&surface, &adapter, &window, options)?;
        let SurfaceCaps {
            can_copy: surface_can_copy,
            can_receive: surface_can_receive,
        } = caps;
        let format = config.format;

        let lib = ShaderLibrary::discover(options.shader_dir.as_deref());
        let composite = Composite::new(&ctx, &lib)?;
        let shader_watch = ShaderWatch::new(&lib);
        let (player, instance) = editor_player(&ctx, &lib, state)?;

        let egui_ctx = egui::Context::default();
        egui_ctx.set_visuals(egui::Visuals::dark());
        let egui_state = egui_state(&egui_ctx, &window, &ctx);
        let editor_profile =
            EditorProfile::of_kind(ctx.profile.kind).with(&options.editor_settings);
        let ui_painter = UiPainter::new(&ctx.device, format, editor_profile.lean_painter);
        // Software adapters keep the window's image between frames (see retained.rs).
        let retained = (editor_profile.retained_window && surface_can_receive).then(|| {
            config.usage |= wgpu::TextureUsages::COPY_DST;
            crate::editor::window::retained::RetainedUi::default()
        });
        surface.configure(&ctx.device, &config);
        log::info!(
            "editor: {}x{} surface {:?}, COPY_SRC {}, UI painter {}, retained UI {}",
            config.width,
            config.height,
            config.format,
            surface_can_copy,
            ui_painter.name(),
            retained.is_some()
        );
        Ok(Self {
            window,
            surface,
            config,
            editor_profile,
            surface_can_copy,
            gpu_effect: state.running.clone(),
            ctx,
            player,
            instance,
            composite,
            egui_ctx,
            egui_state,
            ui_painter,
            viewport_texture: None,
            viewport_image: None,
            log: FrameLog::default(),
            viewport_px: (1, 1),
            live_rect: egui::Rect::NOTHING,
            retained,
            pass_timer,
            profiler: StageProfiler::new(options.profile),
            shader_watch,
            sprite_watch: None,
            export: None,
            sweep: None,
            state_textures: None,
            peak_slots: 0,
            wants_fresh_device: false,
        })
    }

    pub(crate) fn resize(&mut self, width: u32, height: u32) {
        if width == 0 || height == 0 {
            return;
        }
        self.config.width = width;
        self.config.height = height;
        self.surface.configure(&self.ctx.device, &self.config);
    }

    /// Step 1, the UI: the panel edits `state`, the viewport moves the camera and
    /// measures itself. Returns egui's output, painted in [`Self::paint_ui`].
    pub(crate) fn run_ui(
        &mut self,
        state: &mut EditorState,
        camera: &mut OrbitCamera,
    ) -> egui::FullOutput {
        self.profiler.begin(&self.ctx);
        let raw_input = self.egui_state.take_egui_input(&self.window);
        let texture = self.viewport_texture;
        let state_textures = &mut self.state_textures;
        let mut viewport = ViewportOutput::default();
        let mut timeline = egui::Rect::NOTHING;
        let mut output = self.egui_ctx.run_ui(raw_input, |ui| {
            egui::Panel::right("inspector")
                .resizable(true)
                .default_size(PANEL_WIDTH)
                .size_range(300.0..=640.0)
                .show(ui, |ui| panel_ui(ui, state));
            timeline = egui::Panel::bottom("timeline")
                .show(ui, |ui| {
                    crate::editor::panel::timeline::timeline_ui(ui, state);
                })
                .response
                .rect;
            egui::CentralPanel::no_frame().show(ui, |ui| {
                viewport = viewport_ui(ui, camera, state, texture);
            });
            crate::editor::diagnostics::inspector::state_view_ui(ui.ctx(), state, state_textures);
            state.end_frame(ui.ctx());
        });
        let platform = std::mem::take(&mut output.platform_output);
        self.egui_state
            .handle_platform_output(&self.window, platform);
        self.viewport_px = viewport.size_px;
        // The timeline under the viewport moves every frame too: the retained image repaints
        // both (one rectangle, as the timeline spans the viewport's width: the inspector
        // panel is laid out first).
        self.live_rect = viewport.rect.union(timeline);
        self.profiler.end_stage(&self.ctx);
        output
    }

    /// Step 3, draw and composite: the player's compute and draws into the composite's
    /// HDR target, bloom and tonemap (the steps `ignis render` records too), then a copy
    /// egui shows; one submit. Returns the CPU time of the recording.
    pub(crate) fn draw_viewport(
        &mut self,
        state: &mut EditorState,
        camera: &OrbitCamera,
    ) -> Duration {
        let start = Instant::now();
        self.composite.exposure = state.view.exposure;
        self.composite.draft = state.view.draft;
        self.composite.test_scene = state.view.test_scene;
        self.composite.heat_haze = state.view.heat_haze;
        self.player.set_asset_dir(state.asset_dir());
        let lights_grid = state.view.show_grid && state.view.fire_lights_grid;
        self.player.set_light_estimate(lights_grid);
        state.fire_light = self.player.effect_light(self.instance);
        state.light_error = self.player.light_estimate_error().map(str::to_owned);
        let mut encoder = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("editor::viewport"),
            });
        let camera = camera.view(self.viewport_px);
        let timing = self.pass_timer.as_mut().is_some_and(|t| t.begin_frame());
        let Self {
            composite,
            player,
            ctx,
            pass_timer,
            ..
        } = self;
        match pass_timer.as_mut().filter(|_| timing) {
            Some(t) => {
                let depth = composite.draw_scene(ctx, &mut encoder, &camera);
                player.collide_with(&camera, depth.as_ref());
                t.scope(&mut encoder, "update", |enc| player.simulate(enc));
                t.scope(&mut encoder, "sort + splat", |enc| {
                    composite.record_player(enc, player, &camera, depth.as_ref())
                });
                t.scope(&mut encoder, "draw + composite", |enc| {
                    composite.draw(ctx, enc, player, &camera)
                });
                t.end_frame(&mut encoder);
            }
            None => composite.record(ctx, &mut encoder, player, &camera),
        }
        state.sprite_errors = self.player.sprite_errors();
        let cpu = start.elapsed();
        self.copy_viewport_image(&mut encoder);
        self.ctx.queue.submit([encoder.finish()]);
        if let Some(t) = self.pass_timer.as_mut() {
            if timing {
                t.after_submit();
            }
            t.poll(&self.ctx);
            state.stats.gpu_pass_ms = t.latest.clone();
            if let Some(probe) = state.cost_probe.as_mut() {
                match probe.frame(&state.stats.gpu_pass_ms) {
                    crate::editor::diagnostics::emitter_cost::ProbeStep::Play(e) => {
                        state.probe_effect = Some(e)
                    }
                    crate::editor::diagnostics::emitter_cost::ProbeStep::Done(_, costs) => {
                        state.emitter_costs = costs;
                        state.cost_probe = None;
                        state.probe_effect = None;
                    }
                }
            }
        }
        self.profiler.end_stage(&self.ctx);
        cpu
    }

    /// The Stats section's figures, and the camera framed when the panel asked.
    pub(crate) fn update_stats(
        &mut self,
        state: &mut EditorState,
        camera: &mut OrbitCamera,
        tick: Tick,
        cpu: Duration,
    ) {
        if state.frame_requested {
            state.frame_requested = false;
            self.frame_camera(camera);
        }
        self.refresh_stats(state, false);
        let inspected = crate::editor::diagnostics::inspector::Inspected {
            player: &self.player,
            instance: self.instance,
            viewport_px: self.viewport_px,
            frame: self.log.index,
        };
        crate::editor::diagnostics::inspector::update_inspect(&inspected, state, camera);
        self.log.record(tick, cpu);
        if self.log.index > 1 {
            state
                .stats
                .push_frame(tick.dt_secs as f32, cpu.as_secs_f32());
        }
        state.stats.viewport_px = self.viewport_px;
    }

    /// What a `--frames` run measured (after its last frame).
    pub(crate) fn run_report(
        &mut self,
        state: &mut EditorState,
        devices_recreated: u32,
    ) -> RunReport {
        self.refresh_stats(state, true);
        let (median_frame_secs, median_cpu_secs) = self.log.medians();
        RunReport {
            frames: self.log.index as u32,
            median_frame_secs,
            median_cpu_secs,
            alive: state.stats.total_alive(),
            viewport_px: self.viewport_px,
            window_px: (self.config.width, self.config.height),
            ui_repaints: self
                .retained
                .as_ref()
                .map(|r| (r.full_repaints, r.live_repaints)),
            adapter: self.ctx.info.name.clone(),
            profile: self.profiler.report(WARMUP_FRAMES),
            devices_recreated,
            edits: None,
        }
    }
    /// Makes the player follow `state.running` (plus the mouse collider); on a GPU
    /// refusal, goes back to the last effect that worked. Returns whether it changed.
    pub(crate) fn apply_running(&mut self, state: &mut EditorState) -> bool {
        let base = state.probe_effect.as_ref().unwrap_or(&state.running);
        let wanted = crate::editor::state::with_mouse_collider(base, state.mouse_point);
        if wanted == *self.player.effect() {
            return false;
        }
        match self.player.set_effect(&wanted) {
            // A cost measurement's effect is not one to fall back to.
            Ok(()) if state.probe_effect.is_some() => {}
            Ok(()) => {
                self.gpu_effect.clone_from(&state.running);
                let slots = total_slots(&wanted);
                self.peak_slots = self.peak_slots.max(slots);
                self.wants_fresh_device = wants_fresh_device(self.peak_slots, slots);
            }
            Err(err) => {
                log::warn!("effect refused by the GPU: {err}");
                state.reject_running(&self.gpu_effect, err.to_string());
                let back =
                    crate::editor::state::with_mouse_collider(&self.gpu_effect, state.mouse_point);
                if let Err(err) = self.player.set_effect(&back) {
                    log::error!("the last effect that worked was refused too: {err}");
                }
            }
        }
        self.player.set_seed(self.instance, self.gpu_effect.seed);
        true
    }

    /// Rebuilds the pipelines whose shaders changed on disk; a failure keeps the last
    /// good pipeline and shows the error (file, line, caret) in the panel.
    /// Returns whether a pipeline was rebuilt.
    pub(crate) fn reload_changed_shaders(&mut self, state: &mut EditorState) -> bool {
        let Some(watch) = &mut self.shader_watch else {
            return false;
        };
        let changed = wgsl_names(&watch.watcher.poll());
        if changed.is_empty() {
            return false;
        }
        let noticed = Instant::now();
        let report = watch.reloader.reload(
            &self.ctx,
            &watch.dir,
            &mut self.player,
            &mut self.composite,
            &changed,
            noticed,
        );
        log::info!(
            "shaders changed ({}): rebuilt {:?}, failed {:?}",
            changed.join(", "),
            report.rebuilt,
            report.failed
        );
        state.shader_errors = watch
            .reloader
            .errors
            .values()
            .map(|e| e.to_string())
            .collect();
        let succeeded = report.failed.is_empty() && !report.rebuilt.is_empty();
        let rebuilt = !report.rebuilt.is_empty();
        state.stats.shader_reload = Some(ShaderReloadStats {
            changed,
            latency_secs: succeeded
                .then_some(watch.reloader.last_latency)
                .flatten()
                .map(|d| d.as_secs_f32()),
            rebuilt: report.rebuilt,
            failed: report.failed,
        });
        rebuilt
    }

    /// Step 2, simulate: the player follows the running effect (and changed shaders) and
    /// plans this frame's steps, recorded with the viewport; an export in progress takes
    /// its share of the frame.
    pub(crate) fn simulate(&mut self, state: &mut EditorState, frame_dt_secs: f64) {
        let reloaded = self.reload_changed_shaders(state);
        let edited = self.apply_running(state) || reloaded;
        crate::editor::panel::timeline::play(
            &mut self.player,
            self.instance,
            &mut state.playback,
            edited,
            frame_dt_secs,
        );
        crate::editor::panel::export_ui::drive(
            &self.ctx,
            &state.running,
            state.asset_dir(),
            &mut state.export,
            &mut self.export,
            EXPORT_BUDGET,
        );
        crate::editor::panel::measure_ui::drive(
            &self.ctx,
            &state.running,
            state.asset_dir(),
            &mut state.measure,
            &mut self.sweep,
            MEASURE_BUDGET,
        );
        self.profiler.end_stage(&self.ctx);
    }

    /// Copies the player's clock and per-emitter figures into the stats (the alive counts
    /// only every few frames: the readback waits for the GPU).
    pub(crate) fn refresh_stats(&mut self, state: &mut EditorState, force: bool) {
        let stats = &mut state.stats;
        let clock = self.player.clock_stats();
        stats.steps_last_frame = clock.steps;
        stats.dt_secs = clock.step_secs;
        stats.dropped_steps = clock.dropped_steps;
        stats.sim_time_secs = self.player.time_secs(self.instance).unwrap_or_default();
        let emitters = self.player.emitter_stats(self.instance).unwrap_or_default();
        stats
            .emitters
            .resize(emitters.len(), EmitterStats::default());
        for (s, e) in stats.emitters.iter_mut().zip(&emitters) {
            s.capacity = e.capacity;
            s.window = e.visited;
            s.spawn = e.spawn;
        }
        if !(force || self.log.index % COUNTER_INTERVAL_FRAMES == 1) {
            return;
        }
        match self.player.count_particles(self.instance) {
            Ok(counts) => {
                for (s, c) in stats.emitters.iter_mut().zip(counts) {
                    s.alive = c.alive;
                    s.nonfinite = c.nonfinite;
                    s.events = c.events;
                }
                stats.counters_age_frames = 0;
            }
            Err(err) => log::warn!("counting the particles: {err}"),
        }
    }

    /// Centres the camera on the alive particles (or on the emitters when none).
    fn frame_camera(&self, camera: &mut OrbitCamera) {
        let positions = self
            .player
            .particle_positions(self.instance)
            .unwrap_or_else(|err| {
                log::warn!("reading particles for framing: {err}");
                Vec::new()
            });
        let (center, radius) =
            frame_bounds(&positions).unwrap_or_else(|| emitter_bounds(&self.gpu_effect));
        camera.frame(center, radius);
    }

    /// Copies the renderer's display image into the texture egui shows (recreated and
    /// re-registered after a resize).
    ///
    /// egui samples textures as gamma-encoded bytes, while the display image is
    /// `Rgba8UnormSrgb` (sampling would decode it). A copy into an `Rgba8Unorm` texture of
    /// the same bytes is legal between sRGB and non-sRGB twins and, unlike a
    /// reinterpreting view, needs no `VIEW_FORMATS` support (the GL backend lacks it).
    fn copy_viewport_image(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let size = self.viewport_px;
        let stale = self
            .viewport_image
            .as_ref()
            .is_none_or(|t| (t.width(), t.height()) != size);
        if stale || self.viewport_texture.is_none() {
            let image = crate::gpu::texture_2d(
                &self.ctx.device,
                "editor::viewport_image",
                size,
                1,
                wgpu::TextureFormat::Rgba8Unorm,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            );
            let view = image.create_view(&wgpu::TextureViewDescriptor::default());
            self.viewport_texture = Some(self.ui_painter.set_native_texture(
                &self.ctx.device,
                &view,
                self.viewport_texture,
            ));
            self.viewport_image = Some(image);
        }
        let targets = self.composite.targets(&self.ctx, size);
        if let Some(image) = &self.viewport_image
            && targets.size == size
        {
            encoder.copy_texture_to_texture(
                targets.ldr.as_image_copy(),
                image.as_image_copy(),
                image.size(),
            );
        }
    }

    /// Drops PNG sprites that changed on disk (they reload on the next frame) and
    /// keeps the watcher on the folders of the sprites in use.
    pub(crate) fn reload_changed_sprites(&mut self) {
        let gfx = self;
        let dirs = gfx.player.sprite_folders();
        if gfx.sprite_watch.as_ref().is_none_or(|w| w.0 != dirs) {
            let paths: Vec<&std::path::Path> = dirs.iter().map(PathBuf::as_path).collect();
            let watcher = if paths.is_empty() {
                None
            } else {
                FileWatcher::new(&paths)
                    .map_err(|e| log::warn!("not watching sprite folders: {e}"))
                    .ok()
            };
            gfx.sprite_watch = Some((dirs, watcher));
        }
        let Some((_, Some(watcher))) = &gfx.sprite_watch else {
            return;
        };
        let changed = watcher.poll();
        if !changed.is_empty() && gfx.player.reload_sprites(&changed) {
            log::info!("sprite changed on disk, reloading");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_large_pool_given_up_asks_for_a_fresh_device() {
        let large = LARGE_POOL_SLOTS;
        assert!(!wants_fresh_device(7168, 7168), "the campfire");
        assert!(!wants_fresh_device(large, large), "still large");
        assert!(!wants_fresh_device(large - 1, 1), "never large");
        assert!(wants_fresh_device(16 * large, 7168), "back to the campfire");
        assert!(!wants_fresh_device(16 * large, large + 1));
    }
}
