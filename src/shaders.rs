//! The shader library: WGSL read from `shaders/` (or the copies embedded in the binary),
//! composed with `#import "file.wgsl"`, validated with naga, and errors located at the
//! original file, line and column with a caret snippet.
//!
//! Composition is a small resolver rather than naga_oil: every `#import` line is replaced
//! by the imported file (once per pipeline, so diamonds and cycles are harmless) and every
//! output line remembers where it came from, so naga's error positions map back to the
//! file the designer is editing.

use std::path::{Path, PathBuf};

/// Every shader file embedded in the binary (the fallback when there is no `shaders/`).
pub const EMBEDDED: &[(&str, &str)] = &[
    ("common.wgsl", include_str!("../shaders/common.wgsl")),
    ("rng.wgsl", include_str!("../shaders/rng.wgsl")),
    ("curves.wgsl", include_str!("../shaders/curves.wgsl")),
    ("noise.wgsl", include_str!("../shaders/noise.wgsl")),
    ("spawn.wgsl", include_str!("../shaders/spawn.wgsl")),
    ("forces.wgsl", include_str!("../shaders/forces.wgsl")),
    (
        "integrators.wgsl",
        include_str!("../shaders/integrators.wgsl"),
    ),
    ("collide.wgsl", include_str!("../shaders/collide.wgsl")),
    ("depth_off.wgsl", include_str!("../shaders/depth_off.wgsl")),
    ("depth_on.wgsl", include_str!("../shaders/depth_on.wgsl")),
    (
        "events_off.wgsl",
        include_str!("../shaders/events_off.wgsl"),
    ),
    ("events_on.wgsl", include_str!("../shaders/events_on.wgsl")),
    ("events.wgsl", include_str!("../shaders/events.wgsl")),
    (
        "event_types.wgsl",
        include_str!("../shaders/event_types.wgsl"),
    ),
    (
        "trail_ring.wgsl",
        include_str!("../shaders/trail_ring.wgsl"),
    ),
    ("trail_off.wgsl", include_str!("../shaders/trail_off.wgsl")),
    ("trail_on.wgsl", include_str!("../shaders/trail_on.wgsl")),
    ("trail.wgsl", include_str!("../shaders/trail.wgsl")),
    (
        "alive_count.wgsl",
        include_str!("../shaders/alive_count.wgsl"),
    ),
    ("update.wgsl", include_str!("../shaders/update.wgsl")),
    ("params.wgsl", include_str!("../shaders/params.wgsl")),
    (
        "params_instanced.wgsl",
        include_str!("../shaders/params_instanced.wgsl"),
    ),
    (
        "state_full.wgsl",
        include_str!("../shaders/state_full.wgsl"),
    ),
    (
        "state_packed.wgsl",
        include_str!("../shaders/state_packed.wgsl"),
    ),
    (
        "state_tiny.wgsl",
        include_str!("../shaders/state_tiny.wgsl"),
    ),
    ("births.wgsl", include_str!("../shaders/births.wgsl")),
    ("count.wgsl", include_str!("../shaders/count.wgsl")),
    ("look.wgsl", include_str!("../shaders/look.wgsl")),
    ("lit.wgsl", include_str!("../shaders/lit.wgsl")),
    (
        "sprite_trim.wgsl",
        include_str!("../shaders/sprite_trim.wgsl"),
    ),
    (
        "raster_edges.wgsl",
        include_str!("../shaders/raster_edges.wgsl"),
    ),
    ("quad.wgsl", include_str!("../shaders/quad.wgsl")),
    ("billboard.wgsl", include_str!("../shaders/billboard.wgsl")),
    ("tiles.wgsl", include_str!("../shaders/tiles.wgsl")),
    (
        "sprite_project.wgsl",
        include_str!("../shaders/sprite_project.wgsl"),
    ),
    (
        "tile_lists.wgsl",
        include_str!("../shaders/tile_lists.wgsl"),
    ),
    ("splat.wgsl", include_str!("../shaders/splat.wgsl")),
    (
        "splat_accum.wgsl",
        include_str!("../shaders/splat_accum.wgsl"),
    ),
    (
        "splat_accum64.wgsl",
        include_str!("../shaders/splat_accum64.wgsl"),
    ),
    ("sort.wgsl", include_str!("../shaders/sort.wgsl")),
    ("tonemap.wgsl", include_str!("../shaders/tonemap.wgsl")),
    ("bloom.wgsl", include_str!("../shaders/bloom.wgsl")),
    ("clear.wgsl", include_str!("../shaders/clear.wgsl")),
    (
        "haze_apply.wgsl",
        include_str!("../shaders/haze_apply.wgsl"),
    ),
    (
        "test_scene.wgsl",
        include_str!("../shaders/test_scene.wgsl"),
    ),
    (
        "depth_resolve.wgsl",
        include_str!("../shaders/depth_resolve.wgsl"),
    ),
    ("light.wgsl", include_str!("../shaders/light.wgsl")),
    (
        "light_apply.wgsl",
        include_str!("../shaders/light_apply.wgsl"),
    ),
    (
        "particle_bindings.wgsl",
        include_str!("../shaders/particle_bindings.wgsl"),
    ),
    (
        "workgroup_scan.wgsl",
        include_str!("../shaders/workgroup_scan.wgsl"),
    ),
];

/// The packed-state update: update.wgsl with state_packed.wgsl composed in place of
/// state_full.wgsl (the state I/O).
pub const PACKED_STATE_IO: (&str, &str) = ("state_full.wgsl", "state_packed.wgsl");

/// The tiny-state update: update.wgsl with state_tiny.wgsl as the state I/O.
pub const TINY_STATE_IO: (&str, &str) = ("state_full.wgsl", "state_tiny.wgsl");

/// The batched update of a runtime player's instances: one SimParams per instance, each
/// instance's pool a segment of shared buffers (see `params_instanced.wgsl`).
pub const PARAMS_INSTANCED: (&str, &str) = ("params.wgsl", "params_instanced.wgsl");

/// The update of an emitter with events or fed by them: events_on.wgsl (the hooks and
/// their bindings) in place of events_off.wgsl (nothing).
pub const EVENTS_IO: (&str, &str) = ("events_off.wgsl", "events_on.wgsl");

/// The update of an emitter with a trail: trail_on.wgsl (the ring of positions) in
/// place of trail_off.wgsl (nothing).
pub const TRAIL_IO: (&str, &str) = ("trail_off.wgsl", "trail_on.wgsl");

/// The splat's accumulation where the device has 64-bit atomics: one u64 per pixel
/// (splat_accum64.wgsl) in place of three u32 (splat_accum.wgsl).
pub const SPLAT_ACCUM64: (&str, &str) = ("splat_accum.wgsl", "splat_accum64.wgsl");

/// The update of an emitter that collides with the host's depth buffer: depth_on.wgsl
/// (the march and its group 2) in place of depth_off.wgsl (nothing).
pub const DEPTH_IO: (&str, &str) = ("depth_off.wgsl", "depth_on.wgsl");

/// Imports that some pipelines replace by another file (see
/// [`ShaderLibrary::compose_with`]).
pub const IMPORT_VARIANTS: &[(&str, &str)] = &[
    PACKED_STATE_IO,
    TINY_STATE_IO,
    PARAMS_INSTANCED,
    EVENTS_IO,
    TRAIL_IO,
    SPLAT_ACCUM64,
];

/// The entry files, one per pipeline family; the others are imported by them.
pub const ENTRY_FILES: &[&str] = &[
    "update.wgsl",
    "count.wgsl",
    "events.wgsl",
    "billboard.wgsl",
    "splat.wgsl",
    "tiles.wgsl",
    "sort.wgsl",
    "tonemap.wgsl",
    "bloom.wgsl",
    "clear.wgsl",
    "depth_resolve.wgsl",
    "light.wgsl",
    "light_apply.wgsl",
    "test_scene.wgsl",
    "haze_apply.wgsl",
];

/// A shader problem, located in the file the user edits.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShaderError {
    /// A file could not be read.
    #[error("{path}: cannot read shader: {reason}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        reason: String,
    },
    /// A parse, validation, import or pipeline error at a known place.
    #[error("{0}")]
    Located(Box<LocatedError>),
    /// An error wgpu reported that has no source position (e.g. a layout mismatch).
    #[error("{file}: {message}")]
    Pipeline {
        /// The entry file of the pipeline.
        file: String,
        /// wgpu's message.
        message: String,
    },
}

/// An error with a file, line and column, formatted like rustc/naga with a caret.
#[derive(Clone, Debug, PartialEq)]
pub struct LocatedError {
    /// Path of the file (as shown to the user).
    pub file: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub column: u32,
    /// What is wrong.
    pub message: String,
    /// The source line and a caret under the problem.
    pub snippet: String,
}

impl std::fmt::Display for LocatedError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "error: {}\n  --> {}:{}:{}\n{}",
            self.message, self.file, self.line, self.column, self.snippet
        )
    }
}

impl ShaderError {
    /// The `(file, line, column)` of the problem when known.
    pub fn location(&self) -> Option<(&str, u32, u32)> {
        match self {
            ShaderError::Located(e) => Some((&e.file, e.line, e.column)),
            _ => None,
        }
    }
}

/// Where shader files come from.
#[derive(Clone, Debug, PartialEq)]
pub enum ShaderSourceDir {
    /// The copies compiled into the binary.
    Embedded,
    /// A folder on disk (hot-reloadable).
    Dir(PathBuf),
}

/// Reads and composes shaders.
#[derive(Clone, Debug)]
pub struct ShaderLibrary {
    source: ShaderSourceDir,
    /// Files replaced in memory (the bench's bare variant).
    overrides: Vec<(String, String)>,
}

/// A composed, validated shader: one WGSL string for one pipeline.
#[derive(Debug)]
pub struct Composed {
    /// The entry file name.
    pub entry: String,
    /// The full WGSL text.
    pub source: String,
    /// Every file this pipeline depends on (entry first).
    pub files: Vec<String>,
    /// The naga module (validated).
    pub module: naga::Module,
    /// For each output line (0-based): (file index into `files`, 1-based line in that file).
    line_map: Vec<(usize, u32)>,
}

impl ShaderLibrary {
    /// The shaders compiled into the binary.
    pub fn embedded() -> Self {
        #[cfg(feature = "mutants")]
        if let Some(dir) = std::env::var_os("IGNIS_MUTANT_SHADERS") {
            return Self::from_dir(PathBuf::from(dir));
        }
        Self {
            source: ShaderSourceDir::Embedded,
            overrides: Vec::new(),
        }
    }

    /// Shaders read from `dir` on every compose.
    pub fn from_dir(dir: impl Into<PathBuf>) -> Self {
        Self {
            source: ShaderSourceDir::Dir(dir.into()),
            overrides: Vec::new(),
        }
    }

    /// `shaders/` in the working directory when it exists, else the embedded copies
    /// (with the `mutants` feature, IGNIS_MUTANT_SHADERS before either).
    pub fn discover(explicit: Option<&Path>) -> Self {
        if let Some(dir) = explicit {
            return Self::from_dir(dir);
        }
        #[cfg(feature = "mutants")]
        if std::env::var_os("IGNIS_MUTANT_SHADERS").is_some() {
            return Self::embedded();
        }
        let local = Path::new("shaders");
        if local.join("update.wgsl").is_file() {
            Self::from_dir(local)
        } else {
            Self::embedded()
        }
    }

    /// Where the files come from.
    pub fn source(&self) -> &ShaderSourceDir {
        &self.source
    }

    /// The path shown to the user for a file name.
    pub fn display_path(&self, name: &str) -> String {
        match &self.source {
            ShaderSourceDir::Embedded => format!("<embedded>/shaders/{name}"),
            ShaderSourceDir::Dir(dir) => dir.join(name).display().to_string(),
        }
    }

    /// The same library with every optional module's code removed (the lines between
    /// `// module-begin` and `// module-end`): the reference pipeline the perf bench
    /// compares "module compiled out by its override constant" against.
    pub fn without_modules(&self) -> Result<ShaderLibrary, ShaderError> {
        let mut bare = self.clone();
        for (name, _) in EMBEDDED {
            let text = self.read(name)?;
            let mut keep = true;
            let stripped: Vec<&str> = text
                .lines()
                .filter(|l| {
                    let t = l.trim_start();
                    if t.starts_with("// module-begin") {
                        keep = false;
                    }
                    let k = keep;
                    if t.starts_with("// module-end") {
                        keep = true;
                    }
                    k
                })
                .collect();
            bare.overrides
                .push(((*name).to_owned(), stripped.join("\n")));
        }
        Ok(bare)
    }

    /// Reads one file's text.
    pub fn read(&self, name: &str) -> Result<String, ShaderError> {
        if let Some((_, text)) = self.overrides.iter().find(|(n, _)| n == name) {
            return Ok(text.clone());
        }
        match &self.source {
            ShaderSourceDir::Embedded => EMBEDDED
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, text)| (*text).to_owned())
                .ok_or_else(|| ShaderError::Io {
                    path: self.display_path(name),
                    reason: "no such embedded shader".into(),
                }),
            ShaderSourceDir::Dir(dir) => {
                let path = dir.join(name);
                let bytes = std::fs::read(&path).map_err(|e| ShaderError::Io {
                    path: path.display().to_string(),
                    reason: e.to_string(),
                })?;
                String::from_utf8(bytes).map_err(|_| ShaderError::Io {
                    path: path.display().to_string(),
                    reason: "the file is not valid UTF-8".into(),
                })
            }
        }
    }

    /// Every file the pipelines of `entry` depend on: its imports, and — where it imports a
    /// file that has a variant in [`IMPORT_VARIANTS`] — the variant's imports too (so an
    /// edit to `state_packed.wgsl` rebuilds the update pass).
    pub fn dependencies(&self, entry: &str) -> Result<Vec<String>, ShaderError> {
        let mut files = self.compose(entry)?.files;
        for &variant in IMPORT_VARIANTS {
            if files.iter().any(|f| f == variant.0) {
                for f in self.compose_with(entry, &[variant])?.files {
                    if !files.contains(&f) {
                        files.push(f);
                    }
                }
            }
        }
        Ok(files)
    }

    /// Composes `entry` with its imports and validates the result with naga.
    pub fn compose(&self, entry: &str) -> Result<Composed, ShaderError> {
        self.compose_with(entry, &[])
    }

    /// As [`compose`](Self::compose), with `(import, replacement)` pairs: an
    /// `#import "import"` reads `replacement` instead (how the packed state swaps the
    /// update pass's state I/O, `state_full.wgsl` → `state_packed.wgsl`).
    pub fn compose_with(
        &self,
        entry: &str,
        aliases: &[(&str, &str)],
    ) -> Result<Composed, ShaderError> {
        let mut out = Composer {
            lib: self,
            aliases,
            source: String::new(),
            files: Vec::new(),
            line_map: Vec::new(),
        };
        out.include(entry, None)?;
        let Composer {
            source,
            files,
            line_map,
            ..
        } = out;
        let mut composed = Composed {
            entry: entry.to_owned(),
            source,
            files,
            module: naga::Module::default(),
            line_map,
        };
        if composed.source.trim().is_empty() {
            return Err(ShaderError::Io {
                path: self.display_path(entry),
                reason: "the file is empty".into(),
            });
        }
        let module = match naga::front::wgsl::parse_str(&composed.source) {
            Ok(m) => m,
            Err(e) => {
                let loc = e.location(&composed.source);
                let label = e.labels().next().map(|(_, l)| l.to_owned());
                return Err(composed.locate(self, loc, e.message().to_owned(), label));
            }
        };
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        );
        if let Err(e) = validator.validate(&module) {
            let loc = e.location(&composed.source);
            let label = e.spans().next().map(|(_, l)| l.clone());
            let mut message = e.as_inner().to_string();
            let mut cause = std::error::Error::source(e.as_inner());
            while let Some(c) = cause {
                message.push_str(": ");
                message.push_str(&c.to_string());
                cause = c.source();
            }
            return Err(composed.locate(self, loc, message, label));
        }
        composed.module = module;
        Ok(composed)
    }
}

struct Composer<'a> {
    lib: &'a ShaderLibrary,
    aliases: &'a [(&'a str, &'a str)],
    source: String,
    files: Vec<String>,
    line_map: Vec<(usize, u32)>,
}

impl Composer<'_> {
    /// Appends `name` (once), replacing its `#import` lines by the imported files.
    fn include(&mut self, name: &str, from: Option<(usize, u32, &str)>) -> Result<(), ShaderError> {
        let name = self
            .aliases
            .iter()
            .find(|(from, _)| *from == name)
            .map_or(name, |(_, to)| *to);
        if self.files.iter().any(|f| f == name) {
            return Ok(());
        }
        let text = match self.lib.read(name) {
            Ok(t) => t,
            Err(e) => {
                // A missing import is reported at the `#import` line that asked for it.
                return Err(match from {
                    Some((file_index, line, line_text)) => {
                        let reason = match e {
                            ShaderError::Io { reason, .. } => reason,
                            other => other.to_string(),
                        };
                        let file = self.lib.display_path(&self.files[file_index]);
                        let column = line_text.find('"').map_or(1, |c| c as u32 + 1);
                        ShaderError::Located(Box::new(LocatedError {
                            message: format!("cannot import \"{name}\": {reason}"),
                            snippet: caret_snippet(
                                line,
                                line_text,
                                column,
                                name.len() as u32 + 2,
                                "imported here",
                            ),
                            file,
                            line,
                            column,
                        }))
                    }
                    None => e,
                });
            }
        };
        let index = self.files.len();
        self.files.push(name.to_owned());
        for (i, line) in text.lines().enumerate() {
            let line_no = i as u32 + 1;
            if let Some(rest) = line.trim_start().strip_prefix("#import") {
                let target = rest.trim().trim_matches('"');
                if target.is_empty() || !rest.trim().starts_with('"') {
                    return Err(ShaderError::Located(Box::new(LocatedError {
                        file: self.lib.display_path(name),
                        line: line_no,
                        column: 1,
                        message: "malformed import; write `#import \"file.wgsl\"`".into(),
                        snippet: caret_snippet(line_no, line, 1, line.len() as u32, "here"),
                    })));
                }
                self.include(target, Some((index, line_no, line)))?;
                // Keep the line count stable so positions stay 1:1 within this file.
                self.source.push('\n');
                self.line_map.push((index, line_no));
            } else {
                self.source.push_str(line);
                self.source.push('\n');
                self.line_map.push((index, line_no));
            }
        }
        Ok(())
    }
}

impl Composed {
    /// Turns a position in the composed text into a located error in the original file.
    fn locate(
        &self,
        lib: &ShaderLibrary,
        loc: Option<naga::SourceLocation>,
        message: String,
        label: Option<String>,
    ) -> ShaderError {
        let Some(loc) = loc else {
            return ShaderError::Pipeline {
                file: lib.display_path(&self.entry),
                message,
            };
        };
        let (file_index, line) = self
            .line_map
            .get(loc.line_number.saturating_sub(1) as usize)
            .copied()
            .unwrap_or((0, loc.line_number));
        let line_text = self
            .source
            .lines()
            .nth(loc.line_number.saturating_sub(1) as usize)
            .unwrap_or("");
        let label = label.unwrap_or_default();
        ShaderError::Located(Box::new(LocatedError {
            file: lib.display_path(&self.files[file_index]),
            line,
            column: loc.line_position,
            snippet: caret_snippet(
                line,
                line_text,
                loc.line_position,
                loc.length.max(1),
                &label,
            ),
            message,
        }))
    }

    /// The byte size naga computes for a named struct in this module (layout checks).
    pub fn struct_size(&self, name: &str) -> Option<u32> {
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(self.module.to_ctx()).ok()?;
        self.module
            .types
            .iter()
            .find(|(_, ty)| ty.name.as_deref() == Some(name))
            .map(|(handle, _)| layouter[handle].size)
    }
}

/// A rustc-style snippet: the line, and a caret run under the columns of the problem.
fn caret_snippet(line: u32, text: &str, column: u32, length: u32, label: &str) -> String {
    let gutter = line.to_string().len();
    let pad = " ".repeat(gutter);
    let text_len = text.len() as u32;
    let carets = length
        .min(text_len.saturating_sub(column - 1).max(1))
        .max(1);
    format!(
        "{pad} |\n{line} | {text}\n{pad} | {}{} {label}",
        " ".repeat(column.saturating_sub(1) as usize),
        "^".repeat(carets as usize)
    )
}

/// Creates a shader module and runs `build` inside a wgpu validation error scope, so an
/// invalid shader or pipeline returns an error instead of panicking.
pub fn create_checked<T>(
    device: &wgpu::Device,
    composed: &Composed,
    lib: &ShaderLibrary,
    build: impl FnOnce(&wgpu::ShaderModule) -> T,
) -> Result<T, ShaderError> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&composed.entry),
        source: wgpu::ShaderSource::Wgsl(composed.source.as_str().into()),
    });
    let built = build(&module);
    match pollster::block_on(scope.pop()) {
        None => Ok(built),
        Some(err) => Err(ShaderError::Pipeline {
            file: lib.display_path(&composed.entry),
            message: format!(
                "the GPU rejected the pipeline (check bindings and struct layouts against \
                    src/gpu/types.rs): {err}"
            ),
        }),
    }
}
