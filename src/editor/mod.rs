//! The editor: a winit window with an egui side panel and a 3D viewport of the running
//! effect.
//!
//! The UI is plain functions over [`EditorState`] (no GPU needed, so tests drive them
//! with an `egui::Context`), in rooms: [`panel`] (one file per section of the side panel,
//! the timeline and the viewport), [`window`] (the window, the frame loop and the GPU
//! owner) and [`diagnostics`] (statistics, the inspector, costs and profiles).

pub mod diagnostics;
pub mod panel;
pub mod state;
pub mod undo;
pub mod window;

pub use state::EditorState;
pub use window::app::{EditOptions, run};
