//! Per-frame resources shared by both draw paths: the camera and per-emitter look
//! uniforms, the bind-group layouts, and bind groups over the state buffers (cached by
//! buffer generation and parity).

use std::collections::HashMap;

use std::path::Path;
use std::sync::Arc;

use crate::effect::rows_key;
use crate::effect::{
    BlendMode, DrawPath, Effect, FlipbookMode, Look, SPLAT_BELOW_PX, SPLAT_PX_PER_QUAD, Streak,
    TILES_ABOVE_PX, TILES_MIN_FILL_PX,
};
use crate::gpu::types::{CameraUniform, LookUniform, PARAMS_STRIDE, StateLayout};
use crate::gpu::{AdapterProfile, GpuContext};
use crate::render::camera::Camera;
use crate::render::lit::{LitUniform, SceneLighting, write_lit};
use crate::render::look::{
    RAMP_WIDTH, ROWS_PER_EMITTER, bake_look_curves, bake_ramp, gradient_key, look_curve_params,
};
use crate::render::sort::{SortJob, SortMember};
use crate::render::sprites::{SpriteError, SpriteLibrary, SpriteTexture};
use crate::sim::Modules;
use crate::sim::gpu_sim::SimState;

/// One simulation to draw: its state and the effect it runs (one instance of a player).
#[derive(Clone, Copy)]
pub struct Scene<'a> {
    /// The particles.
    pub sim: &'a dyn SimState,
    /// The effect they follow (looks, forces for closed-form emitters).
    pub effect: &'a Effect,
}

/// Instances drawn together, one draw per emitter: their pools are segments of one set
/// of state buffers (a batch; `members[k]` owns segment k, `None` an empty segment), or
/// one instance's own buffers.
pub type SceneGroup<'a> = [Option<Scene<'a>>];

/// Looks one draw reads at most (a batch's instances).
pub const LOOKS_PER_DRAW: usize = crate::sim::batch::BATCH_SLOTS as usize;

/// One emitter of a group of instances to draw this frame.
#[derive(Clone, Debug)]
pub struct DrawItem {
    /// Emitter index in its effect (the colour ramp's row).
    pub index: usize,
    /// The look uniform slot of the group's first instance (the others follow).
    pub look_slot: usize,
    /// The group of instances it draws (its index in the frame; items of one group
    /// share their instances, member by member).
    pub group: usize,
    /// Instances (segments) the draw covers.
    pub members: u32,
    /// Key of the cached particle bind group.
    pub key: (u64, usize, bool),
    /// Slots of each instance's pool.
    pub capacity: u32,
    /// Quads per instance: the widest live window of the group.
    pub width: u32,
    /// The back-to-front sort of the group's slots (alpha-blended emitters).
    pub sort: Option<SortJob>,
    /// Blend mode.
    pub blend: BlendMode,
    /// The path chosen for this frame: the compute splat.
    pub splat: bool,
    /// The path chosen for this frame: the compute tile rasteriser (`tiles.rs`).
    pub tiles: bool,
    /// The billboard pipeline variant.
    pub variant: LookVariant,
    /// The sprite texture.
    pub sprite: Arc<SpriteTexture>,
    /// The particles' largest size on screen at the emitter's distance, pixels.
    pub size_px: f32,
    /// The trail's ribbon: segments per particle, and whether the sprite is drawn too.
    pub trail: Option<(u32, bool)>,
}

impl DrawItem {
    /// Whether the billboards draw it (neither the splat nor the tiles do).
    pub fn is_billboard(&self) -> bool {
        !self.splat && !self.tiles
    }

    /// The order of a frame's draws: alpha-blended layers first, as given (back to
    /// front), then the light by emitter (each emitter's instances share a pipeline and a
    /// sprite; light adds up in any order).
    pub fn draw_key(&self) -> (u8, usize) {
        match self.blend {
            BlendMode::Alpha => (0, 0),
            BlendMode::Additive => (1, self.index),
        }
    }

    /// A large additive billboard that a draft render draws at half resolution
    /// (streaks stay sharp: they are thin however long).
    pub fn is_glow(&self) -> bool {
        !self.splat
            && !self.tiles
            && self.blend == BlendMode::Additive
            && !self.variant.streak
            && self.size_px >= GLOW_MIN_PX
    }
}

/// Billboards at least this large on screen (pixels at full resolution) count as glow.
pub const GLOW_MIN_PX: f32 = 12.0;

/// What `prepare` draws one group with.
struct GroupView<'g, 'a> {
    group: &'g SceneGroup<'a>,
    camera: &'g Camera,
    alpha: f32,
    asset_dir: Option<&'g Path>,
    /// The first group reports sprite errors and bakes the ramps.
    first_group: bool,
}

/// Uniform buffers, layouts and bind groups for the draw passes.
pub struct FrameResources {
    /// Group 0 of both draw paths: camera + the looks of a draw's instances (storage,
    /// dynamic offset) + ramps.
    pub frame_layout: wgpu::BindGroupLayout,
    /// Group 1: previous and current state.
    pub particle_layout: wgpu::BindGroupLayout,
    camera: wgpu::Buffer,
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
    /// Draw and sort only each emitter's live window of the ring (on by default; off
    /// visits every slot, for comparisons).
    pub live_window_only: bool,
    /// Trim rectangles by (sprite id, flipbook rows, columns, threshold bits).
    trims: HashMap<(u64, u32, u32, u32), [f32; 4]>,
    /// Let small additive particles take the compute splat (off in the runtime player,
    /// which draws everything inside the host's pass).
    pub allow_splat: bool,
    /// Soft edges read the host's depth buffer instead of the preset's ground plane.
    pub soft_depth: bool,
    /// The tile rasteriser exists (the device's limits allow it).
    pub allow_tiles: bool,
    /// This frame's look blocks on their way to `looks`.
    look_bytes: Vec<u8>,
    /// The light lit layers are drawn in (the host's, or the effect's own `lighting`
    /// when `None`).
    pub lighting: Option<SceneLighting>,
    /// Each look slot's simulation-space origin in the last `prepare` (the effect's
    /// light is moved between emitters' spaces with them).
    pub slot_origins: Vec<glam::DVec3>,
}

/// Emitter `i` across a group's instances (`FrameResources::group_looks`).
struct GroupLooks<'s> {
    /// Each instance's look (`None`: the instance has no such emitter or nothing alive).
    looks: Vec<Option<LookUniform>>,
    /// Each instance's part of the sort (alpha-blended emitters).
    members: Vec<SortMember>,
    /// The pool the instances' segments are in.
    pool: Option<crate::sim::gpu_sim::EmitterBuffers<'s>>,
    /// The nearest instance's distance from the camera (m).
    distance: f32,
}

/// What the automatic draw path looks at: the particles' largest projected size (pixels),
/// the quads of the draw (the widest live window × the instances: at least the live
/// particles), the instances, whether a trail's ribbon is drawn, and the target's size.
struct PathScene {
    size_px: f32,
    quads: u32,
    instances: u32,
    trail: bool,
    target_px: (u32, u32),
}

/// Writes the draw's looks into `block` (one per instance, at `PARAMS_STRIDE`), each with
/// the draw's widest window `width`; a missing instance gets an empty segment of its pool
/// of `capacity` slots (no window, nothing drawn).
fn write_looks(block: &mut [u8], looks: &[Option<LookUniform>], width: u32, capacity: u32) {
    for (k, u) in looks.iter().enumerate() {
        let mut u = u.unwrap_or(LookUniform {
            ring_b: [0, 0, capacity, 0],
            ..LookUniform::default()
        });
        u.ring[3] = width;
        block[k * PARAMS_STRIDE as usize..][..size_of::<LookUniform>()]
            .copy_from_slice(bytemuck::bytes_of(&u));
    }
}

/// The look uniform of an emitter (everything but the matrices, the ground height and
/// stateless motion, which depend on the frame). `ramp_row` is the emitter's colour ramp
/// row (its curve rows follow it), `salt` its per-particle random salt, `sprite_integral` the sprite's ∫ brightness.
pub fn look_uniform(look: &Look, ramp_row: u32, salt: u32, sprite_integral: f32) -> LookUniform {
    let (rows, cols, mode, fps, random_start) = match &look.flipbook {
        Some(f) => {
            let (mode, fps) = match f.mode {
                FlipbookMode::OverLife => (0, 0.0),
                FlipbookMode::FrameRate { fps } => (1, fps),
                FlipbookMode::Frames(_) => (2, 0.0),
            };
            (
                f.rows.max(1),
                f.cols.max(1),
                mode,
                fps,
                u32::from(f.random_start),
            )
        }
        None => (1, 1, 0, 0.0, 0),
    };
    let blend = match look.blend {
        BlendMode::Additive => 0,
        BlendMode::Alpha => 1,
    };
    let streak = look.streak.unwrap_or(Streak {
        length_secs: 0.0,
        max_length_m: 0.0,
    });
    let inv_soft = if look.soft_ground_m > 0.0 {
        1.0 / look.soft_ground_m
    } else {
        0.0
    };
    LookUniform {
        // x, y: the trail's width and opacity at its tail (fractions; trail.wgsl).
        size_intensity: [
            look.trail.as_ref().map_or(1.0, |t| t.tail_width),
            look.trail.as_ref().map_or(1.0, |t| t.tail_opacity),
            look.intensity,
            0.0,
        ],
        ids: [ramp_row, blend, rows, cols],
        flags: [mode, random_start, salt, 0],
        extra: [
            sprite_integral,
            0.0,
            look.rotation_random_deg.to_radians(),
            fps,
        ],
        // x: the trail's width (× the particle's size; trail.wgsl).
        spin_streak: [
            look.trail.as_ref().map_or(0.0, |t| t.width),
            0.0,
            streak.length_secs,
            streak.max_length_m,
        ],
        soft: [0.0, inv_soft, 0.0, 0.0],
        trim: [0.0, 0.0, 1.0, 1.0],
        ..LookUniform::default()
    }
}

/// Which billboard pipeline variant draws an emitter: the look modules it uses (each is
/// compiled out of the others).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LookVariant {
    /// Premultiplied alpha, drawn through the sort order (else additive).
    pub alpha: bool,
    /// Flipbook atlas lookup.
    pub flipbook: bool,
    /// Cross-fade between flipbook frames.
    pub flip_blend: bool,
    /// Velocity-stretched quads.
    pub streak: bool,
    /// Ground-plane depth fade.
    pub soft: bool,
    /// Fade against the host's depth buffer (replaces the ground-plane fade).
    pub soft_depth: bool,
    /// The motion pass: screen-space motion weighted by visibility, added up.
    pub motion: bool,
    /// The trail's ribbon (segments between recorded positions) instead of the sprite.
    pub trail: bool,
    /// How the shaders read the emitter's state (both draw paths).
    pub state: StateVariant,
    /// Lit smoke: six-way maps under the slot's `LitUniform` (`lit.wgsl`).
    pub lit: bool,
}

/// How look.wgsl reads an emitter's state: its layout and whether positions are closed
/// form (stateless). Pipeline constants of both draw paths, not branches: a CPU adapter
/// would run every layout's code for every particle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct StateVariant {
    /// The state layout (how a slot is stored).
    pub layout: StateLayout,
    /// Closed-form (stateless) positions.
    pub stateless: bool,
}

impl StateVariant {
    /// The override constants `STATE_LAYOUT` and `STATELESS`.
    pub fn constants(self) -> [(&'static str, f64); 2] {
        [
            ("STATE_LAYOUT", f64::from(self.layout.index())),
            ("STATELESS", if self.stateless { 1.0 } else { 0.0 }),
        ]
    }
}

impl LookVariant {
    /// The variant a look needs, for state read as `state`.
    pub fn of(look: &Look, state: StateVariant) -> Self {
        Self {
            alpha: look.blend == BlendMode::Alpha,
            flipbook: look.flipbook.is_some(),
            flip_blend: look.flipbook.as_ref().is_some_and(|f| f.blend_frames),
            streak: look.streak.is_some(),
            soft: look.soft_ground_m > 0.0,
            soft_depth: false,
            motion: false,
            trail: false,
            state,
            lit: look.lit.is_some() && look.blend == BlendMode::Alpha,
        }
    }

    /// The ribbon variant of this look (no flipbook, no streak: a ribbon samples the
    /// sprite's middle column across its width).
    pub fn with_trail(self) -> Self {
        Self {
            trail: true,
            flipbook: false,
            flip_blend: false,
            streak: false,
            lit: false,
            ..self
        }
    }

    /// This variant's motion pass.
    pub fn with_motion(self) -> Self {
        Self {
            motion: true,
            ..self
        }
    }

    /// The plain variant of a blend mode (full state, no look modules).
    pub fn basic(alpha: bool) -> Self {
        Self {
            alpha,
            flipbook: false,
            flip_blend: false,
            streak: false,
            soft: false,
            soft_depth: false,
            motion: false,
            trail: false,
            state: StateVariant::default(),
            lit: false,
        }
    }

    /// The override constants of this variant's billboard pipeline.
    pub fn constants(self) -> [(&'static str, f64); 11] {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let [layout, stateless] = self.state.constants();
        [
            ("SORTED", b(self.alpha)),
            ("FLIPBOOK", b(self.flipbook)),
            ("FLIP_BLEND", b(self.flip_blend)),
            ("STREAK", b(self.streak)),
            ("SOFT", b(self.soft && !self.soft_depth)),
            ("SOFT_DEPTH", b(self.soft && self.soft_depth)),
            ("MOTION", b(self.motion)),
            ("TRAIL", b(self.trail)),
            ("LIT", b(self.lit)),
            layout,
            stateless,
        ]
    }
}

impl FrameResources {
    /// Creates the layouts and uniform buffers.
    pub fn new(ctx: &GpuContext) -> Self {
        let d = &ctx.device;
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
            live_window_only: true,
            trims: HashMap::new(),
            allow_splat: true,
            soft_depth: false,
            allow_tiles: false,
            look_bytes: Vec::new(),
            lighting: None,
            slot_origins: Vec::new(),
        }
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
        let cam = camera.uniform(alpha);
        ctx.queue
            .write_buffer(&self.camera, 0, bytemuck::bytes_of(&cam));
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
        // (behind the tiles' blended layers) and leave the others their path.
        if items
            .iter()
            .any(|d| d.blend == BlendMode::Alpha && !d.tiles && d.trail.is_none())
        {
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

    /// Uploads the looks the last [`FrameResources::prepare`] built, through `uploads`
    /// with a copy recorded into `enc` (outside a pass).
    pub fn upload_looks(&self, uploads: &mut crate::gpu::Uploads, enc: &mut wgpu::CommandEncoder) {
        let bytes = &self.look_bytes;
        if let Some(mut view) = uploads.write(enc, &self.looks, 0, bytes.len() as u64) {
            view.copy_from_slice(bytes);
        }
    }

    /// Emitter `i`'s look of every instance (its salt, place and ring are set per
    /// instance by `member_look`): the look's settings and the sprite's trim.
    fn base_look(&mut self, effect: &Effect, i: usize, sprite: &SpriteTexture) -> LookUniform {
        let e = &effect.emitters[i];
        let mut u = look_uniform(&e.look, ROWS_PER_EMITTER * i as u32, 0, sprite.integral);
        // Six-way maps hold two images side by side: their quads are not trimmed.
        let lit = e.look.lit.is_some() && e.look.blend == BlendMode::Alpha;
        if self.trim_sprites && e.look.streak.is_none() && !lit {
            let (rows, cols) = e
                .look
                .flipbook
                .as_ref()
                .map_or((1, 1), |f| (f.rows, f.cols));
            // What is invisible at intensity 1 shows when the light is multiplied.
            let gain = (e.look.intensity * effect.post.exposure).max(1.0);
            let threshold = crate::render::sprites::TRIM_THRESHOLD / gain;
            u.trim = *self
                .trims
                .entry((sprite.id, rows, cols, threshold.to_bits()))
                .or_insert_with(|| sprite.trim_rect(rows, cols, threshold));
        }
        u
    }

    /// Writes lit emitter `i`'s `LitUniform` of every instance of the group into `block`
    /// (each in its simulation space; the effect's own light is added on the GPU).
    fn write_lit_looks(
        &self,
        view: &GroupView<'_, '_>,
        i: usize,
        lit: &crate::effect::Lit,
        block: &mut [u8],
    ) {
        for (k, scene) in view.group.iter().enumerate() {
            let Some(scene) = scene else {
                continue;
            };
            let own;
            let lighting = match &self.lighting {
                Some(l) => l,
                None => {
                    own = SceneLighting::from(&scene.effect.lighting);
                    &own
                }
            };
            let origin =
                (scene.sim.planner().emitters.get(i)).map_or(glam::DVec3::ZERO, |p| p.origin());
            let u = LitUniform::new(lit, lighting, origin);
            write_lit(
                &mut block[k * PARAMS_STRIDE as usize..][..PARAMS_STRIDE as usize],
                &u,
            );
        }
    }

    /// Emitter `i`'s look uniform of one instance, from the group's `base`, its pool and
    /// its part of the group's sort (`None`: no pool).
    fn member_look<'s>(
        &self,
        view: &GroupView<'_, '_>,
        scene: &Scene<'s>,
        i: usize,
        base: &LookUniform,
    ) -> Option<(
        LookUniform,
        crate::sim::gpu_sim::EmitterBuffers<'s>,
        SortMember,
    )> {
        let (sim, effect) = (scene.sim, scene.effect);
        let e = effect.emitters.get(i)?;
        let origin = sim
            .planner()
            .emitters
            .get(i)
            .map(|p| p.origin())
            .unwrap_or_default();
        let mut u = *base;
        u.flags[2] = crate::rng::pcg4d([effect.seed, i as u32, e.seed_offset, 0x5EED_100C])[0];
        u.clip_from_sim = view.camera.clip_from_sim(origin).to_cols_array_2d();
        let ground = e.collisions.ground.as_ref().map_or(0.0, |g| g.height_m);
        u.soft[0] = (f64::from(ground) - origin.y) as f32;
        if Modules::in_effect(effect, i).contains(Modules::STATELESS) {
            // Closed-form evaluation at the render time (between the last two steps).
            let planner = sim.planner();
            let t = planner.time_secs - (1.0 - view.alpha as f64) * planner.last_dt_secs as f64;
            let a = e.forces.constant_acceleration();
            let w = e.forces.wind_m_per_s;
            u.motion_a = [a.x, a.y, a.z, e.forces.drag_per_sec];
            u.motion_b = [w[0], w[1], w[2], t.rem_euclid(4096.0) as f32];
        }
        let mut b = sim.emitter_buffers(i)?;
        if !self.live_window_only {
            b.window = crate::sim::planner::LiveWindow::all(b.capacity);
        }
        // The ring, for packed state's re-derived lifetimes; the capacity and the live
        // window's length (ring_b.zw) place the draws' and the splat's invocations.
        u.soft[2] = b.life_range.0;
        u.soft[3] = b.life_range.1;
        u.ring = [
            (b.spawned_total % u64::from(b.capacity.max(1))) as u32,
            b.spawned_total as u32,
            (b.spawned_total >> 32) as u32,
            0,
        ];
        // w: the live window's length (it ends at the ring's head, ring.x).
        u.ring_b = [b.seed_salt.0, b.seed_salt.1, b.capacity, b.window.len];
        [u.tiny, u.tiny_b, u.tiny_c] = b.tiny;
        // The trail's newest entries are from before the last step (trail.wgsl).
        u.tiny_c[1] = b.last_step;
        // An emitter that inherits its parent's colour: the parent's ramp row + 1.
        u.tiny_c[2] = effect
            .color_parent(i)
            .map_or(0, |p| ROWS_PER_EMITTER * p as u32 + 1);
        u.flags[3] = b.slot_base;
        // The window ends at the ring's head (u.ring[0]).
        let cap = b.capacity.max(1);
        let sort = SortMember {
            eye: (view.camera.eye_f64() - origin)
                .as_vec3()
                .extend(0.0)
                .to_array(),
            window: [
                (u.ring[0] + cap - b.window.len.min(cap)) % cap,
                b.window.len,
                b.slot_base,
                0,
            ],
        };
        Some((u, b, sort))
    }

    /// Writes emitter `i`'s look uniform of every instance of a group into `block` and
    /// returns its draw (look slot left for the caller), or `None` when it has no pool or
    /// is disabled. The first group's emitters also bake the shared colour ramps.
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
        let (sprite, error) = match e
            .look
            .lit
            .as_ref()
            .filter(|_| e.look.blend == BlendMode::Alpha)
        {
            Some(lit) => self.sprites.resolve_lit(ctx, &lit.maps, view.asset_dir),
            None => self.sprites.resolve(ctx, &e.look.sprite, view.asset_dir),
        };
        if let Some(err) = error.filter(|_| view.first_group) {
            self.sprite_errors.push((i, err));
        }
        if view.first_group {
            // Emitter i of every instance shares ramp row i: the first group's look bakes it.
            self.upload_ramp(ctx, i, &e.look);
        }
        let base = self.base_look(first.effect, i, &sprite);
        let GroupLooks {
            looks,
            members,
            pool,
            distance,
        } = self.group_looks(view, i, &base);
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
                instances: n,
                trail: trail.is_some(),
                target_px: view.camera.size_px(),
            },
        );
        let mut variant = LookVariant::of(
            &e.look,
            StateVariant {
                layout: b.layout,
                stateless: Modules::in_effect(first.effect, i).contains(Modules::STATELESS),
            },
        );
        variant.soft_depth = self.soft_depth;
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

    /// Emitter `i`'s look in every instance of the group (from `base`), each instance's
    /// sort member, the pool the instances share and the nearest instance's distance from
    /// the camera (it decides the projected size, and so the path).
    fn group_looks<'s>(
        &self,
        view: &GroupView<'_, 's>,
        i: usize,
        base: &LookUniform,
    ) -> GroupLooks<'s> {
        let mut out = GroupLooks {
            looks: Vec::with_capacity(view.group.len()),
            members: Vec::new(),
            pool: None,
            distance: f32::INFINITY,
        };
        for scene in view.group {
            let Some((scene, (u, b, sort))) = scene
                .as_ref()
                .and_then(|s| Some((s, self.member_look(view, s, i, base)?)))
            else {
                out.looks.push(None);
                out.members.push(SortMember::default());
                continue;
            };
            let placed = glam::Vec3::from(scene.effect.emitters[i].transform.position_m);
            out.distance = out.distance.min((view.camera.eye() - placed).length());
            out.members.push(sort);
            out.looks.push(Some(u));
            out.pool.get_or_insert(b);
        }
        out
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
        let PathScene {
            size_px,
            quads,
            instances,
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
            && !splat
            && look.streak.is_none()
            && !trail
            && match look.draw_path {
                DrawPath::Auto => {
                    // Billboard fill at most (every quad at the largest size). A group of
                    // several instances (a runtime host's batch) keeps billboards: a grid
                    // of 100 torches measured 6.5 ms a frame with the tiles, 2.8 without.
                    let fill = quads as f32 * size_px * size_px;
                    profile.tile_raster
                        && instances == 1
                        && size_px >= TILES_ABOVE_PX
                        && fill >= TILES_MIN_FILL_PX
                }
                DrawPath::Tiles => true,
                DrawPath::Billboard | DrawPath::Splat => false,
            };
        (splat, tiles)
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
