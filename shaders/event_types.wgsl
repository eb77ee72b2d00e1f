// event_types.wgsl — the event buffers' structs, shared by the update's hooks
// (events_on.wgsl) and the scan (events.wgsl). Keep in sync with src/sim/events.rs.

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

struct EventRecord {
    // xyz: position (the parent's simulation space), w: children (u32 bits).
    pos_count: vec4<f32>,
    // xyz: velocity, w: the event's key (u32 bits).
    vel_key: vec4<f32>,
}

struct EventOut {
    rules: array<EventRule, 2>,
    records: array<EventRecord>,
}

struct EventSpawn {
    // xyz: position in the child's simulation space, w: the event's key (u32 bits).
    pos_key: vec4<f32>,
    // xyz: the inherited velocity, w: the child's index within its event (u32 bits).
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
