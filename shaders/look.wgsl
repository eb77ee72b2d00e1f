// look.wgsl — how a particle looks, shared by both draw paths (billboards and the
// compute splat) so they render the same fire. A designer hook: `particle_color`.
//
// Contract: the including file declares `camera: CameraUniform`, `look: LookUniform` (the
// instance being drawn, a private copy of its `LookSlot`; keep both in sync with `src/gpu/types.rs`), `ramps: texture_2d<f32>` (one
// Rgba32Float colour ramp row per emitter, each followed by its two curve rows; see
// curves.wgsl) and the state: `prev`, `cur`
// (array<Particle>) and the same buffers as `prev_packed`, `cur_packed`
// (array<PackedParticle>, read when `STATE_LAYOUT` says the state is packed or tiny),
// and `births: array<Birth>` (a tiny-state emitter's birth table, births.wgsl).
#import "common.wgsl"
#import "rng.wgsl"
#import "births.wgsl"
#import "curves.wgsl"

struct CameraUniform {
    clip_from_world: mat4x4<f32>,
    // xyz: camera right (world), w: interpolation alpha between prev and cur.
    right_alpha: vec4<f32>,
    // xyz: camera up (world), w: the motion pass's interval (s; billboard.wgsl MOTION).
    up: vec4<f32>,
    // xy: target size in pixels, z: pixels per unit of (size / clip w), w: unused.
    viewport: vec4<f32>,
    // View-space z from a depth d: (x·d + y) / (z·d + w) (soft edges against the host's
    // depth buffer).
    depth_to_view: vec4<f32>,
}

struct LookUniform {
    // The emitter's simulation space → clip, composed in f64 on the CPU so effects far
    // from the world origin render without f32 jitter.
    clip_from_sim: mat4x4<f32>,
    // x, y: the trail's tail width and opacity, z: intensity, w: heat haze's strength.
    size_intensity: vec4<f32>,
    // x: colour ramp row (the curve rows A and B follow it), y: blend (0 additive,
    // 1 alpha), z: flipbook rows, w: columns.
    ids: vec4<u32>,
    // x: flipbook mode (0 over life, 1 frame rate, 2 frame curve), y: random start frame (0/1),
    // z: per-emitter random salt, w: the first slot of the pool's segment in the state
    // buffers (a batched instance's; else 0).
    flags: vec4<u32>,
    // x: ∫ sprite brightness over the quad (the splat's energy), y: heat haze's ripples
    // per sprite, z: random rotation spread (rad), w: flipbook frames per second.
    extra: vec4<f32>,
    // x: the trail's width, y: heat haze's speed (cycles/s), z: streak length (s), w:
    // longest streak (m).
    spin_streak: vec4<f32>,
    // x: ground height in simulation space (m), y: 1 / soft-edge distance (1/m),
    // z, w: lifetime range (s; packed state re-derives lifetimes from it).
    soft: vec4<f32>,
    // x: next spawn slot (head), y, z: spawned total (lo, hi), w: quads per instance of
    // the unsorted billboard draw this look is part of (the widest live window).
    ring: vec4<u32>,
    // Packed state: x: effect seed, y: emitter salt; z: capacity; w: the live window's
    // length (the slots before the head that can hold living particles).
    ring_b: vec4<u32>,
    // Stateless emitters: xyz constant acceleration, w linear drag k.
    motion_a: vec4<f32>,
    // Stateless emitters: xyz wind, w render time on the 4096 s clock.
    motion_b: vec4<f32>,
    // The sprite's occupied part of each frame: u0, v0, u1, v1 in frame texture
    // coordinates (v down); billboards are cut to it.
    trim: vec4<f32>,
    // Tiny state (STATE_LAYOUT = 2): x, y: the current state's time on the emitter's clock
    // (double-single hi, lo, as f32 bits), z: the birth table's first sequence number,
    // w: its entries.
    tiny: vec4<u32>,
    // Tiny state: x: the birth table's index mask, y: the last step's size (f32 bits),
    // z: the oldest entry's first spawn counter, w: the counters from it to the newest.
    tiny_b: vec4<u32>,
    // Tiny state: x: the counters from the oldest entry's first to the last step's first
    // spawn (a slot's previous state holds its particle only below it); y: the trail's
    // last step; z: the colour parent's ramp row + 1 (0: none); w: the octagon's corner
    // cuts (pack4x8unorm; sprite_trim.wgsl, billboards).
    tiny_c: vec4<u32>,
}

// A lit layer's light (lit.wgsl; keep in sync with `LitUniform` in src/render/scene_lighting.rs),
// in the emitter's simulation space (the world's axes). Zero for unlit layers.
struct LitUniform {
    // xyz: towards the sun, w: the effect light's gain (`self_light`).
    sun_dir: vec4<f32>,
    // rgb: the sun's colour, w: host point lights in `points` (0..=4).
    sun_color: vec4<f32>,
    // rgb: ambient, w: emission (the colour over life's share that glows by itself).
    ambient: vec4<f32>,
    // rgb: albedo, w: unused.
    albedo: vec4<f32>,
    // The effect's own light, written on the GPU each frame (light.wgsl `light_apply`):
    // xyz its light-weighted centre, w its spread² (m²); rgb its power, w: luminance.
    self_pos: vec4<f32>,
    self_rgb: vec4<f32>,
    // Host point lights, two vec4 each: (position, range in m), (colour × intensity, 0).
    points: array<vec4<f32>, 8>,
}

// A look at the 512-byte stride of the looks buffer (src/render/frame.rs; the draws
// read their instances' looks as `array<LookSlot>`).
struct LookSlot {
    look: LookUniform,
    lit: LitUniform,
}

override INTERPOLATE: bool = true;
// The emitter's state layout (0 full, 1 packed, 2 tiny) and whether it is stateless
// (closed-form positions). Pipeline constants, set per emitter by the renderer, not
// branches on the uniform: a CPU adapter runs both sides of a branch for every SIMD batch
// of particles (masked lanes), so run-time switches would make every particle pay for
// every layout (the million-spark splat took 2× as long).
override STATE_LAYOUT: u32 = 0u;
override STATELESS: bool = false;

// Texels per colour ramp row (keep in sync with `RAMP_WIDTH` in src/render/look_bake.rs).
const RAMP_WIDTH: u32 = 1024u;

// Colour and alpha at normalised age t: the emitter's gradient baked into a ramp row
// (exact at the texel centres, t = i / (RAMP_WIDTH - 1); linear in between).
fn particle_color(t: f32) -> vec4<f32> {
    return ramp_at(look.ids.x, t);
}

// Colour ramp row `row` at normalised age t.
fn ramp_at(row: u32, t: f32) -> vec4<f32> {
    let x = clamp(t, 0.0, 1.0) * f32(RAMP_WIDTH - 1u);
    let i = min(u32(x), RAMP_WIDTH - 1u);
    let j = min(i + 1u, RAMP_WIDTH - 1u);
    let c0 = textureLoad(ramps, vec2<i32>(i32(i), i32(row)), 0);
    let c1 = textureLoad(ramps, vec2<i32>(i32(j), i32(row)), 0);
    return mix(c0, c1, x - f32(i));
}

// What multiplies the colour of a particle with lifetime `life`: for an emitter that
// inherits its parent's colour (look.tiny_c.z = the parent's ramp row + 1), the parent's
// ramp at the age the child carries in its lifetime's lowest 8 bits (events_on.wgsl);
// white otherwise.
fn inherited_rgb(life: f32) -> vec3<f32> {
    if look.tiny_c.z == 0u {
        return vec3<f32>(1.0);
    }
    let t = f32(bitcast<u32>(life) & 0xFFu) / 255.0;
    return ramp_at(look.tiny_c.z - 1u, t).rgb;
}

// Four random numbers in [0, 1) fixed for one particle's life: a hash of the slot and
// its lifetime bits (each spawn draws a fresh lifetime) with the emitter's salt.
fn particle_random(slot: u32, life: f32) -> vec4<f32> {
    return unorm4(pcg4d(vec4<u32>(slot, bitcast<u32>(life), look.flags.z, 0x1007u)));
}

// The look's curves at normalised age t for random numbers u: x size (m), y opacity,
// z spin angle turned since birth per second of lifetime (rad; × life is the angle),
// w flipbook frame (frame curve mode).
fn look_curves(t: f32, u: vec4<f32>) -> vec4<f32> {
    let c = curve_texels(t);
    let row = i32(look.ids.x) + 1;
    let a = mix(textureLoad(ramps, vec2<i32>(i32(c.i), row), 0), textureLoad(ramps, vec2<i32>(i32(c.j), row), 0), c.f);
    let b = mix(textureLoad(ramps, vec2<i32>(i32(c.i), row + 1), 0), textureLoad(ramps, vec2<i32>(i32(c.j), row + 1), 0), c.f);
    return mix(a, b, u);
}

// The random numbers blending a particle's curves (size, opacity, spin, frame): the size
// and spin keep `particle_random`'s x and z (a range of sizes or spins draws what the
// start-to-end size's random factor and the spin range always drew); opacity and frame
// have a hash of their own.
fn curve_random(slot: u32, life: f32, rnd: vec4<f32>) -> vec4<f32> {
    let own = unorm4(pcg4d(vec4<u32>(slot, bitcast<u32>(life), look.flags.z, 0xC0u)));
    return vec4<f32>(rnd.x, own.y, rnd.z, own.w);
}

// Flipbook frame selection: x = frame, y = next frame, z = weight of y (0 without
// blending). Over life: frame 0 at birth, the last frame at death. Frame rate: loops.
// Frame curve: `curve_frame` (fractional frames blend), clamped to the last.
fn flipbook_frames(age: f32, life: f32, start01: f32, blend: bool, curve_frame: f32) -> vec3<f32> {
    let count = max(look.ids.z * look.ids.w, 1u);
    let n = f32(count);
    var start = 0u;
    if look.flags.y != 0u {
        start = min(u32(start01 * n), count - 1u);
    }
    if look.flags.x == 2u {
        let pos = clamp(curve_frame, 0.0, n - 1.0);
        let f0 = min(u32(pos), count - 1u);
        let f1 = min(f0 + 1u, count - 1u);
        return vec3<f32>(f32((f0 + start) % count), f32((f1 + start) % count), select(0.0, pos - f32(f0), blend));
    }
    if look.flags.x == 0u {
        let t = age_fraction(age, life);
        if blend {
            let pos = t * (n - 1.0);
            let f0 = min(u32(pos), count - 1u);
            let f1 = min(f0 + 1u, count - 1u);
            return vec3<f32>(f32((f0 + start) % count), f32((f1 + start) % count), pos - f32(f0));
        }
        let f = min(u32(t * n), count - 1u);
        return vec3<f32>(f32((f + start) % count), f32((f + start) % count), 0.0);
    }
    let pos = max(age, 0.0) * look.extra.w;
    let whole = floor(pos);
    let f0 = (u32(whole) + start) % count;
    let f1 = (f0 + 1u) % count;
    return vec3<f32>(f32(f0), f32(f1), select(0.0, pos - whole, blend));
}

// Atlas coordinates of frame `frame` at quad uv ∈ [-1, 1]² (y up; frames row-major from
// the top-left).
fn atlas_uv(frame: f32, uv: vec2<f32>) -> vec2<f32> {
    let cols = max(look.ids.w, 1u);
    let rows = max(look.ids.z, 1u);
    let f = u32(frame);
    let cell = vec2<f32>(f32(f % cols), f32(f / cols));
    let local = vec2<f32>(uv.x * 0.5 + 0.5, 0.5 - uv.y * 0.5);
    return (cell + local) / vec2<f32>(f32(cols), f32(rows));
}

// Position and age to draw: between the last two steps when interpolating, and only when
// the slot still holds the same particle.
fn draw_state(p: Particle, q: Particle) -> vec4<f32> {
    var pos = p.pos_age.xyz;
    var age = p.pos_age.w;
    if INTERPOLATE {
        if is_alive(q) && q.pos_age.w < p.pos_age.w {
            let a = camera.right_alpha.w;
            pos = mix(q.pos_age.xyz, pos, a);
            age = mix(q.pos_age.w, age, a);
        }
    }
    return vec4<f32>(pos, age);
}

// The particle in `slot`: (after the last step, before it), unpacked when packed.
fn load_pair(slot: u32) -> array<Particle, 2> {
    if STATE_LAYOUT != 0u {
        let c = slot_counter(slot, look.ring.x, look.ring.y, look.ring.z, look.ring_b.z);
        let key = spawn_key(look.ring_b.x, look.ring_b.y, slot, c.x, c.y);
        let life = spawn_life(key, look.soft.z, look.soft.w);
        if STATE_LAYOUT == 2u {
            // Tiny: ages from the birth table; the previous state is one step younger, and
            // holds this particle only if it was born before the last step (otherwise the
            // slot's previous occupant, or nothing).
            let odd = (slot & 1u) != 0u;
            let b = birth_entry(c.x, vec3<u32>(look.tiny.zw, look.tiny_b.x), look.tiny_b.z, look.tiny_b.w);
            let age = birth_age(b, c.x, bitcast<vec2<f32>>(look.tiny.xy));
            var ages = vec2<f32>(age, age - bitcast<f32>(look.tiny_b.y));
            if c.x - look.tiny_b.z >= look.tiny_c.x {
                ages.y = -1.0;
            }
            let s = array<TinySlot, 2>(
                tiny_decode(tiny_bits(cur_packed[slot >> 1u], odd)),
                tiny_decode(tiny_bits(prev_packed[slot >> 1u], odd)),
            );
            var out: array<Particle, 2>;
            for (var i = 0u; i < 2u; i++) {
                if !s[i].dead && ages[i] >= 0.0 && ages[i] < life {
                    out[i] = Particle(vec4<f32>(s[i].pos, ages[i]), vec4<f32>(s[i].vel, life));
                }
            }
            return out;
        }
        // A batched instance's pool is a segment of the buffers from look.flags.w.
        let i = look.flags.w + slot;
        let q = cur_packed[i];
        // The previous state is only used while it holds the same particle (younger).
        return array<Particle, 2>(unpack_particle(q, life), unpack_particle(prev_packed[i], life));
    }
    return array<Particle, 2>(cur[look.flags.w + slot], prev[look.flags.w + slot]);
}

// A particle as drawn: position, velocity, age, lifetime, alive.
struct Drawn {
    pos: vec3<f32>,
    vel: vec3<f32>,
    age: f32,
    life: f32,
    alive: bool,
}

// The particle in slot state `p` (previous state `q`) as drawn. Stateless emitters store
// spawn records (x0, birth time; v0, lifetime) and are evaluated here in closed form:
// x(t) = x0 + v0·φ + (a + k·wind)·ψ, φ = (1 − e^{−kt})/k, ψ = (t − φ)/k (exact for constant
// acceleration with linear drag, the only forces stateless mode allows).
fn drawn(p: Particle, q: Particle) -> Drawn {
    if STATELESS {
        let life = p.vel_life.w;
        var age = look.motion_b.w - p.pos_age.w;
        if age < 0.0 {
            age += 4096.0;
        }
        let k = look.motion_a.w;
        let pp = exp_phi_psi(k, age);
        let c = look.motion_a.xyz + k * look.motion_b.xyz;
        let pos = p.pos_age.xyz + p.vel_life.xyz * pp.x + c * pp.y;
        // v(t) = v0·e^{−kt} + c·φ, with e^{−kt} = 1 − kφ.
        let vel = p.vel_life.xyz * (1.0 - k * pp.x) + c * pp.x;
        return Drawn(pos, vel, age, life, life > 0.0 && age < life);
    }
    let s = draw_state(p, q);
    return Drawn(s.xyz, p.vel_life.xyz, s.w, p.vel_life.w, is_alive(p));
}

// Normalised age and billboard size of a drawn state.
fn age_fraction(age: f32, life: f32) -> f32 {
    return clamp(age / life, 0.0, 1.0);
}
