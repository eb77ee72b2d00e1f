//! Benchmarks as commands: they print tables and write Markdown + JSON (+ CSV, SVG)
//! under `bench/results/`, with the adapter, driver and command line that produced them.

pub mod accuracy;
pub mod adapters;
pub mod export;
pub mod perf;
pub mod presets;
pub mod report;
pub mod runtime;

pub use report::Report;
