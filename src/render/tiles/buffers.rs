//! The tile rasteriser's buffers and bind groups, sized to the target and the frame's
//! sprites, and each frame's jobs.

use super::*;

/// The frame's buffers for one target size and sprite capacity.
pub(super) struct TileBuffers {
    pub(super) size: (u32, u32),
    /// Sprites the buffers hold (whole blocks).
    pub(super) capacity: u32,
    /// Entries the bins' lists hold in all.
    pub(super) list_capacity: u32,
    /// Chunks the job buffer and the dispatch arguments hold.
    pub(super) chunks: u32,
    pub(super) job_buffer: wgpu::Buffer,
    /// The resolve's draw arguments, a flag per tile and the shaded tiles' list.
    pub(super) touched: wgpu::Buffer,
    /// Each chunk's shade dispatch arguments per piece, written by the bin (`ARGS_STRIDE`
    /// apart).
    pub(super) dispatch_args: wgpu::Buffer,
    pub(super) group: wgpu::BindGroup,
    pub(super) bin_group: wgpu::BindGroup,
    pub(super) resolve_group: wgpu::BindGroup,
    pub(super) depth: Option<wgpu::TextureView>,
    /// Everything else the group binds, kept alive with it: the sprites (read back by
    /// tests), the bins' lists, their counts and places, and the accumulation.
    pub(super) lists: [wgpu::Buffer; 4],
}

impl TilePass {
    /// Uploads one job per piece of each chunk (`TileJob`: its first sprite and quads,
    /// the chunk's sprites, the lists' capacity; its index, the pieces, the blocks and the
    /// tile lists' chunk capacity; its first quad of its item; every piece's first sprite),
    /// `MAX_ITEMS` jobs a chunk; the resolve's draw arguments (six vertices per shaded tile,
    /// counted by the shades) and the shades' dispatch arguments (bins counted by the bin
    /// scan, 64 tiles each), `ARGS_STRIDE` bytes a chunk.
    pub(super) fn upload_jobs(
        &self,
        (enc, uploads): (&mut wgpu::CommandEncoder, &mut Uploads),
        chunks: &[Chunk],
    ) {
        let Some(b) = self.buffers.as_ref() else {
            return;
        };
        let words = JOB_STRIDE as usize / 4;
        let mut jobs = vec![0u32; chunks.len() * MAX_ITEMS * words];
        let mut args = vec![0u32; chunks.len() * ARGS_STRIDE as usize / 4];
        for (c, chunk) in chunks.iter().enumerate() {
            let firsts = chunk.firsts();
            let total = firsts[firsts.len() - 1];
            for (k, p) in chunk.pieces.iter().enumerate() {
                let job = &mut jobs[(c * MAX_ITEMS + k) * words..][..words];
                let head = [
                    firsts[k],
                    p.quads,
                    total,
                    b.list_capacity,
                    k as u32,
                    chunk.pieces.len() as u32,
                    total / BLOCK,
                    chunk_capacity(b.list_capacity, b.size),
                    p.base,
                ];
                job[..head.len()].copy_from_slice(&head);
                job[12..12 + firsts.len()].copy_from_slice(&firsts);
                let a = c * ARGS_STRIDE as usize / 4 + 4 * k;
                args[a..a + 4].copy_from_slice(&[0, 64, 1, 0]);
            }
        }
        // Up to the last chunk's last job (a frame of one chunk writes its items' only).
        let last = chunks.last().map_or(0, |c| c.pieces.len());
        jobs.truncate(((chunks.len().max(1) - 1) * MAX_ITEMS + last) * words);
        uploads.write_bytes(enc, &b.job_buffer, 0, bytemuck::cast_slice(&jobs));
        uploads.write_bytes(enc, &b.touched, 0, bytemuck::cast_slice(&[6u32, 0, 0, 0]));
        uploads.write_bytes(enc, &b.dispatch_args, 0, bytemuck::cast_slice(&args));
    }

    /// Creates the buffers for `size`, `sprites` quads a chunk (capacity in powers of
    /// two), `lists` list entries and `chunks` chunks of jobs unless the current ones hold
    /// them; rebinds a new depth view.
    pub(super) fn ensure_buffers(
        &mut self,
        ctx: &GpuContext,
        size: (u32, u32),
        (sprites, list_capacity): (u32, u32),
        chunks: u32,
        depth: Option<&wgpu::TextureView>,
    ) {
        if let Some(b) = &self.buffers
            && b.size == size
            && b.capacity >= sprites
            && b.list_capacity >= list_capacity
            && (self.list_capacity.is_none() || b.list_capacity == list_capacity)
            && b.chunks >= chunks
            && b.depth.as_ref() == depth
        {
            return;
        }
        let capacity = sprites.next_power_of_two().max(BLOCK);
        let chunks = chunks.next_power_of_two();
        let (bx, by) = grid(size, BIN_PX);
        let bins = u64::from(bx * by);
        let buffer = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: usage | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let none = wgpu::BufferUsages::empty();
        let indirect = wgpu::BufferUsages::INDIRECT;
        let c = u64::from(capacity);
        // `touched`: the resolve's arguments, a flag per tile, the shaded tiles, and each
        // item's bins.
        let touched_words = TOUCHED_FLAGS + 2 * grid_tiles(size) + MAX_ITEMS as u64 * bins;
        // `bin_meta`: counts and places per bin and block, each bin's total and start; then
        // the tiles' lists (tile_lists.wgsl).
        let bin_words = 2 * bins * (c / u64::from(BLOCK)) + 2 * bins + 1;
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        let tile_words = tile_list_words(
            (list_capacity, self.tile_list_capacity),
            size,
            bin_words,
            limit,
        );
        let meta_words = bin_words + tile_words;
        let lists = [
            buffer(
                "TilePass::sprites",
                c * SPRITE_BYTES,
                wgpu::BufferUsages::COPY_SRC,
            ),
            buffer("TilePass::touched", touched_words * 4, indirect),
            buffer(
                "TilePass::bin_lists",
                u64::from(list_capacity) * LIST_ENTRY_BYTES,
                none,
            ),
            buffer("TilePass::bin_meta", meta_words * 4, none),
            buffer(
                "TilePass::accum",
                u64::from(size.0) * u64::from(size.1) * 8,
                none,
            ),
        ];
        let job_bytes = u64::from(chunks) * MAX_ITEMS as u64 * JOB_STRIDE;
        let job_buffer = buffer("TilePass::jobs", job_bytes, none);
        // Per chunk: each piece's shade, then the tile lists' chunk passes.
        let args_bytes = u64::from(chunks) * ARGS_STRIDE;
        let dispatch_args = buffer("TilePass::dispatch_args", args_bytes, indirect);
        let depth_view = depth.unwrap_or(&self.no_depth);
        let [tile_group, bin_group, resolve_group] =
            self.bind_groups(ctx, &lists, (&job_buffer, &dispatch_args), depth_view);
        let [sprites_buf, touched, bin_lists, meta, accum] = lists;
        self.buffers = Some(TileBuffers {
            size,
            capacity,
            list_capacity,
            chunks,
            job_buffer,
            touched,
            dispatch_args,
            group: tile_group,
            bin_group,
            resolve_group,
            depth: depth.cloned(),
            lists: [sprites_buf, bin_lists, meta, accum],
        });
    }

    /// Every sprite's pixel bounds in the buffers (lo x, lo y, hi x, hi y; empty when lo
    /// exceeds hi), read back after the GPU's work so far (blocking); none before a draw.
    pub(super) fn read_bounds(&self, ctx: &GpuContext) -> Result<Vec<[i32; 4]>, GpuError> {
        let Some(b) = self.buffers.as_ref() else {
            return Ok(Vec::new());
        };
        let sprites = &b.lists[0];
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("TilePass::sprite_bounds"),
            size: sprites.size(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(sprites, 0, &staging, 0, sprites.size());
        ctx.queue.submit([enc.finish()]);
        let bytes = crate::gpu::readback::map_read(ctx, &staging)?;
        Ok(bytes
            .chunks_exact(SPRITE_BYTES as usize)
            .map(|s| bytemuck::pod_read_unaligned::<[i32; 4]>(&s[..16]))
            .collect())
    }

    /// The tile group (`lists`: sprites, touched, bin lists, bin meta, accumulation; the
    /// host's depth view; the jobs), the bin passes' group (the same and the dispatch
    /// arguments) and the resolve's group (accumulation and touched), over new buffers.
    pub(super) fn bind_groups(
        &self,
        ctx: &GpuContext,
        lists: &[wgpu::Buffer; 5],
        (job_buffer, dispatch_args): (&wgpu::Buffer, &wgpu::Buffer),
        depth_view: &wgpu::TextureView,
    ) -> [wgpu::BindGroup; 3] {
        let group = |layout, args: Option<&wgpu::Buffer>| {
            let mut entries: Vec<wgpu::BindGroupEntry<'_>> = lists
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry {
                    binding: [0, 1, 2, 3, 4][i],
                    resource: b.as_entire_binding(),
                })
                .collect();
            entries.push(wgpu::BindGroupEntry {
                binding: 5,
                resource: wgpu::BindingResource::TextureView(depth_view),
            });
            entries.push(wgpu::BindGroupEntry {
                binding: 6,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: job_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(JOB_STRIDE),
                }),
            });
            entries.extend(args.map(|a| wgpu::BindGroupEntry {
                binding: 7,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: a,
                    offset: 0,
                    size: wgpu::BufferSize::new(ARGS_STRIDE),
                }),
            }));
            ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("TilePass::group"),
                layout,
                entries: &entries,
            })
        };
        let tile_group = group(&self.tile_layout, None);
        let bin_group = group(&self.bin_group_layout, Some(dispatch_args));
        let resolve_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("TilePass::resolve_group"),
            layout: &self.resolve_group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: lists[4].as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: lists[1].as_entire_binding(),
                },
            ],
        });
        [tile_group, bin_group, resolve_group]
    }
}
