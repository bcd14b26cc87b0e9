// Mesh colors: vertex pulling plus a per-fragment mesh-colors lookup in the colour atlas.
//
// The vertex stage draws 3·F vertices without a vertex buffer: face = vertex_index / 3,
// corner = vertex_index % 3, vertex ids and positions pulled from RGBA32 data textures
// (one texel fetch per entry; positions are relative to the render origin, see
// crates/render/src/mesh_gpu.rs). It also reads the face record and decodes everything per face
// the fragment stage needs into flat varyings, so a fragment's only memory accesses are
// the atlas texels of its samples.
//
// The fragment stage mirrors the CPU reference exactly — keep in sync with:
//   crates/core/src/colors/layout.rs   `sanitize_barycentric`, `linear_samples_uv`, `nearest_sample`,
//                   `edge_storage_offset`, `edge_level_offset`, `interior_level_offset`
//   crates/core/src/packing/sampler.rs  `packed_sample_index`, `sample`
// Same f32 operations in the same order, same clamping, same sub-triangle choice; the
// integer addressing is the same arithmetic rearranged (branch-free, u32 wrapping, exact).
//
// Performance notes (software rasterisers such as lavapipe run fragments as SIMD lanes
// and execute both sides of every `if` under a mask): the filter and level mode are
// pipeline-overridable constants (`FILTER_KIND`, `LEVEL_MODE`), one pipeline each, so a
// fragment runs only its own filter's code; lattice-point classification uses `select`
// instead of branches; level offsets are computed once per face (fixed level, in the
// vertex stage) or once per fragment and level (automatic level), never per sample.
//
// The colour buffer lives in a 2D "colour atlas" texture of width `atlas_width`: sample
// `index` is texel (index % W, index / W). Rgba8 sRGB samples are decoded to linear by
// the hardware on textureLoad; 16F and 32F samples are linear already.

// `FrameUniforms`, the `FLAG_*` bits and `wireframe_overlay` are in shaders/frame.wgsl; the
// uniform block `u`, the geometry data textures, the level of detail, `pull_corner` and
// `finish_fragment` in shaders/mesh_common.wgsl. The renderer prepends both to this file.

// Pipeline constants, set by the renderer from `FilterMode::uniform_fields` (keep in sync
// with `MESH_PIPELINE_KEYS` in crates/render/src/renderer.rs): 0 = nearest, 1 = linear.
override FILTER_KIND: u32 = 1u;
// 0 = fixed level `u.level`, 1 = automatic level (trilinear).
override LEVEL_MODE: u32 = 1u;

const LOG2_SHIFT: u32 = 28u;
const BASE_MASK: u32 = 0x0fffffffu;
const MAX_LOG2_RESOLUTION: u32 = 12u;

// Keep in sync with `FaceRecord` in src/packed.rs: (interior, edge0, edge1, edge2),
// each word `base | log2 << 28`.
@group(0) @binding(3) var face_records: texture_2d<u32>;
@group(0) @binding(4) var atlas: texture_2d<f32>;
// Per-face addressing at one requested MIP level L: the colour-buffer index of every
// lattice point (i, j) of resolution `r` follows from these (see `sample_index`). Every
// shared element is read at a level that does not depend on the face reading it
// (sampler.rs module docs): the face lattice at min(L, log2 R_f), vertices at
// min(L, vertex_levels − 1), edge k at min(L, log2 R_e).
struct LevelData {
    // Resolution of the face's lattice, R_f >> min(L, log2 R_f).
    r: u32,
    // Colour index of corner c's vertex sample at min(L, vertex_levels − 1).
    vertex: vec3<u32>,
    // Face edge k at its level: the lattice point at position p (1..r-1 from the edge's
    // start corner) is edge_start[k] + p · edge_step[k] (u32 wrapping; edge_step is
    // −stride when the face walks the edge against its canonical direction), the edge's
    // own sample at position p_e (1..r·stride − 1) is edge_start[k] ± p_e.
    edge_start: vec3<u32>,
    edge_step: vec3<u32>,
    // r_e / r of each face edge at this level (> 1: a fine side, the seam rule applies).
    stride: vec3<u32>,
    // Colour index of interior offset 0 at this level.
    interior: u32,
}

// Per-face data that does not depend on the level (automatic level of detail).
struct FaceData {
    log2_f: u32,
    // Vertex id · vertex_levels of each corner.
    vertex_base: vec3<u32>,
    edge_base: vec3<u32>,
    // log2 R_e of each face edge, clamped to [log2 R_f, MAX_LOG2_RESOLUTION].
    edge_log2: vec3<u32>,
    // Whether face edge k runs against its canonical direction (lower → higher vertex id).
    reversed: vec3<bool>,
    interior_base: u32,
}

// Few varyings: a software rasteriser sets up and stores every one per vertex/triangle.
struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) bary: vec3<f32>,
    // rgb: the face's heat-map colour (linear); a: dot(face normal, light direction).
    @location(1) @interpolate(flat) shade: vec4<f32>,
    // LEVEL_MODE 0: `LevelData` at the face's fixed level; 1: `FaceData` (see pack_*).
    @location(2) @interpolate(flat) face0: vec4<u32>,
    @location(3) @interpolate(flat) face1: vec4<u32>,
    // LEVEL_MODE 1: (view depth, μ) of the level of detail (crates/core/src/packing/lod.rs), interpolated
    // perspective-correctly, so lod = log2(depth) + μ is one function over the mesh.
    @location(4) lod: vec2<f32>,
    // FLAG_SMOOTH: dot(corner normal, light direction), interpolated (Gouraud).
    @location(5) light_dot: f32,
}

// layout::edge_level_offset: 2R − 2(R >> level) − level.
fn edge_level_offset(log2_r: u32, level: u32) -> u32 {
    return 2u * (1u << log2_r) - 2u * (1u << (log2_r - level)) - level;
}

// layout::interior_level_offset (thesis eq. 3.4b, closed form), m = log2 R, l = level.
fn interior_level_offset(m: u32, l: u32) -> u32 {
    let squares = ((1u << (2u * m + 1u)) - (1u << (2u * (m - l) + 1u))) / 3u;
    let linear = 3u * ((1u << m) - (1u << (m - l)));
    return squares + l - linear;
}

// Decodes the face record and corners of `face` (sampler::packed_sample_index's inputs).
fn face_data(face: u32, corners: vec3<u32>) -> FaceData {
    let record = textureLoad(face_records, data_texel(min(face, max(u.face_count, 1u) - 1u)), 0);
    var f: FaceData;
    f.log2_f = min(record.x >> LOG2_SHIFT, MAX_LOG2_RESOLUTION);
    f.vertex_base = corners * u.vertex_levels;
    let edges = record.yzw;
    f.edge_base = edges & vec3<u32>(BASE_MASK);
    // A valid record never has R_e < R_f; a corrupt one reads something in range.
    f.edge_log2 = clamp(edges >> vec3<u32>(LOG2_SHIFT), vec3<u32>(f.log2_f), vec3<u32>(MAX_LOG2_RESOLUTION));
    f.reversed = corners > corners.yzx;
    f.interior_base = record.x & BASE_MASK;
    return f;
}

// The addressing of face `f` at requested level `requested` (any value),
// sampler::packed_sample_index / packed_edge_index with everything that does not depend on
// (i, j) folded into start values.
fn level_data(f: FaceData, requested: u32) -> LevelData {
    var d: LevelData;
    let level = min(requested, f.log2_f);
    d.r = 1u << (f.log2_f - level);
    d.vertex = f.vertex_base + vec3<u32>(min(requested, max(u.vertex_levels, 1u) - 1u));
    for (var k = 0u; k < 3u; k++) {
        let log2_e = f.edge_log2[k];
        let edge_level = min(requested, log2_e);
        // r_e / r = 2^((log2 R_e − edge level) − (log2 R_f − face level)); equal to
        // R_e / R_f whenever the lattice has edge points (r >= 2, both levels = requested).
        let stride = 1u << ((log2_e - edge_level) - (f.log2_f - level));
        let r_edge_level = 1u << (log2_e - edge_level);
        let start = f.edge_base[k] + edge_level_offset(log2_e, edge_level);
        // Storage offset p·stride − 1 forwards, r_edge_level − 1 − p·stride reversed.
        d.edge_start[k] = select(start - 1u, start + r_edge_level - 1u, f.reversed[k]);
        d.edge_step[k] = select(stride, 0u - stride, f.reversed[k]);
        d.stride[k] = stride;
    }
    d.interior = f.interior_base + interior_level_offset(f.log2_f, level);
    return d;
}

// Flat-varying encodings of LevelData and FaceData (two vec4<u32>). Bit fields of the
// first word: LevelData: r (bits 0..12), log2 of edge k's stride (13 + 4k), edge k
// reversed (25 + k); FaceData: log2 R_f (0..3), log2 R_e of edge k (4 + 4k), edge k
// reversed (16 + k).
fn reversed_bits(reversed: vec3<bool>, shift: u32) -> u32 {
    let bits = select(vec3<u32>(0u), vec3<u32>(1u, 2u, 4u), reversed);
    return (bits.x | bits.y | bits.z) << shift;
}

fn pack_level(f: FaceData, d: LevelData) -> array<vec4<u32>, 2> {
    let s = countTrailingZeros(d.stride);
    let bits = d.r | (s.x << 13u) | (s.y << 17u) | (s.z << 21u) | reversed_bits(f.reversed, 25u);
    return array<vec4<u32>, 2>(vec4<u32>(bits, d.vertex), vec4<u32>(d.edge_start, d.interior));
}

fn unpack_level(a: vec4<u32>, b: vec4<u32>) -> LevelData {
    var d: LevelData;
    d.r = a.x & 0x1fffu;
    d.vertex = a.yzw;
    d.edge_start = b.xyz;
    d.interior = b.w;
    let stride = vec3<u32>(1u) << ((vec3<u32>(a.x) >> vec3<u32>(13u, 17u, 21u)) & vec3<u32>(15u));
    let reversed = (vec3<u32>(a.x) & vec3<u32>(1u << 25u, 1u << 26u, 1u << 27u)) != vec3<u32>(0u);
    d.edge_step = select(stride, vec3<u32>(0u) - stride, reversed);
    d.stride = stride;
    return d;
}

fn pack_face(f: FaceData) -> array<vec4<u32>, 2> {
    let bits = f.log2_f | (f.edge_log2.x << 4u) | (f.edge_log2.y << 8u) | (f.edge_log2.z << 12u)
        | reversed_bits(f.reversed, 16u);
    return array<vec4<u32>, 2>(vec4<u32>(bits, f.vertex_base), vec4<u32>(f.edge_base, f.interior_base));
}

fn unpack_face(a: vec4<u32>, b: vec4<u32>) -> FaceData {
    var f: FaceData;
    f.log2_f = a.x & 15u;
    f.edge_log2 = (vec3<u32>(a.x) >> vec3<u32>(4u, 8u, 12u)) & vec3<u32>(15u);
    f.reversed = ((vec3<u32>(a.x) >> vec3<u32>(16u, 17u, 18u)) & vec3<u32>(1u)) != vec3<u32>(0u);
    f.vertex_base = a.yzw;
    f.edge_base = b.xyz;
    f.interior_base = b.w;
    return f;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOut {
    let face = vertex_index / 3u;
    let corner = vertex_index % 3u;
    let pulled = pull_corner(face, corner, LEVEL_MODE == 1u);
    let c = pulled.corners;
    let f = face_data(face, c);
    var packed: array<vec4<u32>, 2>;
    if LEVEL_MODE == 1u {
        packed = pack_face(f);
    } else {
        packed = pack_level(f, level_data(f, u.level));
    }
    var out: VertexOut;
    out.clip = pulled.clip;
    out.bary = pulled.bary;
    out.lod = pulled.lod;
    out.shade = vec4<f32>(heat_color(f.log2_f), pulled.face_dot);
    out.light_dot = pulled.light_dot;
    out.face0 = packed[0];
    out.face1 = packed[1];
    return out;
}

// layout::sanitize_barycentric: negatives and non-finite become 0, the rest is
// renormalised; all-zero input becomes corner 0.
fn sanitize_barycentric(b: vec3<f32>) -> vec3<f32> {
    let finite = (bitcast<vec3<u32>>(b) & vec3<u32>(0x7f800000u)) != vec3<u32>(0x7f800000u);
    let clean = select(vec3<f32>(0.0), b, finite & (b > vec3<f32>(0.0)));
    let sum = clean.x + clean.y + clean.z;
    return select(vec3<f32>(1.0, 0.0, 0.0), clean / sum, is_finite(sum) && sum > 0.0);
}

// Three lattice samples (i, j) with weights (layout::linear_samples_uv).
struct Samples {
    i: vec3<u32>,
    j: vec3<u32>,
    w: vec3<f32>,
}

// layout::linear_samples_uv: the sub-triangle containing (u, v) in lattice units of
// resolution `res`, clamped onto the lattice, weights clamped and renormalised.
fn linear_samples_uv(res: u32, u_in: f32, v_in: f32) -> Samples {
    let uu = select(u_in, 0.0, is_nan(u_in));
    let vv = select(v_in, 0.0, is_nan(v_in));
    let max_index = f32(res - 1u);
    let i = u32(clamp(floor(uu), 0.0, max_index));
    let j = u32(clamp(floor(vv), 0.0, f32(res - 1u - i)));
    let fu = uu - f32(i);
    let fv = vv - f32(j);
    let upper = fu + fv > 1.0 && i + j + 2u <= res;
    var s: Samples;
    s.i = select(vec3<u32>(i, i + 1u, i), vec3<u32>(i + 1u, i + 1u, i), upper);
    s.j = select(vec3<u32>(j, j, j + 1u), vec3<u32>(j + 1u, j, j + 1u), upper);
    let w = select(vec3<f32>(1.0 - fu - fv, fu, fv), vec3<f32>(fu + fv - 1.0, 1.0 - fv, 1.0 - fu), upper);
    let clamped = clamp(w, vec3<f32>(0.0), vec3<f32>(1.0));
    let sum = clamped.x + clamped.y + clamped.z;
    s.w = select(vec3<f32>(1.0, clamped.y, clamped.z), clamped / sum, sum > 0.0);
    return s;
}

// sampler::packed_sample_index for lattice point (i, j) (inside the lattice of d.r):
// vertices first, then face edges 0, 1, 2, then the interior (thesis eq. 3.2), as
// layout::classify_sample — written as selects, later ones taking precedence.
fn sample_index(d: LevelData, i: u32, j: u32) -> u32 {
    let r = d.r;
    var index = d.interior + (i - 1u) * (2u * r - 2u - i) / 2u + (j - 1u);
    index = select(index, d.edge_start.z + (r - j) * d.edge_step.z, i == 0u);
    index = select(index, d.edge_start.y + j * d.edge_step.y, i + j == r);
    index = select(index, d.edge_start.x + i * d.edge_step.x, j == 0u);
    // i + j <= r, so i == r means (r, 0) and j == r means (0, r).
    index = select(index, d.vertex.z, j == r);
    index = select(index, d.vertex.y, i == r);
    index = select(index, d.vertex.x, (i | j) == 0u);
    return index;
}

// Texel of colour index `index` (clamped below sample_count): (index % W, index / W),
// computed without an integer division (which SIMD rasterisers run lane by lane).
// Exact while the quotient (the atlas row) is below 2^16 and W <= 2^16, even with a
// reciprocal good to only 2^-10: the float estimate of the quotient is then off by at
// most 64, one float step on the exact remainder brings it within one, and the final
// compares fix that.
fn atlas_texel(index: u32) -> vec2<u32> {
    let idx = min(index, max(u.sample_count, 1u) - 1u);
    let w = max(u.atlas_width, 1u);
    let inv_w = 1.0 / f32(w);
    let q0 = u32(f32(idx) * inv_w);
    let r0 = i32(idx - q0 * w);
    let q1 = u32(i32(q0) + i32(floor(f32(r0) * inv_w)));
    let r1 = i32(idx - q1 * w);
    let below = r1 < 0;
    let above = r1 >= i32(w);
    let x = select(select(r1, r1 - i32(w), above), r1 + i32(w), below);
    let y = select(select(q1, q1 + 1u, above), q1 - 1u, below);
    return vec2<u32>(u32(x), y);
}

fn load_sample(index: u32) -> vec4<f32> {
    return textureLoad(atlas, atlas_texel(index), 0);
}

// sampler::sample at one level with the pipeline's filter; `bary` is sanitised.
fn sample_level(d: LevelData, bary: vec3<f32>) -> vec4<f32> {
    let res = f32(d.r);
    let s = linear_samples_uv(d.r, res * bary.y, res * bary.z);
    if FILTER_KIND == 0u {
        // Nearest: the highest weight, the first one on ties.
        let pick1 = s.w.y > s.w.x;
        let best_w = select(s.w.x, s.w.y, pick1);
        let pick2 = s.w.z > best_w;
        let i = select(select(s.i.x, s.i.y, pick1), s.i.z, pick2);
        let j = select(select(s.j.x, s.j.y, pick1), s.j.z, pick2);
        return load_sample(sample_index(d, i, j));
    }
    let ca = load_sample(sample_index(d, s.i.x, s.j.x));
    let cb = load_sample(sample_index(d, s.i.y, s.j.y));
    let cc = load_sample(sample_index(d, s.i.z, s.j.z));
    // sampler::sample_linear: only a "lower" sub-triangle (listed (i,j), (i+1,j), (i,j+1))
    // has sides on the face's boundary; a side on an edge with r_e > r is a fine side.
    let i = s.i.x;
    let j = s.j.x;
    let lower = s.j.x == s.j.y;
    let on_side = vec3<bool>(lower && j == 0u, lower && i + j + 1u == d.r, lower && i == 0u);
    let fine = on_side & (d.stride > vec3<u32>(1u));
    if !any(fine) {
        // No fine side: eq. 2.4 as before the seam rule.
        var out = vec4<f32>(0.0);
        out += s.w.x * ca;
        out += s.w.y * cb;
        out += s.w.z * cc;
        return out;
    }
    return seam_fan(d, s, ca, cb, cc, fine);
}

// Colour index of the edge's own sample at position p (1..r_e − 1, from the face edge's
// start corner) of face edge k at its level (sampler::packed_edge_index).
fn edge_index(d: LevelData, k: u32, p: u32) -> u32 {
    let unit = select(0u - 1u, 1u, d.edge_step[k] == d.stride[k]);
    return d.edge_start[k] + p * unit;
}

// sampler::sample_linear's seam rule: the sub-triangle fanned from its centroid G; the
// point lies in the sector of the side opposite its smallest weight; the colour is
// γ·G + (1 − γ)·E(t), E the side's own edge samples interpolated (fine side) or the
// lerp of the side's two corners.
fn seam_fan(d: LevelData, s: Samples, ca: vec4<f32>, cb: vec4<f32>, cc: vec4<f32>, fine: vec3<bool>) -> vec4<f32> {
    let a = s.w.x;
    let b = s.w.y;
    let c = s.w.z;
    var k = 0u;
    var gamma = 3.0 * c;
    var num = b - c;
    var start_color = ca;
    var end_color = cb;
    var q = s.i.x;
    if !(c <= a && c <= b) {
        if a <= b {
            k = 1u;
            gamma = 3.0 * a;
            num = c - a;
            start_color = cb;
            end_color = cc;
            q = s.j.x;
        } else {
            k = 2u;
            gamma = 3.0 * b;
            num = a - b;
            start_color = cc;
            end_color = ca;
            q = d.r - s.j.x - 1u;
        }
    }
    let den = 1.0 - gamma;
    let t = select(0.0, clamp(num / den, 0.0, 1.0), den > 0.0);
    var e0 = start_color;
    var e1 = end_color;
    var f = t;
    if fine[k] {
        let m = d.stride[k];
        let x = t * f32(m);
        let n = u32(clamp(floor(x), 0.0, f32(m - 1u)));
        f = x - f32(n);
        let p0 = q * m + n;
        e0 = select(load_sample(edge_index(d, k, p0)), start_color, n == 0u);
        e1 = select(load_sample(edge_index(d, k, p0 + 1u)), end_color, n + 1u == m);
    }
    let centroid = (ca + cb + cc) / 3.0;
    let edge = (1.0 - f) * e0 + f * e1;
    return gamma * centroid + (1.0 - gamma) * edge;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    // Barycentric widths for the wireframe, in uniform control flow.
    let bary_width = fwidth(in.bary);
    let bary = sanitize_barycentric(in.bary);

    var color: vec4<f32>;
    if LEVEL_MODE == 1u {
        // Automatic level, continuous over the mesh (crates/core/src/packing/lod.rs):
        // lod = log2(view depth) + μ, both interpolated from the face's vertices.
        let f = unpack_face(in.face0, in.face1);
        var lod = log2(max(in.lod.x, 1e-30)) + in.lod.y;
        lod = select(lod, 0.0, is_nan(lod));
        // Clamped to the mesh's last level (vertex_levels − 1, = log2 R_f on uniform
        // meshes): past its own last level a face keeps blending its vertices' coarser
        // levels, as its finer neighbours do (sampler::sample_trilinear).
        let last = max(u.vertex_levels, 1u) - 1u;
        lod = clamp(lod, 0.0, f32(last));
        let l0 = u32(floor(lod));
        let t = lod - f32(l0);
        let c0 = sample_level(level_data(f, l0), bary);
        let c1 = sample_level(level_data(f, min(l0 + 1u, last)), bary);
        color = select(c0, mix(c0, c1, t), t > 0.0);
    } else {
        color = sample_level(unpack_level(in.face0, in.face1), bary);
    }

    return finish_fragment(color, in.shade.rgb, in.shade.w, in.light_dot, front_facing, in.bary, bary_width);
}
