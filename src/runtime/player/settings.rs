//! What a player is told (`PlayerSettings`) and what it can fail with (`PlayerError`).

use super::*;

/// How a [`Player`] draws into the host's render pass.
#[derive(Clone, Debug, PartialEq)]
pub struct PlayerSettings {
    /// The format of the colour attachment the particles are drawn into. An HDR format
    /// (`Rgba16Float`) keeps the fire's light for the host's own tonemap; an sRGB display
    /// format works too (additive light then clips at white).
    pub color_format: wgpu::TextureFormat,
    /// The format of the host's depth attachment, or `None` to draw without depth.
    pub depth_format: Option<wgpu::TextureFormat>,
    /// The depth test (`LessEqual` for the usual 0 = near; `GreaterEqual` for reversed
    /// Z). Particles never write depth.
    pub depth_compare: wgpu::CompareFunction,
    /// Samples per pixel of the host's attachments (MSAA).
    pub sample_count: u32,
    /// The folder the preset's PNG sprite paths are relative to (the preset's own
    /// folder); `None`: the working directory.
    pub asset_dir: Option<PathBuf>,
    /// Batch instances (on by default): up to [`PlayerSettings::max_batch_instances`]
    /// instances share each emitter's buffers and one update dispatch. Off, every
    /// instance has a simulation of its own: it costs a dispatch per instance, and in
    /// return an edit ([`Player::set_effect`]) that resizes a pool keeps the particles
    /// that fit — what an editor wants.
    pub batch_instances: bool,
    /// Instances one batch holds at most (128 by default; taken between 1 and 128). A
    /// batch's buffers double as instances come (16, 32, 64, 128 instances' worth) and a
    /// full batch starts another; an effect with large pools holds fewer (a batch
    /// allocates at most 64 MiB of particle state unless one instance needs more). Lower
    /// it to bound the memory one batch grows to; each batch costs its own dispatches and
    /// draws.
    pub max_batch_instances: u32,
    /// A folder of WGSL files to build the pipelines from instead of the shaders built
    /// into the library (a host that edits them; see [`Player::reload_shader`]).
    pub shader_dir: Option<PathBuf>,
    /// The choices that differ between GPUs and software adapters; `None`: from the
    /// device's adapter type.
    pub adapter_profile: Option<AdapterProfile>,
    /// The host world's up axis (+Y by default; `Vec3::Z` for a z-up host). Presets are
    /// made y-up: gravity, buoyancy, wind and the preset's ground and colliders are
    /// turned with the world by the shortest rotation from +Y to this axis (for +Z: a
    /// preset's +Z becomes the host's −Y, as a y-up glTF scene imports into a z-up one).
    /// Instances' transforms, cameras and the positions and lights the player reports
    /// are all in the host's world; an unrotated instance burns along the host's up.
    pub world_up: Vec3,
}

impl PlayerSettings {
    /// Settings for a colour attachment of `color_format`: no depth, one sample.
    pub fn new(color_format: wgpu::TextureFormat) -> Self {
        Self {
            color_format,
            depth_format: None,
            depth_compare: wgpu::CompareFunction::LessEqual,
            sample_count: 1,
            asset_dir: None,
            batch_instances: true,
            max_batch_instances: crate::sim::batch::BATCH_SLOTS,
            shader_dir: None,
            adapter_profile: None,
            world_up: Vec3::Y,
        }
    }

    /// The rotation from the presets' y-up world to the host's (`None`: the host is y-up).
    pub(crate) fn host_from_preset(&self) -> Option<Quat> {
        let up = self.world_up.normalize_or(Vec3::Y);
        (up.dot(Vec3::Y) < 1.0 - 1e-7).then(|| Quat::from_rotation_arc(Vec3::Y, up))
    }
}

/// Why a player could not be created, an instance added or an edit applied.
#[derive(Debug, thiserror::Error)]
pub enum PlayerError {
    /// The preset file could not be read.
    #[error(transparent)]
    Preset(#[from] crate::preset::PresetError),
    /// The effect has impossible values (each error names the field).
    #[error("the effect is not valid: {}", list(.0))]
    Invalid(Vec<ValidationError>),
    /// A shader, a device limit or a GPU readback failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The instance was removed.
    #[error("no such instance (it was removed)")]
    NoInstance,
    /// The host's device lacks limits the player needs (each named with both values).
    #[error(
        "the device's limits are too low for ignis: {}; request ignis::required_limits() when \
            creating the device (docs/embedding.md: what the host provides)",
        list(.0)
    )]
    DeviceLimits(Vec<MissingLimit>),
    /// The device refused to build the player's pipelines for these settings (a colour
    /// format that cannot blend, a sample count the formats do not support…).
    #[error("the device refused the player's pipelines for these settings: {0}")]
    Device(String),
    /// The depth view handed to [`Player::record`] cannot be used for soft edges and
    /// occlusion; that frame was recorded without it (particles tested only by the
    /// pass's depth attachment), so the fire still shows.
    #[error("the host's depth cannot be sampled: {0}; the frame was drawn without soft edges")]
    HostDepth(String),
}

pub(super) fn list(errors: &[impl ToString]) -> String {
    errors
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("; ")
}
