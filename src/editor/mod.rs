//! The editor: a winit window with an egui side panel and a 3D viewport of the running
//! effect.
//!
//! The UI is plain functions over [`EditorState`] (no GPU needed, so tests drive them
//! with an `egui::Context`); [`app`] owns the window and the frame loop.

pub mod app;
pub mod curve_editor;
pub mod emitter_cost;
mod emitter_ui;
pub mod events_ui;
pub mod export_ui;
mod forces_ui;
mod gfx;
pub mod inspect;
mod lighting_ui;
pub mod look;
pub mod measure_ui;
pub mod panel;
mod present;
pub mod profile;
pub mod report;
pub mod retained;
pub mod screenshot;
mod scripted_edits;
pub mod state;
pub mod stats;
mod time_ui;
pub mod timeline;
pub mod ui_painter;
pub mod undo;
pub mod viewport;

pub use app::{EditOptions, RunReport, run};
pub use state::{EditorState, Playback, ViewSettings};
pub use undo::UndoHistory;
