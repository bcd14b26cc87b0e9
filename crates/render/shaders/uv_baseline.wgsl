// The UV baseline: the same mesh drawn the conventional way, with its glTF UVs and
// base-colour texture through a hardware sampler (linear, trilinear mipmaps, repeat).
// It is the reference for visual equivalence with mesh colors and the baseline every
// speed ratio is measured against, so it does the same shading work as
// shaders/mesh_colors.wgsl (lighting, wireframe) and nothing more.
//
// Vertices come from a vertex buffer, three per face (faces keep their own UVs across
// seams), positions relative to the render origin. Each corner carries its material's
// baseColorFactor (× COLOR_0), which multiplies the texel; a mesh with several materials is
// one draw per texture, untextured faces reading a 1×1 white texture.

// `FrameUniforms` (the uniform block `u`), the `FLAG_*` bits and `wireframe_overlay` are in
// shaders/frame.wgsl, which the renderer prepends to this file.

@group(0) @binding(0) var<uniform> u: FrameUniforms;
@group(0) @binding(1) var base_color: texture_2d<f32>;
@group(0) @binding(2) var base_sampler: sampler;

// Keep in sync with `BaselineVertex` in crates/render/src/baseline.rs.
struct VertexIn {
    @builtin(vertex_index) vertex_index: u32,
    @location(0) position: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) normal: vec3<f32>,
    @location(3) color: vec4<f32>,
    @location(4) corner_normal: vec3<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) bary: vec3<f32>,
    @location(2) @interpolate(flat) normal: vec3<f32>,
    @location(3) color: vec4<f32>,
    // FLAG_SMOOTH: the corner normals (vertex normals within the crease), interpolated.
    @location(4) smooth_normal: vec3<f32>,
}

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    let corner = in.vertex_index % 3u;
    var out: VertexOut;
    out.clip = u.clip_from_world * vec4<f32>(in.position, 1.0);
    out.uv = in.uv;
    out.bary = vec3<f32>(f32(corner == 0u), f32(corner == 1u), f32(corner == 2u));
    out.normal = in.normal;
    out.color = in.color;
    out.smooth_normal = in.corner_normal;
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    // Implicit derivatives (textureSample) and fwidth in uniform control flow.
    let texel = textureSample(base_color, base_sampler, in.uv);
    let bary_width = fwidth(in.bary);

    var rgb = texel.rgb * in.color.rgb * u.tint.rgb;
    let alpha = texel.a * in.color.a * u.tint.a;
    if (u.flags & FLAG_LIT) != 0u {
        var n = select(-in.normal, in.normal, front_facing);
        if (u.flags & FLAG_SMOOTH) != 0u {
            let s = normalize(in.smooth_normal);
            n = select(-s, s, front_facing);
        }
        let ambient = u.light.w;
        let diffuse = max(dot(n, u.light.xyz), 0.0);
        rgb = rgb * (ambient + (1.0 - ambient) * diffuse);
    }
    if (u.flags & FLAG_WIREFRAME) != 0u {
        rgb = wireframe_overlay(rgb, in.bary, bary_width, u.wire_color, u.wire_width);
    }
    return vec4<f32>(rgb, alpha);
}
