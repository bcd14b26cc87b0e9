// Mesh Color Textures (Yuksel 2017): mesh colors converted into one 2D atlas whose
// texels duplicate shared vertex and edge colours, filtered by the hardware sampler.
//
// The vertex stage pulls corners as shaders/mesh_colors.wgsl does (mesh_common.wgsl) and
// places each corner in the atlas from the face's 4-byte record and the band table:
// level 0 in the face's tent (`tent`, absolute texel-space point, interpolated), levels
// ≥ 1 in its square (`square`: the point relative to the square's frame in level-0 units,
// scaled per level in the fragment stage — the talk's 4D coordinate u_ℓ = u_s / 2^ℓ + u_δ
// with u_δ the square's origin at that level). Keep in sync with
// crates/core/src/mct/layout.rs (`MctFaceRecord`, `MctBands`, `frame_of`) and
// crates/core/src/mct/sample.rs (`sample_level`, `sample_trilinear`, the CPU evaluation the
// GPU is tested against).

// 0 = fixed level `u.level` (bilinear), 1 = automatic level (trilinear), as mesh colors.
override LEVEL_MODE: u32 = 1u;

// Number of block-resolution groups and levels per group (`GROUPS` in layout.rs).
const MCT_GROUPS: u32 = 13u;

// One u32 per face in .x (R32Uint data texture; bits: layout.rs `MctFaceRecord`).
@group(0) @binding(3) var mct_records: texture_2d<u32>;
@group(0) @binding(4) var mct_atlas: texture_2d<f32>;
@group(0) @binding(6) var mct_sampler: sampler;
// Keep in sync with `MctBands` in crates/core/src/mct/layout.rs: [y, per_row, 0, 0] of
// group g at level l at index g · 13 + l.
struct MctBands {
    bands: array<vec4<u32>, 169>,
}
@group(0) @binding(7) var<uniform> mct_bands: MctBands;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) bary: vec3<f32>,
    // rgb: heat-map colour of log2 R_b; a: dot(face normal, light direction).
    @location(1) @interpolate(flat) shade: vec4<f32>,
    // Level 0: the normalised atlas coordinate of the tent point, (point + 0.5) / size.
    @location(2) tent: vec2<f32>,
    // Levels ≥ 1: R_b · (w_α e_x + w_β e_y) of the square frame (see `square_point`).
    @location(3) square: vec2<f32>,
    @location(4) @interpolate(flat) record: u32,
    @location(5) lod: vec2<f32>,
    @location(6) light_dot: f32,
}

// layout.rs `MctFaceRecord` accessors.
fn mct_corner_p(record: u32) -> u32 {
    return min(record & 3u, 2u);
}
fn mct_corner_q(record: u32) -> u32 {
    return (mct_corner_p(record) + select(2u, 1u, (record & 4u) != 0u)) % 3u;
}
fn mct_second(record: u32) -> bool {
    return (record & 8u) != 0u;
}
fn mct_log2_block(record: u32) -> u32 {
    return min((record >> 4u) & 15u, MCT_GROUPS - 1u);
}

fn mct_band(g: u32, level: u32) -> vec2<u32> {
    return mct_bands.bands[g * MCT_GROUPS + min(level, MCT_GROUPS - 1u)].xy;
}

// layout.rs `frame_of` at level 0 (a tent): the texel-space point of each corner.
fn tent_corner(record: u32, corner: u32) -> vec2<f32> {
    let g = mct_log2_block(record);
    let r = i32(1u << g);
    let pair = record >> 8u;
    let band = mct_band(g, 0u);
    let per_row = max(band.y, 1u);
    let period = pair / 2u;
    let row = i32(period / per_row);
    let col = i32(period % per_row);
    let base_x = col * (2 * r + 6);
    let top = i32(band.x) + row * (r + 1);
    let up = (pair & 1u) == 0u;
    let xc = select(base_x + 2 * r + 4, base_x + r + 1, up);
    let yb = select(top + r, top, up);
    let dy = select(-1, 1, up);
    let dx = select(1, -1, mct_second(record));
    // Right angle at p, α leg towards the third corner (x), β leg towards q (y).
    var point = vec2<i32>(xc, yb);
    let p = mct_corner_p(record);
    let q = mct_corner_q(record);
    if corner == q {
        point.y += dy * r;
    } else if corner != p {
        point.x += dx * r;
    }
    return vec2<f32>(point);
}

// The square frame's corner in level-0 units relative to the right-angle corner (the
// third corner): p at R_b·e_x, q at R_b·e_y; e_x = (1, 0), e_y = (0, 1) for the pair's
// first face, e_x = (0, −1), e_y = (−1, 0) for its second.
fn square_corner(record: u32, corner: u32) -> vec2<f32> {
    let r = f32(1u << mct_log2_block(record));
    let second = mct_second(record);
    let ex = select(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, -1.0), second);
    let ey = select(vec2<f32>(0.0, 1.0), vec2<f32>(-1.0, 0.0), second);
    if corner == mct_corner_p(record) {
        return r * ex;
    }
    if corner == mct_corner_q(record) {
        return r * ey;
    }
    return vec2<f32>(0.0);
}

// layout.rs `frame_of` at level ≥ 1: the square's right-angle corner plus the interpolated
// point scaled to the level's resolution r = max(1, R_b >> level).
fn square_point(record: u32, square: vec2<f32>, level: u32) -> vec2<f32> {
    let g = mct_log2_block(record);
    let r = 1u << (g - min(level, g));
    let side = r + 1u;
    let band = mct_band(g, level);
    let per_row = max(band.y, 1u);
    let pair = record >> 8u;
    var origin = vec2<f32>(f32((pair % per_row) * side), f32(band.x + (pair / per_row) * side));
    if mct_second(record) {
        origin += vec2<f32>(f32(r));
    }
    return origin + square * (f32(r) / f32(1u << g));
}

// Hardware bilinear filtering at a texel-space point.
fn mct_bilinear(point: vec2<f32>) -> vec4<f32> {
    let size = vec2<f32>(textureDimensions(mct_atlas));
    return textureSampleLevel(mct_atlas, mct_sampler, (point + 0.5) / size, 0.0);
}

// sample.rs `sample_level`: level 0 in the tent (`tent_uv` normalised), levels ≥ 1 in the
// square.
fn mct_level(record: u32, tent_uv: vec2<f32>, square: vec2<f32>, level: u32) -> vec4<f32> {
    if level == 0u {
        return textureSampleLevel(mct_atlas, mct_sampler, tent_uv, 0.0);
    }
    return mct_bilinear(square_point(record, square, level));
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOut {
    let face = vertex_index / 3u;
    let corner = vertex_index % 3u;
    let pulled = pull_corner(face, corner, LEVEL_MODE == 1u);
    let record = textureLoad(mct_records, data_texel(min(face, max(u.face_count, 1u) - 1u)), 0).x;
    var out: VertexOut;
    out.clip = pulled.clip;
    out.bary = pulled.bary;
    out.lod = pulled.lod;
    out.shade = vec4<f32>(heat_color(mct_log2_block(record)), pulled.face_dot);
    out.light_dot = pulled.light_dot;
    out.tent = (tent_corner(record, corner) + 0.5) / vec2<f32>(textureDimensions(mct_atlas));
    out.square = square_corner(record, corner);
    out.record = record;
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let bary_width = fwidth(in.bary);
    let last = max(u.vertex_levels, 1u) - 1u;
    var color: vec4<f32>;
    if LEVEL_MODE == 1u {
        // The level of detail of mesh colors (crates/core/src/packing/lod.rs), clamped to
        // the last level (sample.rs `sample_trilinear`).
        var lod = log2(max(in.lod.x, 1e-30)) + in.lod.y;
        lod = clamp(select(lod, 0.0, is_nan(lod)), 0.0, f32(last));
        let l0 = u32(floor(lod));
        let t = lod - f32(l0);
        let c0 = mct_level(in.record, in.tent, in.square, l0);
        let c1 = mct_level(in.record, in.tent, in.square, min(l0 + 1u, last));
        color = select(c0, mix(c0, c1, t), t > 0.0);
    } else {
        color = mct_level(in.record, in.tent, in.square, min(u.level, last));
    }
    return finish_fragment(color, in.shade.rgb, in.shade.w, in.light_dot, front_facing, in.bary, bary_width);
}
