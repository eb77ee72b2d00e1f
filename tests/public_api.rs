//! The runtime's public API is a conscious choice: `cargo doc` of the runtime-only build
//! (`--no-default-features`) lists exactly the items in `docs/public-api.txt`. A new public
//! item, or one that went missing, fails here; after deciding it belongs, update the file
//! with `IGNIS_UPDATE_API=1 cargo test --release --test public_api`.

mod common;

use std::path::Path;

/// The documented items of `all.html` (rustdoc's list of every public item), one
/// "kind path" per line, sorted: `struct Player`, `fn preset::load`.
fn items_of(all_html: &str) -> Vec<String> {
    const KINDS: [&str; 9] = [
        "struct", "enum", "fn", "constant", "trait", "type", "macro", "static", "union",
    ];
    let mut items: Vec<String> = all_html
        .split("href=\"")
        .skip(1)
        .filter_map(|rest| {
            let href = rest.split('"').next()?.strip_suffix(".html")?;
            let (dir, file) = href.rsplit_once('/').unwrap_or(("", href));
            let (kind, name) = file.split_once('.')?;
            if !KINDS.contains(&kind) || dir.starts_with('.') {
                return None;
            }
            let path = if dir.is_empty() {
                name.to_owned()
            } else {
                format!("{}::{name}", dir.replace('/', "::"))
            };
            Some(format!("{kind} {path}"))
        })
        .collect();
    items.sort();
    items.dedup();
    items
}

#[test]
fn the_runtime_api_is_the_committed_list() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // A target of its own: the tests' own build holds the usual one. CI's documentation
    // check of the runtime builds into it first, with the same flags, so this is then a
    // freshness check.
    let target = root.join("target").join("api-doc");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    common::run_ok(
        std::process::Command::new(cargo)
            .current_dir(root)
            .args(["doc", "--offline", "--locked", "--no-deps"])
            .arg("--no-default-features")
            .env("CARGO_TARGET_DIR", &target)
            .env("RUSTDOCFLAGS", "-D warnings"),
    );
    let html = std::fs::read_to_string(target.join("doc/ignis/all.html")).expect("all.html");
    let items = items_of(&html);
    assert!(items.len() > 50, "{} items read", items.len());
    let listed = root.join("docs/public-api.txt");
    let text = items.join("\n") + "\n";
    if std::env::var_os("IGNIS_UPDATE_API").is_some() {
        std::fs::write(&listed, &text).expect("write docs/public-api.txt");
    }
    let committed = std::fs::read_to_string(&listed).expect("docs/public-api.txt");
    let want: Vec<&str> = committed.lines().collect();
    let new: Vec<&String> = items
        .iter()
        .filter(|i| !want.contains(&i.as_str()))
        .collect();
    let gone: Vec<&&str> = want
        .iter()
        .filter(|w| !items.contains(&w.to_string()))
        .collect();
    assert!(
        new.is_empty() && gone.is_empty(),
        "the public API changed: new {new:?}, gone {gone:?}; if intended, update \
         docs/public-api.txt (IGNIS_UPDATE_API=1 cargo test --release --test public_api)"
    );
}

/// The reader finds items at the root and in modules, skips pages that are not items.
#[test]
fn the_item_list_reads_rustdocs_links() {
    let html = r#"<a href="struct.Player.html">Player</a>
        <a href="preset/fn.load.html">load</a>
        <a href="effect/enum.Param.html">Param</a>
        <a href="../static.files/rustdoc.css">x</a>
        <a href="index.html">i</a><a href="struct.Player.html">again</a>"#;
    assert_eq!(
        items_of(html),
        ["enum effect::Param", "fn preset::load", "struct Player"]
    );
}
