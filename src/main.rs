//! The `ignis` binary: the editor, the renderer, the exporter and the benches
//! (`ignis --help`).

fn main() {
    ignis::cli::main();
}
