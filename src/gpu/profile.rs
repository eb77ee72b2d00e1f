//! [`AdapterProfile`]: every decision that differs between GPUs and software adapters
//! (lavapipe: the CI machine's and GPU-less machines' "GPU"), made once from the adapter
//! and overridable (`--adapter-profile`). Code elsewhere asks the profile; nothing else
//! looks at the adapter's type. Each software choice was measured on lavapipe; the
//! reasons are in `docs/architecture.md` ("Software adapters").

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
    /// The update's per-step parameters are read-only storage, not a uniform buffer
    /// (lavapipe recompiles a shader at every new uniform offset).
    pub params_in_storage: bool,
    /// The update counts alive particles as it goes (a workgroup reduction); otherwise
    /// they are counted on demand.
    pub count_in_update: bool,
    /// On-demand counts add with one atomic per particle instead of a workgroup
    /// reduction (barriers are very expensive on a software adapter).
    pub direct_atomic_counts: bool,
    /// Billboard quads are indexed triangle lists over a shared index buffer rather than
    /// one instance per quad.
    pub indexed_quads: bool,
    /// GPU timestamps are trustworthy (per-pass timings in the editor and the benches).
    pub timestamps: bool,
    /// The editor renders its viewport at this fraction of its size by default.
    pub render_scale: f32,
    /// The editor draws large glow at half resolution by default (draft quality).
    pub draft: bool,
    /// The editor paints its UI with its lean painter and keeps a retained window image.
    pub lean_ui: bool,
}

impl AdapterProfile {
    /// The choices for a hardware GPU.
    pub const GPU: Self = Self {
        kind: ProfileKind::Gpu,
        params_in_storage: false,
        count_in_update: true,
        direct_atomic_counts: false,
        indexed_quads: false,
        timestamps: true,
        render_scale: 1.0,
        draft: false,
        lean_ui: false,
    };

    /// The choices for a software adapter.
    pub const SOFTWARE: Self = Self {
        kind: ProfileKind::Software,
        params_in_storage: true,
        count_in_update: false,
        direct_atomic_counts: true,
        indexed_quads: true,
        timestamps: false,
        render_scale: 0.5,
        draft: true,
        lean_ui: true,
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
}
