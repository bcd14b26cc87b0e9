// Mesh colors: vertex pulling plus a per-fragment mesh-colors lookup in the colour atlas.
//
// The vertex stage draws 3·F vertices without a vertex buffer: face = vertex_index / 3,
// corner = vertex_index % 3, positions pulled from the index and position storage
// buffers (positions are relative to the render origin, see src/render/mesh_gpu.rs).
//
// The fragment stage mirrors the CPU reference exactly — keep in sync with:
//   src/layout.rs   `sanitize_barycentric`, `linear_samples_uv`, `nearest_sample`,
//                   `edge_storage_offset`, `edge_level_offset`, `interior_level_offset`
//   src/sampler.rs  `packed_sample_index`, `sample`
// Same f32 operations in the same order, same clamping, same sub-triangle choice.
//
// The colour buffer lives in a 2D "colour atlas" texture of width `atlas_width`: sample
// `index` is texel (index % W, index / W). Rgba8 sRGB samples are decoded to linear by
// the hardware on textureLoad; 16F and 32F samples are linear already.

// Keep in sync with `FrameUniforms` in src/render/uniforms.rs (160 bytes).
struct FrameUniforms {
    // clip ← (world − render origin)
    clip_from_world: mat4x4<f32>,
    // xyz: unit vector towards the light (world space); w: ambient term in [0, 1].
    light: vec4<f32>,
    // Wireframe colour, linear RGBA.
    wire_color: vec4<f32>,
    // Multiplies the base colour (the baseline's glTF baseColorFactor; 1 for mesh colors).
    tint: vec4<f32>,
    // 0 = nearest, 1 = linear.
    filter_kind: u32,
    // 0 = fixed level `level`, 1 = automatic level from screen-space derivatives.
    level_mode: u32,
    // Fixed MIP level (clamped per face to log2 R_f).
    level: u32,
    // FLAG_* bits.
    flags: u32,
    // Atlas width W in texels.
    atlas_width: u32,
    // Samples in the colour buffer (>= 1; every index is clamped below it).
    sample_count: u32,
    // Colours per vertex (1 + log2 max R).
    vertex_levels: u32,
    // Wireframe line width in pixels.
    wire_width: f32,
    // Number of faces (face records).
    face_count: u32,
    // Number of vertices (positions).
    vertex_count: u32,
    _pad0: u32,
    _pad1: u32,
}

const FLAG_LIT: u32 = 1u;
const FLAG_WIREFRAME: u32 = 2u;
const FLAG_HEATMAP: u32 = 4u;

const LOG2_SHIFT: u32 = 28u;
const BASE_MASK: u32 = 0x0fffffffu;
const MAX_LOG2_RESOLUTION: u32 = 12u;

@group(0) @binding(0) var<uniform> u: FrameUniforms;
// x, y, z of each vertex, relative to the render origin.
@group(0) @binding(1) var<storage, read> positions: array<f32>;
// c0, c1, c2 of each face.
@group(0) @binding(2) var<storage, read> indices: array<u32>;
// Keep in sync with `FaceRecord` in src/packed.rs: (interior, edge0, edge1, edge2),
// each word `base | log2 << 28`.
@group(0) @binding(3) var<storage, read> face_records: array<vec4<u32>>;
@group(0) @binding(4) var atlas: texture_2d<f32>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) bary: vec3<f32>,
    @location(1) @interpolate(flat) face: u32,
    @location(2) @interpolate(flat) normal: vec3<f32>,
}

fn face_corners(face: u32) -> vec3<u32> {
    let f = min(face, max(u.face_count, 1u) - 1u);
    let last = max(u.vertex_count, 1u) - 1u;
    return min(vec3<u32>(indices[3u * f], indices[3u * f + 1u], indices[3u * f + 2u]), vec3<u32>(last));
}

fn load_position(v: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn is_nan(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOut {
    let face = vertex_index / 3u;
    let corner = vertex_index % 3u;
    let c = face_corners(face);
    let p0 = load_position(c.x);
    let p1 = load_position(c.y);
    let p2 = load_position(c.z);
    var p = p0;
    var bary = vec3<f32>(1.0, 0.0, 0.0);
    if corner == 1u {
        p = p1;
        bary = vec3<f32>(0.0, 1.0, 0.0);
    } else if corner == 2u {
        p = p2;
        bary = vec3<f32>(0.0, 0.0, 1.0);
    }
    // Face normal from the three positions (counter-clockwise front); a degenerate
    // face gets +Z instead of NaN.
    let n = cross(p1 - p0, p2 - p0);
    let len = length(n);
    var normal = vec3<f32>(0.0, 0.0, 1.0);
    if len > 0.0 && is_finite(len) {
        normal = n / len;
    }
    var out: VertexOut;
    out.clip = u.clip_from_world * vec4<f32>(p, 1.0);
    out.bary = bary;
    out.face = face;
    out.normal = normal;
    return out;
}

// layout::sanitize_barycentric: negatives and non-finite become 0, the rest is
// renormalised; all-zero input becomes corner 0.
fn sanitize_barycentric(b: vec3<f32>) -> vec3<f32> {
    var clean = vec3<f32>(0.0);
    for (var k = 0u; k < 3u; k++) {
        if is_finite(b[k]) && b[k] > 0.0 {
            clean[k] = b[k];
        }
    }
    let sum = clean.x + clean.y + clean.z;
    if !(is_finite(sum) && sum > 0.0) {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    return clean / sum;
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
    var uu = u_in;
    var vv = v_in;
    if is_nan(uu) {
        uu = 0.0;
    }
    if is_nan(vv) {
        vv = 0.0;
    }
    let max_index = f32(res - 1u);
    let i = u32(clamp(floor(uu), 0.0, max_index));
    let j = u32(clamp(floor(vv), 0.0, f32(res - 1u - i)));
    let fu = uu - f32(i);
    let fv = vv - f32(j);
    let upper = fu + fv > 1.0 && i + j + 2u <= res;
    var s: Samples;
    if upper {
        s.i = vec3<u32>(i + 1u, i + 1u, i);
        s.j = vec3<u32>(j + 1u, j, j + 1u);
        s.w = vec3<f32>(fu + fv - 1.0, 1.0 - fv, 1.0 - fu);
    } else {
        s.i = vec3<u32>(i, i + 1u, i);
        s.j = vec3<u32>(j, j, j + 1u);
        s.w = vec3<f32>(1.0 - fu - fv, fu, fv);
    }
    s.w = clamp(s.w, vec3<f32>(0.0), vec3<f32>(1.0));
    let sum = s.w.x + s.w.y + s.w.z;
    if sum > 0.0 {
        s.w = s.w / sum;
    } else {
        s.w.x = 1.0;
    }
    return s;
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

// Everything a face's lookups need, read once per fragment.
struct FaceInfo {
    record: vec4<u32>,
    corners: vec3<u32>,
    log2_f: u32,
}

// sampler::packed_sample_index: colour-buffer index of lattice point (i, j) of the face
// at `level` (already clamped to log2 R_f).
fn sample_index(f: FaceInfo, level: u32, i: u32, j: u32) -> u32 {
    let r = 1u << (f.log2_f - level);
    // Vertices.
    var corner = 3u;
    if i == 0u && j == 0u {
        corner = 0u;
    } else if i == r && j == 0u {
        corner = 1u;
    } else if i == 0u && j == r {
        corner = 2u;
    }
    if corner < 3u {
        let vertex = f.corners[corner];
        return vertex * u.vertex_levels + min(level, max(u.vertex_levels, 1u) - 1u);
    }
    // Edges: face edge k and position along it from its start corner.
    var k = 3u;
    var position = 0u;
    if j == 0u {
        k = 0u;
        position = i;
    } else if i + j == r {
        k = 1u;
        position = j;
    } else if i == 0u {
        k = 2u;
        position = r - j;
    }
    if k < 3u {
        let word = f.record[k + 1u];
        let base = word & BASE_MASK;
        // A valid record never has R_e < R_f; a corrupt one reads something in range.
        let log2_e = clamp(word >> LOG2_SHIFT, f.log2_f, MAX_LOG2_RESOLUTION);
        let stride_log2 = log2_e - f.log2_f;
        let r_edge_level = 1u << (log2_e - level);
        let p = position << stride_log2;
        let reversed = f.corners[k] > f.corners[(k + 1u) % 3u];
        var in_level = p - 1u;
        if reversed {
            in_level = r_edge_level - 1u - p;
        }
        return base + edge_level_offset(log2_e, level) + in_level;
    }
    // Interior (thesis eq. 3.2), row by row.
    let base = f.record.x & BASE_MASK;
    let interior = (i - 1u) * (2u * r - 2u - i) / 2u + (j - 1u);
    return base + interior_level_offset(f.log2_f, level) + interior;
}

fn load_sample(index: u32) -> vec4<f32> {
    let idx = min(index, max(u.sample_count, 1u) - 1u);
    let w = max(u.atlas_width, 1u);
    return textureLoad(atlas, vec2<u32>(idx % w, idx / w), 0);
}

// sampler::sample at one level with the uniform's filter.
fn sample_level(f: FaceInfo, bary: vec3<f32>, level_in: u32) -> vec4<f32> {
    let level = min(level_in, f.log2_f);
    let r = 1u << (f.log2_f - level);
    let res = f32(r);
    let s = linear_samples_uv(r, res * bary.y, res * bary.z);
    if u.filter_kind == 0u {
        // Nearest: the highest weight, the first one on ties.
        var best = 0u;
        if s.w.y > s.w[best] {
            best = 1u;
        }
        if s.w.z > s.w[best] {
            best = 2u;
        }
        return load_sample(sample_index(f, level, s.i[best], s.j[best]));
    }
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 3u; k++) {
        out += s.w[k] * load_sample(sample_index(f, level, s.i[k], s.j[k]));
    }
    return out;
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

// Resolution heat map: a ramp over log2 R = 0..12 (dark blue, blue, cyan, green, yellow,
// orange, magenta at 0, 2, 4, …, 12).
fn heat_color(log2_r: u32) -> vec3<f32> {
    var stops = array<vec3<f32>, 7>(
        vec3<f32>(0.10, 0.10, 0.45),
        vec3<f32>(0.15, 0.40, 0.95),
        vec3<f32>(0.00, 0.85, 0.90),
        vec3<f32>(0.20, 0.85, 0.25),
        vec3<f32>(0.98, 0.90, 0.15),
        vec3<f32>(0.98, 0.45, 0.08),
        vec3<f32>(0.90, 0.15, 0.70),
    );
    let t = f32(min(log2_r, 12u)) * 0.5;
    let k = min(u32(floor(t)), 5u);
    let c = mix(stops[k], stops[k + 1u], t - f32(k));
    return srgb_to_linear(c);
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    // Derivatives first, in uniform control flow: lattice-coordinate footprint (per unit
    // resolution) and barycentric widths for the wireframe.
    let duv_dx = dpdx(in.bary.yz);
    let duv_dy = dpdy(in.bary.yz);
    let bary_width = fwidth(in.bary);

    let face = min(in.face, max(u.face_count, 1u) - 1u);
    var f: FaceInfo;
    f.record = face_records[face];
    f.corners = face_corners(face);
    f.log2_f = min(f.record.x >> LOG2_SHIFT, MAX_LOG2_RESOLUTION);
    let bary = sanitize_barycentric(in.bary);

    var color: vec4<f32>;
    if u.level_mode == 1u {
        // Automatic level: u = R_f·w1, v = R_f·w2; lod = log2 of the larger footprint.
        let res_f = f32(1u << f.log2_f);
        let footprint = max(length(duv_dx * res_f), length(duv_dy * res_f));
        var lod = log2(footprint);
        if is_nan(lod) {
            lod = 0.0;
        }
        lod = clamp(lod, 0.0, f32(f.log2_f));
        let l0 = u32(floor(lod));
        let t = lod - f32(l0);
        color = sample_level(f, bary, l0);
        if t > 0.0 {
            color = mix(color, sample_level(f, bary, min(l0 + 1u, f.log2_f)), t);
        }
    } else {
        color = sample_level(f, bary, u.level);
    }

    var rgb = color.rgb * u.tint.rgb;
    let alpha = color.a * u.tint.a;
    if (u.flags & FLAG_HEATMAP) != 0u {
        rgb = heat_color(f.log2_f);
    }
    if (u.flags & FLAG_LIT) != 0u {
        let n = select(-in.normal, in.normal, front_facing);
        let ambient = u.light.w;
        let diffuse = max(dot(n, u.light.xyz), 0.0);
        rgb = rgb * (ambient + (1.0 - ambient) * diffuse);
    }
    if (u.flags & FLAG_WIREFRAME) != 0u {
        let pixels = in.bary / max(bary_width, vec3<f32>(1e-12));
        let edge = min(pixels.x, min(pixels.y, pixels.z));
        let coverage = clamp(0.5 * u.wire_width + 0.5 - edge, 0.0, 1.0);
        rgb = mix(rgb, u.wire_color.rgb, coverage * u.wire_color.a);
    }
    return vec4<f32>(rgb, alpha);
}
