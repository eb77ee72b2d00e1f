//! Structs shared with WGSL. Keep in sync with `shaders/common.wgsl` and
//! `shaders/billboard.wgsl`; `tests/shaders.rs` compares these sizes with naga's layout.

use bytemuck::{Pod, Zeroable};

/// One particle slot, 32 bytes (keep in sync with `Particle` in `shaders/common.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Particle {
    /// xyz: world position (m), w: age (s).
    pub pos_age: [f32; 4],
    /// xyz: velocity (m/s), w: lifetime (s).
    pub vel_life: [f32; 4],
}

impl Particle {
    /// Alive while age < lifetime (never-spawned slots are all zero, hence dead).
    pub fn is_alive(&self) -> bool {
        self.pos_age[3] < self.vel_life[3]
    }

    /// World position.
    pub fn position(&self) -> glam::Vec3 {
        glam::Vec3::from_slice(&self.pos_age[..3])
    }

    /// Velocity.
    pub fn velocity(&self) -> glam::Vec3 {
        glam::Vec3::from_slice(&self.vel_life[..3])
    }
}

/// One particle slot in the packed layout, 20 bytes (keep in sync with `PackedParticle` in
/// `shaders/common.wgsl`): f32 position, f16 velocity, the remaining life fraction as
/// unorm16 (0 = dead); the lifetime is re-derived from the spawn hash.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PackedParticle {
    /// Position x, y, z (m).
    pub pos: [f32; 3],
    /// f16 velocity x (low half), y (high half).
    pub vxy: u32,
    /// f16 velocity z (low half), remaining life fraction as unorm16 (high half).
    pub vz_rest: u32,
}

impl PackedParticle {
    /// The particle, given its (re-derived) lifetime.
    pub fn unpack(&self, life: f32) -> Particle {
        let rest = (self.vz_rest >> 16) as f32 / 65535.0;
        if rest <= 0.0 {
            return Particle::default();
        }
        let h = |bits: u32| half::f16::from_bits(bits as u16).to_f32();
        Particle {
            pos_age: [self.pos[0], self.pos[1], self.pos[2], (1.0 - rest) * life],
            vel_life: [
                h(self.vxy & 0xFFFF),
                h(self.vxy >> 16),
                h(self.vz_rest & 0xFFFF),
                life,
            ],
        }
    }
}

/// One step's births in a tiny-state emitter's birth table (keep in sync with `Birth` in
/// `shaders/common.wgsl`): `count` spawns from counter `first` (low 32 bits), the k-th born
/// at t0 + dt · clamp(frac0 + k · frac_step, 0, 1) on the emitter's clock.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Birth {
    /// Spawn counter of the step's first birth, low 32 bits.
    pub first: u32,
    /// Births in the step.
    pub count: u32,
    /// The step's start, double-single high part (s).
    pub t0_hi: f32,
    /// The step's start, low part.
    pub t0_lo: f32,
    /// The step's size (s).
    pub dt: f32,
    /// Birth fraction of the first spawn within the step.
    pub frac0: f32,
    /// Birth fraction increment per spawn.
    pub frac_step: f32,
    /// Padding.
    pub pad: u32,
}

/// A time as a double-single: `hi = f32(t)`, `lo = f32(t − hi)` (the GPU subtracts two of
/// them part by part, so ages stay exact to f32 however long the run).
pub fn double_single(t: f64) -> (f32, f32) {
    let hi = t as f32;
    (hi, (t - f64::from(hi)) as f32)
}

/// The tiny state's decoding (mirror of `tiny_bits` / `tiny_decode` in
/// `shaders/common.wgsl`): slot `slot`'s position and velocity in the pair `words`
/// (element `slot / 2` of the buffer as 20-byte pairs), or `None` when marked dead.
pub fn tiny_decode(words: [u32; 5], slot: u32) -> Option<([f32; 3], [f32; 3])> {
    let [w0, w1, w2, w3, w4] = words;
    let (xy, z, vel) = if slot & 1 == 1 {
        ((w2 >> 16) | (w3 << 16), w3 >> 16, w4)
    } else {
        (w0, w1 & 0xFFFF, (w1 >> 16) | (w2 << 16))
    };
    if xy & 0xFFFF == 0xFFFF {
        return None;
    }
    let h = |bits: u32| half::f16::from_bits(bits as u16).to_f32();
    let scale = 2f32.powi((vel & 31) as i32 - 23);
    let m = |shift: u32| (((vel >> shift) & 511) as f32 - 256.0) * scale;
    Some(([h(xy), h(xy >> 16), h(z)], [m(5), m(14), m(23)]))
}

/// How an emitter's state is stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum StateLayout {
    /// 32-byte [`Particle`]s.
    #[default]
    Full,
    /// 20-byte [`PackedParticle`]s.
    Packed,
    /// 10 bytes a slot, slots paired in 20-byte words (`tiny` in `shaders/common.wgsl`).
    Tiny,
}

impl StateLayout {
    /// Bytes one slot occupies.
    pub fn slot_bytes(self) -> u64 {
        match self {
            Self::Full => 32,
            Self::Packed => 20,
            Self::Tiny => 10,
        }
    }

    /// Bytes a pool of `capacity` slots occupies (tiny pools hold whole pairs).
    pub fn bytes(self, capacity: u32) -> u64 {
        match self {
            Self::Tiny => u64::from(capacity.div_ceil(2)) * 20,
            _ => u64::from(capacity) * self.slot_bytes(),
        }
    }

    /// The shaders' layout number (the `STATE_LAYOUT` pipeline constant).
    pub fn index(self) -> u32 {
        self as u32
    }
}

/// The spawn counter of the particle in `slot` of a ring of `capacity` slots that has
/// spawned `total` (mirror of `slot_counter` in `shaders/common.wgsl`).
pub fn slot_counter(slot: u32, total: u64, capacity: u32) -> u64 {
    let head = (total % u64::from(capacity)) as u32;
    let back = (head + capacity - 1 - slot) % capacity + 1;
    total.wrapping_sub(u64::from(back))
}

/// Per-step, per-emitter simulation parameters (keep in sync with `SimParams` in
/// `shaders/common.wgsl`). Uploaded once per step at a 256-byte aligned dynamic offset.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SimParams {
    /// Emitter space → world.
    pub world_from_emitter: [[f32; 4]; 4],
    /// Shape parameters (see `shaders/spawn.wgsl`).
    pub shape_a: [f32; 4],
    /// More shape parameters.
    pub shape_b: [f32; 4],
    /// xyz: unit initial direction (emitter space), w: spread half-angle (rad).
    pub direction_spread: [f32; 4],
    /// speed min, speed max, lifetime min, lifetime max.
    pub speed_life: [f32; 4],
    /// xyz: gravity + buoyancy (m/s²), w: drag k (1/s).
    pub accel_drag: [f32; 4],
    /// xyz: wind (m/s), w: wrapped simulated time for noise (s).
    pub wind_time: [f32; 4],
    /// frequency, position amplitude, direction amplitude, scroll.
    pub noise: [f32; 4],
    /// Step size, seconds.
    pub dt_secs: f32,
    /// Effect seed.
    pub seed: u32,
    /// Per-emitter salt (index and seed offset mixed).
    pub emitter_salt: u32,
    /// `Shape::kind_index`.
    pub shape_kind: u32,
    /// Slots in the ring.
    pub capacity: u32,
    /// First slot of this step's spawn window.
    pub spawn_head: u32,
    /// Number of slots born this step.
    pub spawn_count: u32,
    /// Spawn counter of the first born slot, low 32 bits.
    pub spawn_base_lo: u32,
    /// High 32 bits.
    pub spawn_base_hi: u32,
    /// Tiny state: the birth table's index mask (its size − 1).
    pub flags: u32,
    /// Birth fraction (within the step) of the first spawn.
    pub spawn_frac0: f32,
    /// Birth fraction increment per spawn.
    pub spawn_frac_step: f32,
    /// strength, frequency, octaves, scroll.
    pub turbulence: [f32; 4],
    /// gust strength, gust frequency, quadratic drag, flame pull strength.
    pub gusts_qdrag_pull: [f32; 4],
    /// xyz: vortex centre, w: falloff radius.
    pub vortex_center: [f32; 4],
    /// xyz: unit vortex axis, w: swirl acceleration.
    pub vortex_axis: [f32; 4],
    /// xyz: attractor position, w: strength.
    pub attractor: [f32; 4],
    /// radius, falloff mode, flame pull exponent, unused.
    pub attractor_b: [f32; 4],
    /// Emitter origin in world space.
    pub axis_origin: [f32; 4],
    /// Emitter direction in world space.
    pub axis_dir: [f32; 4],
    /// Ground: height, elasticity, friction, kill.
    pub ground: [f32; 4],
    /// rest speed, sphere count, kill on spheres, ground on.
    pub collide_b: [f32; 4],
    /// Sphere colliders: centre, radius.
    pub spheres: [[f32; 4]; 4],
    /// x: stick on contact, y: depth collision's thickness (m), z: kill on depth contact,
    /// w: unused.
    pub collide_c: [f32; 4],
    /// The slots this step updates: first slot, count (wrapping at the capacity) — the
    /// ring's live window plus this step's spawns; every other slot is dead in both
    /// state buffers; unused, unused.
    pub update_window: [u32; 4],
    /// Tiny state: the step's start on the emitter's clock as a double-single (hi, lo; f32
    /// bits), the birth table's first sequence number and its number of entries.
    pub tiny: [u32; 4],
    /// Tiny state: the oldest birth-table entry's first spawn counter (low 32 bits), the
    /// counters from it to the newest spawn; the step's number (the event scan's stamp);
    /// unused.
    pub tiny_b: [u32; 4],
}

/// How an emitter's simulation space is seen by the host's depth (keep in sync with
/// `DepthView` in `shaders/depth_on.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DepthViewUniform {
    /// Simulation space → clip (composed in f64, rounded once).
    pub clip_from_sim: [[f32; 4]; 4],
    /// Its inverse.
    pub sim_from_clip: [[f32; 4]; 4],
    /// xy: the target's size (px), z: +1 when depth grows away from the camera, −1 for
    /// reversed Z, w: 1 when a depth is bound (0: nothing collides).
    pub viewport: [f32; 4],
}

/// Camera data for the billboard pass (keep in sync with `CameraUniform` in
/// `shaders/billboard.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CameraUniform {
    /// World → clip.
    pub clip_from_world: [[f32; 4]; 4],
    /// xyz: camera right, w: interpolation alpha.
    pub right_alpha: [f32; 4],
    /// xyz: camera up, w: the motion pass's interval (s; the export's motion vectors).
    pub up: [f32; 4],
    /// xy: target size in pixels, z: pixels per unit of size / clip w.
    pub viewport: [f32; 4],
    /// View-space z from a depth d: (x·d + y) / (z·d + w) (soft edges against the host's
    /// depth buffer).
    pub depth_to_view: [f32; 4],
}

/// Look data for both draw paths (keep in sync with `LookUniform` in
/// `shaders/look.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LookUniform {
    /// Emitter simulation space → clip (camera-relative, composed in f64).
    pub clip_from_sim: [[f32; 4]; 4],
    /// size start, size end, intensity, random size fraction.
    pub size_intensity: [f32; 4],
    /// ramp row, blend (0 additive, 1 alpha), flipbook rows, flipbook columns.
    pub ids: [u32; 4],
    /// flipbook mode (0 over life, 1 frame rate), random start frame, random salt, the
    /// first slot of the pool's segment in the state buffers (a batched instance's; else 0).
    pub flags: [u32; 4],
    /// ∫ sprite brightness over the quad, unused (stateless mode is the draw pipelines'
    /// `STATELESS` constant), rotation spread (rad), flipbook fps.
    pub extra: [f32; 4],
    /// spin min, spin max (rad/s), streak length (s), longest streak (m).
    pub spin_streak: [f32; 4],
    /// ground height in simulation space (m), 1 / soft-edge distance (1/m), lifetime
    /// range (s).
    pub soft: [f32; 4],
    /// Next spawn slot (the ring's head), spawned total (lo, hi), quads per instance of
    /// the unsorted billboard draw this look is part of (the widest live window).
    pub ring: [u32; 4],
    /// Packed state: effect seed, emitter salt; capacity; the live window's length (the
    /// window ends at the ring's head, `ring[0]`).
    pub ring_b: [u32; 4],
    /// Stateless: constant acceleration xyz, drag k.
    pub motion_a: [f32; 4],
    /// Stateless: wind xyz, render time on the 4096 s clock.
    pub motion_b: [f32; 4],
    /// The sprite's occupied part of a frame, u0 v0 u1 v1 (billboards are cut to it).
    pub trim: [f32; 4],
    /// Tiny state: the current state's time (double-single hi, lo; f32 bits), the birth
    /// table's first sequence number and entries.
    pub tiny: [u32; 4],
    /// Tiny state: the birth table's index mask, the last step's size (f32 bits), the
    /// oldest entry's first spawn counter, the counters from it to the newest spawn.
    pub tiny_b: [u32; 4],
    /// Tiny state: the counters from the oldest entry's first to the last step's first
    /// spawn (a slot's previous state is its particle's only below it); the trail's last
    /// step; the colour parent's ramp row + 1 (0: none); the octagon's corner cuts
    /// (`Trim::packed_cuts`, billboards).
    pub tiny_c: [u32; 4],
}

/// Tonemap settings (keep in sync with `ToneUniform` in `shaders/tonemap.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ToneUniform {
    /// x: exposure, y: bloom intensity, z: bloom threshold, w: unused.
    pub exposure: [f32; 4],
}

/// Byte stride between per-step `SimParams` blocks (the dynamic-offset alignment).
pub const PARAMS_STRIDE: u64 = 512;

const _: () = assert!(std::mem::size_of::<SimParams>() as u64 <= PARAMS_STRIDE);
const _: () = assert!(std::mem::size_of::<Particle>() == 32);
const _: () = assert!(std::mem::size_of::<PackedParticle>() == 20);
const _: () = assert!(std::mem::size_of::<Birth>() == 32);
const _: () = assert!(std::mem::size_of::<LookUniform>() as u64 <= PARAMS_STRIDE);
// look.wgsl's `LookSlot` pads a look to PARAMS_STRIDE with 14 vec4s: keep in sync.
const _: () = assert!(std::mem::size_of::<LookUniform>() as u64 + 14 * 16 == PARAMS_STRIDE);
