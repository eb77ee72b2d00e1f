//! Per-frame resources shared by both draw paths: the camera and per-emitter look
//! uniforms, the bind-group layouts, and bind groups over the state buffers (cached by
//! buffer generation and parity).

use std::collections::HashMap;

use std::path::Path;
use std::sync::Arc;

use crate::effect::rows_key;
use crate::effect::{
    BlendMode, DrawPath, Look, SPLAT_BELOW_PX, SPLAT_PX_PER_QUAD, TILES_ABOVE_PX,
    TILES_MIN_FILL_PX, TILES_MIN_QUADS,
};
use crate::gpu::types::{CameraUniform, PARAMS_STRIDE};
use crate::gpu::{AdapterProfile, GpuContext};
use crate::render::camera::Camera;
use crate::render::look_bake::{
    RAMP_WIDTH, ROWS_PER_EMITTER, bake_look_curves, bake_ramp, gradient_key, look_curve_params,
};
use crate::render::scene_lighting::SceneLighting;
use crate::render::sort::{SortJob, SortMember};
use crate::render::sprites::{SpriteError, SpriteLibrary, SpriteTexture};

mod looks;

use super::draw_item::glow_sized;
pub use super::draw_item::{DrawItem, LOOKS_PER_DRAW, Scene, SceneGroup};
pub use super::variant::{LookVariant, StateVariant};
pub use looks::look_uniform;
use looks::{GroupLooks, write_looks};

/// What `prepare` draws one group with.
struct GroupView<'g, 'a> {
    group: &'g SceneGroup<'a>,
    camera: &'g Camera,
    alpha: f32,
    asset_dir: Option<&'g Path>,
    /// The first group reports sprite errors and bakes the ramps.
    first_group: bool,
}

/// A sprite trim as the looks use it: the rectangle, the octagon's packed cuts and the
/// share of the rectangle the octagon draws.
pub(crate) type LookTrim = ([f32; 4], u32, f32);

/// Uniform buffers, layouts and bind groups for the draw passes.
pub struct FrameResources {
    /// Group 0 of both draw paths: camera + the looks of a draw's instances (storage,
    /// dynamic offset) + ramps.
    pub frame_layout: wgpu::BindGroupLayout,
    /// Group 1: previous and current state.
    pub particle_layout: wgpu::BindGroupLayout,
    camera: wgpu::Buffer,
    /// The camera the last `prepare` was given, for `upload_looks`.
    camera_block: CameraUniform,
    looks: wgpu::Buffer,
    look_slots: usize,
    ramps: wgpu::Texture,
    ramp_rows: usize,
    /// What each ramp row holds (`gradient_key`), to upload only changes.
    ramp_keys: Vec<Option<u64>>,
    /// Sprite textures (built-in and PNG).
    pub sprites: SpriteLibrary,
    /// Sprite load errors of the last `prepare`: (emitter index, error).
    pub sprite_errors: Vec<(usize, SpriteError)>,
    /// The group-0 bind group.
    pub frame_group: wgpu::BindGroup,
    /// Particle bind groups with the order buffer each was made over (a sort's buffers
    /// are replaced when its batch's instance count changes).
    particle_groups: HashMap<(u64, usize, bool), (wgpu::Buffer, wgpu::BindGroup)>,
    /// Bound as the draw order of emitters that are not sorted.
    no_order: wgpu::Buffer,
    /// Bound as the trail ring of emitters without a trail.
    no_trail: wgpu::Buffer,
    /// Cut billboards to the occupied part of their sprite (on by default; off draws the
    /// whole square, for comparisons).
    pub trim_sprites: bool,
    /// Cut billboards to an octagon where their sprite leaves the rectangle's corners
    /// empty (on by default; off draws rectangles, for comparisons).
    pub octagons: bool,
    /// Draw and sort only each emitter's live window of the ring (on by default; off
    /// visits every slot, for comparisons).
    pub live_window_only: bool,
    /// Sprite trims by (sprite id, flipbook rows, columns, threshold bits): found once.
    trims: HashMap<(u64, u32, u32, u32), LookTrim>,
    /// Let small additive particles take the compute splat (off in the runtime player,
    /// which draws everything inside the host's pass).
    pub allow_splat: bool,
    /// Soft edges read the host's depth buffer instead of the preset's ground plane.
    pub soft_depth: bool,
    /// The tile rasteriser exists (the device's limits allow it).
    pub allow_tiles: bool,
    /// The host draws the alpha-blended layer at reduced resolution: its emitters stay
    /// off the tiles, which resolve at the host's full size.
    pub blended_reduced: bool,
    /// The host draws the glow layer at reduced resolution: large additive emitters
    /// (what [`DrawItem::is_glow`] names) stay off the tiles too.
    pub glow_reduced: bool,
    /// This frame's look blocks on their way to `looks`.
    look_bytes: Vec<u8>,
    /// The light lit layers are drawn in (the host's, or the effect's own `lighting`
    /// when `None`).
    pub lighting: Option<SceneLighting>,
    /// Each look slot's simulation-space origin in the last `prepare` (the effect's
    /// light is moved between emitters' spaces with them).
    pub slot_origins: Vec<glam::DVec3>,
}

/// What the automatic draw path looks at: the particles' largest projected size (pixels),
/// the quads of the draw (the widest live window × the instances: at least the live
/// particles), whether a trail's ribbon is drawn, and the target's size.
struct PathScene {
    size_px: f32,
    quads: u32,
    trail: bool,
    target_px: (u32, u32),
}

impl FrameResources {
    /// Creates the layouts and uniform buffers.
    pub fn new(ctx: &GpuContext) -> Self {
        let d = &ctx.device;
        let (frame_layout, particle_layout) = Self::layouts(d);
        let camera = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("FrameResources::camera"),
            size: size_of::<CameraUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (looks, ramps, frame_group) = Self::look_buffer(ctx, &frame_layout, &camera, (4, 4));
        Self {
            frame_layout,
            particle_layout,
            camera,
            camera_block: Default::default(),
            looks,
            look_slots: 4,
            ramps,
            ramp_rows: 4,
            ramp_keys: vec![None; 4],
            sprites: SpriteLibrary::new(ctx),
            sprite_errors: Vec::new(),
            frame_group,
            particle_groups: HashMap::new(),
            no_order: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("FrameResources::no_order"),
                size: 16,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            }),
            no_trail: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("FrameResources::no_trail"),
                size: 64,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            }),
            trim_sprites: true,
            octagons: true,
            live_window_only: true,
            trims: HashMap::new(),
            allow_splat: true,
            soft_depth: false,
            allow_tiles: false,
            blended_reduced: false,
            glow_reduced: false,
            look_bytes: Vec::new(),
            lighting: None,
            slot_origins: Vec::new(),
        }
    }

    /// Group 0 (the camera, the looks, the ramps) and group 1 (the particles' state).
    fn layouts(d: &wgpu::Device) -> (wgpu::BindGroupLayout, wgpu::BindGroupLayout) {
        let all = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        // Both draw paths read the looks as read-only *storage*: an array of a draw's
        // instances, and lavapipe (Mesa 22.3) inlines uniform-buffer values that steer
        // branches into the shader and recompiles it on every bind of a new offset — ~3 ms
        // per emitter and instance.
        let buffer = |binding, ty, dynamic| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: all,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let frame_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("FrameResources::frame_layout"),
            entries: &[
                buffer(0, wgpu::BufferBindingType::Uniform, false),
                buffer(
                    1,
                    wgpu::BufferBindingType::Storage { read_only: true },
                    true,
                ),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: all,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let particle_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("FrameResources::particle_layout"),
            // 3, 4: the same state buffers as 0, 1, seen as packed (or tiny) state; 5: the
            // tiny state's birth table; 6: the trail's ring (the billboards' ribbons; vertex
            // only, so that it does not count toward the compute paths' storage buffers).
            entries: &[
                storage(0),
                storage(1),
                storage(2),
                storage(3),
                storage(4),
                storage(5),
                wgpu::BindGroupLayoutEntry {
                    visibility: wgpu::ShaderStages::VERTEX,
                    ..storage(6)
                },
            ],
        });
        (frame_layout, particle_layout)
    }

    /// The looks buffer (`slots.0` uniforms), the ramps (`slots.1` rows) and a group 0
    /// over them for each of `layouts`.
    fn look_buffer(
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        camera: &wgpu::Buffer,
        (slots, rows): (usize, usize),
    ) -> (wgpu::Buffer, wgpu::Texture, wgpu::BindGroup) {
        let looks = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("FrameResources::looks"),
            // Room for a full draw's array from the last slot.
            size: (slots + LOOKS_PER_DRAW) as u64 * PARAMS_STRIDE,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let ramps = crate::gpu::texture_2d(
            &ctx.device,
            "FrameResources::ramps",
            (RAMP_WIDTH, rows as u32),
            1,
            wgpu::TextureFormat::Rgba32Float,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        let ramp_view = ramps.create_view(&Default::default());
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("FrameResources::frame_group"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: camera.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    // A draw's instances' looks, as an array from the dynamic offset.
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &looks,
                        offset: 0,
                        size: wgpu::BufferSize::new(LOOKS_PER_DRAW as u64 * PARAMS_STRIDE),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&ramp_view),
                },
            ],
        });
        (looks, ramps, group)
    }

    /// The dynamic offset of emitter `index`'s look uniform.
    pub fn look_offset(slot: usize) -> u32 {
        (slot as u64 * PARAMS_STRIDE) as u32
    }

    /// The particle bind group for a draw item.
    pub fn particle_group(&self, key: (u64, usize, bool)) -> Option<&wgpu::BindGroup> {
        self.particle_groups.get(&key).map(|(_, g)| g)
    }

    /// Bakes and uploads emitter `i`'s colour ramp and curve rows (rows
    /// `ROWS_PER_EMITTER · i` on) when its gradient or curves changed.
    fn upload_ramp(&mut self, ctx: &GpuContext, i: usize, look: &Look) {
        let key = gradient_key(look) ^ rows_key(&look_curve_params(look)).rotate_left(1);
        if self.ramp_keys.get(i).copied().flatten() == Some(key) {
            return;
        }
        let mut rows = bake_ramp(&look.color_over_life);
        let [a, b] = bake_look_curves(look);
        rows.extend(a);
        rows.extend(b);
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.ramps,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: ROWS_PER_EMITTER * i as u32,
                    z: 0,
                },
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&rows),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(RAMP_WIDTH * 16),
                rows_per_image: Some(ROWS_PER_EMITTER),
            },
            wgpu::Extent3d {
                width: RAMP_WIDTH,
                height: ROWS_PER_EMITTER,
                depth_or_array_layers: 1,
            },
        );
        if let Some(k) = self.ramp_keys.get_mut(i) {
            *k = Some(key);
        }
    }

    /// Grows the looks buffer to `slots` uniforms and the ramps to `rows` rows (powers of
    /// two; both only grow).
    fn reserve(&mut self, ctx: &GpuContext, slots: usize, rows: usize) {
        if slots <= self.look_slots && rows <= self.ramp_rows {
            return;
        }
        self.look_slots = self.look_slots.max(slots.next_power_of_two());
        self.ramp_rows = self.ramp_rows.max(rows.next_power_of_two());
        let (looks, ramps, group) = Self::look_buffer(
            ctx,
            &self.frame_layout,
            &self.camera,
            (self.look_slots, self.ramp_rows),
        );
        self.looks = looks;
        self.ramps = ramps;
        self.ramp_keys = vec![None; self.ramp_rows];
        self.frame_group = group;
    }

    /// Uploads this frame's camera, builds its looks ([`FrameResources::upload_looks`]
    /// uploads them) and returns what to draw, with each emitter's path:
    /// one item per group and emitter. A group's instances take consecutive look slots
    /// for each emitter; emitter `i` of every instance shares ramp row `i` (the groups
    /// are instances of one effect).
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        groups: &[&SceneGroup<'_>],
        camera: &Camera,
        alpha: f32,
        sort: &mut crate::render::sort::SortPass,
        asset_dir: Option<&Path>,
    ) -> Vec<DrawItem> {
        self.camera_block = camera.uniform(alpha);
        let emitters = |g: &SceneGroup<'_>| {
            g.iter()
                .flatten()
                .next()
                .map_or(0, |s| s.effect.emitters.len())
        };
        let slots: usize = groups.iter().map(|g| g.len() * emitters(g)).sum();
        let rows =
            ROWS_PER_EMITTER as usize * groups.iter().map(|g| emitters(g)).max().unwrap_or(0);
        self.reserve(ctx, slots, rows);
        self.sprite_errors.clear();
        // Reused from frame to frame: a fresh allocation of this size is fresh pages.
        let mut blocks = std::mem::take(&mut self.look_bytes);
        blocks.clear();
        blocks.resize(slots * PARAMS_STRIDE as usize, 0);
        let mut items = Vec::new();
        let mut slot = 0;
        self.slot_origins.clear();
        for (n, group) in groups.iter().enumerate() {
            for i in 0..emitters(group) {
                self.slot_origins.extend(group.iter().map(|s| {
                    s.as_ref()
                        .and_then(|s| s.sim.planner().emitters.get(i).map(|p| p.origin()))
                        .unwrap_or_default()
                }));
                let block = &mut blocks[slot * PARAMS_STRIDE as usize..]
                    [..group.len() * PARAMS_STRIDE as usize];
                let view = GroupView {
                    group,
                    camera,
                    alpha,
                    asset_dir,
                    first_group: n == 0,
                };
                let item = self.prepare_emitter(ctx, &view, i, sort, block);
                items.extend(item.map(|d| DrawItem {
                    look_slot: slot,
                    group: n,
                    ..d
                }));
                slot += group.len();
            }
        }
        self.look_bytes = blocks;
        // Alpha-blended layers are drawn in one order by one path: all by the tiles or
        // none — but ribbons, which only the billboards draw: those are drawn first
        // (behind the tiles' blended layers) and leave the others their path; and heat
        // haze, which is not drawn in colour at all.
        if items.iter().any(|d| {
            d.blend == BlendMode::Alpha && !d.tiles && d.trail.is_none() && !d.variant.haze
        }) {
            for d in items.iter_mut().filter(|d| d.blend == BlendMode::Alpha) {
                d.tiles = false;
            }
        }
        let live: std::collections::HashSet<u64> = items.iter().map(|d| d.key.0).collect();
        self.particle_groups.retain(|k, _| live.contains(&k.0));
        items
    }

    /// The looks buffer (a `LookSlot` per slot; written by the lit layers' light pass).
    pub fn looks_buffer(&self) -> &wgpu::Buffer {
        &self.looks
    }

    /// Uploads the camera and the looks the last [`FrameResources::prepare`] built,
    /// through `uploads` with copies recorded into `enc` (outside a pass).
    pub fn upload_looks(&self, uploads: &mut crate::gpu::Uploads, enc: &mut wgpu::CommandEncoder) {
        let camera = bytemuck::bytes_of(&self.camera_block);
        uploads.write_bytes(enc, &self.camera, 0, camera);
        uploads.write_bytes(enc, &self.looks, 0, &self.look_bytes);
    }

    /// Writes emitter `i`'s look uniform of every instance of a group into `block` and
    /// returns its draw (look slot left for the caller), or `None` when it has no pool or
    /// is disabled. The first group's emitters also bake the shared colour ramps.
    /// Emitter `i`'s texture: its six-way maps when lit, else its sprite (a load error is
    /// reported once, by the first group).
    fn emitter_sprite(
        &mut self,
        ctx: &GpuContext,
        view: &GroupView<'_, '_>,
        i: usize,
        look: &Look,
    ) -> Arc<SpriteTexture> {
        let lit = look.lit.as_ref().filter(|_| look.blend == BlendMode::Alpha);
        let (sprite, error) = match lit {
            Some(lit) => self.sprites.resolve_lit(ctx, &lit.maps, view.asset_dir),
            None => self.sprites.resolve(ctx, &look.sprite, view.asset_dir),
        };
        if let Some(err) = error.filter(|_| view.first_group) {
            self.sprite_errors.push((i, err));
        }
        sprite
    }

    fn prepare_emitter(
        &mut self,
        ctx: &GpuContext,
        view: &GroupView<'_, '_>,
        i: usize,
        sort: &mut crate::render::sort::SortPass,
        block: &mut [u8],
    ) -> Option<DrawItem> {
        let first = view.group.iter().flatten().next()?;
        let e = first.effect.emitters.get(i)?;
        let sprite = self.emitter_sprite(ctx, view, i, &e.look);
        if view.first_group {
            // Emitter i of every instance shares ramp row i: the first group's look bakes it.
            self.upload_ramp(ctx, i, &e.look);
        }
        let (base, octagon_share) = self.base_look(first.effect, i, &sprite);
        let emitter = looks::GroupEmitter::of(first.effect, i);
        let GroupLooks {
            looks,
            members,
            pool,
            distance,
        } = self.group_looks(view, &emitter, &base);
        let b = pool?;
        let width = looks
            .iter()
            .flatten()
            .map(|u| u.ring_b[3])
            .max()
            .unwrap_or(0);
        write_looks(block, &looks, width, b.capacity);
        if let Some(lit) = e
            .look
            .lit
            .as_ref()
            .filter(|_| e.look.blend == BlendMode::Alpha)
        {
            self.write_lit_looks(view, i, lit, block);
        }
        if !e.enabled {
            return None;
        }
        let n = view.group.len() as u32;
        let (job, key) = self.bind_particles(ctx, sort, &b, e.look.blend, (width, n), members);
        let size_m = e.look.size_m.bounds().1;
        let size_px = size_m * view.camera.pixels_per_unit() / distance.max(1e-3);
        // A trail's ribbon is drawn by the billboards (segments between its recorded
        // points), and so is its particle's sprite.
        let trail = e
            .look
            .trail
            .as_ref()
            .filter(|_| b.trail.is_some())
            .map(|t| {
                let step = first.effect.time.nominal_step_secs();
                (t.segments(step), t.draw_sprite)
            });
        let (splat, tiles) = self.choose_path(
            &ctx.profile,
            &e.look,
            PathScene {
                size_px,
                quads: width * n,
                trail: trail.is_some(),
                target_px: view.camera.size_px(),
            },
        );
        let mut variant = LookVariant::of(
            &e.look,
            StateVariant {
                layout: b.layout,
                stateless: emitter.stateless,
            },
        );
        variant.soft_depth = self.soft_depth;
        // Billboards alone (the compute paths cut by the rectangle): the octagon where
        // it spares enough of the rectangle's fill to pay for twice the vertices.
        variant.octagon = self.octagons
            && !splat
            && !tiles
            && octagon_share.is_some_and(|s| s <= crate::render::sprite_trim::OCTAGON_SHARE);
        Some(DrawItem {
            index: i,
            look_slot: 0,
            group: 0,
            members: n,
            key,
            capacity: b.capacity,
            width,
            sort: job,
            blend: e.look.blend,
            splat,
            tiles,
            variant,
            sprite,
            size_px,
            trail,
        })
    }

    /// The sort job of an alpha-blended emitter (drawn back to front through the sort's
    /// order: one sort over the group's slots, `shape` = (widest window, instances)) and
    /// the key of the particle bind group over pool `b`, made here unless it exists.
    fn bind_particles(
        &mut self,
        ctx: &GpuContext,
        sort: &mut crate::render::sort::SortPass,
        b: &crate::sim::gpu_sim::EmitterBuffers<'_>,
        blend: BlendMode,
        shape: (u32, u32),
        members: Vec<SortMember>,
    ) -> (Option<SortJob>, (u64, usize, bool)) {
        let (width, n) = shape;
        let sorted = blend == BlendMode::Alpha;
        let job = sorted.then(|| SortJob {
            key: b.generation,
            state: b.current.clone(),
            layout: b.layout,
            capacity: b.capacity,
            width,
            members,
        });
        let order_buffer = job
            .as_ref()
            .map(|j| sort.buffers(ctx, j.key, b.capacity * n).values.clone());
        let key = (b.generation, b.parity, sorted);
        self.ensure_particle_group(ctx, key, b, order_buffer);
        (job, key)
    }

    /// The draw path of an emitter with look `look` in `scene`: (splat, tiles); neither is
    /// the billboards. The look's `draw_path` forces one (where the emitter can take it);
    /// `Auto` chooses from the projected size, the count and the adapter `profile`
    /// (`tile_raster`, `splat_dense_only`).
    fn choose_path(&self, profile: &AdapterProfile, look: &Look, scene: PathScene) -> (bool, bool) {
        if look.heat_haze.is_some() {
            // Haze is drawn by the billboards only, into the distortion target.
            return (false, false);
        }
        let PathScene {
            size_px,
            quads,
            trail,
            target_px: (tw, th),
        } = scene;
        // Dense enough for the splat's whole-target clear and resolve to pay.
        let dense =
            !profile.splat_dense_only || quads as f32 * SPLAT_PX_PER_QUAD >= tw as f32 * th as f32;
        let splat = self.allow_splat
            && look.blend == BlendMode::Additive
            && !trail
            && match look.draw_path {
                // Streaks are long even when the particles are small.
                DrawPath::Auto => size_px < SPLAT_BELOW_PX && look.streak.is_none() && dense,
                DrawPath::Billboard | DrawPath::Tiles => false,
                DrawPath::Splat => true,
            };
        // The compute paths test the host's depth themselves: they need its view.
        // Streaks stay billboards: slivers a pixel or two wide, whose coverage and mip
        // level the rasteriser decides per 2×2 pixels.
        let tiles = self.allow_splat
            && self.allow_tiles
            && !self.reduced(look, size_px)
            && !splat
            && look.streak.is_none()
            && !trail
            && match look.draw_path {
                DrawPath::Auto => {
                    // Billboard fill at most (every quad at the largest size), of every
                    // instance of a group (a runtime host's batch is one group): on an
                    // H100 at 1080p, 100 torches on a grid took 2.2 ms a frame on the
                    // tiles against 3.2 on billboards, and 100 at one spot 15.7 ms against
                    // 31.2 (`bench/results/runtime-nvidia-h100-80gb.md`). Many quads take
                    // them whatever their fill.
                    let fill = quads as f32 * size_px * size_px;
                    let heavy = fill >= TILES_MIN_FILL_PX || quads >= TILES_MIN_QUADS;
                    profile.tile_raster && size_px >= TILES_ABOVE_PX && heavy
                }
                DrawPath::Tiles => true,
                DrawPath::Billboard | DrawPath::Splat => false,
            };
        (splat, tiles)
    }

    /// Whether an emitter with look `look`, its particles up to `size_px` on screen, is
    /// in a layer the host draws at reduced resolution (then not on the tiles).
    fn reduced(&self, look: &Look, size_px: f32) -> bool {
        match look.blend {
            BlendMode::Alpha => self.blended_reduced,
            BlendMode::Additive => {
                self.glow_reduced && glow_sized(look.blend, look.streak.is_some(), size_px)
            }
        }
    }

    /// Creates the particle bind group `key` names unless it exists: `b`'s state, and
    /// `order` (the sort's) or the unsorted placeholder.
    fn ensure_particle_group(
        &mut self,
        ctx: &GpuContext,
        key: (u64, usize, bool),
        b: &crate::sim::gpu_sim::EmitterBuffers<'_>,
        order: Option<wgpu::Buffer>,
    ) {
        let order = order.unwrap_or_else(|| self.no_order.clone());
        if self
            .particle_groups
            .get(&key)
            .is_some_and(|(bound, _)| *bound == order)
        {
            return;
        }
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("FrameResources::particle_group"),
            layout: &self.particle_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: b.previous.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: b.current.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: order.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: b.previous.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: b.current.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: b.births.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: b.trail.unwrap_or(&self.no_trail).as_entire_binding(),
                },
            ],
        });
        self.particle_groups.insert(key, (order, group));
    }
}
