// Packed Ptex (Kim, Hillesland, Hensley 2011): per-pair square blocks with their MIP chains,
// sorted by resolution into one texture with one-texel borders, placed per pixel by the
// paper's nRes / nRow tables (its Listing 1, slips fixed: crates/core/src/ptex/layout.rs).
//
// The vertex stage pulls corners as shaders/mesh_colors.wgsl does (mesh_common.wgsl) and
// gives each corner its point in the block's unit square (the face record) and the block
// index; the fragment stage picks its level(s) per pixel, finds the block's slice and place
// from the tables and takes one hardware-bilinear lookup per level (trilinear: two, blended
// at mesh colors' continuous level of detail).
// Keep in sync with crates/core/src/ptex/layout.rs (`PtexFaceRecord`, `PtexTables`,
// `PtexLayout::frame`) and crates/core/src/ptex/sample.rs (`sample_level`,
// `sample_trilinear`, the CPU evaluation the GPU is tested against).

// 0 = fixed level `u.level` (bilinear), 1 = automatic level (trilinear), as mesh colors.
override LEVEL_MODE: u32 = 1u;

// The FLAG_* bits this pipeline draws with (one pipeline per set the renderer meets).
override PTEX_FLAGS: u32 = 0u;

// Slices (resolutions 2^0 ..= 2^12): `SLICES` in crates/core/src/ptex/layout.rs.
const PTEX_SLICES: u32 = 13u;

// One u32 per face in .x (R32Uint data texture; bits: layout.rs `PtexFaceRecord`).
@group(0) @binding(3) var ptex_records: texture_2d<u32>;
@group(0) @binding(4) var ptex_texture: texture_2d<f32>;
@group(0) @binding(6) var ptex_sampler: sampler;
// Per slice k: (nRes[k], nRow[k], blocks per row, 0) (crates/render/src/ptex.rs `gpu_tables`).
@group(0) @binding(7) var<storage, read> ptex_tables: array<vec4<u32>>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    // FLAG_WIREFRAME: the barycentric unit vector of the corner.
    @location(0) bary: vec3<f32>,
    // rgb: FLAG_HEATMAP's colour of log2 n; a: FLAG_LIT's dot(face normal, light).
    @location(1) @interpolate(flat) shade: vec4<f32>,
    // The point in the block's unit square.
    @location(2) square: vec2<f32>,
    // The block index and log2 of its level-0 resolution m.
    @location(3) @interpolate(flat) block: vec2<u32>,
    // Trilinear: view depth and the level-of-detail term μ (mesh_common.wgsl `lod_term`).
    @location(4) lod: vec2<f32>,
    // FLAG_SMOOTH: the smooth-shading light term.
    @location(5) light_dot: f32,
}

// layout.rs `PtexFaceRecord`: the corner's point in the unit square (third vertex at (0, 0)
// for the first face, (1, 1) for the second; p at (1, 0); q at (0, 1)).
fn ptex_square_corner(record: u32, corner: u32) -> vec2<f32> {
    let t = min(record & 3u, 2u);
    let p = (t + select(2u, 1u, (record & 4u) != 0u)) % 3u;
    if corner == p {
        return vec2<f32>(1.0, 0.0);
    }
    if corner == t {
        return select(vec2<f32>(0.0), vec2<f32>(1.0), (record & 8u) != 0u);
    }
    return vec2<f32>(0.0, 1.0);
}

// layout.rs `PtexTables::log2_of`: Listing 1's clamp from the finest slice down.
fn ptex_log2_of(block: u32) -> u32 {
    var k = i32(PTEX_SLICES) - 1;
    while k > 0 && ptex_tables[k].x > block {
        k -= 1;
    }
    return u32(k);
}

// layout.rs `PtexLayout::frame` and `PtexTables::origin`: the normalised texture coordinate
// of unit-square point `square` of `block` (level-0 log2 `m`) at `level`.
fn ptex_coordinate(block: u32, m: u32, square: vec2<f32>, level: u32) -> vec2<f32> {
    let k = m - min(level, m);
    let entry = ptex_tables[k];
    let size = (1u << k) + 2u;
    let i = block - min(entry.x, block);
    let per_row = max(entry.z, 1u);
    let top_left = vec2<u32>((i % per_row) * size, entry.y + (i / per_row) * size);
    let point = vec2<f32>(top_left + 1u) + square * f32(1u << k);
    return point / vec2<f32>(textureDimensions(ptex_texture));
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOut {
    let face = vertex_index / 3u;
    let corner = vertex_index % 3u;
    let lit = (PTEX_FLAGS & (FLAG_LIT | FLAG_SMOOTH)) != 0u;
    let pulled = pull_corner_with(face, corner, LEVEL_MODE != 0u, PTEX_FLAGS, lit);
    let record = textureLoad(ptex_records, data_texel(min(face, max(u.face_count, 1u) - 1u)), 0).x;
    let block = record >> 4u;
    let m = ptex_log2_of(block);
    var out: VertexOut;
    out.clip = pulled.clip;
    out.bary = select(vec3<f32>(0.0), pulled.bary, (PTEX_FLAGS & FLAG_WIREFRAME) != 0u);
    out.shade = vec4<f32>(0.0);
    if (PTEX_FLAGS & FLAG_HEATMAP) != 0u {
        out.shade = vec4<f32>(heat_color(m), 0.0);
    }
    out.shade.w = select(0.0, pulled.face_dot, lit);
    out.light_dot = select(0.0, pulled.light_dot, (PTEX_FLAGS & FLAG_SMOOTH) != 0u);
    out.lod = pulled.lod;
    out.square = ptex_square_corner(record, corner);
    out.block = vec2<u32>(block, m);
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    var bary_width = vec3<f32>(0.0);
    if (PTEX_FLAGS & FLAG_WIREFRAME) != 0u {
        bary_width = fwidth(in.bary);
    }
    let last = max(u.vertex_levels, 1u) - 1u;
    var color: vec4<f32>;
    if LEVEL_MODE != 0u {
        // The paper's per-pixel level, here mesh colors' continuous level of detail
        // (crates/core/src/packing/lod.rs) clamped to the last level (sample.rs
        // `sample_trilinear`); levels l0 and l1 blended.
        var lod = log2(max(in.lod.x, 1e-30)) + in.lod.y;
        lod = clamp(select(lod, 0.0, is_nan(lod)), 0.0, f32(last));
        let l0 = u32(lod);
        let t = lod - f32(l0);
        let l1 = min(l0 + 1u, last);
        let c0 = textureSampleLevel(ptex_texture, ptex_sampler, ptex_coordinate(in.block.x, in.block.y, in.square, l0), 0.0);
        let c1 = textureSampleLevel(ptex_texture, ptex_sampler, ptex_coordinate(in.block.x, in.block.y, in.square, l1), 0.0);
        color = mix(c0, c1, t);
    } else {
        let level = min(u.level, last);
        color = textureSampleLevel(ptex_texture, ptex_sampler, ptex_coordinate(in.block.x, in.block.y, in.square, level), 0.0);
    }
    return finish_fragment_with(PTEX_FLAGS, color, in.shade.rgb, in.shade.w, in.light_dot, front_facing, in.bary, bary_width);
}
