// light_apply.wgsl — the effect's light handed to its lit layers on the GPU, the frame it
// is measured: for each lit look slot, the totals of light.wgsl (one per additive emitter
// of the same instance) are summed, moved into the lit emitter's simulation space, and
// written into the slot's `LitUniform` (look.wgsl: `self_pos`, `self_rgb`) before the
// draws read it. No readback, no latency.
//
// Contract: 0 `sums` (light.wgsl's partials and totals: two vec4 per entry), 1 `looks`
// (the looks buffer, written), 2 `plan`: element 0 = (targets, 0, 0, 0), then one header
// per target (look slot, first source, sources, 0), then the sources (the offset from
// the lit emitter's origin to the source's, as f32 bits, and the total's index).

@group(0) @binding(0) var<storage, read> sums: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> looks: array<SlotWords>;
@group(0) @binding(2) var<storage, read> plan: array<vec4<u32>>;

// A look slot as words: `LookUniform` is 18 vec4s, `LitUniform` the 14 after it (keep in
// sync with look.wgsl; tests/shaders.rs checks the sizes).
struct SlotWords {
    w: array<vec4<f32>, 32>,
}

const SELF_POS: u32 = 22u;
const SELF_RGB: u32 = 23u;

@compute @workgroup_size(64)
fn light_apply(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = id.x;
    if t >= plan[0].x {
        return;
    }
    let head = plan[1u + t];
    var rgb = vec4<f32>(0.0);
    var moments = vec4<f32>(0.0);
    for (var k = 0u; k < head.z; k++) {
        let src = plan[head.y + k];
        let delta = bitcast<vec3<f32>>(src.xyz);
        let a = sums[src.w * 2u];
        let b = sums[src.w * 2u + 1u];
        // Σ Y·(p + δ) and Σ Y·|p + δ|² from the source's Σ Y, Σ Y·p and Σ Y·|p|².
        rgb += a;
        moments += vec4<f32>(b.xyz + delta * a.w, b.w + 2.0 * dot(delta, b.xyz) + dot(delta, delta) * a.w);
    }
    var pos = vec4<f32>(0.0);
    if rgb.w > 0.0 {
        let centre = moments.xyz / rgb.w;
        pos = vec4<f32>(centre, max(moments.w / rgb.w - dot(centre, centre), 0.0));
    }
    looks[head.x].w[SELF_POS] = pos;
    looks[head.x].w[SELF_RGB] = rgb;
}
