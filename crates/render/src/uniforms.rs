//! Uniform blocks shared with the WGSL shaders.

use bytemuck::{Pod, Zeroable};

/// Per-draw uniforms of both pipelines.
///
/// Keep in sync with `struct FrameUniforms` in shaders/frame.wgsl, which both shaders
/// include (same field names, same order, 176 bytes; crates/render/tests/gpu/shaders.rs compares every
/// member's offset with [`std::mem::offset_of!`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    /// Column-major `clip ← (world − render origin)`.
    pub clip_from_world: [[f32; 4]; 4],
    /// xyz: unit vector towards the light (world space); w: ambient term in `[0, 1]`.
    pub light: [f32; 4],
    /// Wireframe colour, linear RGBA (alpha = line opacity).
    pub wire_color: [f32; 4],
    /// Multiplies the base colour (1 for both pipelines; the baseline's `baseColorFactor` is per vertex).
    pub tint: [f32; 4],
    /// Trilinear level of detail (crates/core/src/packing/lod.rs): xyz the camera's eye relative to the
    /// render origin, w `κ = 2 tan(fov_y / 2) / height`, the world size of a pixel at unit depth.
    pub lod_eye: [f32; 4],
    /// Reconstruction filter: [`FrameUniforms::FILTER_NEAREST`] or [`FrameUniforms::FILTER_LINEAR`].
    pub filter_kind: u32,
    /// [`FrameUniforms::LEVEL_FIXED`] or [`FrameUniforms::LEVEL_AUTO`] (trilinear).
    pub level_mode: u32,
    /// The fixed MIP level (clamped per face to `log2 R_f` in the shader).
    pub level: u32,
    /// `FLAG_*` bits.
    pub flags: u32,
    /// Colour-atlas width `W`: sample `index` is texel `(index % W, index / W)`.
    pub atlas_width: u32,
    /// Samples in the colour buffer (at least 1: shaders clamp every index below it).
    pub sample_count: u32,
    /// Colours per vertex in the colour buffer (`1 + log2 max R`).
    pub vertex_levels: u32,
    /// Wireframe line width in pixels.
    pub wire_width: f32,
    /// Number of faces.
    pub face_count: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Padding to a multiple of 16 bytes (`_pad0`, `_pad1` as in the WGSL struct: uniform
    /// arrays need a 16-byte stride there).
    pub _pad0: u32,
    /// See [`FrameUniforms::_pad0`].
    pub _pad1: u32,
}

const _: () = assert!(std::mem::size_of::<FrameUniforms>() == 176);

impl FrameUniforms {
    /// Nearest-sample reconstruction.
    pub const FILTER_NEAREST: u32 = 0;
    /// Linear (three-sample) reconstruction.
    pub const FILTER_LINEAR: u32 = 1;
    /// Sample the fixed level [`FrameUniforms::level`].
    pub const LEVEL_FIXED: u32 = 0;
    /// Choose the level per pixel (continuous over the mesh, crates/core/src/packing/lod.rs), blend two levels.
    pub const LEVEL_AUTO: u32 = 1;
    /// Lambert + ambient shading with the face normal. The `FLAG_*` bits: keep in sync with
    /// the `FLAG_*` constants in shaders/frame.wgsl (crates/render/tests/gpu/shaders.rs compares them).
    pub const FLAG_LIT: u32 = 1;
    /// Wireframe overlay.
    pub const FLAG_WIREFRAME: u32 = 2;
    /// Per-face resolution heat map instead of the painted colour.
    pub const FLAG_HEATMAP: u32 = 4;
    /// With [`FrameUniforms::FLAG_LIT`]: smooth normals (meshpaint_core::mesh::normals) instead of the face normal.
    pub const FLAG_SMOOTH: u32 = 8;
}
