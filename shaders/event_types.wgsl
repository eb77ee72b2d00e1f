// event_types.wgsl — the event buffers' structs, shared by the update's hooks
// (events_on.wgsl) and the scan (events.wgsl). Keep in sync with src/sim/event_scan.rs.

struct EventRule {
    trigger: u32,
    count_min: u32,
    count_max: u32,
    rate: f32,
    probability: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// A parent's event buffer: its two rules, then u32 words — first the children each slot
// asks for per rule (`words[rule · capacity + slot]`, written for every slot the update
// visits; BORN_BIT set when the particle was born this step), then a record per rule and slot, written only when it asks for children
// (`RECORD_WORDS` words from `2 · capacity + (rule · capacity + slot) · RECORD_WORDS`:
// position xyz (the parent's simulation space), the event's key, velocity xyz, the
// parent's normalised age × 255 (bits 0–7) and the number of the event's first child in
// the parent's life (bits 8–31: over-life children are keyed by it)).
// The scan reads every count but only the records of slots with children.
struct EventOut {
    rules: array<EventRule, 2>,
    words: array<u32>,
}

const RECORD_WORDS: u32 = 8u;
// Set in a slot's count word when the particle was born this step.
const BORN_BIT: u32 = 0x80000000u;

// The first word of rule `rule`'s record of `slot` in a pool of `capacity` slots.
fn record_at(rule: u32, slot: u32, capacity: u32) -> u32 {
    return 2u * capacity + (rule * capacity + slot) * RECORD_WORDS;
}

struct EventSpawn {
    // xyz: position in the child's simulation space, w: the event's key (u32 bits).
    pos_key: vec4<f32>,
    // xyz: the inherited velocity, w (u32 bits): the child's index within its event (low
    // 16 bits), the parent's normalised age × 255 (bits 16–23), inherit the colour (bit 24).
    vel_j: vec4<f32>,
}

struct EventIn {
    head: u32,
    count: u32,
    stamp: u32,
    dropped: u32,
    total: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
    list: array<EventSpawn>,
}
