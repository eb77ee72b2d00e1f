//! [`AdapterProfile`]: every decision of the runtime that differs between GPUs and
//! software adapters (lavapipe: the CI machine's and GPU-less machines' "GPU"), made once
//! from the adapter and overridable (`--adapter-profile`, one field at a time with
//! `--adapt`). The editor's own choices live in its `EditorProfile`, of the same kind. Code
//! elsewhere asks the profile; nothing else looks at the adapter's type. Each software
//! choice is measured by `ignis bench adapters` (kept only where it takes ≥ 10 % off the
//! editor's software frame); the reasons are in `docs/architecture.md` ("Software
//! adapters").

use std::str::FromStr;

/// Which set of choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ProfileKind {
    /// A hardware GPU.
    Gpu,
    /// A software rasteriser running on the CPU's cores.
    Software,
}

/// The choices that differ between GPUs and software adapters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdapterProfile {
    /// Which set this is.
    pub kind: ProfileKind,
    /// GPU timestamps are trustworthy (per-pass timings in the editor and the benches).
    pub timestamps: bool,
    /// The automatic draw path sends large sprites to the compute tile rasteriser
    /// (`tiles.wgsl`) instead of the billboards.
    pub tile_raster: bool,
    /// The automatic draw path splats small particles only where they are dense (a quad
    /// per `effect::SPLAT_PX_PER_QUAD` pixels of the target or more): the splat
    /// clears and resolves the whole target, which costs a GPU more than a few thousand
    /// small billboards. Off, every small additive sprite splats (lavapipe: the thesis
    /// preset's 16384 points at 1920×1080 took 92.6 ms a frame splatted, 109.1 as
    /// billboards).
    pub splat_dense_only: bool,
}

impl AdapterProfile {
    /// The choices for a hardware GPU.
    pub const GPU: Self = Self {
        kind: ProfileKind::Gpu,
        timestamps: true,
        tile_raster: true,
        splat_dense_only: true,
    };

    /// The choices for a software adapter.
    pub const SOFTWARE: Self = Self {
        kind: ProfileKind::Software,
        timestamps: false,
        tile_raster: false,
        splat_dense_only: false,
    };

    /// The profile for an adapter of `device_type`.
    pub fn for_device_type(device_type: wgpu::DeviceType) -> Self {
        match device_type {
            wgpu::DeviceType::Cpu => Self::SOFTWARE,
            _ => Self::GPU,
        }
    }

    /// The profile `kind` names.
    pub fn of_kind(kind: ProfileKind) -> Self {
        match kind {
            ProfileKind::Gpu => Self::GPU,
            ProfileKind::Software => Self::SOFTWARE,
        }
    }

    /// Whether this is the software set.
    pub fn is_software(&self) -> bool {
        self.kind == ProfileKind::Software
    }

    /// Every field but the kind, as settings (in declaration order).
    pub fn settings(&self) -> [ProfileSetting; 3] {
        use ProfileSetting as S;
        [
            S::Timestamps(self.timestamps),
            S::TileRaster(self.tile_raster),
            S::SplatDenseOnly(self.splat_dense_only),
        ]
    }

    /// The settings that turn `self` into `other` (the fields where they differ).
    pub fn differences(&self, other: &Self) -> Vec<ProfileSetting> {
        self.settings()
            .into_iter()
            .zip(other.settings())
            .filter(|(a, b)| a != b)
            .map(|(_, b)| b)
            .collect()
    }

    /// This profile with `settings` applied in order.
    pub fn with(mut self, settings: &[ProfileSetting]) -> Self {
        for s in settings {
            s.apply(&mut self);
        }
        self
    }
}

/// A profile asked for (the command line's `--adapter-profile` and `--adapt`): a set, or
/// the adapter's own, then fields set one by one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProfileRequest {
    /// The set to start from (`None`: the adapter's own).
    pub kind: Option<ProfileKind>,
    /// Fields set on top, in order.
    pub settings: Vec<ProfileSetting>,
}

impl ProfileRequest {
    /// The profile asked for, on an adapter whose own profile is `adapters`.
    pub fn resolve(&self, adapters: AdapterProfile) -> AdapterProfile {
        self.kind
            .map_or(adapters, AdapterProfile::of_kind)
            .with(&self.settings)
    }
}

/// One field of an [`AdapterProfile`] set on its own: `--adapt FIELD=VALUE` (the field's
/// name as in the struct, and a bool).
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(missing_docs)] // each variant is the field of the same name
pub enum ProfileSetting {
    Timestamps(bool),
    TileRaster(bool),
    SplatDenseOnly(bool),
}

impl ProfileSetting {
    /// The field names `--adapt` accepts.
    pub const FIELDS: [&'static str; 3] = ["timestamps", "tile_raster", "splat_dense_only"];

    /// Sets the field in `profile`.
    pub fn apply(&self, p: &mut AdapterProfile) {
        match *self {
            Self::Timestamps(v) => p.timestamps = v,
            Self::TileRaster(v) => p.tile_raster = v,
            Self::SplatDenseOnly(v) => p.splat_dense_only = v,
        }
    }

    /// The field's name.
    pub fn field(&self) -> &'static str {
        let i = AdapterProfile::GPU
            .settings()
            .iter()
            .position(|s| std::mem::discriminant(s) == std::mem::discriminant(self))
            .unwrap_or(0);
        Self::FIELDS[i]
    }
}

impl std::fmt::Display for ProfileSetting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (Self::Timestamps(v) | Self::TileRaster(v) | Self::SplatDenseOnly(v)) = *self;
        write!(f, "{}={v}", self.field())
    }
}

impl FromStr for ProfileSetting {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (name, value) = split_setting(s)?;
        let flag = || parse_flag(name, value);
        Ok(match name {
            "timestamps" => Self::Timestamps(flag()?),
            "tile_raster" => Self::TileRaster(flag()?),
            "splat_dense_only" => Self::SplatDenseOnly(flag()?),
            other => {
                return Err(format!(
                    "unknown adapter profile field {other:?}: expected one of {}",
                    Self::FIELDS.join(", ")
                ));
            }
        })
    }
}

/// `FIELD=VALUE` split and trimmed, or an error that shows the form.
pub fn split_setting(s: &str) -> Result<(&str, &str), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("{s:?}: expected FIELD=VALUE, e.g. tile_raster=false"))?;
    Ok((name.trim(), value.trim()))
}

/// A setting's bool value, or an error naming the field.
pub fn parse_flag(name: &str, value: &str) -> Result<bool, String> {
    value
        .parse::<bool>()
        .map_err(|_| format!("{name}: {value:?} is not a bool (expected true or false)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_adapter_type_picks_the_profile() {
        assert_eq!(
            AdapterProfile::for_device_type(wgpu::DeviceType::Cpu),
            AdapterProfile::SOFTWARE
        );
        for t in [
            wgpu::DeviceType::DiscreteGpu,
            wgpu::DeviceType::IntegratedGpu,
            wgpu::DeviceType::VirtualGpu,
            wgpu::DeviceType::Other,
        ] {
            assert_eq!(AdapterProfile::for_device_type(t), AdapterProfile::GPU);
        }
        assert!(AdapterProfile::of_kind(ProfileKind::Software).is_software());
    }

    /// Every decision lives in the profile: the two sets differ in exactly the listed
    /// fields, each field round-trips through its `--adapt` text, and setting the
    /// differences turns one set into the other.
    #[test]
    fn the_two_sets_differ_in_exactly_the_listed_fields() {
        let (gpu, soft) = (AdapterProfile::GPU, AdapterProfile::SOFTWARE);
        let differ: Vec<&str> = gpu.differences(&soft).iter().map(|s| s.field()).collect();
        assert_eq!(differ, ["timestamps", "tile_raster", "splat_dense_only"]);
        let mut turned = gpu.with(&gpu.differences(&soft));
        assert_ne!(turned, soft, "the kind is not a setting");
        turned.kind = ProfileKind::Software;
        assert_eq!(turned, soft);
        for s in soft.settings().into_iter().chain(gpu.settings()) {
            assert_eq!(s.to_string().parse::<ProfileSetting>(), Ok(s));
        }
        for bad in [
            "tile_raster",
            "tile_raster=maybe",
            "draft=true",
            "colour=true",
        ] {
            assert!(bad.parse::<ProfileSetting>().is_err(), "{bad}");
        }
    }
}
