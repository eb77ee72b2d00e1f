//! The editor's window and what puts pixels in it: the event loop and the frame
//! ([`app`]), the GPU owner ([`gfx`]: device, surface, player, composite), presenting the
//! frame ([`present`]), egui's painters ([`ui_painter`]), the retained window of software
//! adapters ([`retained`]), screenshots ([`screenshot`]), the scripted edits of the
//! device-loss test ([`scripted_edits`]) and the report of a `--frames` run
//! ([`run_report`]).

pub mod app;
pub mod editor_profile;
pub mod gfx;
pub mod present;
pub mod retained;
pub mod run_report;
pub mod screenshot;
pub mod scripted_edits;
pub mod ui_painter;
