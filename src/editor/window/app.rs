//! The editor window: winit's event loop and the frame loop.
//!
//! One frame, top to bottom (`App::frame`): the UI runs (edits land in
//! `EditorState::effect`, the valid ones in `running`); the player follows them and
//! plans its steps; the viewport is drawn — the player's compute and draws into the
//! composite's HDR target, bloom and tonemap, as `ignis render` does; egui's output is
//! painted and presented. The viewport is a host of the public runtime API, as any
//! program that embeds ignis. The steps live on `Gfx` (`gfx.rs`, `present.rs`); a lost
//! GPU device is recreated here, keeping the effect and its undo history.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context as _, anyhow};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

use crate::effect::Effect;
use crate::gpu::ProfileRequest;
use crate::hot_reload::FileWatcher;
use crate::render::OrbitCamera;

use crate::editor::state::EditorState;
use crate::editor::window::gfx::Gfx;
pub use crate::editor::window::run_report::RunReport;
use crate::editor::window::run_report::Tick;
use crate::editor::window::screenshot::{Screenshot, read_back};

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
    /// Viewport render scale (default: the adapter profile's).
    pub render_scale: Option<f32>,
    /// The adapter profile asked for instead of the adapter's own.
    pub adapter_profile: ProfileRequest,
    /// Fields of the editor's profile set on top of the set of the adapter's kind (the
    /// runtime's fields among them are ignored: they are in `adapter_profile`).
    pub editor_settings: Vec<super::editor_profile::AdaptSetting>,
    /// Drain the GPU after each frame stage and report where the time goes.
    pub profile: bool,
    /// Open exactly these panel sections at start (ids: emitter, look, …).
    pub sections: Option<Vec<String>>,
    /// Select this emitter (by name) at start.
    pub select: Option<String>,
    /// Draft viewport (default: on for software adapters).
    pub draft: Option<bool>,
    /// Start with the test scene shown (View → Test scene).
    pub test_scene: bool,
    /// Destroy the GPU device after this frame (tests the recovery from a lost device).
    pub lose_device_at: Option<u32>,
    /// With `lose_device_at`: edit the effect twice before the loss and undo once after
    /// it (`scripted_edits.rs`); the report says what the run ended with.
    pub edit_around_loss: bool,
    /// Start Time ▸ Measure this effect at launch over this span, seconds (scripted runs
    /// and screenshots).
    pub measure_span: Option<f64>,
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
            if let Some(span) = options.measure_span {
                state.measure.span_secs = span;
                state.measure.start_requested = true;
            }
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
        devices_recreated: 0,
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
    /// GPU devices lost and recreated so far.
    devices_recreated: u32,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        let gfx = open_window(event_loop, &self.options, &self.state)
            .and_then(|window| Gfx::new(window, &self.instance, &self.options, &self.state));
        match gfx {
            Ok(gfx) => {
                self.state.stats.adapter = gfx.ctx.info.name.clone();
                self.state.stats.ui_painter = gfx.ui_painter.name();
                // The adapter profile's render scale and draft quality, unless asked.
                self.state.view.render_scale = self
                    .options
                    .render_scale
                    .unwrap_or(gfx.editor_profile.render_scale)
                    .clamp(0.1, 1.0);
                self.state.view.draft = self.options.draft.unwrap_or(gfx.editor_profile.draft);
                self.state.view.test_scene |= self.options.test_scene;
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
        let _ = gfx.egui_state.on_window_event(&gfx.window, &event);
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

/// The editor's window, titled with the effect and where it came from.
fn open_window(
    event_loop: &ActiveEventLoop,
    options: &EditOptions,
    state: &EditorState,
) -> anyhow::Result<Arc<Window>> {
    let (w, h) = options.window_size;
    let attributes = Window::default_attributes()
        .with_title(format!("ignis — {} ({})", state.effect.name, state.source))
        .with_inner_size(winit::dpi::LogicalSize::new(w as f64, h as f64))
        .with_min_inner_size(winit::dpi::LogicalSize::new(640.0, 400.0));
    let window = event_loop
        .create_window(attributes)
        .context("creating the editor window")?;
    Ok(Arc::new(window))
}

impl App {
    /// One frame. Returns true when the editor should exit (`--frames` done).
    fn frame(&mut self) -> anyhow::Result<bool> {
        self.reload_changed_preset();
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(false);
        };
        gfx.reload_changed_sprites();
        if let (true, Some(n)) = (self.options.edit_around_loss, self.options.lose_device_at) {
            crate::editor::window::scripted_edits::apply(&mut self.state, gfx.log.index, n);
        }
        let tick = gfx.log.tick(self.options.frames);
        let ui = gfx.run_ui(&mut self.state, &mut self.camera);
        gfx.simulate(&mut self.state, tick.dt_secs);
        let cpu = gfx.draw_viewport(&mut self.state, &self.camera);
        gfx.update_stats(&mut self.state, &mut self.camera, tick, cpu);
        let painted = gfx.paint_ui(ui);
        let wanted = self.options.screenshot.clone().filter(|_| tick.is_last);
        let shot = gfx.present(painted, &self.instance, wanted)?;
        self.lose_device_when_asked();
        if let Some(reason) = self.gfx.as_ref().and_then(|g| g.ctx.lost()) {
            self.recreate_gpu(Some(&reason))?;
            return Ok(false);
        }
        if self.gfx.as_ref().is_some_and(|g| g.wants_fresh_device) {
            self.recreate_gpu(None)?;
            return Ok(false);
        }
        self.finish(tick, shot)
    }

    /// `--lose-device-at N`: destroys the device after frame N (a recovery test).
    fn lose_device_when_asked(&self) {
        if let Some(gfx) = &self.gfx
            && self
                .options
                .lose_device_at
                .is_some_and(|n| gfx.log.index == u64::from(n) && self.devices_recreated == 0)
        {
            log::warn!("destroying the GPU device (--lose-device-at)");
            gfx.ctx.device.destroy();
            // `destroy` reports the loss (calls the lost callback) only once the queue
            // drains, where a driver's loss is reported at once: wait for it, so that the
            // next frame never records onto the dead device.
            if let Err(err) = gfx.ctx.device.poll(wgpu::PollType::wait_indefinitely()) {
                log::warn!("waiting for the destroyed device's work: {err}");
            }
        }
    }

    /// A new device in the same window, with new pipelines, player and painter; the
    /// effect, the undo history and the rest of the editor's state are kept. After a loss
    /// (`lost`: why) the panel says so; without one the old device had held a large pool
    /// the effect no longer needs (small work on it stays slow), and the move is silent.
    fn recreate_gpu(&mut self, lost: Option<&str>) -> anyhow::Result<()> {
        let Some(old) = self.gfx.take() else {
            return Ok(());
        };
        match lost {
            Some(reason) => log::warn!("the GPU device was lost ({reason}); recreating it"),
            None => log::info!("moving to a fresh GPU device after a large pool was freed"),
        }
        let window = old.window.clone();
        let log = std::mem::take(&mut { old }.log);
        let mut gfx = Gfx::new(window, &self.instance, &self.options, &self.state)
            .context("recreating the GPU device")?;
        gfx.log = log;
        // The new player starts at time 0: nothing is parked, no frames were played.
        self.state.playback.parked_at = None;
        self.state.playback.frame_times.clear();
        if let Some(reason) = lost {
            self.devices_recreated += 1;
            self.state.device_notice = Some(format!(
                "The GPU device was lost ({reason}) and has been recreated; the effect and \
                 its undo history were kept."
            ));
        }
        gfx.window.request_redraw();
        self.gfx = Some(gfx);
        Ok(())
    }

    /// After the last frame of a `--frames` run: the screenshot saved and the report
    /// made. Returns true when the run is over.
    fn finish(&mut self, tick: Tick, shot: Option<Screenshot>) -> anyhow::Result<bool> {
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(false);
        };
        if !tick.is_last {
            return Ok(false);
        }
        if let Some(shot) = shot {
            let path = shot.path.clone();
            read_back(&gfx.ctx, shot)
                .with_context(|| format!("saving the screenshot {}", path.display()))?;
        } else if let Some(path) = &self.options.screenshot {
            // No frame this time: try again on the next one, but not forever.
            let wanted = u64::from(self.options.frames.unwrap_or(0));
            if gfx.log.index > wanted + MAX_EXTRA_FRAMES {
                return Err(anyhow!(
                    "no frame could be acquired from the window for the screenshot {}",
                    path.display()
                ));
            }
            return Ok(false);
        }
        let mut report = gfx.run_report(&mut self.state, self.devices_recreated);
        if self.options.edit_around_loss {
            report.edits = Some(crate::editor::window::scripted_edits::summary(
                &self.state,
                gfx.player.effect(),
            ));
        }
        self.report = Some(report);
        Ok(true)
    }

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
}
