// events_on.wgsl — the update's event hooks (composed in place of events_off.wgsl for an
// emitter with events, or one that spawns from them). Group 1: binding 0 this emitter's
// event records (written), binding 1 the spawn list its parent's event feeds (read).
//
// Contract:
// - MOD_EVENTS (a parent): every visited slot writes per rule how many children it spawns
//   this step (0 when no event fired), and, when some, a record — its position, velocity
//   and a key (seed, slot, the particle's spawn counter, rule, event ordinal) that the
//   children's randomness comes from (event_types.wgsl). Counts of slots outside the
//   window are stale: the scan (events.wgsl) reads the window only.
// - MOD_EVENT_SPAWN (a child): the slots [head, head + count) of the ring (the list's
//   header, written by the scan this step — `stamp` says which step) are born at the
//   event's position plus the child's own shape offset, with the velocity of its own
//   spawn settings plus the inherited part of the parent's.
// Mirrored by `src/sim/event_scan.rs` (the CPU reference of counts, keys and the scan).
#import "common.wgsl"
#import "rng.wgsl"
#import "event_types.wgsl"

override MOD_EVENTS: bool = false;
override MOD_EVENT_SPAWN: bool = false;

const TRIGGER_DEATH: u32 = 0u;
const TRIGGER_COLLISION: u32 = 1u;
const TRIGGER_BIRTH: u32 = 2u;
const TRIGGER_OVER_LIFE: u32 = 3u;
// A rule slot with no event.
const TRIGGER_NONE: u32 = 0xFFFFFFFFu;
// Keep in sync with MAX_CHILDREN_PER_EVENT (src/effect/events.rs).
const MAX_CHILDREN: u32 = 64u;
// A collision's ordinal is the parent's age in these units (keep in sync with
// COLLISION_ORDINALS_PER_SEC in src/sim/event_scan.rs): the same bounce draws the same
// children at any step, where the age's own bits would differ with the step.
const COLLISION_ORDINALS_PER_SEC: f32 = 16.0;

@group(1) @binding(0) var<storage, read_write> event_out: EventOut;
@group(1) @binding(1) var<storage, read> event_in: EventIn;

struct EventBirth {
    born: bool,
    p: Particle,
}

fn event_birth(slot: u32) -> EventBirth {
    var out = EventBirth(false, Particle(vec4<f32>(0.0), vec4<f32>(0.0)));
    if !MOD_EVENT_SPAWN || event_in.stamp != params.tiny_b.z {
        return out;
    }
    var rel = slot + params.capacity - event_in.head;
    if rel >= params.capacity {
        rel -= params.capacity;
    }
    if rel >= event_in.count {
        return out;
    }
    let s = event_in.list[rel];
    // w: the child's index in its event (low 16 bits), the parent's normalised age to
    // 1/255 (bits 16–23) and whether the child inherits its colour (bit 24).
    let bits = bitcast<u32>(s.vel_j.w);
    let key = child_key(params.seed, params.emitter_salt, bitcast<u32>(s.pos_key.w), bits & 0xFFFFu);
    let q = spawn_particle(slot, key);
    // The child's own shape, centred on the event.
    let offset = q.pos_age.xyz - params.world_from_emitter[3].xyz;
    var life = q.vel_life.w;
    if (bits & 0x1000000u) != 0u {
        // The parent's colour travels in the lifetime's lowest 8 bits (a relative change
        // below 3e-5; look.wgsl's inherited_rgb reads it back).
        life = bitcast<f32>((bitcast<u32>(life) & 0xFFFFFF00u) | ((bits >> 16u) & 0xFFu));
    }
    out.born = true;
    out.p = Particle(
        vec4<f32>(s.pos_key.xyz + offset, 0.0),
        vec4<f32>(q.vel_life.xyz + s.vel_j.xyz, life),
    );
    return out;
}

// The random stream of the j-th child of the event `event_key`.
fn child_key(seed: u32, salt: u32, event_key: u32, j: u32) -> vec4<u32> {
    return pcg4d(vec4<u32>(seed, salt ^ 0xE7E7E7E7u, event_key, j * 0x9E3779B9u));
}

// The key of rule `e`'s event of the particle with spawn counter `counter` in `slot`; the
// ordinal tells apart several events of one life (collisions, over-life children).
fn event_key(slot: u32, counter: vec2<u32>, e: u32, ordinal: u32) -> u32 {
    let h = pcg4d(vec4<u32>(params.seed ^ (slot * 0x9E3779B9u), counter.x, counter.y ^ (e << 28u), ordinal));
    return h.x ^ params.emitter_salt;
}

fn emit_events(slot: u32, p: Particle, born: bool, was_alive: bool, alive: bool, hit: bool, age_start: f32) {
    if !MOD_EVENTS {
        return;
    }
    // The particle's spawn counter: the ring has spawned base + count after this step.
    let total_lo = params.spawn_base_lo + params.spawn_count;
    let total_hi = params.spawn_base_hi + select(0u, 1u, total_lo < params.spawn_count);
    var head = params.spawn_head + params.spawn_count;
    if head >= params.capacity {
        head -= params.capacity;
    }
    let counter = slot_counter(slot, head, total_lo, total_hi, params.capacity);
    let lived = born || was_alive;
    for (var e = 0u; e < 2u; e++) {
        let rule = event_out.rules[e];
        if rule.trigger == TRIGGER_NONE {
            continue;
        }
        var fired = false;
        var n = 0u;
        var ordinal = 0u;
        // Over life: the first child's number in the parent's life (children are keyed by
        // it, so the k-th child is the same whatever step it falls in).
        var first = 0u;
        switch rule.trigger {
            case TRIGGER_DEATH: {
                fired = lived && !alive;
            }
            case TRIGGER_COLLISION: {
                fired = lived && hit;
                ordinal = u32(floor(p.pos_age.w * COLLISION_ORDINALS_PER_SEC));
            }
            case TRIGGER_BIRTH: {
                fired = born;
            }
            default: {
                // Over life: the children due between the step's start and end ages.
                if lived {
                    let a0 = select(age_start, 0.0, born);
                    let a1 = min(p.pos_age.w, p.vel_life.w);
                    let k0 = floor(rule.rate * a0);
                    n = u32(max(floor(rule.rate * a1) - k0, 0.0));
                    first = u32(k0);
                }
            }
        }
        // The key only where it is used: most slots fire nothing in a step, and the hash is
        // most of this hook's arithmetic.
        var key = 0u;
        if fired || n > 0u {
            key = event_key(slot, counter, e, ordinal);
        }
        if fired {
            let h = pcg4d(vec4<u32>(key, params.seed, e, 0xC0u));
            let span = rule.count_max - rule.count_min + 1u;
            n = select(0u, rule.count_min + h.y % span, unorm4(h).z < rule.probability);
        }
        n = min(n, MAX_CHILDREN);
        let s = slot_base + slot;
        // Bit 31: born this step (a ribbon per parent starts afresh, events.wgsl).
        event_out.words[e * params.capacity + s] = n | select(0u, BORN_BIT, born);
        if n > 0u {
            let at = record_at(e, s, params.capacity);
            let pos = bitcast<vec3<u32>>(p.pos_age.xyz);
            let vel = bitcast<vec3<u32>>(p.vel_life.xyz);
            event_out.words[at] = pos.x;
            event_out.words[at + 1u] = pos.y;
            event_out.words[at + 2u] = pos.z;
            event_out.words[at + 3u] = key;
            event_out.words[at + 4u] = vel.x;
            event_out.words[at + 5u] = vel.y;
            event_out.words[at + 6u] = vel.z;
            // The parent's normalised age to 1/255 (its colour, for children that inherit
            // it), and above it the first child's number (over life).
            let t = u32(clamp(p.pos_age.w / p.vel_life.w, 0.0, 1.0) * 255.0 + 0.5);
            event_out.words[at + 7u] = (first << 8u) | t;
        }
    }
}
