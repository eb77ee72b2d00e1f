//! The house rules the source keeps (docs/architecture.md). Layers: `gpu` (with
//! `shaders`, `rng`) → the model (`effect`, `preset`) → `sim` → `render` → `runtime` → the
//! clients (`composite`, `headless`, `export`, `editor`, `bench`, `tune`, `hot_reload`); no
//! module names one above it — every `crate::…` path in `src/` (code, and doc links) is
//! read and its target's layer compared with the file's. And no file over 800 lines.

use std::path::Path;

/// The layer of a top-level module (`None`: the crate root, which ties them together).
fn layer(module: &str) -> Option<u32> {
    Some(match module {
        "gpu" | "shaders" | "rng" => 0,
        "effect" | "preset" => 1,
        "sim" => 2,
        "render" => 3,
        "runtime" => 4,
        "composite" | "headless" | "export" | "editor" | "bench" | "tune" | "hot_reload"
        | "cli" | "testing" => 5,
        _ => return None,
    })
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src").flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level modules a line names through `crate::`: `crate::a::…` and each first
/// name of `crate::{a, b::…}`.
fn named(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find("crate::") {
        rest = &rest[at + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let inner = group.split('}').next().unwrap_or_default();
            out.extend(inner.split(',').filter_map(|p| {
                let first = p.trim().split("::").next()?.trim();
                (!first.is_empty()).then(|| first.to_owned())
            }));
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.push(name);
        }
    }
    out
}

/// The layer check itself, on `(file, top-level module, text)`: every breach as
/// "file:line names `target` (layer n) from `module` (layer m)".
fn breaches(files: &[(String, String, String)]) -> Vec<String> {
    let mut found = Vec::new();
    for (file, module, text) in files {
        let Some(own) = layer(module) else {
            continue;
        };
        for (n, line) in text.lines().enumerate() {
            for target in named(line) {
                if let Some(theirs) = layer(&target).filter(|t| *t > own) {
                    found.push(format!(
                        "{file}:{} names `{target}` (layer {theirs}) from `{module}` (layer {own})",
                        n + 1
                    ));
                }
            }
        }
    }
    found
}

#[test]
fn no_module_imports_one_above_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut paths = Vec::new();
    sources(&root, &mut paths);
    let files: Vec<(String, String, String)> = paths
        .iter()
        .map(|p| {
            let rel = p.strip_prefix(&root).expect("under src");
            let first = rel.components().next().expect("a component");
            let module = first
                .as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_owned();
            let text = std::fs::read_to_string(p).expect("read");
            (rel.display().to_string(), module, text)
        })
        .collect();
    assert!(files.len() > 100, "{} source files", files.len());
    let unknown: Vec<&String> = files
        .iter()
        .map(|f| &f.1)
        .filter(|m| layer(m).is_none() && !["lib", "main"].contains(&m.as_str()))
        .collect();
    assert!(unknown.is_empty(), "modules with no layer: {unknown:?}");
    let found = breaches(&files);
    assert!(
        found.is_empty(),
        "imports above their layer:\n{}",
        found.join("\n")
    );
}

/// The check finds what it must: a `gpu` file naming `sim`, a grouped `use` naming
/// `runtime` from `render`, and lets a client name anything.
#[test]
fn the_layer_check_catches_an_import_from_above() {
    let file = |f: &str, m: &str, t: &str| (f.to_owned(), m.to_owned(), t.to_owned());
    let found = breaches(&[
        file("gpu/timer.rs", "gpu", "use crate::sim::gpu_sim::map_read;"),
        file(
            "render/x.rs",
            "render",
            "use crate::{gpu::GpuContext, runtime::Player};",
        ),
        file(
            "editor/y.rs",
            "editor",
            "use crate::{render::Camera, runtime::Player};",
        ),
    ]);
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(found[0].starts_with("gpu/timer.rs:1 names `sim`"));
    assert!(found[1].starts_with("render/x.rs:1 names `runtime`"));
}

/// One concern per file: no source file over 800 lines (split a file by type first).
#[test]
fn no_source_file_is_over_800_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut paths = Vec::new();
    sources(&root, &mut paths);
    let long: Vec<String> = paths
        .iter()
        .filter_map(|p| {
            let n = std::fs::read_to_string(p).expect("read").lines().count();
            (n > 800).then(|| format!("{} ({n} lines)", p.display()))
        })
        .collect();
    assert!(long.is_empty(), "files over 800 lines: {long:?}");
}

/// The functions of `text` longer than `max` lines, as "name (n lines)": a function runs
/// from its `fn` line to the first line that closes at its indentation.
fn long_functions(text: &str, max: usize) -> Vec<String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let indent = &line[..line.len() - trimmed.len()];
        let signature = [
            "pub fn ",
            "pub(crate) fn ",
            "pub(super) fn ",
            "fn ",
            "const fn ",
        ]
        .iter()
        .find_map(|p| trimmed.strip_prefix(p));
        let Some(rest) = signature else {
            continue;
        };
        if trimmed.ends_with(';') {
            continue;
        }
        let close = format!("{indent}}}");
        let end = lines[i + 1..]
            .iter()
            .position(|l| l.starts_with(&close))
            .map_or(lines.len(), |p| i + 1 + p);
        let n = end - i + 1;
        if n > max {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            found.push(format!("{name} ({n} lines)"));
        }
    }
    found
}

/// No function over 100 lines in the crate, its tests, examples and the Bevy plugin, but
/// for tables of cases (a list of data, read as one).
#[test]
fn no_function_is_over_100_lines() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths = Vec::new();
    for dir in [
        "src",
        "tests",
        "examples",
        "crates/bevy_ignis",
        "crates/bench_hanabi",
    ] {
        sources(&base.join(dir), &mut paths);
    }
    let tables = ["malformed_cases"];
    let long: Vec<String> = paths
        .iter()
        .filter(|p| !p.components().any(|c| c.as_os_str() == "target"))
        .flat_map(|p| {
            let text = std::fs::read_to_string(p).expect("read");
            long_functions(&text, 100)
                .into_iter()
                .filter(|f| !tables.iter().any(|t| f.starts_with(&format!("{t} "))))
                .map(move |f| format!("{}: {f}", p.display()))
        })
        .collect();
    assert!(paths.len() > 150, "{} files read", paths.len());
    assert!(long.is_empty(), "functions over 100 lines: {long:#?}");
}

/// The length check counts a function from `fn` to its closing brace, nested ones apart.
#[test]
fn the_length_check_counts_to_the_closing_brace() {
    let body = "    let x = 1;\n".repeat(100);
    let text = format!("fn long() {{\n{body}}}\n\nfn short() {{\n    inner();\n}}\n");
    assert_eq!(long_functions(&text, 100), ["long (102 lines)"]);
    assert!(long_functions(&text, 102).is_empty());
    let nested = format!("impl A {{\n    pub fn f() {{\n{body}    }}\n}}\n");
    assert_eq!(long_functions(&nested, 100), ["f (102 lines)"]);
}

/// `docs/architecture.md` is a map of every file: each source file of the crate, its
/// shaders, tests, examples and the Bevy plugin is named there (by its path).
#[test]
fn every_source_file_is_on_the_map() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    let map = std::fs::read_to_string(base.join("docs/architecture.md")).expect("read");
    let mut paths = Vec::new();
    for dir in [
        "src",
        "tests",
        "examples",
        "crates/bevy_ignis/src",
        "crates/bench_hanabi/src",
    ] {
        sources(&base.join(dir), &mut paths);
    }
    for entry in std::fs::read_dir(base.join("shaders"))
        .expect("shaders")
        .flatten()
    {
        paths.push(entry.path());
    }
    let missing: Vec<String> = paths
        .iter()
        .map(|p| {
            p.strip_prefix(base)
                .expect("under the crate")
                .display()
                .to_string()
        })
        .filter(|rel| !rel.starts_with("tests/fixtures") && !map.contains(&format!("`{rel}`")))
        .collect();
    assert!(paths.len() > 200, "{} files read", paths.len());
    assert!(
        missing.is_empty(),
        "files docs/architecture.md does not name: {missing:?}"
    );
}
