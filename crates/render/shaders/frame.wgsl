// Shared by both pipelines: the per-draw uniform block, its flag bits and the wireframe
// overlay. Not a shader by itself: the renderer prepends this file to
// shaders/mesh_colors.wgsl and shaders/uv_baseline.wgsl (`concat!` in
// crates/render/src/renderer.rs, `MESH_COLORS_WGSL` / `UV_BASELINE_WGSL`), so those files use
// these names without declaring them (and cannot start with `enable` directives).

// Keep in sync with `FrameUniforms` in crates/render/src/uniforms.rs (same fields, same order,
// 176 bytes; crates/render/tests/gpu/shaders.rs compares the member offsets). The baseline reads
// clip_from_world, light, wire_color, tint (1; the baseline carries baseColorFactor per vertex), flags and wire_width.
struct FrameUniforms {
    // clip ← (world − render origin)
    clip_from_world: mat4x4<f32>,
    // xyz: unit vector towards the light (world space); w: ambient term in [0, 1].
    light: vec4<f32>,
    // Wireframe colour, linear RGBA.
    wire_color: vec4<f32>,
    // Multiplies the base colour (the baseline's glTF baseColorFactor; 1 for mesh colors).
    tint: vec4<f32>,
    // Trilinear level of detail (crates/core/src/packing/lod.rs): xyz the eye relative to the render
    // origin, w the world size of a pixel at unit depth, 2 tan(fov_y / 2) / height.
    lod_eye: vec4<f32>,
    // 0 = nearest, 1 = linear. The mesh-colors pipeline is chosen by it: the shader reads
    // the override FILTER_KIND, which the renderer sets to the same value.
    filter_kind: u32,
    // 0 = fixed level `level`, 1 = automatic level from screen-space derivatives (chosen
    // by pipeline, as filter_kind: the shader reads the override LEVEL_MODE).
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

// Bits of `FrameUniforms::flags`. Keep in sync with `FrameUniforms::FLAG_*` in
// crates/render/src/uniforms.rs (crates/render/tests/gpu/shaders.rs compares the values).
const FLAG_LIT: u32 = 1u;
const FLAG_WIREFRAME: u32 = 2u;
const FLAG_HEATMAP: u32 = 4u;
// With FLAG_LIT: smooth shading (vertex normals) instead of the face normal.
const FLAG_SMOOTH: u32 = 8u;

// The wireframe overlay: `wire_color` blended over `rgb` within about `wire_width` pixels of
// a triangle edge. `bary` are the interpolated barycentrics, `bary_width` their fwidth
// (taken in uniform control flow by the caller).
fn wireframe_overlay(
    rgb: vec3<f32>,
    bary: vec3<f32>,
    bary_width: vec3<f32>,
    wire_color: vec4<f32>,
    wire_width: f32,
) -> vec3<f32> {
    let pixels = bary / max(bary_width, vec3<f32>(1e-12));
    let edge = min(pixels.x, min(pixels.y, pixels.z));
    let coverage = clamp(0.5 * wire_width + 0.5 - edge, 0.0, 1.0);
    return mix(rgb, wire_color.rgb, coverage * wire_color.a);
}
