//! The GPU device: adapter choice, limits sized to the capacity, clear errors.

use std::sync::Arc;

/// Storage buffers per shader stage the tile rasteriser binds (`render::tiles`): a device
/// is asked for up to this many, where its adapter allows.
pub const TILE_STORAGE_BUFFERS: u32 = 13;

/// Failures to get a usable GPU.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter matched.
    #[error(
        "no GPU adapter found ({0}); install a Vulkan driver (e.g. Mesa's lavapipe: apt install \
            mesa-vulkan-drivers) or set WGPU_BACKEND"
    )]
    NoAdapter(String),
    /// The device request failed.
    #[error("the GPU device could not be created: {0}")]
    Device(String),
    /// A capacity needs more than a device limit allows.
    #[error(
        "emitter \"{emitter}\": capacity {capacity} needs {needed_bytes} bytes per state \
            buffer, but this adapter's {limit} is {limit_bytes} bytes (at most {max_capacity} \
            particles); lower the capacity"
    )]
    CapacityTooLarge {
        /// Emitter name.
        emitter: String,
        /// Requested slots.
        capacity: u32,
        /// Bytes it needs.
        needed_bytes: u64,
        /// Which wgpu limit.
        limit: &'static str,
        /// The limit's value.
        limit_bytes: u64,
        /// Largest capacity that fits.
        max_capacity: u64,
    },
    /// Reading a buffer back from the GPU failed.
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// A trail's ring of positions needs more than one storage binding holds.
    #[error(
        "emitter \"{emitter}\": a trail of {points} points over {capacity} slots needs \
            {needed_bytes} bytes, but this adapter's max_storage_buffer_binding_size is \
            {limit_bytes} bytes; use fewer trail points or a smaller capacity"
    )]
    TrailTooLarge {
        /// Emitter name.
        emitter: String,
        /// Trail points.
        points: u32,
        /// Slots.
        capacity: u32,
        /// Bytes it needs.
        needed_bytes: u64,
        /// The limit's value.
        limit_bytes: u64,
    },
    /// An emitter's event records (a count and a record per rule and slot) need more
    /// than one storage binding holds.
    #[error(
        "emitter \"{emitter}\": its events over {capacity} slots need {needed_bytes} bytes \
            of records, but this adapter's max_storage_buffer_binding_size is {limit_bytes} \
            bytes; lower the emitter's capacity to {max_capacity} or less"
    )]
    EventsTooLarge {
        /// Emitter name.
        emitter: String,
        /// Slots.
        capacity: u32,
        /// Bytes it needs.
        needed_bytes: u64,
        /// The limit's value.
        limit_bytes: u64,
        /// Largest capacity that fits.
        max_capacity: u64,
    },
}

/// 64-bit integers and every atomic operation on them: the splat adds a pixel's light
/// with one atomic (`render::splat::packed`). Asked for where the adapter has them.
pub const INT64_ATOMICS: wgpu::Features =
    wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS);

/// An adapter, device and queue, shared by the simulation and the renderers.
#[derive(Clone)]
pub struct GpuContext {
    /// The adapter in use (`None` on a host's device: the runtime is given a device).
    pub adapter: Option<Arc<wgpu::Adapter>>,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter description for logs and bench files.
    pub info: wgpu::AdapterInfo,
    /// What differs between GPUs and software adapters (from the adapter's type unless
    /// overridden with [`GpuContext::with_profile`] before anything is built).
    pub profile: crate::gpu::AdapterProfile,
    /// Why the device was lost, once it was (set by wgpu's device-lost callback; never
    /// on a host's device, whose loss is the host's to handle).
    lost: Arc<std::sync::Mutex<Option<String>>>,
}

impl GpuContext {
    /// A headless context (tests, `ignis render`, `ignis bench`). The adapter may be forced
    /// with `WGPU_BACKEND` / `WGPU_ADAPTER_NAME`.
    pub fn headless() -> Result<Self, GpuError> {
        Self::headless_without(wgpu::Features::empty())
    }

    /// Creates the device on `adapter`, asking for the largest buffers it offers.
    pub fn from_adapter(adapter: wgpu::Adapter) -> Result<Self, GpuError> {
        Self::from_adapter_without(adapter, wgpu::Features::empty())
    }

    /// A headless context whose device lacks `features` even where the adapter has them
    /// (tests take the paths of devices without them).
    #[doc(hidden)]
    pub fn headless_without(features: wgpu::Features) -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
            &instance, None,
        ))
        .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        Self::from_adapter_without(adapter, features)
    }

    /// [`GpuContext::from_adapter`], leaving out `without` of the features it asks for.
    fn from_adapter_without(
        adapter: wgpu::Adapter,
        without: wgpu::Features,
    ) -> Result<Self, GpuError> {
        let info = adapter.get_info();
        let supported = adapter.limits();
        let mut limits = wgpu::Limits::default().using_resolution(supported.clone());
        limits.max_storage_buffer_binding_size = supported.max_storage_buffer_binding_size;
        limits.max_buffer_size = supported.max_buffer_size;
        // The tile rasteriser's passes read the state, the looks and its own lists: more
        // storage buffers than the default 8 (see `TilePass::supported`).
        limits.max_storage_buffers_per_shader_stage = supported
            .max_storage_buffers_per_shader_stage
            .max(limits.max_storage_buffers_per_shader_stage)
            .min(TILE_STORAGE_BUFFERS);
        // Blending into 32-bit float targets where the adapter can (the export's
        // accumulation of bright additive light; f16 rounds it by a few percent); the
        // adapter's own format features (the tiles' compute resolve reads and writes the
        // HDR image in place).
        // And 64-bit atomics (the splat adds a pixel's light with one).
        let wanted = wgpu::Features::FLOAT32_BLENDABLE
            | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
            | INT64_ATOMICS;
        let features =
            crate::gpu::timer::timing_features(&adapter) | (adapter.features() & wanted & !without);
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("ignis device"),
            required_features: features,
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        // Nothing the GPU reports may panic the editor: log what no error scope caught.
        device.on_uncaptured_error(Arc::new(|err| {
            log::error!("uncaptured GPU error: {err}");
        }));
        let lost = Arc::new(std::sync::Mutex::new(None));
        let flag = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            log::error!("GPU device lost ({reason:?}): {message}");
            if let Ok(mut l) = flag.lock() {
                *l = Some(if message.is_empty() {
                    format!("{reason:?}")
                } else {
                    format!("{reason:?}: {message}")
                });
            }
        });
        log::info!(
            "GPU: {} ({:?}, {:?}, driver {} {})",
            info.name,
            info.device_type,
            info.backend,
            info.driver,
            info.driver_info
        );
        Ok(Self {
            adapter: Some(Arc::new(adapter)),
            device,
            queue,
            profile: crate::gpu::AdapterProfile::for_device_type(info.device_type),
            info,
            lost,
        })
    }

    /// A context over a host's device and queue (the runtime player). The host's error
    /// handling is left alone.
    pub fn from_device(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let info = device.adapter_info();
        Self {
            adapter: None,
            device: device.clone(),
            queue: queue.clone(),
            profile: crate::gpu::AdapterProfile::for_device_type(info.device_type),
            info,
            lost: Arc::default(),
        }
    }

    /// Why the device was lost, if it was (a context of its own only; see
    /// [`Self::from_adapter`]).
    pub fn lost(&self) -> Option<String> {
        self.lost.lock().ok().and_then(|l| l.clone())
    }

    /// The same context with `profile` instead of the adapter's own (call it before
    /// building pipelines: they are specialised by it).
    pub fn with_profile(mut self, profile: Option<crate::gpu::AdapterProfile>) -> Self {
        if let Some(p) = profile {
            self.profile = p;
        }
        self
    }

    /// The same context with the profile `request` asks for (see [`Self::with_profile`]).
    pub fn with_request(mut self, request: &crate::gpu::profile::ProfileRequest) -> Self {
        self.profile = request.resolve(self.profile);
        self
    }

    /// The largest particle pool one state buffer can hold on this device.
    pub fn max_capacity(&self) -> u64 {
        let limits = self.device.limits();
        let per = std::mem::size_of::<crate::gpu::types::Particle>() as u64;
        limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
            / per
    }

    /// Checks that `capacity` slots fit in one storage binding, naming the limit if not.
    /// Fails with a clear message when emitter `emitter`'s trail ring does not fit one
    /// storage binding.
    pub fn check_trail(
        &self,
        emitter: &str,
        (capacity, points): (u32, u32),
        needed_bytes: u64,
    ) -> Result<(), GpuError> {
        let limit_bytes = self.device.limits().max_storage_buffer_binding_size;
        if needed_bytes > limit_bytes {
            return Err(GpuError::TrailTooLarge {
                emitter: emitter.to_owned(),
                points,
                capacity,
                needed_bytes,
                limit_bytes,
            });
        }
        Ok(())
    }

    /// Fails with a clear message when emitter `emitter`'s event records over `capacity`
    /// slots, `bytes_per_slot` each after `fixed_bytes`, do not fit one storage binding.
    pub fn check_events(
        &self,
        emitter: &str,
        capacity: u32,
        (fixed_bytes, bytes_per_slot): (u64, u64),
    ) -> Result<(), GpuError> {
        let limit_bytes = self.device.limits().max_storage_buffer_binding_size;
        let needed_bytes = fixed_bytes + bytes_per_slot * u64::from(capacity);
        if needed_bytes > limit_bytes {
            return Err(GpuError::EventsTooLarge {
                emitter: emitter.to_owned(),
                capacity,
                needed_bytes,
                limit_bytes,
                max_capacity: limit_bytes.saturating_sub(fixed_bytes) / bytes_per_slot.max(1),
            });
        }
        Ok(())
    }

    /// Fails with a clear message when `capacity` slots do not fit a storage binding.
    pub fn check_capacity(&self, emitter: &str, capacity: u32) -> Result<(), GpuError> {
        let limits = self.device.limits();
        let per = std::mem::size_of::<crate::gpu::types::Particle>() as u64;
        let needed = capacity as u64 * per;
        let (limit, limit_bytes) =
            if limits.max_storage_buffer_binding_size < limits.max_buffer_size {
                (
                    "max_storage_buffer_binding_size",
                    limits.max_storage_buffer_binding_size,
                )
            } else {
                ("max_buffer_size", limits.max_buffer_size)
            };
        if needed > limit_bytes {
            return Err(GpuError::CapacityTooLarge {
                emitter: emitter.to_owned(),
                capacity,
                needed_bytes: needed,
                limit,
                limit_bytes,
                max_capacity: limit_bytes / per,
            });
        }
        Ok(())
    }
}
