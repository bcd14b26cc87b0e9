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
// band table and the face's place in its strip row, found once per vertex) and takes two
// lookups. The atlas wraps around in x (the sampler repeats: tents cross the right edge).
// Keep in sync with crates/core/src/mct/layout.rs (`MctFaceRecord`, `MctBands`, `frame_of`) and
// crates/core/src/mct/sample.rs (`sample_level`, `sample_trilinear`, the CPU evaluation the
// GPU is tested against).

// 0 = fixed level `u.level` (bilinear), 1 = automatic level (trilinear), as mesh colors;
// 2 = anisotropic: the hardware's anisotropic sampler at the two levels around trilinear's
// level made finer by log2 of the taps (crates/render/src/renderer.rs `MCT_LEVEL_ANISOTROPIC`).
override LEVEL_MODE: u32 = 1u;

// Keep in sync with `MAX_ANISOTROPY` in crates/render/src/mct.rs.
const MCT_MAX_ANISOTROPY: f32 = 16.0;

// The FLAG_* bits this pipeline draws with (the renderer builds one pipeline per set of
// flags it meets and ignores `u.flags` here): a disabled overlay or lighting costs nothing,
// where a software rasteriser would run a uniform branch's code for every fragment.
override MCT_FLAGS: u32 = 0u;

// Number of block-resolution groups and levels per group (`GROUPS` in layout.rs).
const MCT_GROUPS: u32 = 13u;

// One u32 per face in .x (R32Uint data texture; bits: layout.rs `MctFaceRecord`), then the
// strip-row masks (layout.rs `MctLayout::masks`) from texel `u.face_count` on.
@group(0) @binding(3) var mct_records: texture_2d<u32>;
@group(0) @binding(4) var mct_atlas: texture_2d<f32>;
@group(0) @binding(6) var mct_sampler: sampler;
// Linear in all three filters with an anisotropy clamp of MCT_MAX_ANISOTROPY (1 where the
// adapter has no anisotropic filtering; the renderer then draws LEVEL_MODE 1 instead).
@group(0) @binding(8) var mct_anisotropic: sampler;
// The band table (`MctBands` in crates/core/src/mct/layout.rs) as crates/render/src/mct.rs
// uploads it (`gpu_bands`): at index g · levels + l, the bands of group g at level l (x) and
// at the next level min(l + 1, last) (y), each packed as y | per_row << 16 (per_row ≥ 1;
// tent periods at level 0, strip rows above), their empty leading slots (z: l | next << 16)
// and the group's strip rows (w: log2 S | pieces << 3 | first mask << 9), so that one lookup
// gives a fragment both of its levels.
@group(0) @binding(7) var<storage, read> mct_bands: array<vec4<u32>>;

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
    // Trilinear: log2 R_b, the strip row k, the pair's index j in it and the piece starts
    // before it in the row (layout.rs `frame_of`).
    @location(3) @interpolate(flat) block: vec4<u32>,
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
fn mct_flip(record: u32) -> bool {
    return (record & 256u) != 0u;
}
fn mct_swap(record: u32) -> bool {
    return (record & 512u) != 0u;
}
fn mct_pair(record: u32) -> u32 {
    return record >> 10u;
}

// The band-table entry of group `g` at `level` (see `mct_bands`).
fn mct_bands_at(g: u32, level: u32) -> vec4<u32> {
    let levels = max(u.vertex_levels, 1u);
    return mct_bands[g * levels + min(level, levels - 1u)];
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
    let pair = mct_pair(record);
    let entry = mct_bands_at(g, 0u);
    let band = entry.x;
    let periods = f32(band >> 16u);
    let r = i32(1u << g);
    let row_col = div_rem(f32((pair >> 1u) + (entry.z & 0xffffu)), periods, 1.0 / periods);
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
// or the second face's (1, 1); p and q exchanged (swap: the tent's p is the square's q) and
// mirrored vertically when the record says so. A point of the face is texel
// `x₀ + r · square` at every level.
fn square_unit_corner(record: u32, corner: u32) -> vec2<f32> {
    var square = select(vec2<f32>(0.0), vec2<f32>(1.0), mct_second(record));
    let at_p = select(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0), mct_swap(record));
    if corner == mct_corner_p(record) {
        square = at_p;
    } else if corner == mct_corner_q(record) {
        square = at_p.yx;
    }
    if mct_flip(record) {
        square.y = 1.0 - square.y;
    }
    return square;
}

// The face's place in its group's strip rows (layout.rs `frame_of`): (strip row k, index j
// in the row, piece starts before it in the row), from its pair index and the row's mask.
fn strip_place(g: u32, pair: u32) -> vec3<u32> {
    let strips = mct_bands_at(g, 0u).w;
    let log2_row = strips & 7u;
    let k = pair >> log2_row;
    let j = pair & ((1u << log2_row) - 1u);
    // Loaded without a branch: on lavapipe a texel fetch under a branch, even a uniform
    // one, doubled the vertex stage's time. A mesh of one level has no masks; the fetch
    // is out of range there (robust access: zero or some texel) and its count unused.
    let mask = textureLoad(mct_records, data_texel(u.face_count + (strips >> 9u) + k), 0).x;
    let before = select(0u, countOneBits(mask & ((2u << j) - 2u)), u.vertex_levels > 1u);
    return vec3<u32>(k, j, before);
}

// layout.rs `frame_of` at level ≥ 1: the texel-space point of `square` in the square at
// `place` (`strip_place`) of group `g` at `level`, whose band-table words are `band` (y |
// per_row << 16), `skip` and `strips`: the square's corner, plus `square` scaled by the
// block's resolution r = max(1, R_b >> level).
fn square_point(g: u32, place: vec3<u32>, square: vec2<f32>, level: u32, band: u32, skip: u32, strips: u32) -> vec2<f32> {
    let per_row = f32(band >> 16u);
    let r = f32(1u << (g - min(level, g)));
    let width = f32(1u << (strips & 7u)) * r + f32((strips >> 3u) & 63u);
    let row_col = div_rem(f32(place.x + skip), per_row, 1.0 / per_row);
    let x = row_col.y * width + f32(place.y) * r + f32(place.z);
    return vec2<f32>(x, f32(band & 0xffffu) + row_col.x * (r + 1.0)) + r * square;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOut {
    let face = vertex_index / 3u;
    let corner = vertex_index % 3u;
    let lit = (MCT_FLAGS & (FLAG_LIT | FLAG_SMOOTH)) != 0u;
    let pulled = pull_corner_with(face, corner, LEVEL_MODE != 0u, MCT_FLAGS, lit);
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
    let place = strip_place(g, mct_pair(record));
    out.block = vec4<u32>(g, place);
    let level = select(0u, min(u.level, max(u.vertex_levels, 1u) - 1u), LEVEL_MODE == 0u);
    // Both placed and one selected: no memory read under a branch (see `strip_place`).
    let entry = mct_bands_at(g, max(level, 1u));
    let on_square = square_point(g, place, square, max(level, 1u), entry.x, entry.z & 0xffffu, entry.w);
    let point = select(tent_corner(record, corner), on_square, level > 0u);
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
    if LEVEL_MODE != 0u {
        // The level of detail of mesh colors (crates/core/src/packing/lod.rs), clamped to
        // the last level (sample.rs `sample_trilinear`); levels l0 and l1 blended, each
        // placed without a branch (level 0 is the tent's interpolated coordinate).
        let last = max(u.vertex_levels, 1u) - 1u;
        var lod = log2(max(in.lod.x, 1e-30)) + in.lod.y;
        // Anisotropic: the footprint's axes from the derivatives of the square frame (the
        // tent's at level 0 is the same up to axes and scale), as many taps as the one is
        // longer than the other (at most MCT_MAX_ANISOTROPY), the level finer by log2 of them.
        let dx = dpdx(in.uv_square.zw);
        let dy = dpdy(in.uv_square.zw);
        let dx_tent = dpdx(in.uv_square.xy);
        let dy_tent = dpdy(in.uv_square.xy);
        if LEVEL_MODE == 2u {
            let major = max(length(dx), length(dy));
            let minor = min(length(dx), length(dy));
            let taps = clamp(ceil(major / max(minor, 1e-30)), 1.0, MCT_MAX_ANISOTROPY);
            lod -= log2(select(taps, 1.0, is_nan(taps)));
        }
        lod = clamp(select(lod, 0.0, is_nan(lod)), 0.0, f32(last));
        let l0 = u32(lod);
        let t = lod - f32(l0);
        let l1 = min(l0 + 1u, last);
        let inv_size = 1.0 / vec2<f32>(textureDimensions(mct_atlas));
        let g = in.block.x;
        let place = in.block.yzw;
        let bands = mct_bands_at(g, l0);
        let s0 = (square_point(g, place, in.uv_square.zw, max(l0, 1u), bands.x, bands.z & 0xffffu, bands.w) + 0.5) * inv_size;
        let s1 = (square_point(g, place, in.uv_square.zw, max(l1, 1u), bands.y, bands.z >> 16u, bands.w) + 0.5) * inv_size;
        let c0 = textureSampleLevel(mct_atlas, mct_sampler, select(s0, in.uv_square.xy, l0 == 0u), 0.0);
        let c1 = textureSampleLevel(mct_atlas, mct_sampler, select(s1, in.uv_square.xy, l1 == 0u), 0.0);
        color = mix(c0, c1, t);
        if LEVEL_MODE == 2u {
            // The same points with the footprint scaled to each level's texels: the sampler
            // takes its taps along the long axis at the atlas's one level. Taps leave the
            // face's block where the footprint does (docs/MCT.md, anisotropic).
            let r0 = f32(1u << (g - min(l0, g))) * inv_size;
            let r1 = f32(1u << (g - min(l1, g))) * inv_size;
            let a0 = textureSampleGrad(mct_atlas, mct_anisotropic, select(s0, in.uv_square.xy, l0 == 0u), select(dx * r0, dx_tent, l0 == 0u), select(dy * r0, dy_tent, l0 == 0u));
            let a1 = textureSampleGrad(mct_atlas, mct_anisotropic, select(s1, in.uv_square.xy, l1 == 0u), select(dx * r1, dx_tent, l1 == 0u), select(dy * r1, dy_tent, l1 == 0u));
            // Where the footprint's long axis at l0 covers at most one texel the sampler
            // magnifies, which lavapipe's anisotropic filter does blockily: trilinear there.
            let magnified = max(length(dx), length(dy)) * f32(1u << (g - min(l0, g))) <= 1.0;
            color = select(mix(a0, a1, t), color, magnified);
        }
    } else {
        color = textureSampleLevel(mct_atlas, mct_sampler, in.uv_square.xy, 0.0);
    }
    return finish_fragment_with(MCT_FLAGS, color, in.shade.rgb, in.shade.w, in.light_dot, front_facing, in.bary, bary_width);
}
