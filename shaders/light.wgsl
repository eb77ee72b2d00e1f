// light.wgsl — the effect's light: how much light the additive (emissive) particles
// alive now give, and from where. Pass 1 (`light_sum`): each workgroup sums, over its
// slots of one instance's pool, each living particle's emitted light E (colour · alpha ·
// opacity · intensity · ∫ sprite brightness · (size / 2)², in m²) and its luminance-
// weighted position moments; pass 2 (`light_total`, one dispatch for the whole frame): one
// invocation per instance and emitter sums its workgroups' partials. The CPU reads the
// totals back a frame or two later.
//
// Contract:
// - groups 0 and 1: particle_bindings.wgsl (camera, looks with a dynamic offset per
//   emitter, ramps; the state buffers).
// - group 2: 0 `sums`: the partials (2 × vec4 per workgroup: (ΣE.rgb, ΣY), (ΣY·p, ΣY·|p|²)),
//   then the totals (the same per instance) from `job.total_base` on; 2 `job` (dynamic
//   offset per `light_sum` dispatch). One buffer for both: a device's 8 storage buffers
//   per stage. `light_total` binds group 2 alone: 0 `sums`, 1 `totals_plan`.
#import "common.wgsl"
#import "rng.wgsl"
#import "look.wgsl"
#import "particle_bindings.wgsl"


struct LightJob {
    // The first partial of this dispatch's first instance.
    partial_base: u32,
    // Workgroups (partials) per instance.
    groups_per_member: u32,
    // The first total of this dispatch's first instance (after every partial).
    total_base: u32,
    // Instances in the dispatch.
    members: u32,
}

@group(2) @binding(0) var<storage, read_write> sums_out: array<vec4<f32>>;
@group(2) @binding(2) var<uniform> job: LightJob;
// `light_total`'s plan: [0].x the totals; then per total (its first partial, its
// partials, its index in `sums_out`).
@group(2) @binding(1) var<storage, read> totals_plan: array<vec4<u32>>;

// Rec. 709 luminance of linear RGB.
const LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

var<workgroup> sums: array<array<vec4<f32>, 2>, 256>;

// A living particle's emitted light and where it is (simulation space).
fn emitted(i: u32) -> array<vec4<f32>, 2> {
    var out: array<vec4<f32>, 2>;
    if i >= look.ring_b.w {
        return out;
    }
    var slot = look.ring.x + look.ring_b.z - look.ring_b.w + i;
    if slot >= look.ring_b.z {
        slot -= look.ring_b.z;
    }
    let pair = load_pair(slot);
    let d = drawn(pair[0], pair[1]);
    if !d.alive {
        return out;
    }
    let t = age_fraction(d.age, d.life);
    let color = particle_color(t) * vec4<f32>(inherited_rgb(d.life), 1.0);
    let rnd = particle_random(slot, d.life);
    let lc = look_curves(t, curve_random(slot, d.life, rnd));
    let half = 0.5 * lc.x;
    let e = color.rgb * (color.a * lc.y * look.size_intensity.z * look.extra.x * half * half);
    let y = dot(e, LUMA);
    out[0] = vec4<f32>(e, y);
    out[1] = vec4<f32>(d.pos * y, y * dot(d.pos, d.pos));
    return out;
}

@compute @workgroup_size(256)
fn light_sum(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    look = looks[wg.z].look;
    let group = wg.y * nwg.x + wg.x;
    sums[lid] = emitted(group * 256u + lid);
    // A tree over the workgroup (every invocation reaches every barrier).
    for (var stride = 128u; stride > 0u; stride >>= 1u) {
        workgroupBarrier();
        if lid < stride {
            sums[lid][0] += sums[lid + stride][0];
            sums[lid][1] += sums[lid + stride][1];
        }
    }
    if lid == 0u && group < job.groups_per_member {
        let at = (job.partial_base + wg.z * job.groups_per_member + group) * 2u;
        sums_out[at] = sums[0][0];
        sums_out[at + 1u] = sums[0][1];
    }
}

// Every total of the frame (each instance of each job) in one dispatch.
@compute @workgroup_size(64)
fn light_total(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= totals_plan[0].x {
        return;
    }
    let p = totals_plan[id.x + 1u];
    var a = vec4<f32>(0.0);
    var b = vec4<f32>(0.0);
    for (var k = 0u; k < p.y; k++) {
        a += sums_out[(p.x + k) * 2u];
        b += sums_out[(p.x + k) * 2u + 1u];
    }
    sums_out[p.z * 2u] = a;
    sums_out[p.z * 2u + 1u] = b;
}
