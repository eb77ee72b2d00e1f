//! GPU plumbing: the device context and the structs shared with WGSL.

pub mod commands;
pub mod context;
pub mod profile;
pub mod readback;
pub mod timer;
pub mod types;
pub mod upload;

pub use context::{GpuContext, GpuError, INT64_ATOMICS};
pub use profile::{AdapterProfile, ProfileKind, ProfileRequest, ProfileSetting};
pub use readback::TextureReadback;
pub use upload::Uploads;

/// The compute pass open in `pass`, begun in `enc` (labelled `label`) on first need: the
/// steps and the sorts of a frame each share one pass.
pub fn compute_pass<'p>(
    pass: &'p mut Option<wgpu::ComputePass<'static>>,
    enc: &mut wgpu::CommandEncoder,
    label: &str,
) -> &'p mut wgpu::ComputePass<'static> {
    pass.get_or_insert_with(|| {
        enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: None,
        })
        .forget_lifetime()
    })
}

/// A render pass (labelled `label`) over one colour target that starts with `load` (a
/// clear, or what the target holds) and stores what it draws; no depth.
pub fn color_pass<'a>(
    enc: &'a mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
    label: &str,
) -> wgpu::RenderPass<'a> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            },
        })],
        ..Default::default()
    })
}

/// What a plain render pipeline is made of: one vertex and one fragment entry of
/// `module` (no override constants), its vertex buffers, depth state and colour targets,
/// with the default primitive state.
pub struct PipelineParts<'a> {
    /// Debug label.
    pub label: &'a str,
    /// The layout (`None`: derived from the module).
    pub layout: Option<&'a wgpu::PipelineLayout>,
    /// The shader module.
    pub module: &'a wgpu::ShaderModule,
    /// The vertex and fragment entry points.
    pub entries: (&'a str, &'a str),
    /// Vertex buffers.
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    /// Depth test and write.
    pub depth_stencil: Option<wgpu::DepthStencilState>,
    /// Samples per pixel.
    pub multisample: wgpu::MultisampleState,
    /// The colour targets.
    pub targets: &'a [Option<wgpu::ColorTargetState>],
}

/// The render pipeline of `parts`.
pub fn render_pipeline(ctx: &GpuContext, parts: PipelineParts<'_>) -> wgpu::RenderPipeline {
    let PipelineParts {
        label,
        layout,
        module,
        entries: (vs, fs),
        buffers,
        depth_stencil,
        multisample,
        targets,
    } = parts;
    ctx.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout,
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers,
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil,
            multisample,
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets,
            }),
            multiview_mask: None,
            cache: None,
        })
}

/// A bind group layout of `entries`.
pub fn bind_group_layout(
    ctx: &GpuContext,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    ctx.device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries,
        })
}

/// A 2-D depth texture binding (a host's depth, sampled with `textureLoad`).
pub fn depth_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Depth,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A 1×1 depth texture's view, bound where no host depth is (shaders test its size).
pub fn placeholder_depth(device: &wgpu::Device, label: &str) -> wgpu::TextureView {
    texture_2d(
        device,
        label,
        (1, 1),
        1,
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::TEXTURE_BINDING,
    )
    .create_view(&Default::default())
}

/// A single-sample 2-D texture of `size` (each side at least 1) with `mips` levels.
pub fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    mips: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.0.max(1),
            height: size.1.max(1),
            depth_or_array_layers: 1,
        },
        mip_level_count: mips,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// A fragment-stage 2-D float texture binding.
pub fn fragment_texture_entry(binding: u32, filterable: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A fragment-stage filtering-sampler binding.
pub fn fragment_sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// A fragment-stage buffer binding without dynamic offset (`ty`: uniform or storage).
pub fn fragment_buffer_entry(
    binding: u32,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A compute-stage storage-buffer binding (read-only or read-write), the most common
/// layout entry of the compute passes.
pub fn compute_storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A compute pipeline of `entry` in `module` with override `constants`.
pub fn compute_pipeline(
    ctx: &GpuContext,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    ctx.device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            cache: None,
        })
}
