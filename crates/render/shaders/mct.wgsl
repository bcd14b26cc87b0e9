// Mesh Color Textures (Yuksel 2017): mesh colors converted into one 2D atlas whose
// texels duplicate shared vertex and edge colours, filtered by the hardware sampler.
//
// The vertex stage pulls corners as shaders/mesh_colors.wgsl does (mesh_common.wgsl) and
// places each corner in the atlas from the face's 4-byte record and the band table. Every
// level's texture coordinate is affine in the barycentrics, so what the vertex stage can
// place exactly it interpolates: at a fixed level (`LEVEL_MODE` 0) the atlas coordinate of
// that level, and the fragment stage takes one lookup. For trilinear (`LEVEL_MODE` 1) it
// interpolates level 0's coordinate in the face's tent and the point in the square frame
// (`uv_square`); the fragment stage places the square at its two levels without a branch
// or an integer division (the talk's 4D coordinate u_ℓ = r_ℓ · u_s + u_δ(ℓ), u_δ from the
// band table) and takes two lookups. Keep in sync with
// crates/core/src/mct/layout.rs (`MctFaceRecord`, `MctBands`, `frame_of`) and
// crates/core/src/mct/sample.rs (`sample_level`, `sample_trilinear`, the CPU evaluation the
// GPU is tested against).

// 0 = fixed level `u.level` (bilinear), 1 = automatic level (trilinear), as mesh colors.
override LEVEL_MODE: u32 = 1u;

// The FLAG_* bits this pipeline draws with (the renderer builds one pipeline per set of
// flags it meets and ignores `u.flags` here): a disabled overlay or lighting costs nothing,
// where a software rasteriser would run a uniform branch's code for every fragment.
override MCT_FLAGS: u32 = 0u;

// Number of block-resolution groups and levels per group (`GROUPS` in layout.rs).
const MCT_GROUPS: u32 = 13u;

// One u32 per face in .x (R32Uint data texture; bits: layout.rs `MctFaceRecord`).
@group(0) @binding(3) var mct_records: texture_2d<u32>;
@group(0) @binding(4) var mct_atlas: texture_2d<f32>;
@group(0) @binding(6) var mct_sampler: sampler;
// The band table (`MctBands` in crates/core/src/mct/layout.rs) as crates/render/src/mct.rs
// uploads it (`gpu_bands`): at index g · 13 + l, the bands of group g at level l and at the
// next level min(l + 1, last), each packed as y | per_row << 16 (per_row ≥ 1; tent periods
// at level 0), so that one lookup gives a fragment both of its levels.
struct MctBands {
    bands: array<vec4<u32>, 169>,
}
@group(0) @binding(7) var<uniform> mct_bands: MctBands;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    // FLAG_WIREFRAME: the barycentric unit vector of the corner.
    @location(0) bary: vec3<f32>,
    // rgb: FLAG_HEATMAP's colour of log2 R_b; a: FLAG_LIT's dot(face normal, light).
    @location(1) @interpolate(flat) shade: vec4<f32>,
    // xy: the normalised atlas coordinate, (point + 0.5) / size, of the fixed level or (for
    // trilinear) of level 0, the tent; zw: the point in the unit square frame of levels ≥ 1
    // (`square_unit_corner`).
    @location(2) uv_square: vec4<f32>,
    // Trilinear: log2 R_b and the pair index.
    @location(3) @interpolate(flat) block: vec2<u32>,
    // Trilinear: view depth and the level-of-detail term μ (mesh_common.wgsl `lod_term`).
    @location(4) lod: vec2<f32>,
    // FLAG_SMOOTH: the smooth-shading light term.
    @location(5) light_dot: f32,
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

// The packed bands of group `g` at `level` (x) and at the next level (y).
fn mct_bands_at(g: u32, level: u32) -> vec2<u32> {
    return mct_bands.bands[g * MCT_GROUPS + min(level, MCT_GROUPS - 1u)].xy;
}

// (⌊a / b⌋, a mod b) of integers a < 2^24 and b ≥ 1 held in f32, by b's reciprocal `inv_b`
// and no integer division (vector units have none: it would run lane by lane). For quotients
// below 2^22 (atlas rows) the float quotient is within 1 of the true one; the remainder,
// exact by fma, corrects it.
fn div_rem(a: f32, b: f32, inv_b: f32) -> vec2<f32> {
    let q0 = floor(a * inv_b);
    let rem = fma(-q0, b, a);
    let q = q0 + select(0.0, 1.0, rem >= b) - select(0.0, 1.0, rem < 0.0);
    return vec2<f32>(q, fma(-q, b, a));
}

// layout.rs `frame_of` at level 0 (a tent): the texel-space point of each corner.
fn tent_corner(record: u32, corner: u32) -> vec2<f32> {
    let g = mct_log2_block(record);
    let pair = record >> 8u;
    let band = mct_bands_at(g, 0u).x;
    let periods = f32(band >> 16u);
    let r = i32(1u << g);
    let row_col = div_rem(f32(pair >> 1u), periods, 1.0 / periods);
    let base_x = i32(row_col.y) * (2 * r + 6);
    let top = i32(band & 0xffffu) + i32(row_col.x) * (r + 1);
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

// layout.rs `frame_of` at level ≥ 1 in units of the square's side r: the pair shares the
// diagonal, p at (1, 0) and q at (0, 1); the third corner is the first face's origin (0, 0)
// or the second face's (1, 1). A point of the face is texel `x₀ + r · square` at every level.
fn square_unit_corner(record: u32, corner: u32) -> vec2<f32> {
    if corner == mct_corner_p(record) {
        return vec2<f32>(1.0, 0.0);
    }
    if corner == mct_corner_q(record) {
        return vec2<f32>(0.0, 1.0);
    }
    return select(vec2<f32>(0.0), vec2<f32>(1.0), mct_second(record));
}

// layout.rs `frame_of` at level ≥ 1: the texel-space point of `square` in the square of
// pair `pair` (in f32, exact) of group `g` at `level`, whose packed band is `band`: the
// square's corner, plus `square` scaled by the block's resolution r = max(1, R_b >> level).
fn square_point(g: u32, pair: f32, square: vec2<f32>, level: u32, band: u32) -> vec2<f32> {
    let per_row = f32(band >> 16u);
    let r = f32(1u << (g - min(level, g)));
    let row_col = div_rem(pair, per_row, 1.0 / per_row);
    let side = r + 1.0;
    return vec2<f32>(row_col.y * side, f32(band & 0xffffu) + row_col.x * side) + r * square;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOut {
    let face = vertex_index / 3u;
    let corner = vertex_index % 3u;
    let lit = (MCT_FLAGS & (FLAG_LIT | FLAG_SMOOTH)) != 0u;
    let pulled = pull_corner_with(face, corner, LEVEL_MODE == 1u, MCT_FLAGS, lit);
    let record = textureLoad(mct_records, data_texel(min(face, max(u.face_count, 1u) - 1u)), 0).x;
    let g = mct_log2_block(record);
    var out: VertexOut;
    out.clip = pulled.clip;
    // Only what this pipeline's flags read, so that unused varyings are constants.
    out.bary = select(vec3<f32>(0.0), pulled.bary, (MCT_FLAGS & FLAG_WIREFRAME) != 0u);
    out.shade = vec4<f32>(0.0);
    if (MCT_FLAGS & FLAG_HEATMAP) != 0u {
        out.shade = vec4<f32>(heat_color(g), 0.0);
    }
    out.shade.w = select(0.0, pulled.face_dot, lit);
    out.light_dot = select(0.0, pulled.light_dot, (MCT_FLAGS & FLAG_SMOOTH) != 0u);
    out.lod = pulled.lod;
    let square = square_unit_corner(record, corner);
    out.block = vec2<u32>(g, record >> 8u);
    let level = select(0u, min(u.level, max(u.vertex_levels, 1u) - 1u), LEVEL_MODE == 0u);
    var point = tent_corner(record, corner);
    if level > 0u {
        point = square_point(g, f32(record >> 8u), square, level, mct_bands_at(g, level).x);
    }
    out.uv_square = vec4<f32>((point + 0.5) / vec2<f32>(textureDimensions(mct_atlas)), square);
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    var bary_width = vec3<f32>(0.0);
    if (MCT_FLAGS & FLAG_WIREFRAME) != 0u {
        bary_width = fwidth(in.bary);
    }
    var color: vec4<f32>;
    if LEVEL_MODE == 1u {
        // The level of detail of mesh colors (crates/core/src/packing/lod.rs), clamped to
        // the last level (sample.rs `sample_trilinear`); levels l0 and l1 blended, each
        // placed without a branch (level 0 is the tent's interpolated coordinate).
        let last = max(u.vertex_levels, 1u) - 1u;
        var lod = log2(max(in.lod.x, 1e-30)) + in.lod.y;
        lod = clamp(select(lod, 0.0, is_nan(lod)), 0.0, f32(last));
        let l0 = u32(lod);
        let t = lod - f32(l0);
        let l1 = min(l0 + 1u, last);
        let inv_size = 1.0 / vec2<f32>(textureDimensions(mct_atlas));
        let g = in.block.x;
        let pair = f32(in.block.y);
        let bands = mct_bands_at(g, l0);
        let s0 = (square_point(g, pair, in.uv_square.zw, max(l0, 1u), bands.x) + 0.5) * inv_size;
        let s1 = (square_point(g, pair, in.uv_square.zw, max(l1, 1u), bands.y) + 0.5) * inv_size;
        let c0 = textureSampleLevel(mct_atlas, mct_sampler, select(s0, in.uv_square.xy, l0 == 0u), 0.0);
        let c1 = textureSampleLevel(mct_atlas, mct_sampler, select(s1, in.uv_square.xy, l1 == 0u), 0.0);
        color = mix(c0, c1, t);
    } else {
        color = textureSampleLevel(mct_atlas, mct_sampler, in.uv_square.xy, 0.0);
    }
    return finish_fragment_with(MCT_FLAGS, color, in.shade.rgb, in.shade.w, in.light_dot, front_facing, in.bary, bary_width);
}
