//! Hot reload: watch files with `notify` (debounced, so an editor's truncate-then-write
//! or rename-replace save arrives as one change), and rebuild only the pipelines that
//! depend on a changed shader. A failed rebuild keeps the last good pipeline — and the
//! particles, which live in buffers no reload touches.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use notify_debouncer_full::{DebounceEventResult, Debouncer, RecommendedCache, new_debouncer};

use crate::composite::Composite;
use crate::gpu::GpuContext;
use crate::runtime::Player;
use crate::shaders::{ENTRY_FILES, ShaderError, ShaderLibrary};

/// How long the debouncer waits for a burst of file events to settle.
pub const DEBOUNCE: Duration = Duration::from_millis(80);

/// Watches folders (non-recursively) and reports changed files.
pub struct FileWatcher {
    _debouncer: Debouncer<notify::RecommendedWatcher, RecommendedCache>,
    rx: Receiver<DebounceEventResult>,
}

impl FileWatcher {
    /// Watches every folder in `dirs`.
    pub fn new(dirs: &[&Path]) -> Result<Self, notify::Error> {
        let (tx, rx) = channel();
        let mut debouncer = new_debouncer(DEBOUNCE, None, tx)?;
        for dir in dirs {
            debouncer.watch(dir, notify::RecursiveMode::NonRecursive)?;
        }
        Ok(Self {
            _debouncer: debouncer,
            rx,
        })
    }

    /// Files changed since the last call (deduplicated), without blocking. Creations,
    /// modifications, renames onto a name and removals all count.
    pub fn poll(&self) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = Vec::new();
        while let Ok(result) = self.rx.try_recv() {
            match result {
                Ok(events) => {
                    for e in events {
                        if matches!(e.kind, notify::EventKind::Access(_)) {
                            continue;
                        }
                        for p in &e.paths {
                            if !out.contains(p) {
                                out.push(p.clone());
                            }
                        }
                    }
                }
                Err(errors) => {
                    for e in errors {
                        log::warn!("file watcher: {e}");
                    }
                }
            }
        }
        out
    }

    /// Waits up to `timeout` for changes (tests and tools).
    pub fn wait(&self, timeout: Duration) -> Vec<PathBuf> {
        let deadline = Instant::now() + timeout;
        loop {
            let changed = self.poll();
            if !changed.is_empty() || Instant::now() >= deadline {
                return changed;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

/// What a reload did.
#[derive(Debug, Default)]
pub struct ReloadReport {
    /// Entry files whose pipelines were rebuilt and swapped in.
    pub rebuilt: Vec<&'static str>,
    /// Entry files whose rebuild failed (the old pipelines keep running).
    pub failed: Vec<&'static str>,
}

/// Tracks which pipelines depend on which shader files, rebuilds the affected ones and
/// keeps the current errors (one per entry file) for the UI.
pub struct ShaderReloader {
    deps: BTreeMap<&'static str, Vec<String>>,
    /// Current errors, per entry file; cleared when that entry rebuilds.
    pub errors: BTreeMap<&'static str, ShaderError>,
    /// File change → new pipeline in use, of the last successful reload.
    pub last_latency: Option<Duration>,
}

impl ShaderReloader {
    /// Records the dependencies of every entry file in `lib`.
    pub fn new(lib: &ShaderLibrary) -> Self {
        let mut deps = BTreeMap::new();
        for entry in ENTRY_FILES {
            let files = lib
                .dependencies(entry)
                .unwrap_or_else(|_| vec![(*entry).to_owned()]);
            deps.insert(*entry, files);
        }
        Self {
            deps,
            errors: BTreeMap::new(),
            last_latency: None,
        }
    }

    /// The entry files that depend on any of `changed` (file names like "forces.wgsl";
    /// a failed entry also depends on every file, since its imports are unknown).
    pub fn affected(&self, changed: &[String]) -> Vec<&'static str> {
        ENTRY_FILES
            .iter()
            .copied()
            .filter(|entry| {
                self.errors.contains_key(entry)
                    || self
                        .deps
                        .get(entry)
                        .is_some_and(|files| files.iter().any(|f| changed.contains(f)))
            })
            .collect()
    }

    /// Rebuilds the pipelines affected by `changed` from the WGSL in `dir`: the player's
    /// through its public [`Player::reload_shader`], the composite's own. `changed_at` is
    /// when the change was noticed (for the latency figure).
    pub fn reload(
        &mut self,
        ctx: &GpuContext,
        dir: &Path,
        player: &mut Player,
        composite: &mut Composite,
        changed: &[String],
        changed_at: Instant,
    ) -> ReloadReport {
        let lib = ShaderLibrary::from_dir(dir);
        let mut report = ReloadReport::default();
        for entry in self.affected(changed) {
            let result = if crate::PLAYER_SHADERS.contains(&entry) {
                player.reload_shader(dir, entry)
            } else {
                composite.reload_shader(ctx, &lib, entry)
            };
            match result {
                Ok(()) => {
                    if let Ok(files) = lib.dependencies(entry) {
                        self.deps.insert(entry, files);
                    }
                    if self.errors.remove(entry).is_some() {
                        log::info!("{entry}: fixed, new pipeline in use");
                    }
                    report.rebuilt.push(entry);
                }
                Err(e) => {
                    log::error!("shader reload failed, keeping the last good pipeline:\n{e}");
                    self.errors.insert(entry, e);
                    report.failed.push(entry);
                }
            }
        }
        if !report.rebuilt.is_empty() && report.failed.is_empty() {
            self.last_latency = Some(changed_at.elapsed());
        }
        report
    }
}

/// File names (not paths) of the `.wgsl` files among `paths`.
pub fn wgsl_names(paths: &[PathBuf]) -> Vec<String> {
    paths
        .iter()
        .filter(|p| p.extension().is_some_and(|x| x == "wgsl"))
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect()
}
