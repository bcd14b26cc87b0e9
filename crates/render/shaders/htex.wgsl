// Htex (Barbier & Dupuy 2022): one square texture per edge (a halfedge and its twin),
// shelf-packed with zero borders into the pages of a 2D texture array, filtered by the
// hardware bilinear sampler with three fetches per pixel — the fragment's own quad, Next's
// and Prev's — each divided by the same three fetches of the border-normalisation texture
// (paper, Algorithm 3).
//
// Each face is drawn once; the fragment finds its intrinsic triangle (halfedge 3·face + k)
// from the interpolated barycentrics: the one opposite the smallest weight. Keep in sync
// with crates/core/src/htex/layout.rs (records, origins, weight blocks) and
// crates/core/src/htex/sample.rs (`fetch`, `sample_halfedge`, `sample_trilinear`: the CPU
// evaluation the GPU is tested against).

// 0 = fixed level `u.level` (bilinear), 1 = automatic level (trilinear), as mesh colors.
override LEVEL_MODE: u32 = 1u;
// The FLAG_* bits this pipeline draws with (crates/render/src/renderer.rs `HTEX_FLAG_BITS`).
override HTEX_FLAGS: u32 = 0u;

// Per face, 3 words (face edge k): quad | lower << 27 | log2 n << 28; then from word
// 3 · face_count the block origins, `u.vertex_levels` per quad: x | y << 13 | page << 26.
@group(0) @binding(3) var htex_records: texture_2d<u32>;
@group(0) @binding(4) var htex_pages: texture_2d_array<f32>;
@group(0) @binding(6) var htex_sampler: sampler;
// R8: per resolution 2^s, a block of ones framed by zeros at x = 2^s − 1 + 2s, y = 0.
@group(0) @binding(7) var htex_weights: texture_2d<f32>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) bary: vec3<f32>,
    // rgb: FLAG_HEATMAP's colour of log2 R; a: FLAG_LIT's dot(face normal, light).
    @location(1) @interpolate(flat) shade: vec4<f32>,
    // The face's three records.
    @location(2) @interpolate(flat) records: vec3<u32>,
    // Trilinear: view depth and the level-of-detail term μ (mesh_common.wgsl `lod_term`).
    @location(3) lod: vec2<f32>,
    @location(4) light_dot: f32,
}

fn htex_word(k: u32) -> u32 {
    return textureLoad(htex_records, data_texel(k), 0).x;
}

struct HtexFetch {
    c: vec4<f32>,
    a: f32,
}

// One fetch of the quad of `record` at intrinsic point `uv` and `level`: the bilinear colour
// (zero border) and the bilinear border-normalisation weight at the same point.
fn htex_fetch(record: u32, uv: vec2<f32>, level: u32) -> HtexFetch {
    let q = record & ((1u << 27u) - 1u);
    let lower = (record & (1u << 27u)) != 0u;
    let log2n = record >> 28u;
    let p = select(vec2<f32>(1.0) - uv, uv, lower);
    let levels = max(u.vertex_levels, 1u);
    let l = min(level, levels - 1u);
    let s = log2n - min(l, log2n);
    let n = f32(1u << s);
    let origin = htex_word(3u * u.face_count + q * levels + l);
    let o = vec2<f32>(f32(origin & 0x1fffu), f32((origin >> 13u) & 0x1fffu));
    let page = origin >> 26u;
    // Clamped to the border texels' centres: the zero border stands for CLAMP_TO_BORDER.
    let t = clamp(p * n, vec2<f32>(-0.5), vec2<f32>(n + 0.5));
    let size = vec2<f32>(textureDimensions(htex_pages).xy);
    var out: HtexFetch;
    out.c = textureSampleLevel(htex_pages, htex_sampler, (o + 1.0 + t) / size, page, 0.0);
    let wx = f32((1u << s) - 1u + 2u * s);
    let wsize = vec2<f32>(textureDimensions(htex_weights));
    out.a = textureSampleLevel(htex_weights, htex_sampler, (vec2<f32>(wx, 0.0) + 1.0 + t) / wsize, 0.0).x;
    return out;
}

// Algorithm 3 at `level`.
fn htex_sample(records: vec3<u32>, bary: vec3<f32>, level: u32) -> vec4<f32> {
    // The intrinsic triangle opposite the smallest weight m: face edge k = m + 1.
    var m = 2u;
    if bary.x <= bary.y && bary.x <= bary.z {
        m = 0u;
    } else if bary.y <= bary.z {
        m = 1u;
    }
    let k = (m + 1u) % 3u;
    let k1 = (k + 1u) % 3u;
    let k2 = (k + 2u) % 3u;
    let uv = vec2<f32>(bary[k] - bary[m], bary[k1] - bary[m]);
    let f0 = htex_fetch(records[k], uv, level);
    let f1 = htex_fetch(records[k1], vec2<f32>(uv.y, -uv.x), level);
    let f2 = htex_fetch(records[k2], vec2<f32>(-uv.y, uv.x), level);
    let a = f0.a + f1.a + f2.a;
    return select(vec4<f32>(0.0), (f0.c + f1.c + f2.c) / a, a > 0.0);
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOut {
    let face = vertex_index / 3u;
    let corner = vertex_index % 3u;
    let lit = (HTEX_FLAGS & (FLAG_LIT | FLAG_SMOOTH)) != 0u;
    let pulled = pull_corner_with(face, corner, LEVEL_MODE != 0u, HTEX_FLAGS, lit);
    let f = min(face, max(u.face_count, 1u) - 1u);
    var out: VertexOut;
    out.clip = pulled.clip;
    out.bary = pulled.bary;
    out.records = vec3<u32>(htex_word(3u * f), htex_word(3u * f + 1u), htex_word(3u * f + 2u));
    out.shade = vec4<f32>(0.0);
    if (HTEX_FLAGS & FLAG_HEATMAP) != 0u {
        let g = max(out.records.x >> 28u, max(out.records.y >> 28u, out.records.z >> 28u));
        out.shade = vec4<f32>(heat_color(g), 0.0);
    }
    out.shade.w = select(0.0, pulled.face_dot, lit);
    out.light_dot = select(0.0, pulled.light_dot, (HTEX_FLAGS & FLAG_SMOOTH) != 0u);
    out.lod = pulled.lod;
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    var bary_width = vec3<f32>(0.0);
    if (HTEX_FLAGS & FLAG_WIREFRAME) != 0u {
        bary_width = fwidth(in.bary);
    }
    var color: vec4<f32>;
    if LEVEL_MODE != 0u {
        // Mesh colors' level of detail (crates/core/src/packing/lod.rs), clamped to the last
        // level (sample.rs `sample_trilinear`); levels l0 and l0 + 1 blended.
        let last = max(u.vertex_levels, 1u) - 1u;
        var lod = log2(max(in.lod.x, 1e-30)) + in.lod.y;
        lod = clamp(select(lod, 0.0, is_nan(lod)), 0.0, f32(last));
        let l0 = u32(lod);
        let t = lod - f32(l0);
        let c0 = htex_sample(in.records, in.bary, l0);
        let c1 = htex_sample(in.records, in.bary, min(l0 + 1u, last));
        color = mix(c0, c1, t);
    } else {
        color = htex_sample(in.records, in.bary, u.level);
    }
    return finish_fragment_with(HTEX_FLAGS, color, in.shade.rgb, in.shade.w, in.light_dot, front_facing, in.bary, bary_width);
}
