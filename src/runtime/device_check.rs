//! What a host's device must offer a [`Player`](super::Player): the limits it is checked
//! against before anything is built, and the error that names each one it lacks.

/// Storage buffers the player binds in one shader stage (the update pass: particle
/// states, spawn records, counters, events and the parameter ring). The tile rasteriser
/// binds more (`render::tiles::STORAGE_BUFFERS_NEEDED`) and is used only where the device
/// has them.
pub const STORAGE_BUFFERS_REQUIRED: u32 = 8;

/// A device limit below what the player needs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MissingLimit {
    /// The `wgpu::Limits` field.
    pub name: &'static str,
    /// The host device's value.
    pub device: u64,
    /// The value the player needs.
    pub needed: u64,
}

impl std::fmt::Display for MissingLimit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} is {} on this device, ignis needs {}",
            self.name, self.device, self.needed
        )
    }
}

/// The limits a host requests for its device so that players can be created on it
/// (merge them into its `DeviceDescriptor::required_limits`, e.g. with
/// `wgpu::Limits::or_better_values_from`): WebGPU's downlevel defaults (compute shaders
/// are required — the simulation runs on the GPU) with
/// [`STORAGE_BUFFERS_REQUIRED`] storage buffers per shader stage. A device that also offers
/// `render::tiles::STORAGE_BUFFERS_NEEDED` gets the tile rasteriser.
pub fn required_limits() -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffers_per_shader_stage: STORAGE_BUFFERS_REQUIRED,
        ..wgpu::Limits::downlevel_defaults()
    }
}

/// Every limit of `device` below [`required_limits`] (empty: the device will do).
pub fn missing_limits(device: &wgpu::Limits) -> Vec<MissingLimit> {
    let mut missing = Vec::new();
    required_limits().check_limits_with_fail_fn(device, false, |name, needed, have| {
        missing.push(MissingLimit {
            name,
            device: have,
            needed,
        });
    });
    missing
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn webgl2_limits_name_compute_and_storage_buffers() {
        let missing = missing_limits(&wgpu::Limits::downlevel_webgl2_defaults());
        let names: Vec<_> = missing.iter().map(|m| m.name).collect();
        assert!(
            names.contains(&"max_storage_buffers_per_shader_stage"),
            "{names:?}"
        );
        assert!(
            names.contains(&"max_compute_invocations_per_workgroup"),
            "{names:?}"
        );
        let storage = missing
            .iter()
            .find(|m| m.name == "max_storage_buffers_per_shader_stage");
        assert_eq!(
            storage.map(|m| (m.device, m.needed)),
            Some((0, u64::from(STORAGE_BUFFERS_REQUIRED)))
        );
        assert!(missing_limits(&required_limits()).is_empty());
        assert!(missing_limits(&wgpu::Limits::default()).is_empty());
    }
}
