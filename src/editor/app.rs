//! The editor window: winit event loop, wgpu surface, egui, and the frame loop.
//!
//! One frame: the UI runs (edits land in `EditorState::effect`, the valid ones in
//! `running`), the player follows them ([`Player::set_effect`]) and advances, the
//! composite records the player's frame into its own HDR target and tonemaps it, then
//! egui draws the panel and composites that image in the same encoder. The viewport is a
//! host of the public runtime API, as any program that embeds ignis.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context as _, anyhow};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

use crate::effect::Effect;
use crate::gpu::{AdapterProfile, GpuContext, ProfileKind};
use crate::hot_reload::{FileWatcher, ShaderReloader, wgsl_names};
use crate::render::{Composite, OrbitCamera};
use crate::runtime::{InstanceId, Player, PlayerSettings};
use crate::shaders::{ShaderLibrary, ShaderSourceDir};

use super::panel::{PANEL_WIDTH, panel_ui};
use super::profile::StageProfiler;
use super::retained::{Repaint, UiReuse};
use super::screenshot::{Screenshot, read_back};
use super::state::EditorState;
use super::stats::{EmitterStats, ShaderReloadStats, median};
use super::ui_painter::{UiPainter, UiPainterKind};
use super::viewport::{ViewportOutput, emitter_bounds, frame_bounds, viewport_ui};

/// Read the GPU's alive counters every this many frames (a blocking readback).
const COUNTER_INTERVAL_FRAMES: u64 = 15;

/// Frames left out of the reported median (start-up: pipeline creation, first present).
const WARMUP_FRAMES: usize = 3;

/// The viewport's background colour (gamma-encoded, as egui's colours are).
const VIEWPORT_BACKGROUND: egui::Color32 = egui::Color32::from_rgb(9, 9, 11);

/// [`VIEWPORT_BACKGROUND`] as the UI pass's clear colour.
const VIEWPORT_CLEAR: wgpu::Color = wgpu::Color {
    r: VIEWPORT_BACKGROUND.r() as f64 / 255.0,
    g: VIEWPORT_BACKGROUND.g() as f64 / 255.0,
    b: VIEWPORT_BACKGROUND.b() as f64 / 255.0,
    a: 1.0,
};

/// Extra frames `--screenshot` waits for the window to hand out a frame.
const MAX_EXTRA_FRAMES: u64 = 120;

/// How `ignis edit` was started.
#[derive(Clone, Debug, Default)]
pub struct EditOptions {
    /// Preset to open (default: the embedded campfire).
    pub preset: Option<PathBuf>,
    /// Exit after this many frames (automation).
    pub frames: Option<u32>,
    /// Save the window's image (UI included) after the last frame.
    pub screenshot: Option<PathBuf>,
    /// Shader folder (default: ./shaders if present, else the embedded copies).
    pub shader_dir: Option<PathBuf>,
    /// Initial window size in logical pixels.
    pub window_size: (u32, u32),
    /// Which egui painter to use.
    pub ui_painter: UiPainterKind,
    /// Viewport render scale (default: the adapter profile's).
    pub render_scale: Option<f32>,
    /// The adapter profile to use instead of the adapter's own.
    pub adapter_profile: Option<ProfileKind>,
    /// Drain the GPU after each frame stage and report where the time goes.
    pub profile: bool,
    /// Open exactly these panel sections at start (ids: emitter, look, …).
    pub sections: Option<Vec<String>>,
    /// Select this emitter (by name) at start.
    pub select: Option<String>,
    /// Draft viewport (default: on for software adapters).
    pub draft: Option<bool>,
}

/// What a run with `--frames` measured.
#[derive(Clone, Debug)]
pub struct RunReport {
    /// Frames rendered.
    pub frames: u32,
    /// Median interval between frames after the warm-up, seconds.
    pub median_frame_secs: f32,
    /// Median CPU wall time of the sim + render recording, seconds.
    pub median_cpu_secs: f32,
    /// Particles alive at the end.
    pub alive: u64,
    /// The viewport's render size, pixels.
    pub viewport_px: (u32, u32),
    /// The window's size, pixels.
    pub window_px: (u32, u32),
    /// The adapter.
    pub adapter: String,
    /// The per-stage breakdown (`--profile`).
    pub profile: Option<String>,
    /// With the retained window image: (frames painted in full, viewport-only frames).
    pub ui_repaints: Option<(u64, u64)>,
    /// With the retained window image: (UI passes built, frames that reused the last).
    pub ui_builds: Option<(u64, u64)>,
}

impl std::fmt::Display for RunReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let fps = if self.median_frame_secs > 0.0 {
            1.0 / self.median_frame_secs
        } else {
            0.0
        };
        write!(
            f,
            "edit: {} frames, median frame {:.1} ms ({:.1} fps), median CPU wall time (sim + render recording) {:.1} ms; window {}x{}, viewport {}x{} px, {} particles alive, on {}",
            self.frames,
            self.median_frame_secs * 1e3,
            fps,
            self.median_cpu_secs * 1e3,
            self.window_px.0,
            self.window_px.1,
            self.viewport_px.0,
            self.viewport_px.1,
            self.alive,
            self.adapter
        )?;
        if let Some((full, live)) = self.ui_repaints {
            write!(
                f,
                "\nretained UI: {full} frames painted in full, {live} only over the viewport"
            )?;
        }
        if let Some((built, reused)) = self.ui_builds {
            write!(
                f,
                "; UI built {built} times, reused on {reused} frames without input"
            )?;
        }
        if let Some(profile) = &self.profile {
            write!(f, "\n{profile}")?;
        }
        Ok(())
    }
}

/// Opens the editor window and runs until it is closed (or `--frames` are done).
pub fn run(options: EditOptions) -> anyhow::Result<Option<RunReport>> {
    let (effect, source) = match &options.preset {
        Some(path) => (crate::preset::load(path)?, path.display().to_string()),
        None => (Effect::default_campfire(), "embedded default".to_owned()),
    };
    let event_loop = EventLoop::new().context(
        "cannot open a window (no display?): set DISPLAY/WAYLAND_DISPLAY, or run under xvfb-run",
    )?;
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
        Box::new(event_loop.owned_display_handle()),
    ));
    let mut app = App {
        camera: OrbitCamera::from_hint(&effect.camera),
        state: {
            let mut state = EditorState::new(effect, source);
            if let Some(path) = &options.preset {
                state.preset_path = path.display().to_string();
                state.loaded_path = Some(path.clone());
            }
            state.open_sections = options.sections.clone();
            if let Some(i) = options
                .select
                .as_ref()
                .and_then(|name| state.effect.emitters.iter().position(|e| &e.name == name))
            {
                state.selected = i;
            }
            state
        },
        options,
        instance,
        gfx: None,
        preset_watch: None,
        fatal: None,
        report: None,
    };
    event_loop
        .run_app(&mut app)
        .context("the window's event loop failed")?;
    if let Some(err) = app.fatal {
        return Err(err);
    }
    Ok(app.report)
}

struct App {
    options: EditOptions,
    instance: wgpu::Instance,
    state: EditorState,
    camera: OrbitCamera,
    gfx: Option<Gfx>,
    /// Watches the loaded preset's folder: an external edit re-applies the preset.
    preset_watch: Option<(std::path::PathBuf, FileWatcher)>,
    fatal: Option<anyhow::Error>,
    report: Option<RunReport>,
}

/// Everything that exists once the window does.
struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    surface_can_copy: bool,
    ctx: GpuContext,
    /// Plays the running effect (one instance, at the origin).
    player: Player,
    instance: InstanceId,
    /// The viewport's HDR target, bloom and tonemap around the player.
    composite: Composite,
    /// The running effect the player last accepted (it plays this plus the mouse
    /// collider).
    gpu_effect: Effect,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    ui_painter: UiPainter,
    viewport_texture: Option<egui::TextureId>,
    /// The viewport image egui shows (a gamma-encoded copy of the display image).
    viewport_image: Option<wgpu::Texture>,
    frame_index: u64,
    last_frame: Option<Instant>,
    frame_log: Vec<f32>,
    cpu_log: Vec<f32>,
    viewport_px: (u32, u32),
    /// Where the viewport is in the window (points).
    viewport_rect: egui::Rect,
    /// The retained window image (lean painter and a surface that can be copied to):
    /// the panel is repainted only when it changed.
    retained: Option<super::retained::RetainedUi>,
    /// With the retained image: the last UI pass, painted again on frames without input.
    ui_reuse: Option<UiReuse>,
    profiler: StageProfiler,
    /// Per-pass GPU timestamps (None on CPU adapters: their timestamps are not trusted).
    pass_timer: Option<crate::gpu::timer::PassTimer>,
    /// Hot reload of `shaders/` (absent with the embedded shaders).
    shader_watch: Option<ShaderWatch>,
    /// Watches the folders of the PNG sprites in use: a changed file is reloaded.
    /// (folders, their watcher).
    sprite_watch: Option<(Vec<PathBuf>, Option<FileWatcher>)>,
    /// The export the Export section started, stepped a little every frame.
    export: Option<crate::export::Export>,
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
/// The time an export may take of each editor frame.
const EXPORT_BUDGET: Duration = Duration::from_millis(40);

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
    let instance = player.add_instance(glam::Mat4::IDENTITY, state.running.seed)?;
    Ok((player, instance))
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        match Gfx::new(event_loop, &self.instance, &self.options, &self.state) {
            Ok(gfx) => {
                self.state.stats.adapter = gfx.ctx.info.name.clone();
                self.state.stats.ui_painter = gfx.ui_painter.name();
                // Software rasterisers pay for every pixel of every billboard: render the
                // soft fire at half resolution there unless asked otherwise.
                let default_scale = gfx.ctx.profile.render_scale;
                self.state.view.render_scale = self
                    .options
                    .render_scale
                    .unwrap_or(default_scale)
                    .clamp(0.1, 1.0);
                // … and draw the large additive sprites at half of that.
                self.state.view.draft = self.options.draft.unwrap_or(gfx.ctx.profile.draft);
                gfx.window.request_redraw();
                self.gfx = Some(gfx);
            }
            Err(err) => {
                self.fatal = Some(err);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(gfx) = self.gfx.as_mut() else {
            return;
        };
        let response = gfx.egui_state.on_window_event(&gfx.window, &event);
        if response.repaint
            && !matches!(event, WindowEvent::RedrawRequested)
            && let Some(reuse) = gfx.ui_reuse.as_mut()
        {
            reuse.input = true;
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                gfx.resize(size.width, size.height);
                gfx.window.request_redraw();
            }
            WindowEvent::RedrawRequested => match self.frame() {
                Ok(true) => event_loop.exit(),
                Ok(false) => {
                    if let Some(gfx) = &self.gfx {
                        gfx.window.request_redraw();
                    }
                }
                Err(err) => {
                    self.fatal = Some(err);
                    event_loop.exit();
                }
            },
            _ => {}
        }
    }
}

impl Gfx {
    fn new(
        event_loop: &ActiveEventLoop,
        instance: &wgpu::Instance,
        options: &EditOptions,
        state: &EditorState,
    ) -> anyhow::Result<Self> {
        let (w, h) = options.window_size;
        let attributes = Window::default_attributes()
            .with_title(format!("ignis — {} ({})", state.effect.name, state.source))
            .with_inner_size(winit::dpi::LogicalSize::new(w as f64, h as f64))
            .with_min_inner_size(winit::dpi::LogicalSize::new(640.0, 400.0));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("creating the editor window")?,
        );
        let surface = instance
            .create_surface(window.clone())
            .context("creating the window's GPU surface")?;
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
            instance,
            Some(&surface),
        ))
        .map_err(|e| anyhow!("no GPU adapter can draw to this window: {e}"))?;
        let ctx = GpuContext::from_adapter(adapter)?
            .with_profile(options.adapter_profile.map(AdapterProfile::of_kind));
        let adapter = ctx
            .adapter
            .clone()
            .ok_or_else(|| anyhow!("the GPU context lost its adapter"))?;
        let pass_timer = crate::gpu::timer::PassTimer::new(&ctx);

        let size = window.inner_size();
        let caps = surface.get_capabilities(&adapter);
        let format = egui_wgpu::preferred_framebuffer_format(&caps.formats)
            .map_err(|e| anyhow!("the window surface offers no usable format: {e:?}"))?;
        let surface_can_copy = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        let surface_can_receive = caps.usages.contains(wgpu::TextureUsages::COPY_DST);
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
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

        let lib = ShaderLibrary::discover(options.shader_dir.as_deref());
        let composite = Composite::new(&ctx, &lib)?;
        let shader_watch = ShaderWatch::new(&lib);
        let (player, instance) = editor_player(&ctx, &lib, state)?;

        let egui_ctx = egui::Context::default();
        egui_ctx.set_visuals(egui::Visuals::dark());
        let max_texture_side = ctx.device.limits().max_texture_dimension_2d as usize;
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(max_texture_side),
        );
        let ui_painter =
            UiPainter::new(&ctx.device, format, options.ui_painter, ctx.profile.lean_ui);
        // Software adapters keep the window's image between frames (see retained.rs).
        let retained = (ui_painter.name() == "lean" && surface_can_receive).then(|| {
            config.usage |= wgpu::TextureUsages::COPY_DST;
            super::retained::RetainedUi::default()
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
            frame_index: 0,
            last_frame: None,
            frame_log: Vec::new(),
            cpu_log: Vec::new(),
            viewport_px: (1, 1),
            viewport_rect: egui::Rect::NOTHING,
            ui_reuse: retained.as_ref().map(|_| UiReuse::default()),
            retained,
            pass_timer,
            profiler: StageProfiler::new(options.profile),
            shader_watch,
            sprite_watch: None,
            export: None,
        })
    }

    fn resize(&mut self, width: u32, height: u32) {
        if width == 0 || height == 0 {
            return;
        }
        self.config.width = width;
        self.config.height = height;
        self.surface.configure(&self.ctx.device, &self.config);
    }

    /// Makes the player follow `state.running` (plus the mouse collider); on a GPU
    /// refusal, goes back to the last effect that worked.
    fn apply_running(&mut self, state: &mut EditorState) {
        let wanted = super::state::with_mouse_collider(&state.running, state.mouse_point);
        if wanted == *self.player.effect() {
            return;
        }
        match self.player.set_effect(&wanted) {
            Ok(()) => self.gpu_effect.clone_from(&state.running),
            Err(err) => {
                log::warn!("effect refused by the GPU: {err}");
                state.reject_running(&self.gpu_effect, err.to_string());
                let back = super::state::with_mouse_collider(&self.gpu_effect, state.mouse_point);
                if let Err(err) = self.player.set_effect(&back) {
                    log::error!("the last effect that worked was refused too: {err}");
                }
            }
        }
        self.player.set_seed(self.instance, self.gpu_effect.seed);
    }

    /// Rebuilds the pipelines whose shaders changed on disk; a failure keeps the last
    /// good pipeline and shows the error (file, line, caret) in the panel.
    fn reload_changed_shaders(&mut self, state: &mut EditorState) {
        let Some(watch) = &mut self.shader_watch else {
            return;
        };
        let changed = wgsl_names(&watch.watcher.poll());
        if changed.is_empty() {
            return;
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
        state.stats.shader_reload = Some(ShaderReloadStats {
            changed,
            latency_secs: succeeded
                .then_some(watch.reloader.last_latency)
                .flatten()
                .map(|d| d.as_secs_f32()),
            rebuilt: report.rebuilt,
            failed: report.failed,
        });
    }

    /// Plans this frame's simulation steps (recorded with the viewport).
    fn simulate(&mut self, state: &mut EditorState, frame_dt_secs: f64) {
        let playback = &mut state.playback;
        if playback.restart_requested {
            playback.restart_requested = false;
            self.player.restart();
        }
        if playback.step_requested {
            playback.step_requested = false;
            playback.is_paused = true;
            self.player.step();
        }
        self.player.set_paused(playback.is_paused);
        self.player.advance(frame_dt_secs);
    }

    /// Copies the player's clock and per-emitter figures into the stats (the alive counts
    /// only every few frames: the readback waits for the GPU).
    fn refresh_stats(&mut self, state: &mut EditorState, force: bool) {
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
        if !(force || self.frame_index % COUNTER_INTERVAL_FRAMES == 1) {
            return;
        }
        match self.player.count_particles(self.instance) {
            Ok(counts) => {
                for (s, c) in stats.emitters.iter_mut().zip(counts) {
                    s.alive = c.alive;
                    s.nonfinite = c.nonfinite;
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
}

impl App {
    /// Re-applies the loaded preset when another program changed it (asking first when
    /// the panel has unsaved edits). Our own saves are recognised and ignored.
    fn reload_changed_preset(&mut self) {
        let Some(path) = self.state.loaded_path.clone() else {
            return;
        };
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .map_or_else(|| std::path::PathBuf::from("."), |d| d.to_path_buf());
        if self.preset_watch.as_ref().is_none_or(|(d, _)| *d != dir) {
            self.preset_watch = match FileWatcher::new(&[dir.as_path()]) {
                Ok(w) => Some((dir, w)),
                Err(e) => {
                    log::warn!("not watching {} for preset edits: {e}", dir.display());
                    None
                }
            };
        }
        let Some((_, watcher)) = &self.preset_watch else {
            return;
        };
        let changed = watcher.poll();
        if !changed.iter().any(|p| p.file_name() == path.file_name()) {
            return;
        }
        match crate::preset::load(&path) {
            Ok(effect) if effect == self.state.saved => {}
            _ => {
                log::info!("{} changed on disk", path.display());
                self.state.preset_changed_on_disk();
            }
        }
    }

    /// Drops PNG sprites that changed on disk (they reload on the next frame) and
    /// keeps the watcher on the folders of the sprites in use.
    fn reload_changed_sprites(&mut self) {
        let Some(gfx) = self.gfx.as_mut() else {
            return;
        };
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

    /// One frame. Returns true when the editor should exit (`--frames` done).
    fn frame(&mut self) -> anyhow::Result<bool> {
        self.reload_changed_preset();
        self.reload_changed_sprites();
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(false);
        };
        let now = Instant::now();
        let frame_dt_secs = gfx
            .last_frame
            .map_or(1.0 / 60.0, |t| now.duration_since(t).as_secs_f64());
        gfx.last_frame = Some(now);
        gfx.frame_index += 1;

        // 1. The UI: edits, camera, the viewport's size — or, on a software adapter with
        // no input, the last UI pass again (see `UiReuse`).
        gfx.profiler.begin(&gfx.ctx);
        let is_last = self
            .options
            .frames
            .is_some_and(|n| gfx.frame_index >= n as u64);
        if let Some(reuse) = gfx.ui_reuse.as_mut() {
            reuse.tick(Duration::try_from_secs_f64(frame_dt_secs).unwrap_or(Duration::MAX));
        }
        let build_ui = gfx.ui_reuse.as_ref().is_none_or(|r| r.due(is_last));
        let mut ui_output = None;
        if build_ui {
            let raw_input = gfx.egui_state.take_egui_input(&gfx.window);
            let state = &mut self.state;
            let camera = &mut self.camera;
            let texture = gfx.viewport_texture;
            let mut viewport = ViewportOutput::default();
            let full_output = gfx.egui_ctx.run_ui(raw_input, |ui| {
                egui::Panel::right("inspector")
                    .resizable(true)
                    .default_size(PANEL_WIDTH)
                    .size_range(300.0..=640.0)
                    .show(ui, |ui| panel_ui(ui, state));
                egui::CentralPanel::no_frame().show(ui, |ui| {
                    viewport = viewport_ui(ui, camera, state, texture);
                });
                state.end_frame(ui.ctx());
            });
            gfx.egui_state
                .handle_platform_output(&gfx.window, full_output.platform_output);
            gfx.viewport_px = viewport.size_px;
            gfx.viewport_rect = viewport.rect;
            ui_output = Some((
                full_output.shapes,
                full_output.pixels_per_point,
                full_output.textures_delta,
                full_output.viewport_output,
            ));
        }

        // 2. The simulation follows the running effect and steps.
        gfx.profiler.end_stage(&gfx.ctx);
        gfx.reload_changed_shaders(&mut self.state);
        gfx.apply_running(&mut self.state);
        let cpu_start = Instant::now();
        gfx.simulate(&mut self.state, frame_dt_secs);
        super::export_ui::drive(
            &gfx.ctx,
            &self.state.running,
            self.state.asset_dir(),
            &mut self.state.export,
            &mut gfx.export,
            EXPORT_BUDGET,
        );

        // 3. The viewport image: the player's frame → HDR → tonemap, then a copy egui can
        // show.
        gfx.profiler.end_stage(&gfx.ctx);
        gfx.composite.exposure = self.state.view.exposure;
        gfx.composite.draft = self.state.view.draft;
        gfx.player.set_asset_dir(self.state.asset_dir());
        let mut encoder = gfx
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("editor::viewport"),
            });
        let timing = gfx.pass_timer.as_mut().is_some_and(|t| t.begin_frame());
        {
            let Gfx {
                composite,
                player,
                ctx,
                pass_timer,
                viewport_px,
                ..
            } = &mut *gfx;
            let camera = self.camera.view(*viewport_px);
            match pass_timer.as_mut().filter(|_| timing) {
                Some(t) => {
                    t.scope(&mut encoder, "update", |enc| player.simulate(enc));
                    t.scope(&mut encoder, "draw + composite", |enc| {
                        composite.record(ctx, enc, player, &camera)
                    });
                }
                None => composite.record(ctx, &mut encoder, player, &camera),
            }
        }
        self.state.sprite_errors = gfx.player.sprite_errors();
        if let Some(t) = gfx.pass_timer.as_mut().filter(|_| timing) {
            t.end_frame(&mut encoder);
        }
        let cpu_secs = cpu_start.elapsed().as_secs_f32();
        gfx.copy_viewport_image(&mut encoder);
        gfx.ctx.queue.submit([encoder.finish()]);
        if let Some(t) = gfx.pass_timer.as_mut() {
            if timing {
                t.after_submit();
            }
            t.poll(&gfx.ctx);
            self.state.stats.gpu_pass_ms = t.latest.clone();
        }

        if self.state.frame_requested {
            self.state.frame_requested = false;
            gfx.frame_camera(&mut self.camera);
        }
        gfx.refresh_stats(&mut self.state, false);
        if gfx.frame_index > 1 {
            self.state.stats.push_frame(frame_dt_secs as f32, cpu_secs);
            gfx.frame_log.push(frame_dt_secs as f32);
            gfx.cpu_log.push(cpu_secs);
        }
        self.state.stats.viewport_px = gfx.viewport_px;
        gfx.profiler.end_stage(&gfx.ctx);

        // 4. egui: textures first (always, even when no frame can be drawn), then paint.
        let mut encoder = gfx
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("editor::ui"),
            });
        let rebuilt = ui_output.is_some();
        let (paint_jobs, ppp, textures_delta) = match ui_output {
            Some((shapes, ppp, textures_delta, viewports)) => {
                let jobs = gfx.egui_ctx.tessellate(shapes, ppp);
                let repaint_after = viewports
                    .get(&egui::ViewportId::ROOT)
                    .map_or(Duration::ZERO, |v| v.repaint_delay);
                if let Some(reuse) = gfx.ui_reuse.as_mut() {
                    reuse.built(ppp, repaint_after);
                }
                (jobs, ppp, textures_delta)
            }
            None => {
                let (jobs, ppp) = gfx.ui_reuse.as_mut().map(UiReuse::take).unwrap_or_default();
                (jobs, ppp, egui::TexturesDelta::default())
            }
        };
        for (id, deltas) in &textures_delta.set {
            for delta in deltas {
                gfx.ui_painter
                    .update_texture(&gfx.ctx.device, &gfx.ctx.queue, *id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [gfx.config.width, gfx.config.height],
            pixels_per_point: ppp,
        };
        // Software adapters: repaint only the viewport while the panel is unchanged.
        let textures_changed = !textures_delta.set.is_empty() || !textures_delta.free.is_empty();
        let retained = match gfx.retained.as_mut() {
            Some(r) => {
                let image = r
                    .image(
                        &gfx.ctx.device,
                        (gfx.config.width, gfx.config.height),
                        gfx.config.format,
                    )
                    .clone();
                let repaint = r.plan(
                    &paint_jobs,
                    rebuilt,
                    gfx.viewport_rect,
                    screen.size_in_pixels,
                    textures_changed,
                    VIEWPORT_BACKGROUND,
                    gfx.viewport_texture,
                );
                Some((image, repaint))
            }
            None => None,
        };
        // Cleared to the viewport's background (egui paints only the panel and overlays),
        // or kept for a viewport-only repaint.
        let (jobs, load) = match &retained {
            Some((_, Repaint::Live(jobs))) => (jobs.as_slice(), wgpu::LoadOp::Load),
            _ => (paint_jobs.as_slice(), wgpu::LoadOp::Clear(VIEWPORT_CLEAR)),
        };
        let callbacks =
            gfx.ui_painter
                .prepare(&gfx.ctx.device, &gfx.ctx.queue, &mut encoder, jobs, &screen);

        let frame = match gfx.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) => Some(f),
            wgpu::CurrentSurfaceTexture::Suboptimal(f) => {
                // Draw this one; reconfigure for the next.
                gfx.resize(gfx.config.width, gfx.config.height);
                Some(f)
            }
            wgpu::CurrentSurfaceTexture::Outdated => {
                let size = gfx.window.inner_size();
                gfx.resize(size.width, size.height);
                None
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                gfx.surface = self
                    .instance
                    .create_surface(gfx.window.clone())
                    .context("recreating the lost window surface")?;
                gfx.surface.configure(&gfx.ctx.device, &gfx.config);
                None
            }
            wgpu::CurrentSurfaceTexture::Timeout
            | wgpu::CurrentSurfaceTexture::Occluded
            | wgpu::CurrentSurfaceTexture::Validation => None,
        };

        let mut screenshot = None;
        if let (Some(frame), Some((image, _))) = (&frame, &retained) {
            gfx.ui_painter
                .paint(&mut encoder, &image.view, jobs, &screen, load);
            encoder.copy_texture_to_texture(
                image.texture.as_image_copy(),
                frame.texture.as_image_copy(),
                image.texture.size(),
            );
            if is_last && let Some(path) = &self.options.screenshot {
                screenshot = Some(Screenshot::record(
                    &gfx.ctx,
                    &mut encoder,
                    &image.texture,
                    path.clone(),
                ));
            }
        } else if let Some(frame) = &frame {
            let view = frame
                .texture
                .create_view(&wgpu::TextureViewDescriptor::default());
            gfx.ui_painter
                .paint(&mut encoder, &view, jobs, &screen, load);
            if is_last && let Some(path) = &self.options.screenshot {
                if gfx.surface_can_copy {
                    screenshot = Some(Screenshot::record(
                        &gfx.ctx,
                        &mut encoder,
                        &frame.texture,
                        path.clone(),
                    ));
                } else {
                    // The surface cannot be copied from: draw the UI again offscreen.
                    let offscreen = crate::gpu::texture_2d(
                        &gfx.ctx.device,
                        "editor::screenshot_target",
                        (frame.texture.width(), frame.texture.height()),
                        1,
                        gfx.config.format,
                        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    );
                    let off_view = offscreen.create_view(&Default::default());
                    gfx.ui_painter
                        .paint(&mut encoder, &off_view, jobs, &screen, load);
                    screenshot = Some(Screenshot::record(
                        &gfx.ctx,
                        &mut encoder,
                        &offscreen,
                        path.clone(),
                    ));
                }
            }
        }
        if frame.is_none()
            && let Some(r) = gfx.retained.as_mut()
        {
            // Nothing was painted: the image no longer matches the panel.
            r.invalidate();
            if let Some(reuse) = gfx.ui_reuse.as_mut() {
                reuse.invalidate();
            }
        }
        gfx.ctx
            .queue
            .submit(callbacks.into_iter().chain([encoder.finish()]));
        gfx.profiler.end_stage(&gfx.ctx);
        if let Some(frame) = frame {
            gfx.window.pre_present_notify();
            gfx.ctx.queue.present(frame);
        }
        gfx.profiler.end_stage(&gfx.ctx);
        for id in &textures_delta.free {
            gfx.ui_painter.free_texture(id);
        }
        if let Some(reuse) = gfx.ui_reuse.as_mut() {
            // Kept for the next frames without input (a lost frame invalidated it).
            reuse.jobs = paint_jobs;
        }

        if !is_last {
            return Ok(false);
        }
        if let Some(shot) = screenshot {
            let path = shot.path.clone();
            read_back(&gfx.ctx, shot)
                .with_context(|| format!("saving the screenshot {}", path.display()))?;
        } else if let Some(path) = &self.options.screenshot {
            // No frame this time: try again on the next one, but not forever.
            let wanted = self.options.frames.unwrap_or(0) as u64;
            if gfx.frame_index > wanted + MAX_EXTRA_FRAMES {
                return Err(anyhow!(
                    "no frame could be acquired from the window for the screenshot {}",
                    path.display()
                ));
            }
            return Ok(false);
        }
        gfx.refresh_stats(&mut self.state, true);
        let warm = gfx.frame_log.len().min(WARMUP_FRAMES);
        self.report = Some(RunReport {
            frames: gfx.frame_index as u32,
            median_frame_secs: median(&gfx.frame_log[warm..]),
            median_cpu_secs: median(&gfx.cpu_log[warm..]),
            alive: self.state.stats.total_alive(),
            viewport_px: gfx.viewport_px,
            window_px: (gfx.config.width, gfx.config.height),
            ui_repaints: gfx
                .retained
                .as_ref()
                .map(|r| (r.full_repaints, r.live_repaints)),
            ui_builds: gfx.ui_reuse.as_ref().map(|r| (r.builds, r.reuses)),
            adapter: gfx.ctx.info.name.clone(),
            profile: gfx.profiler.report(WARMUP_FRAMES),
        });
        Ok(true)
    }
}
