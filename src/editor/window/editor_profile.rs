//! [`EditorProfile`]: the editor's choices that differ between GPUs and software adapters
//! (the runtime's are in [`AdapterProfile`]), of the same kind as the adapter's profile and
//! overridable one field at a time with `--adapt`, which takes both kinds of field
//! ([`AdaptSetting`]). Each software choice is measured by `ignis bench adapters`.

use std::str::FromStr;

use crate::gpu::profile::{parse_flag, split_setting};
use crate::gpu::{AdapterProfile, ProfileKind, ProfileSetting};

/// The editor's choices that differ between GPUs and software adapters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditorProfile {
    /// The viewport renders at this fraction of its size by default.
    pub render_scale: f32,
    /// Large glow is drawn at half resolution by default (draft quality).
    pub draft: bool,
    /// The UI is painted with the branch-free lean painter instead of egui-wgpu's.
    pub lean_painter: bool,
    /// The window's image is kept and only the viewport repainted while the panel is
    /// unchanged.
    pub retained_window: bool,
}

impl EditorProfile {
    /// The choices on a hardware GPU.
    pub const GPU: Self = Self {
        render_scale: 1.0,
        draft: false,
        lean_painter: false,
        retained_window: false,
    };

    /// The choices on a software adapter.
    pub const SOFTWARE: Self = Self {
        render_scale: 0.5,
        draft: true,
        lean_painter: true,
        retained_window: true,
    };

    /// The set of `kind`.
    pub fn of_kind(kind: ProfileKind) -> Self {
        match kind {
            ProfileKind::Gpu => Self::GPU,
            ProfileKind::Software => Self::SOFTWARE,
        }
    }

    /// Every field, as settings (in declaration order).
    pub fn settings(&self) -> [EditorSetting; 4] {
        use EditorSetting as S;
        [
            S::RenderScale(self.render_scale),
            S::Draft(self.draft),
            S::LeanPainter(self.lean_painter),
            S::RetainedWindow(self.retained_window),
        ]
    }

    /// This profile with the editor's fields of `settings` applied in order.
    pub fn with(mut self, settings: &[AdaptSetting]) -> Self {
        for s in settings {
            if let AdaptSetting::Editor(e) = s {
                e.apply(&mut self);
            }
        }
        self
    }
}

/// One field of an [`EditorProfile`] set on its own (`render_scale` a number in 0.1..=1,
/// the others bools).
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(missing_docs)] // each variant is the field of the same name
pub enum EditorSetting {
    RenderScale(f32),
    Draft(bool),
    LeanPainter(bool),
    RetainedWindow(bool),
}

impl EditorSetting {
    /// The field names.
    pub const FIELDS: [&'static str; 4] =
        ["render_scale", "draft", "lean_painter", "retained_window"];

    /// Sets the field in `p`.
    pub fn apply(&self, p: &mut EditorProfile) {
        match *self {
            Self::RenderScale(v) => p.render_scale = v,
            Self::Draft(v) => p.draft = v,
            Self::LeanPainter(v) => p.lean_painter = v,
            Self::RetainedWindow(v) => p.retained_window = v,
        }
    }

    /// The field's name.
    pub fn field(&self) -> &'static str {
        match self {
            Self::RenderScale(_) => "render_scale",
            Self::Draft(_) => "draft",
            Self::LeanPainter(_) => "lean_painter",
            Self::RetainedWindow(_) => "retained_window",
        }
    }

    /// Parses `value` for the field `name`; `None` when `name` is not an editor field.
    fn parse(name: &str, value: &str) -> Option<Result<Self, String>> {
        let flag = || parse_flag(name, value);
        Some(match name {
            "render_scale" => match value.parse::<f32>() {
                Ok(v) if (0.1..=1.0).contains(&v) => Ok(Self::RenderScale(v)),
                _ => Err(format!(
                    "render_scale: {value:?} is not a number in 0.1..=1"
                )),
            },
            "draft" => flag().map(Self::Draft),
            "lean_painter" => flag().map(Self::LeanPainter),
            "retained_window" => flag().map(Self::RetainedWindow),
            _ => return None,
        })
    }
}

/// A value of the command line's `--adapt FIELD=VALUE`: a field of the runtime's
/// [`AdapterProfile`] or of the editor's [`EditorProfile`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AdaptSetting {
    /// A field the runtime decides (timestamps, tile rasteriser, splat).
    Adapter(ProfileSetting),
    /// A field the editor decides (render scale, draft glow, painter, retained window).
    Editor(EditorSetting),
}

impl AdaptSetting {
    /// The runtime's settings among `settings`, in order.
    pub fn adapter_settings(settings: &[Self]) -> Vec<ProfileSetting> {
        settings
            .iter()
            .filter_map(|s| match s {
                Self::Adapter(a) => Some(*a),
                Self::Editor(_) => None,
            })
            .collect()
    }

    /// The field's name.
    pub fn field(&self) -> &'static str {
        match self {
            Self::Adapter(a) => a.field(),
            Self::Editor(e) => e.field(),
        }
    }

    /// Every field where the software sets differ from the GPU's, as the GPU's values:
    /// what turns the software profiles into the GPU's (runtime's first).
    pub fn software_to_gpu() -> Vec<Self> {
        let adapter = AdapterProfile::SOFTWARE.differences(&AdapterProfile::GPU);
        let (soft, gpu) = (
            EditorProfile::SOFTWARE.settings(),
            EditorProfile::GPU.settings(),
        );
        let editor = soft
            .into_iter()
            .zip(gpu)
            .filter(|(s, g)| s != g)
            .map(|(_, g)| g);
        adapter
            .into_iter()
            .map(Self::Adapter)
            .chain(editor.map(Self::Editor))
            .collect()
    }
}

impl std::fmt::Display for AdaptSetting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Adapter(a) => a.fmt(f),
            Self::Editor(e) => {
                let value = match *e {
                    EditorSetting::RenderScale(v) => v.to_string(),
                    EditorSetting::Draft(v)
                    | EditorSetting::LeanPainter(v)
                    | EditorSetting::RetainedWindow(v) => v.to_string(),
                };
                write!(f, "{}={value}", e.field())
            }
        }
    }
}

impl FromStr for AdaptSetting {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (name, value) = split_setting(s)?;
        if let Some(editor) = EditorSetting::parse(name, value) {
            return editor.map(Self::Editor);
        }
        if ProfileSetting::FIELDS.contains(&name) {
            return s.parse().map(Self::Adapter);
        }
        let fields: Vec<&str> = ProfileSetting::FIELDS
            .iter()
            .chain(&EditorSetting::FIELDS)
            .copied()
            .collect();
        Err(format!(
            "unknown adapter profile field {name:?}: expected one of {}",
            fields.join(", ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The software and GPU sets differ in every field but the timestamps' capability
    /// listed here; each field round-trips through its `--adapt` text; unknown fields and
    /// bad values are refused with the field named.
    #[test]
    fn every_field_round_trips_and_the_sets_differ() {
        let fields: Vec<&str> = AdaptSetting::software_to_gpu()
            .iter()
            .map(AdaptSetting::field)
            .collect();
        assert_eq!(
            fields,
            [
                "timestamps",
                "tile_raster",
                "splat_dense_only",
                "render_scale",
                "draft",
                "lean_painter",
                "retained_window"
            ]
        );
        let all = EditorProfile::SOFTWARE
            .settings()
            .into_iter()
            .chain(EditorProfile::GPU.settings())
            .map(AdaptSetting::Editor)
            .chain(
                AdapterProfile::SOFTWARE
                    .settings()
                    .map(AdaptSetting::Adapter),
            );
        for s in all {
            assert_eq!(s.to_string().parse::<AdaptSetting>(), Ok(s));
        }
        let turned = EditorProfile::SOFTWARE.with(&AdaptSetting::software_to_gpu());
        assert_eq!(turned, EditorProfile::GPU);
        for bad in ["draft", "draft=maybe", "render_scale=2", "colour=true"] {
            let err = bad.parse::<AdaptSetting>().expect_err(bad);
            assert!(!err.is_empty());
        }
        let unknown = "colour=true".parse::<AdaptSetting>().expect_err("unknown");
        assert!(unknown.contains("render_scale") && unknown.contains("tile_raster"));
    }
}
