//! Everything the editor UI edits or shows, without any GPU object: the panel and its
//! tests drive this struct with a plain `egui::Context`.

use crate::effect::{Effect, ValidationError};

use crate::editor::diagnostics::stats::Stats;
use crate::editor::undo::UndoHistory;

/// Viewing options that are not part of the effect (they do not change the fire, only
/// how the editor shows it).
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSettings {
    /// Exposure multiplier applied before tonemapping.
    pub exposure: f32,
    /// Draw the ground grid (y = 0, 0.5 m spacing).
    pub show_grid: bool,
    /// Light the grid with the effect's own light (`EditorState::fire_light`).
    pub fire_lights_grid: bool,
    /// Draw the wireframe of every emitter's spawn shape.
    pub show_gizmos: bool,
    /// Render the viewport at this fraction of its pixel size (upscaled when shown).
    pub render_scale: f32,
    /// Draft quality: large additive sprites (flame tongues) at half the render
    /// resolution, alpha-blended layers at half their own (`Renderer::draft`).
    pub draft: bool,
    /// Draw the test scene's props into the viewport and its depth (`Composite::test_scene`).
    pub test_scene: bool,
    /// Apply the effect's heat haze (`Composite::heat_haze`).
    pub heat_haze: bool,
    /// A sphere collider follows the pointer over the viewport: push the fire around.
    pub mouse_collider: bool,
    /// Show the particle under the pointer (or the one clicked) and the forces on it.
    pub inspect: bool,
    /// Show the selected emitter's state buffer as images.
    pub state_view: bool,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            exposure: 1.0,
            show_grid: true,
            fire_lights_grid: true,
            show_gizmos: true,
            render_scale: 1.0,
            draft: false,
            test_scene: false,
            heat_haze: true,
            mouse_collider: false,
            inspect: false,
            state_view: false,
        }
    }
}

/// Playback requests from the panel and the keyboard, consumed by the frame loop.
#[derive(Clone, Debug, PartialEq)]
pub struct Playback {
    /// The simulation is frozen (rendering goes on).
    pub is_paused: bool,
    /// Run exactly one step on the next frame (pauses).
    pub step_requested: bool,
    /// Kill every particle and restart time on the next frame.
    pub restart_requested: bool,
    /// Seek to this time on the next frame (the timeline; pauses there).
    pub seek_to: Option<f64>,
    /// The time the last seek parked at, while paused there: an edit re-simulates to it.
    pub parked_at: Option<f64>,
    /// Playback speed (the viewer's: the effect's own time settings are not changed).
    pub speed: f32,
    /// Play this span of the effect's time over and over (seconds).
    pub loop_region: Option<(f64, f64)>,
    /// The frames played since the last restart or seek (their durations, speed
    /// included): a frame-delta effect seeks by replaying them.
    pub frame_times: Vec<f64>,
}

impl Default for Playback {
    fn default() -> Self {
        Self {
            is_paused: false,
            step_requested: false,
            restart_requested: false,
            seek_to: None,
            parked_at: None,
            speed: 1.0,
            loop_region: None,
            frame_times: Vec::new(),
        }
    }
}

/// The editor's model: the effect under edit, the last valid one that runs, undo
/// history, playback and statistics.
pub struct EditorState {
    /// The effect the widgets edit.
    pub effect: Effect,
    /// The last valid effect: what the simulation runs.
    pub running: Effect,
    /// Why `effect` is not running (validation errors), empty when it is.
    pub validation_errors: Vec<ValidationError>,
    /// An effect the GPU refused (e.g. a capacity over a device limit) and why; not
    /// offered again until it changes.
    pub gpu_rejected: Option<(Effect, String)>,
    /// Shader errors from the last hot reload (the last good pipelines keep running).
    pub shader_errors: Vec<String>,
    /// Sprites that failed to load: (emitter index, message); the soft disc is drawn.
    pub sprite_errors: Vec<(usize, String)>,
    /// The effect's own light as last measured (the grid is lit by it).
    pub fire_light: Option<crate::runtime::EffectLight>,
    /// Why the effect's light on the scene is off (its shaders failed to build), until a
    /// shader reload builds them.
    pub light_error: Option<String>,
    /// Panel sections to open (all others closed) on the next frame, then cleared.
    pub open_sections: Option<Vec<String>>,
    /// The last simulation failure (the simulation pauses), until playback resumes.
    pub sim_error: Option<String>,
    /// The GPU device was lost and recreated (shown until dismissed).
    pub device_notice: Option<String>,
    /// View ▸ Inspect: the particle looked at.
    pub inspect: crate::editor::diagnostics::inspector::Inspect,
    /// Stats ▸ cost per emitter: the measurement in progress.
    pub cost_probe: Option<crate::editor::diagnostics::emitter_cost::CostProbe>,
    /// The effect the measurement plays now (instead of `running`).
    pub probe_effect: Option<crate::effect::Effect>,
    /// The last measurement's results.
    pub emitter_costs: Vec<crate::editor::diagnostics::emitter_cost::EmitterCost>,
    /// Index of the emitter shown in the emitter-specific sections.
    pub selected: usize,
    /// Undo/redo of `effect`.
    pub history: UndoHistory,
    /// Pause, single step, restart.
    pub playback: Playback,
    /// Exposure, grid, gizmos.
    pub view: ViewSettings,
    /// Frame and simulation statistics.
    pub stats: Stats,
    /// Set by the viewport (double-click) or the F key: frame the camera on the effect.
    pub frame_requested: bool,
    /// Where the mouse collider is (world metres), while it is on and the pointer is over
    /// the viewport. Not part of the effect: it is added to the simulated copy each frame.
    pub mouse_point: Option<glam::Vec3>,
    /// Where the effect was loaded from, for the title.
    pub source: String,
    /// The preset file Save writes and Load reads (edited in the header).
    pub preset_path: String,
    /// The outcome of the last save or load: `Ok(message)` or `Err(message)`.
    pub preset_message: Option<Result<String, String>>,
    /// The effect as last loaded or saved: the edited effect differs from it ⇒ unsaved.
    pub saved: Effect,
    /// The file the effect was loaded from or saved to (watched for external edits).
    pub loaded_path: Option<std::path::PathBuf>,
    /// An action that would discard unsaved edits, waiting for the user's confirmation.
    pub pending: Option<PendingAction>,
    /// The Export section and the export it runs.
    pub export: crate::editor::panel::export_ui::ExportPanel,
    /// Time ▸ Measure this effect: its settings, progress and last result.
    pub measure: crate::editor::panel::measure_ui::MeasurePanel,
}

/// Actions that discard unsaved edits, so they ask first.
#[derive(Clone, Debug, PartialEq)]
pub enum PendingAction {
    /// Load the preset at `preset_path`.
    Load,
    /// The loaded preset changed on disk: re-apply it.
    ExternalReload,
}

impl EditorState {
    /// A state editing `effect` (assumed valid; if not, the errors show at once and the
    /// simulation runs the effect anyway only once it is fixed).
    pub fn new(effect: Effect, source: impl Into<String>) -> Self {
        let validation_errors = effect.validate().err().unwrap_or_default();
        let effect_name = effect.name.clone();
        let effect_for_saved = effect.clone();
        Self {
            running: effect.clone(),
            history: UndoHistory::new(&effect),
            effect,
            validation_errors,
            gpu_rejected: None,
            sprite_errors: Vec::new(),
            fire_light: None,
            light_error: None,
            open_sections: None,
            sim_error: None,
            device_notice: None,
            inspect: Default::default(),
            cost_probe: None,
            probe_effect: None,
            emitter_costs: Vec::new(),
            shader_errors: Vec::new(),
            selected: 0,
            playback: Playback::default(),
            view: ViewSettings::default(),
            stats: Stats::default(),
            frame_requested: false,
            mouse_point: None,
            preset_path: format!("presets/my_{}.ron", crate::preset::file_stem(&effect_name)),
            preset_message: None,
            saved: effect_for_saved,
            loaded_path: None,
            pending: None,
            export: Default::default(),
            measure: Default::default(),
            source: source.into(),
        }
    }

    /// True when the edited effect differs from the last loaded or saved one.
    pub fn is_dirty(&self) -> bool {
        self.effect != self.saved
    }

    /// Load requested from the UI: asks first when there are unsaved edits.
    pub fn request_load(&mut self) {
        if self.is_dirty() {
            self.pending = Some(PendingAction::Load);
        } else {
            self.load_preset();
        }
    }

    /// Back to the last loaded or saved effect (one undo step).
    pub fn revert(&mut self) {
        self.history.observe(&self.effect, false);
        self.effect = self.saved.clone();
        self.history.observe(&self.effect, false);
        self.clamp_selection();
    }

    /// The loaded preset file changed on disk (an external editor saved it): re-apply it,
    /// or ask first when the panel has unsaved edits.
    pub fn preset_changed_on_disk(&mut self) {
        if self.is_dirty() {
            self.pending = Some(PendingAction::ExternalReload);
        } else {
            self.reload_from_disk();
        }
    }

    /// Carries out the pending action (the user confirmed discarding the edits).
    pub fn confirm_pending(&mut self) {
        match self.pending.take() {
            Some(PendingAction::Load) => self.load_preset(),
            Some(PendingAction::ExternalReload) => self.reload_from_disk(),
            None => {}
        }
    }

    fn reload_from_disk(&mut self) {
        if let Some(path) = &self.loaded_path {
            self.preset_path = path.display().to_string();
            self.load_preset();
        }
    }

    /// The folder the loaded preset's PNG sprite paths are relative to (`None`: the
    /// working directory).
    pub fn asset_dir(&self) -> Option<std::path::PathBuf> {
        self.loaded_path
            .as_deref()
            .and_then(std::path::Path::parent)
            .map(std::path::Path::to_path_buf)
    }

    /// Saves the edited effect to `preset_path` (atomically; only a valid effect).
    pub fn save_preset(&mut self) {
        let path = std::path::PathBuf::from(self.preset_path.trim());
        if let Err(why) = check_preset_name(&path) {
            self.preset_message = Some(Err(format!("{}: {why}", path.display())));
            return;
        }
        self.preset_message = Some(match crate::preset::save(&self.effect, &path) {
            Ok(()) => {
                self.saved = self.effect.clone();
                self.loaded_path = Some(path.clone());
                Ok(format!("saved {}", path.display()))
            }
            Err(err) => Err(err.to_string()),
        });
    }

    /// Replaces the edited effect with the preset at `preset_path` (one undo step; the
    /// particles of emitters with the same names keep burning).
    pub fn load_preset(&mut self) {
        let path = std::path::PathBuf::from(self.preset_path.trim());
        self.preset_message = Some(match crate::preset::load(&path) {
            Ok(effect) => {
                self.history.observe(&self.effect, false);
                self.saved = effect.clone();
                self.loaded_path = Some(path.clone());
                self.pending = None;
                self.effect = effect;
                self.history.observe(&self.effect, false);
                self.source = path.display().to_string();
                self.clamp_selection();
                Ok(format!("loaded {}", path.display()))
            }
            Err(err) => Err(err.to_string()),
        });
    }

    /// End-of-frame bookkeeping after the UI ran: handles the undo/redo and playback
    /// shortcuts, records an undo step when a gesture ended, validates the edited effect
    /// and promotes it to `running` when valid. Returns true when `running` changed.
    pub fn end_frame(&mut self, ctx: &egui::Context) -> bool {
        self.handle_shortcuts(ctx);
        if !self.playback.is_paused {
            self.sim_error = None;
        }
        let is_interacting = ctx.input(|i| i.pointer.any_down()) || ctx.text_edit_focused();
        self.history.observe(&self.effect, is_interacting);
        self.apply()
    }

    /// Validates `effect` and makes it the running effect when valid. Returns true when
    /// `running` changed.
    pub fn apply(&mut self) -> bool {
        self.clamp_selection();
        if self.effect == self.running {
            // Back to what runs (e.g. after an undo): nothing to report any more.
            self.validation_errors.clear();
            self.gpu_rejected = None;
            return false;
        }
        match self.effect.validate() {
            Ok(()) => {
                self.validation_errors.clear();
                let refused = self
                    .gpu_rejected
                    .as_ref()
                    .is_some_and(|(e, _)| *e == self.effect);
                if refused {
                    return false;
                }
                self.gpu_rejected = None;
                self.running.clone_from(&self.effect);
                true
            }
            Err(errors) => {
                self.validation_errors = errors;
                false
            }
        }
    }

    /// The GPU refused `running`: go back to `last_good` and remember why.
    pub fn reject_running(&mut self, last_good: &Effect, reason: String) {
        self.gpu_rejected = Some((self.running.clone(), reason));
        self.running.clone_from(last_good);
    }

    /// Undoes the last edit. Returns false when there was nothing to undo.
    pub fn undo(&mut self) -> bool {
        let done = self.history.undo(&mut self.effect);
        self.clamp_selection();
        done
    }

    /// Redoes the last undone edit. Returns false when there was nothing to redo.
    pub fn redo(&mut self) -> bool {
        let done = self.history.redo(&mut self.effect);
        self.clamp_selection();
        done
    }

    fn clamp_selection(&mut self) {
        self.selected = self
            .selected
            .min(self.effect.emitters.len().saturating_sub(1));
    }

    fn handle_shortcuts(&mut self, ctx: &egui::Context) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        // A focused text field has its own undo and takes every key.
        if ctx.text_edit_focused() {
            return;
        }
        let redo = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        let redo_y = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
        let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
        // Shift+Z first: `consume_shortcut` matches logically, so Ctrl+Z would also
        // match Ctrl+Shift+Z.
        let (do_redo, do_undo, pause, step, restart, frame) = ctx.input_mut(|i| {
            let do_redo = i.consume_shortcut(&redo) || i.consume_shortcut(&redo_y);
            let do_undo = i.consume_shortcut(&undo);
            (
                do_redo,
                do_undo,
                i.consume_key(Modifiers::NONE, Key::Space),
                i.consume_key(Modifiers::NONE, Key::Period),
                i.consume_key(Modifiers::NONE, Key::R),
                i.consume_key(Modifiers::NONE, Key::F),
            )
        });
        if do_redo {
            self.redo();
        } else if do_undo {
            self.undo();
        }
        if pause {
            self.playback.is_paused = !self.playback.is_paused;
        }
        if step {
            self.playback.step_requested = true;
        }
        if restart {
            self.playback.restart_requested = true;
        }
        if frame {
            self.frame_requested = true;
        }
    }
}

/// "Save as" names: a `.ron` file whose stem is letters, digits, `_` or `-`.
pub fn check_preset_name(path: &std::path::Path) -> Result<(), String> {
    if path.extension().is_none_or(|x| x != "ron") {
        return Err("a preset file name must end in .ron".into());
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    if stem.is_empty()
        || !stem
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(format!(
            "the name \"{stem}\" may use only letters, digits, _ and -"
        ));
    }
    Ok(())
}

/// Radius of the mouse collider, metres.
pub const MOUSE_COLLIDER_RADIUS_M: f32 = 0.25;

/// `effect` with the mouse collider (a sphere at `point`) added to every enabled emitter
/// that has room for one more sphere.
pub fn with_mouse_collider(effect: &Effect, point: Option<glam::Vec3>) -> Effect {
    let mut out = effect.clone();
    if let Some(p) = point {
        for e in out.emitters.iter_mut().filter(|e| e.enabled) {
            if e.collisions.spheres.len() < crate::effect::MAX_SPHERES {
                e.collisions.spheres.push(crate::effect::SphereCollider {
                    center_m: p.to_array(),
                    radius_m: MOUSE_COLLIDER_RADIUS_M,
                });
            }
        }
    }
    out
}
