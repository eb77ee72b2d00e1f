// sprite_project.wgsl — a particle's quad projected to the pixels it covers, as both compute
// draw paths read it: the tile rasteriser (tiles.wgsl, shaded per tile) and the footprint
// splat (splat.wgsl, added per pixel). The map, the pixel box and the per-pixel light are
// the billboards' (quad.wgsl places the corners on the rasteriser's grid for both).
//
// Contract: as quad.wgsl, plus the importer's `sprite_tex` and `sprite_sampler` (the
// emitter's sprite), `scene_depth` (the host's depth) and `visible(p, z)` (its depth test).
#import "quad.wgsl"
#import "raster_edges.wgsl"

// A projected quad. Its coordinates in the sprite's frame at a pixel p (pixel units, the
// origin at the target's top-left corner): h = (map.xy·p.x + map.zw·p.y + offset.xy,
// map_z·(p, 1)), uv = h.xy / h.z (a projective map: the perspective-correct interpolation
// of the billboard's corners). A camera-facing quad's map is affine (offset.z = 1): uv =
// h.xy; the fields after `ground` then hold the snapped corners (map_z: p0, p1; z_row:
// p2, p3; pixels × 256), read only near a turned sprite's edges. The shade reads the
// first eight fields of every sprite it meets: they fill four whole 32-byte sectors.
// The corners are placed on the rasteriser's sub-pixel grid. An upright rectangle there
// (an unrotated camera-facing sprite) covers exactly the rasteriser's pixels: the centres
// in its half-open pixel box (the top-left rule). Another quad covers the pixels whose uv
// lies in its box: the rasteriser's but for centres within about 1/256 pixel of an edge.
struct TileSprite {
    // Pixel rectangle (x0, y0, x1, y1, inclusive; empty when x0 > x1).
    bounds: vec4<i32>,
    map: vec4<f32>,
    // xy: the map's constant terms, z: 1 when the map is affine (2: and the quad an
    // upright rectangle), w: the depth then.
    offset: vec4<f32>,
    // The quad: uv0.xy to uv1.xy (the sprite's occupied part); an upright rectangle's
    // pixels (x0, y0, x1, y1: the centres in [x0, x1) × [y0, y1)) instead.
    uv_box: vec4<f32>,
    // Premultiplied colour (× intensity when additive).
    color: vec4<f32>,
    // The atlas coordinates at frame coordinates (0, 0) of the flipbook frame (xy) and of
    // the next one it blends into (zw).
    frames: vec4<f32>,
    // xy: atlas coordinates per unit of frame coordinates (the derivatives' scale), z: the
    // next frame's weight, w: the soft edges' 1 / distance.
    grad: vec4<f32>,
    // The ground fade's argument as an affine function of (uv, 1).
    ground: vec4<f32>,
    // A projective map's h.z row, and clip z and w as affine functions of (uv, 1).
    map_z: vec4<f32>,
    z_row: vec4<f32>,
    w_row: vec4<f32>,
    // To 192 bytes: every sprite starts on a sector.
    pad: vec4<f32>,
}

// The atlas coordinates' scale per unit of frame coordinates.
fn atlas_scale() -> vec2<f32> {
    if FLIPBOOK {
        return vec2<f32>(0.5 / f32(max(look.ids.w, 1u)), -0.5 / f32(max(look.ids.z, 1u)));
    }
    return vec2<f32>(0.5, -0.5);
}

// Quad `qd` projected (empty bounds when it draws nothing).
fn project_quad(qd: Quad) -> TileSprite {
    var s: TileSprite;
    s.bounds = vec4<i32>(1, 1, 0, 0);
    if !qd.d.alive {
        return s;
    }
    // Corners 0 (uv0.x, uv0.y), 1 (uv1.x, uv0.y), 2 (uv0.x, uv1.y), 3: the clip position is
    // affine in the frame coordinates (both for rotated squares and streaks).
    let c0 = quad_corner(qd, 0u);
    let c1 = quad_corner(qd, 1u);
    let c2 = quad_corner(qd, 2u);
    let c3 = quad_corner(qd, 3u);
    if min(min(c0.clip.w, c1.clip.w), min(c2.clip.w, c3.clip.w)) <= 1e-4 {
        return s;
    }
    let du = c1.uv.x - c0.uv.x;
    let dv = c2.uv.y - c0.uv.y;
    if abs(du) < 1e-12 || abs(dv) < 1e-12 {
        return s;
    }
    let col_u = (c1.clip - c0.clip) / du;
    let col_v = (c2.clip - c0.clip) / dv;
    let col_1 = c0.clip - col_u * c0.uv.x - col_v * c0.uv.y;
    // Homogeneous pixels (p·w, w) = P · (x, y, w), P = [W/2 0 W/2; 0 −H/2 H/2; 0 0 1].
    let hw = 0.5 * camera.viewport.xy;
    let m = mat3x3<f32>(
        vec3<f32>(hw.x * (col_u.x + col_u.w), hw.y * (col_u.w - col_u.y), col_u.w),
        vec3<f32>(hw.x * (col_v.x + col_v.w), hw.y * (col_v.w - col_v.y), col_v.w),
        vec3<f32>(hw.x * (col_1.x + col_1.w), hw.y * (col_1.w - col_1.y), col_1.w),
    );
    // The adjugate: (uv, 1) ∝ adj(m) · (p, 1) (a scale, sign included, cancels in h.xy / h.z).
    let adj = transpose(mat3x3<f32>(cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1])));
    s.map = vec4<f32>(adj[0].xy, adj[1].xy);
    s.offset = vec4<f32>(adj[2].xy, 0.0, 0.0);
    s.map_z = vec4<f32>(adj[0].z, adj[1].z, adj[2].z, 0.0);
    s.z_row = vec4<f32>(col_u.z, col_v.z, col_1.z, 0.0);
    s.w_row = vec4<f32>(col_u.w, col_v.w, col_1.w, 0.0);
    if quad_flat_w(qd) >= 0.0 {
        // A quad parallel to the image plane (a camera-facing billboard): one depth, and
        // the map is affine — uv = map.xy · p.x + map.zw · p.y + offset.xy, flagged by
        // offset.z = 1, the depth in offset.w (culled here when outside the depth range).
        let z = col_1.z / col_1.w;
        if z < 0.0 || z > 1.0 {
            return s;
        }
        s.offset = vec4<f32>(0.0, 0.0, 1.0, z);
    }
    s.uv_box = vec4<f32>(min(c0.uv, c3.uv), max(c0.uv, c3.uv));
    s.color = qd.color;
    if LIT {
        // A lit sprite's own colour is its glow (lit.wgsl).
        s.color = vec4<f32>(qd.color.rgb * lit.ambient.w, qd.color.a);
    }
    // The flipbook's cells, found here once: the shade maps frame coordinates to the
    // atlas with one multiply-add (the look's `atlas_uv`, rearranged).
    var frames = vec3<f32>(0.0);
    var grid = vec2<u32>(1u);
    if FLIPBOOK {
        frames = quad_frames(qd);
        grid = vec2<u32>(max(look.ids.w, 1u), max(look.ids.z, 1u));
    }
    s.frames = vec4<f32>(cell_centre(frames.x, grid), cell_centre(frames.y, grid));
    if SOFT {
        let g0 = ground_fade_arg(c0.world);
        let gu = (ground_fade_arg(c1.world) - g0) / du;
        let gv = (ground_fade_arg(c2.world) - g0) / dv;
        s.ground = vec4<f32>(gu, gv, g0 - gu * c0.uv.x - gv * c0.uv.y, 0.0);
    }
    // The shade reads nothing of the look (a private copy of it per invocation costs
    // registers).
    s.grad = vec4<f32>(atlas_scale(), frames.z, look.soft.y);
    // The corners where the rasteriser puts them: on its sub-pixel grid, where the
    // billboards' vertex shader puts them too.
    let p0 = grid_pixels(c0.clip);
    let p1 = grid_pixels(c1.clip);
    let p2 = grid_pixels(c2.clip);
    let p3 = grid_pixels(c3.clip);
    if s.offset.z == 1.0 {
        // The affine map from the snapped corners (p = p0 + J · (uv − uv0)), so that the
        // pixels a sprite smaller than a pixel covers are the billboard's.
        let j = mat2x2<f32>((p1 - p0) / du, (p2 - p0) / dv);
        let det = determinant(j);
        if abs(det) < 1e-30 {
            // No area on the grid: the rasteriser draws nothing either.
            return s;
        }
        let inv = mat2x2<f32>(vec2<f32>(j[1].y, -j[0].y), vec2<f32>(-j[1].x, j[0].x)) * (1.0 / det);
        s.map = vec4<f32>(inv[0], inv[1]);
        s.offset = vec4<f32>(c0.uv - inv * p0, s.offset.zw);
        // The snapped corners (pixels × 256, integers), for `quad_covers` near the edges
        // of a turned sprite (an affine map leaves these fields unused).
        s.map_z = vec4<f32>(p0, p1) * 256.0;
        s.z_row = vec4<f32>(p2, p3) * 256.0;
        if p0.x == p2.x && p1.x == p3.x && p0.y == p1.y && p2.y == p3.y {
            // An upright rectangle on the grid (an unrotated camera-facing sprite): the
            // rasteriser's pixels are exactly the centres in [x0, x1) × [y0, y1) (the
            // top-left rule), tested in pixels (offset.z = 2) against this box.
            s.offset.z = 2.0;
            s.uv_box = vec4<f32>(min(p0, p3), max(p0, p3));
        }
    }
    // Pixel centres (x + 0.5) inside the quad's bounding box, clamped to the target.
    let lo = floor(min(min(p0, p1), min(p2, p3)) - 0.5);
    let hi = ceil(max(max(p0, p1), max(p2, p3)) - 0.5);
    let size = vec2<f32>(camera.viewport.xy) - 1.0;
    if any(hi < vec2<f32>(0.0)) || any(lo > size) {
        return s;
    }
    s.bounds = vec4<i32>(vec2<i32>(max(lo, vec2<f32>(0.0))), vec2<i32>(min(hi, size)));
    return s;
}

// The atlas coordinates of flipbook frame `frame`'s centre (frame coordinates (0, 0)) in
// an atlas of `grid` = (columns, rows) cells: look.wgsl's `atlas_uv` at the centre.
fn cell_centre(frame: f32, grid: vec2<u32>) -> vec2<f32> {
    let f = u32(frame);
    return (vec2<f32>(f32(f % grid.x), f32(f / grid.x)) + 0.5) / vec2<f32>(grid);
}


// Where pixel centre `pc` falls in a sprite: its frame coordinates, their derivatives
// per pixel, and the depth.
struct SpritePoint {
    uv: vec2<f32>,
    ddx: vec2<f32>,
    ddy: vec2<f32>,
    z: f32,
}

// A camera-facing (affine) sprite's map at `pc`: derivatives and depth are the quad's.
fn affine_point(map: vec4<f32>, offset: vec4<f32>, pc: vec2<f32>) -> SpritePoint {
    return SpritePoint(map.xy * pc.x + map.zw * pc.y + offset.xy, map.xy, map.zw, offset.w);
}

// A projective sprite's map at `pc` (`map_z`, `z_row`, `w_row`: `TileSprite`'s), the
// derivatives exact at this pixel (the mip level the billboard's fragment would pick).
fn projective_point(map: vec4<f32>, offset: vec4<f32>, map_z: vec4<f32>, z_row: vec4<f32>, w_row: vec4<f32>, pc: vec2<f32>) -> SpritePoint {
    let h = vec3<f32>(map.xy * pc.x + map.zw * pc.y + offset.xy, dot(map_z.xyz, vec3<f32>(pc, 1.0)));
    let uv = h.xy / h.z;
    let ddx = (map.xy * h.z - h.xy * map_z.x) / (h.z * h.z);
    let ddy = (map.zw * h.z - h.xy * map_z.y) / (h.z * h.z);
    let uv1 = vec3<f32>(uv, 1.0);
    return SpritePoint(uv, ddx, ddy, dot(z_row.xyz, uv1) / dot(w_row.xyz, uv1));
}

// Whether the point misses the sprite: outside its box (`box_outside`), or outside the
// depth range (clipped as the rasteriser clips the billboard), or behind the host's
// geometry.
fn sprite_misses(sp: SpritePoint, pc: vec2<f32>, p: vec2<i32>, offset: vec4<f32>, uv_box: vec4<f32>) -> bool {
    return box_outside(sp, pc, offset, uv_box) || depth_misses(sp, p);
}

// Whether the point lies outside the sprite's box: pixels, half-open, for an upright
// rectangle (`offset.z` = 2), else frame coordinates.
fn box_outside(sp: SpritePoint, pc: vec2<f32>, offset: vec4<f32>, uv_box: vec4<f32>) -> bool {
    let upright = offset.z == 2.0;
    let q = select(sp.uv, pc, upright);
    return any(q < uv_box.xy) || any(q > uv_box.zw) || (upright && any(q == uv_box.zw));
}

// Whether the point is outside the depth range or behind the host's geometry.
fn depth_misses(sp: SpritePoint, p: vec2<i32>) -> bool {
    return sp.z < 0.0 || sp.z > 1.0 || !visible(p, sp.z);
}

// Whether a turned camera-facing sprite's (`offset.z` = 1) box edge passes within 1/256
// pixel of the point: there the uv test and the rasteriser may disagree (a tie on its
// grid, or the fourth corner snapped off the parallelogram), and `quad_covers` decides.
// Snapping each corner to the nearest 1/256 pixel moves an edge by at most 1/512 pixel in
// x and in y; the band is twice that. At 1/512 the torch's turned flames differ from the
// billboards on lavapipe and on an NVIDIA H200 alike (tests/tiles.rs, rotated sprites).
fn near_box_edge(sp: SpritePoint, offset: vec4<f32>, uv_box: vec4<f32>) -> bool {
    let tol = (abs(sp.ddx) + abs(sp.ddy)) * (1.0 / 256.0);
    let near = (abs(sp.uv - uv_box.xy) <= tol) | (abs(sp.uv - uv_box.zw) <= tol);
    let within = all(sp.uv >= uv_box.xy - tol) && all(sp.uv <= uv_box.zw + tol);
    return offset.z == 1.0 && within && any(near);
}

// The sprite's texel at frame coordinates `uv` (the atlas scale applied): the frame at
// `frames.xy`, cross-faded towards the one at `frames.zw` by `next` when the flipbook
// blends, with the derivatives `ddx`, `ddy` (atlas units per pixel).
fn sprite_texel(uv: vec2<f32>, frames: vec4<f32>, next: f32, ddx: vec2<f32>, ddy: vec2<f32>) -> vec4<f32> {
    var tex = textureSampleGrad(sprite_tex, sprite_sampler, uv + frames.xy, ddx, ddy);
    if FLIPBOOK && FLIP_BLEND {
        let next_tex = textureSampleGrad(sprite_tex, sprite_sampler, uv + frames.zw, ddx, ddy);
        tex = mix(tex, next_tex, next);
    }
    return tex;
}

// The soft edges' fade at pixel `p`: the ground plane's (`ground`: its argument as an
// affine function of (uv, 1)) or the host's depth's (`inv_distance`: 1 / the soft
// distance), 1 without either.
fn soft_fade(p: vec2<i32>, uv: vec2<f32>, z: f32, ground: vec4<f32>, inv_distance: f32) -> f32 {
    var fade = 1.0;
    if SOFT {
        fade = clamp(dot(ground.xyz, vec3<f32>(uv, 1.0)), 0.0, 1.0);
    }
    if SOFT_DEPTH {
        let scene = textureLoad(scene_depth, p, 0);
        fade *= clamp((view_distance(scene) - view_distance(z)) * inv_distance, 0.0, 1.0);
    }
    return fade;
}

// The view-space distance in front of the camera of a depth-buffer value.
fn view_distance(depth: f32) -> f32 {
    let k = camera.depth_to_view;
    return -(k.x * depth + k.y) / (k.z * depth + k.w);
}
