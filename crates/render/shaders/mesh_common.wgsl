// What both vertex-pulling pipelines share (mesh colors and Mesh Color Textures): the
// uniform block binding, the geometry data textures, the level of detail and the corner
// pulling of the vertex stage. Not a shader by itself: the renderer concatenates
// shaders/frame.wgsl, this file and shaders/mesh_colors.wgsl or shaders/mct.wgsl
// (`MESH_COLORS_WGSL` / `MCT_WGSL` in crates/render/src/renderer.rs). Keep the bindings in sync
// with crates/render/src/layouts.rs.

// Data textures: entry k is texel (k % 2^MESH_DATA_WIDTH_LOG2, k >> MESH_DATA_WIDTH_LOG2).
// Keep in sync with `MESH_DATA_WIDTH` in crates/render/src/mesh_gpu.rs.
const MESH_DATA_WIDTH_LOG2: u32 = 12u;


@group(0) @binding(0) var<uniform> u: FrameUniforms;
// (x, y, z, 0) of each vertex, relative to the render origin.
@group(0) @binding(1) var positions: texture_2d<f32>;
// (c0, c1, c2, 0) of each face.
@group(0) @binding(2) var indices: texture_2d<u32>;

// (nx, ny, nz, 0) of each vertex: the unit area-weighted normal (Rgba16Float), and the
// vertex's sample density in `positions.w` — the trilinear level of detail's inputs
// (keep in sync with `VertexLod` in crates/core/src/packing/lod.rs).
@group(0) @binding(5) var normals: texture_2d<f32>;

// Keep in sync with `MIN_COSINE` and `LOD_TERM_LIMIT` in crates/core/src/packing/lod.rs.
const LOD_MIN_COSINE: f32 = 0.0625;
const LOD_TERM_LIMIT: f32 = 64.0;


// Smooth shading's crease: a corner takes its vertex's area-weighted normal when that is
// within 45° of the face normal, else the face normal (a cube's corners, 54.7° away, stay
// sharp; the faces of a sphere blend). Keep in sync with `SMOOTH_CREASE_COSINE` in
// crates/core/src/mesh/normals.rs (crates/render/tests/gpu/shaders.rs compares them).
const SMOOTH_CREASE_COSINE: f32 = 0.70710677;

fn data_texel(k: u32) -> vec2<u32> {
    return vec2<u32>(k & ((1u << MESH_DATA_WIDTH_LOG2) - 1u), k >> MESH_DATA_WIDTH_LOG2);
}

fn face_corners(face: u32) -> vec3<u32> {
    let f = min(face, max(u.face_count, 1u) - 1u);
    let last = max(u.vertex_count, 1u) - 1u;
    return min(textureLoad(indices, data_texel(f), 0).xyz, vec3<u32>(last));
}

// The per-vertex term μ of the level of detail (crates/core/src/packing/lod.rs): log2 of the pixel's
// footprint at unit depth, stretched by 1 / |n · v̂| on surfaces seen at a grazing angle,
// in samples (times the vertex's sample density), clamped to ±LOD_TERM_LIMIT.
fn lod_term(v: u32, p: vec3<f32>) -> f32 {
    let density = textureLoad(positions, data_texel(v), 0).w;
    let n = textureLoad(normals, data_texel(v), 0).xyz;
    let to_eye = u.lod_eye.xyz - p;
    let distance = length(to_eye);
    let cosine = select(0.0, abs(dot(n, to_eye)) / distance, distance > 0.0);
    let term = log2(u.lod_eye.w * density / max(cosine, LOD_MIN_COSINE));
    return clamp(select(term, -LOD_TERM_LIMIT, is_nan(term)), -LOD_TERM_LIMIT, LOD_TERM_LIMIT);
}

fn load_position(v: u32) -> vec3<f32> {
    return textureLoad(positions, data_texel(v), 0).xyz;
}

fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn is_nan(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

// Resolution heat map: a ramp over log2 R = 0..12 (dark blue, blue, cyan, green, yellow,
// orange, magenta at 0, 2, 4, …, 12, mixed in sRGB), tabulated in linear RGB.
fn heat_color(log2_r: u32) -> vec3<f32> {
    var table = array<vec3<f32>, 13>(
        vec3<f32>(0.0100228, 0.0100228, 0.1706449),
        vec3<f32>(0.0143499, 0.0508761, 0.4479884),
        vec3<f32>(0.0196066, 0.1328683, 0.8900055),
        vec3<f32>(0.0065714, 0.3485102, 0.8377929),
        vec3<f32>(0.0000000, 0.6920712, 0.7874123),
        vec3<f32>(0.0100228, 0.6920712, 0.2901425),
        vec3<f32>(0.0331048, 0.6920712, 0.0508761),
        vec3<f32>(0.3069994, 0.7388448, 0.0331048),
        vec3<f32>(0.9551046, 0.7874123, 0.0196066),
        vec3<f32>(0.9551046, 0.4132082, 0.0125104),
        vec3<f32>(0.9551046, 0.1706449, 0.0071944),
        vec3<f32>(0.8688995, 0.0732390, 0.1259674),
        vec3<f32>(0.7874123, 0.0196066, 0.4479884),
    );
    return table[min(log2_r, 12u)];
}

// One corner of a face as the vertex stage pulls it: the face's vertex ids, the corner's
// position and clip position, its barycentric unit vector, the level-of-detail varyings
// (view depth, μ; zero unless `with_lod`), dot(face normal, light) and the smooth-shading light term.
struct PulledCorner {
    corners: vec3<u32>,
    vertex: u32,
    p: vec3<f32>,
    clip: vec4<f32>,
    bary: vec3<f32>,
    lod: vec2<f32>,
    face_dot: f32,
    light_dot: f32,
}

fn pull_corner(face: u32, corner: u32, with_lod: bool) -> PulledCorner {
    return pull_corner_with(face, corner, with_lod, u.flags, true);
}

// `pull_corner` for the FLAG_* bits `flags` (the uniform's, or a pipeline's constant, which
// removes the code of every disabled feature: software rasterisers run both sides of a
// branch). Without `with_face_normal` only the corner's own position is read and
// `face_dot` is that of +Z.
fn pull_corner_with(face: u32, corner: u32, with_lod: bool, flags: u32, with_face_normal: bool) -> PulledCorner {
    var out: PulledCorner;
    let c = face_corners(face);
    let v = select(select(c.x, c.y, corner == 1u), c.z, corner == 2u);
    let bary = vec3<f32>(f32(corner == 0u), f32(corner == 1u), f32(corner == 2u));
    var p: vec3<f32>;
    var normal = vec3<f32>(0.0, 0.0, 1.0);
    if with_face_normal {
        let p0 = load_position(c.x);
        let p1 = load_position(c.y);
        let p2 = load_position(c.z);
        p = select(select(p0, p1, corner == 1u), p2, corner == 2u);
        // Face normal from the three positions (counter-clockwise front); a degenerate
        // face gets +Z instead of NaN.
        let n = cross(p1 - p0, p2 - p0);
        let len = length(n);
        if len > 0.0 && is_finite(len) {
            normal = n / len;
        }
    } else {
        p = load_position(v);
    }
    out.corners = c;
    out.vertex = v;
    out.p = p;
    out.clip = u.clip_from_world * vec4<f32>(p, 1.0);
    out.bary = bary;
    out.lod = vec2<f32>(0.0);
    if with_lod {
        out.lod = vec2<f32>(out.clip.w, lod_term(v, p));
    }
    // The fragment stage flips the sign for back faces: dot(−n, l) = −dot(n, l) exactly.
    out.face_dot = dot(normal, u.light.xyz);
    out.light_dot = out.face_dot;
    if (flags & FLAG_SMOOTH) != 0u {
        // The vertex normal is stored in f16; it is renormalised here. A face wound against
        // its neighbours (mixed winding) sees it more than 45° away and stays flat.
        let vn = textureLoad(normals, data_texel(v), 0).xyz;
        let vn_len = length(vn);
        if vn_len > 0.0 && dot(vn, normal) >= SMOOTH_CREASE_COSINE * vn_len {
            out.light_dot = dot(vn / vn_len, u.light.xyz);
        }
    }
    return out;
}

// Lighting and overlays of a fragment's filtered colour (both pipelines).
fn finish_fragment(
    color: vec4<f32>,
    heat: vec3<f32>,
    face_dot: f32,
    light_dot: f32,
    front_facing: bool,
    bary: vec3<f32>,
    bary_width: vec3<f32>,
) -> vec4<f32> {
    return finish_fragment_with(u.flags, color, heat, face_dot, light_dot, front_facing, bary, bary_width);
}

// `finish_fragment` for the FLAG_* bits `flags` (see `pull_corner_with`).
fn finish_fragment_with(
    flags: u32,
    color: vec4<f32>,
    heat: vec3<f32>,
    face_dot: f32,
    light_dot: f32,
    front_facing: bool,
    bary: vec3<f32>,
    bary_width: vec3<f32>,
) -> vec4<f32> {
    var rgb = color.rgb * u.tint.rgb;
    let alpha = color.a * u.tint.a;
    if (flags & FLAG_HEATMAP) != 0u {
        rgb = heat;
    }
    if (flags & FLAG_LIT) != 0u {
        let ambient = u.light.w;
        let d = select(face_dot, light_dot, (flags & FLAG_SMOOTH) != 0u);
        let diffuse = max(select(-d, d, front_facing), 0.0);
        rgb = rgb * (ambient + (1.0 - ambient) * diffuse);
    }
    if (flags & FLAG_WIREFRAME) != 0u {
        rgb = wireframe_overlay(rgb, bary, bary_width, u.wire_color, u.wire_width);
    }
    return vec4<f32>(rgb, alpha);
}
