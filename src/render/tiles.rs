//! The tile draw path for large sprites: a compute rasteriser. Each frame's tile items
//! (emitters whose quads are drawn on the compute units) are projected once
//! (`tiles.wgsl` `project`, the quads of `quad.wgsl` that the billboards draw), listed per
//! 128-pixel bin in draw order (counted per block of sprites, scanned, then written:
//! `bin_count_blocks`, `bin_scan`, `bin_starts`, `bin`), and shaded per 16×16 tile and
//! emitter (`shade`):
//! alpha-blended layers back to front, light added, the tile's pixels read and written
//! once per emitter. A full-screen draw composites the result into the host's pass.
//! GPUs that keep only a sliver of their chip for rasterisation (the H100) fill large
//! sprites far faster this way.

use crate::gpu::commands::{CountedCompute, CountedRender};
use std::collections::HashMap;

use crate::gpu::{GpuContext, GpuError, Uploads};
use crate::render::billboard::DrawTarget;
use crate::render::frame::{DrawItem, FrameResources, LookVariant};
use crate::shaders::{ShaderError, ShaderLibrary, create_checked};
use crate::sim::gpu_sim::dispatch_size;

mod buffers;
mod chunks;
mod sizing;

use crate::render::compute_resolve::ComputeResolve;
use buffers::TileBuffers;
use chunks::Chunk;
use sizing::*;

/// Pixels per tile side (one workgroup each; keep in sync with `TILE` in tiles.wgsl).
pub const TILE_PX: u32 = 16;
/// Pixels per bin side (keep in sync with `BIN` in tiles.wgsl).
pub const BIN_PX: u32 = 128;
/// Bytes of one projected sprite (`TileSprite` in tiles.wgsl).
const SPRITE_BYTES: u64 = 192;
/// Tile items (emitters of a group of instances, or pieces of one) a chunk of the tile
/// passes draws at most (`MAX_ITEMS` in tiles.wgsl); more take further chunks.
pub const MAX_ITEMS: usize = 55;
/// Sprites a chunk of the tile passes holds at most (768 MB of projected sprites): a
/// frame with more is drawn chunk after chunk, each shaded over what the ones before it
/// left, an item larger than a chunk in pieces.
const CHUNK_SPRITES: u32 = 1 << 22;
/// Stride of each chunk's dispatch arguments (each piece's shade, then the tile lists'
/// chunk passes: `MAX_ITEMS + 1` of 16 bytes; the storage offset alignment).
const ARGS_STRIDE: u64 = 1024;
/// The `touched` buffer's header: the resolve's indirect draw arguments.
const TOUCHED_FLAGS: u64 = 4;
/// Entries per chunk of the tile lists' passes (`CHUNK` in tile_lists.wgsl).
const CHUNK: u64 = 256;
/// Sprites one bin workgroup lists (`BLOCK` in tiles.wgsl): the blocks of a frame's
/// sprites are binned in parallel; each item's sprites start at a multiple of it.
const BLOCK: u32 = 1024;
/// Bins a target may hold (`MAX_BINS` in tiles.wgsl): 7680×4320 at most, beyond it the
/// frame's tile items are billboards.
const MAX_BINS: u64 = 2048;
/// Stride of the per-dispatch jobs (`TileJob` in tiles.wgsl, to the storage offset
/// alignment).
const JOB_STRIDE: u64 = 512;
/// The bins' lists take at most this many bytes: a frame whose lists need more shades its
/// overflowing bins from the sprites directly.
const MAX_LIST_BYTES: u64 = 128 << 20;
/// Bytes per list entry: the sprite and the bin's tiles it covers.
const LIST_ENTRY_BYTES: u64 = 8;

/// What a build of `tiles.wgsl` makes.
struct Built {
    module: wgpu::ShaderModule,
    /// The basic variant's pipelines (built to validate the module).
    variants: HashMap<LookVariant, Option<[wgpu::ComputePipeline; 2]>>,
    bin: BinPipes,
    resolve: wgpu::RenderPipeline,
    /// The compute resolve, where the adapter can read and write the target in place.
    resolve_over: Option<wgpu::ComputePipeline>,
}

/// The binning's passes: count per block, scan per bin, the bins' starts, the lists; then
/// the tiles' lists: count per chunk, scan per bin, the bins' starts, scatter.
type BinPipes = [wgpu::ComputePipeline; 8];

/// Storage buffers per shader stage the tile passes bind (the looks, the six state
/// views, the tiles' six): a device created with fewer draws every quad as a billboard.
pub const STORAGE_BUFFERS_NEEDED: u32 = crate::gpu::context::TILE_STORAGE_BUFFERS;

/// Project, bin, shade and resolve.
pub struct TilePass {
    target: DrawTarget,
    tile_layout: wgpu::BindGroupLayout,
    /// The resolve's read-only view of the accumulation and the shaded tiles.
    resolve_group_layout: wgpu::BindGroupLayout,
    no_depth: wgpu::TextureView,
    compute_layout: wgpu::PipelineLayout,
    /// The bin's group 3 (the tile group and the shades' dispatch arguments) and layout.
    bin_group_layout: wgpu::BindGroupLayout,
    bin_layout: wgpu::PipelineLayout,
    /// The tiles' lists' passes: the tile group (as the shade's) in group 3.
    list_layout: wgpu::PipelineLayout,
    empty_group: wgpu::BindGroup,
    resolve_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    /// (project, shade) per look variant, built on first use (`None`: failed, logged).
    variants: HashMap<LookVariant, Option<[wgpu::ComputePipeline; 2]>>,
    bin: BinPipes,
    resolve: wgpu::RenderPipeline,
    /// The compute resolve's layouts, pipeline and groups over the targets it wrote last
    /// (`None`: the adapter cannot, or the host's target is not an HDR image).
    compute_resolve: Option<ComputeResolve>,
    resolve_over: Option<wgpu::ComputePipeline>,
    /// Whether [`TilePass::resolve_into`] may resolve by compute (tests compare it with
    /// the draw).
    compute_resolve_on: bool,
    sprites: crate::render::sprites::SpriteGroups,
    buffers: Option<TileBuffers>,
    /// Whether the last record shaded anything (the resolve draws only then).
    drawn: bool,
    /// The bins' lists' capacity in entries, when set (tests force an overflow with it).
    list_capacity: Option<u32>,
    /// The tiles' lists' capacity in entries, when set (tests force an overflow with it).
    tile_list_capacity: Option<u32>,
    /// Sprites per chunk, when set (tests draw a frame in many chunks).
    chunk_sprites: Option<u32>,
    /// The stages a record runs (the bench times them apart).
    stages: TileStages,
}

/// How far a record goes: the bench times the stages by recording the first ones alone.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TileStages {
    /// Project only.
    Project,
    /// Project and bin.
    Bin,
    /// Everything: project, bin and shade.
    #[default]
    All,
}

/// The tile passes' bind group and pipeline layouts.
struct TileLayouts {
    tile: wgpu::BindGroupLayout,
    sprite: wgpu::BindGroupLayout,
    resolve_group: wgpu::BindGroupLayout,
    compute: wgpu::PipelineLayout,
    bin_group: wgpu::BindGroupLayout,
    bin: wgpu::PipelineLayout,
    list: wgpu::PipelineLayout,
    resolve: wgpu::PipelineLayout,
    empty_group: wgpu::BindGroup,
}

impl TileLayouts {
    /// Group 0 is the frame's everywhere; the compute passes add the particles, the sprites
    /// and the tile group; the bin and list passes bind one group of their own at 3.
    fn new(ctx: &GpuContext, frame: &FrameResources) -> Self {
        let d = &ctx.device;
        let sprite_layout =
            crate::render::sprites::compute_sprite_layout(ctx, "TilePass::sprite_layout");
        let tile_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("TilePass::tile_layout"),
            entries: &TilePass::tile_entries(),
        });
        let read = |binding, visibility| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let resolve_group_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("TilePass::resolve_group_layout"),
            entries: &[
                read(
                    0,
                    wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ),
                read(1, wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE),
            ],
        });
        let compute_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("TilePass::compute_layout"),
            bind_group_layouts: &[
                Some(&frame.frame_layout),
                Some(&frame.particle_layout),
                Some(&sprite_layout),
                Some(&tile_layout),
            ],
            immediate_size: 0,
        });
        let bin_group_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("TilePass::bin_group_layout"),
            entries: &TilePass::bin_entries(),
        });
        let empty_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("TilePass::empty_layout"),
            entries: &[],
        });
        let empty_group = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("TilePass::empty_group"),
            layout: &empty_layout,
            entries: &[],
        });
        // The bin passes and the tiles' lists' passes: the frame and one group of their own.
        let group3_layout = |label, group: &wgpu::BindGroupLayout| {
            d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[
                    Some(&frame.frame_layout),
                    Some(&empty_layout),
                    Some(&empty_layout),
                    Some(group),
                ],
                immediate_size: 0,
            })
        };
        let bin_layout = group3_layout("TilePass::bin_layout", &bin_group_layout);
        // The tiles' lists' passes: the tile group (the chunk passes' arguments are read as
        // indirect arguments, so they may not be bound for writing).
        let list_layout = group3_layout("TilePass::list_layout", &tile_layout);
        let resolve_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("TilePass::resolve_layout"),
            bind_group_layouts: &[Some(&frame.frame_layout), Some(&resolve_group_layout)],
            immediate_size: 0,
        });
        Self {
            tile: tile_layout,
            sprite: sprite_layout,
            resolve_group: resolve_group_layout,
            compute: compute_layout,
            bin_group: bin_group_layout,
            bin: bin_layout,
            list: list_layout,
            resolve: resolve_layout,
            empty_group,
        }
    }
}

impl TilePass {
    /// Whether `device` was created with the limits the tile passes need.
    pub fn supported(device: &wgpu::Device) -> bool {
        device.limits().max_storage_buffers_per_shader_stage >= STORAGE_BUFFERS_NEEDED
    }

    /// Builds the pipelines from `lib`; the resolve draws into `target`, and the tiles
    /// test against its depth when it has one.
    pub fn new(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        frame: &FrameResources,
        target: DrawTarget,
    ) -> Result<Self, ShaderError> {
        let d = &ctx.device;
        let l = TileLayouts::new(ctx, frame);
        let compute_resolve = ComputeResolve::new(
            ctx,
            "TilePass::resolve_over",
            target,
            &[&frame.frame_layout, &l.resolve_group],
        );
        let built = Self::build(
            ctx,
            lib,
            [&l.compute, &l.bin, &l.list, &l.resolve],
            compute_resolve.as_ref().map(|c| &c.layout),
            target,
        )?;
        Ok(Self {
            target,
            tile_layout: l.tile,
            resolve_group_layout: l.resolve_group,
            no_depth: crate::gpu::placeholder_depth(d, "TilePass::no_depth"),
            compute_layout: l.compute,
            bin_group_layout: l.bin_group,
            bin_layout: l.bin,
            list_layout: l.list,
            empty_group: l.empty_group,
            resolve_layout: l.resolve,
            module: built.module,
            variants: built.variants,
            bin: built.bin,
            resolve: built.resolve,
            compute_resolve,
            resolve_over: built.resolve_over,
            compute_resolve_on: true,
            sprites: crate::render::sprites::SpriteGroups::new("TilePass::sprite_group", l.sprite),
            buffers: None,
            drawn: false,
            list_capacity: None,
            tile_list_capacity: None,
            chunk_sprites: None,
            stages: TileStages::All,
        })
    }

    /// Group 3: sprites, the shaded tiles, bin lists, bin starts, the accumulation, the
    /// host's depth and the dispatch's job.
    fn tile_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        let storage = |binding, visibility, read_only, dynamic| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        };
        let c = wgpu::ShaderStages::COMPUTE;
        vec![
            storage(0, c, false, false),
            storage(1, c, false, false),
            storage(2, c, false, false),
            storage(3, c, false, false),
            storage(4, c, false, false),
            crate::gpu::depth_texture_entry(5, c),
            storage(6, c, true, true),
        ]
    }

    /// The bin's group 3: the tile group and binding 7, the chunk's shades' dispatch
    /// arguments (a dynamic offset per chunk).
    fn bin_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        let mut entries = Self::tile_entries();
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 7,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: true,
                min_binding_size: None,
            },
            count: None,
        });
        entries
    }

    /// The module (validated with the full-state pipelines), the bin pipeline and the
    /// resolves.
    fn build(
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        [layout, bin_layout, list_layout, resolve_layout]: [&wgpu::PipelineLayout; 4],
        over_layout: Option<&wgpu::PipelineLayout>,
        target: DrawTarget,
    ) -> Result<Built, ShaderError> {
        let composed = lib.compose("tiles.wgsl")?;
        create_checked(&ctx.device, &composed, lib, |module| {
            let bin = [
                ("bin_count_blocks", bin_layout),
                ("bin_scan", bin_layout),
                ("bin_starts", bin_layout),
                ("bin", bin_layout),
                ("tiles_count", list_layout),
                ("tiles_scan", list_layout),
                ("tiles_starts", list_layout),
                ("tiles_scatter", list_layout),
            ]
            .map(|(entry, layout)| Self::compute(ctx, layout, module, entry, &[]));
            let basic = LookVariant::basic(false);
            let variants = HashMap::from([(
                basic,
                Some(Self::variant_pipelines(ctx, layout, module, basic, target)),
            )]);
            let resolve = crate::render::resolve_pipeline(
                ctx,
                "TilePass::resolve",
                resolve_layout,
                module,
                target,
                wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING,
            );
            let resolve_over =
                over_layout.map(|l| Self::compute(ctx, l, module, "resolve_over", &[]));
            Built {
                module: module.clone(),
                variants,
                bin,
                resolve,
                resolve_over,
            }
        })
    }

    fn compute(
        ctx: &GpuContext,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        entry: &str,
        constants: &[(&str, f64)],
    ) -> wgpu::ComputePipeline {
        let label = format!("TilePass::{entry}");
        crate::render::compute_pipeline(ctx, &label, layout, module, entry, constants)
    }

    /// The project and shade pipelines of a look variant.
    fn variant_pipelines(
        ctx: &GpuContext,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        v: LookVariant,
        target: DrawTarget,
    ) -> [wgpu::ComputePipeline; 2] {
        // tiles.wgsl has no motion pass and no ribbons (trails stay billboards).
        let mut constants = crate::render::variant::compute_constants(v, target);
        // Software blending (lavapipe) rounds f16 toward zero; the tiles round as it does.
        // The adapter's, whatever profile it runs (a software adapter may take the GPU
        // profile's choices).
        let round_down = ctx.info.device_type == wgpu::DeviceType::Cpu;
        constants.push(("F16_ROUND_DOWN", if round_down { 1.0 } else { 0.0 }));
        [
            Self::compute(ctx, layout, module, "project", &constants),
            Self::compute(ctx, layout, module, "shade", &constants),
        ]
    }

    /// Rebuilds the pipelines; keeps the old ones on error. Variants are rebuilt on
    /// first use.
    pub fn rebuild(&mut self, ctx: &GpuContext, lib: &ShaderLibrary) -> Result<(), ShaderError> {
        let layouts = [
            &self.compute_layout,
            &self.bin_layout,
            &self.list_layout,
            &self.resolve_layout,
        ];
        let over = self.compute_resolve.as_ref().map(|c| &c.layout);
        let built = Self::build(ctx, lib, layouts, over, self.target)?;
        self.module = built.module;
        self.bin = built.bin;
        self.resolve = built.resolve;
        self.resolve_over = built.resolve_over;
        self.variants = built.variants;
        Ok(())
    }

    /// Builds what the frame's tile items need: pipelines of their variants and sprite
    /// bind groups.
    fn prepare(&mut self, ctx: &GpuContext, items: &[&DrawItem], sampler: &wgpu::Sampler) {
        let (layout, module, target) = (&self.compute_layout, &self.module, self.target);
        self.sprites.prepare(
            ctx,
            ("tile", sampler),
            &mut self.variants,
            items.iter().copied(),
            |v| Self::variant_pipelines(ctx, layout, module, v, target),
        );
    }

    /// Projects, bins and shades every tile item of `items` (compute), testing against
    /// `depth` (the host's, single-sample and `size`) when given: chunk after chunk where
    /// the frame's sprites exceed one (`CHUNK_SPRITES`, or the device's binding limit).
    /// Returns false when there was nothing to draw (then `resolve` draws nothing).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        (enc, uploads): (&mut wgpu::CommandEncoder, &mut Uploads),
        frame: &FrameResources,
        items: &[DrawItem],
        size: (u32, u32),
        depth: Option<&wgpu::TextureView>,
    ) -> bool {
        let order = draw_order(items);
        self.drawn = false;
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        let capacity = self.chunk_sprites.unwrap_or_else(|| chunk_sprites(limit));
        let chunks = chunks::plan(&chunks::shapes(&order), capacity);
        if chunks.is_empty() {
            return false;
        }
        if grid_bins(size) > MAX_BINS {
            // A target larger than the bins: the buffers' memory goes back.
            self.buffers = None;
            return false;
        }
        let sprites = chunks.iter().map(Chunk::sprites).max().unwrap_or(0);
        let lists = self.list_capacity.unwrap_or_else(|| {
            let entries = |c: &Chunk| list_entries(|i| order[i].size_px, c, size, limit);
            chunks.iter().map(entries).max().unwrap_or(1)
        });
        self.prepare(ctx, &order, &frame.sprites.sampler);
        self.ensure_buffers(ctx, size, (sprites, lists), chunks.len() as u32, depth);
        let Some(b) = self.buffers.as_ref() else {
            return false;
        };
        self.upload_jobs((enc, uploads), &chunks);
        enc.clear_buffer(&b.touched, TOUCHED_FLAGS * 4, Some(grid_tiles(size) * 4));
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("TilePass::tiles"),
            timestamp_writes: None,
        });
        for (c, chunk) in chunks.iter().enumerate() {
            if !self.record_chunk(&mut pass, frame, b, (&order, c, chunk), size) {
                return false;
            }
        }
        drop(pass);
        self.drawn = true;
        true
    }

    /// Chunk `c` of the frame: its pieces projected, binned once, then each shaded in
    /// draw order over what the chunks before it left. False when the bench's stages stop
    /// before the shade.
    fn record_chunk(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        frame: &FrameResources,
        b: &TileBuffers,
        (order, c, chunk): (&[&DrawItem], usize, &Chunk),
        size: (u32, u32),
    ) -> bool {
        let jobs = (c * MAX_ITEMS) as u64 * JOB_STRIDE;
        let args = c as u64 * ARGS_STRIDE;
        for stage in 0..2 {
            if stage == 1 {
                if self.stages == TileStages::Project {
                    return false;
                }
                self.record_bins(pass, frame, b, size, (chunk.sprites() / BLOCK, jobs, args));
                if self.stages == TileStages::Bin {
                    return false;
                }
            }
            for (k, p) in chunk.pieces.iter().enumerate() {
                let d = order[p.item];
                let (Some(particles), Some(Some(pipes)), Some(sprite)) = (
                    frame.particle_group(d.key),
                    self.variants.get(&d.variant),
                    self.sprites.get(d.sprite.id),
                ) else {
                    continue;
                };
                pass.set_pipeline(&pipes[stage]);
                let look = FrameResources::look_offset(d.look_slot);
                pass.set_bind_group(0, &frame.frame_group, &[look]);
                pass.set_bind_group(1, particles, &[]);
                pass.set_bind_group(2, sprite, &[]);
                let job = jobs + k as u64 * JOB_STRIDE;
                pass.set_bind_group(3, &b.group, &[job as u32]);
                if stage == 0 {
                    // The piece's last block is filled up with empty sprites.
                    let (x, y) = dispatch_size(p.sprites());
                    pass.dispatch(x, y, 1);
                } else {
                    // Only the bins holding some of the piece's sprites (the bin scan
                    // lists them).
                    pass.dispatch_indirect(&b.dispatch_args, args + k as u64 * 16);
                }
            }
        }
        true
    }

    /// The binning's passes over a chunk's `blocks` blocks of sprites (its jobs and
    /// dispatch arguments at byte offsets `jobs` and `args`): count per block, scan per
    /// bin, the bins' starts, the lists; then the tiles' lists.
    fn record_bins(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        frame: &FrameResources,
        b: &TileBuffers,
        size: (u32, u32),
        (blocks, jobs, args): (u32, u64, u64),
    ) {
        pass.set_bind_group(0, &frame.frame_group, &[0]);
        pass.set_bind_group(1, &self.empty_group, &[]);
        pass.set_bind_group(2, &self.empty_group, &[]);
        pass.set_bind_group(3, &b.bin_group, &[jobs as u32, args as u32]);
        let bins = grid(size, BIN_PX);
        let [
            count,
            scan,
            starts,
            list,
            tile_count,
            tile_scan,
            tile_starts,
            tile_scatter,
        ] = &self.bin;
        pass.set_pipeline(count);
        pass.dispatch(blocks, 1, 1);
        pass.set_pipeline(scan);
        pass.dispatch(bins.0 * bins.1, 1, 1);
        pass.set_pipeline(starts);
        pass.dispatch(1, 1, 1);
        pass.set_pipeline(list);
        pass.dispatch(bins.0, bins.1, blocks);
        // The tiles' lists: over the chunks of the bins' lists (counted by `bin_starts`).
        let chunk_args = args + MAX_ITEMS as u64 * 16;
        pass.set_bind_group(3, &b.group, &[jobs as u32]);
        pass.set_pipeline(tile_count);
        pass.dispatch_indirect(&b.dispatch_args, chunk_args);
        pass.set_pipeline(tile_scan);
        pass.dispatch(bins.0 * bins.1, 1, 1);
        pass.set_pipeline(tile_starts);
        pass.dispatch(1, 1, 1);
        pass.set_pipeline(tile_scatter);
        pass.dispatch_indirect(&b.dispatch_args, chunk_args);
    }

    /// Sets how far the next records go (the bench times the stages apart; a record that
    /// stops before the shade draws nothing).
    #[doc(hidden)]
    pub fn set_stages(&mut self, stages: TileStages) {
        self.stages = stages;
    }

    /// Sets the bins' lists' capacity in entries (`None`: from the sprites' projected
    /// sizes). Tests make it small to force overflowing bins.
    #[doc(hidden)]
    pub fn set_list_capacity(&mut self, entries: Option<u32>) {
        self.list_capacity = entries;
    }

    /// Sets the sprites a chunk holds (`None`: `CHUNK_SPRITES`, within the device's
    /// binding limit). Tests draw a frame in many chunks with it.
    #[doc(hidden)]
    pub fn set_chunk_sprites(&mut self, sprites: Option<u32>) {
        self.chunk_sprites = sprites;
    }

    /// Every sprite's pixel bounds as the last record left them (tests check that records
    /// and block padding are empty sprites).
    #[doc(hidden)]
    pub fn read_sprite_bounds(&self, ctx: &GpuContext) -> Result<Vec<[i32; 4]>, GpuError> {
        self.read_bounds(ctx)
    }

    /// Sets the tiles' lists' capacity in entries (`None`: twice the bins' lists'). Tests
    /// make it small to shade bins from their bin lists.
    #[doc(hidden)]
    pub fn set_tile_list_capacity(&mut self, entries: Option<u32>) {
        self.tile_list_capacity = entries;
        self.buffers = None;
    }

    /// Composites the last record's tiles into an open render pass of the target's
    /// formats (nothing when it drew nothing).
    pub fn resolve(&self, pass: &mut wgpu::RenderPass<'_>, frame: &FrameResources) {
        let Some(b) = self.buffers.as_ref().filter(|_| self.drawn) else {
            return;
        };
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &frame.frame_group, &[0]);
        pass.set_bind_group(1, &b.resolve_group, &[]);
        pass.counted_draw_indirect(&b.touched, 0);
    }

    /// Composites the last record's tiles over `target` (the HDR image of `size` pixels
    /// the resolve would draw into, with storage usage) by compute instead of a draw: the
    /// same `dst · T + C` per shaded pixel, on every compute unit rather than the raster
    /// (the H100 keeps only a sliver of its chip for that). Returns false, recording
    /// nothing, where the adapter cannot (then [`TilePass::resolve`] draws it).
    pub fn resolve_into(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        frame: &FrameResources,
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) -> bool {
        if !self.can_resolve_into(size) {
            return false;
        }
        let (Some(c), Some(pipeline), Some(b)) = (
            self.compute_resolve.as_mut(),
            self.resolve_over.as_ref(),
            self.buffers.as_ref(),
        ) else {
            return false;
        };
        let label = ("TilePass::resolve_over", pipeline);
        let groups = [&b.resolve_group];
        c.dispatch(
            ctx,
            enc,
            label,
            (frame, &groups),
            target,
            grid(size, TILE_PX),
        );
        true
    }

    /// Whether [`TilePass::resolve_into`] resolves the last record into a target of
    /// `size` pixels.
    pub fn can_resolve_into(&self, size: (u32, u32)) -> bool {
        self.drawn
            && self.compute_resolve_on
            && self.resolve_over.is_some()
            && self.buffers.as_ref().is_some_and(|b| b.size == size)
    }

    /// Lets [`TilePass::resolve_into`] resolve by compute (the default) or not (tests
    /// compare the two).
    #[doc(hidden)]
    pub fn set_compute_resolve(&mut self, on: bool) {
        self.compute_resolve_on = on;
    }

    /// Whether the last record drew anything.
    pub fn drawn(&self) -> bool {
        self.drawn
    }
}
