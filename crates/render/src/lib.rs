//! The GPU renderer: wgpu context, packed mesh colors on the GPU, sampling pipelines,
//! the UV-texture baseline, offscreen targets and readback.
//!
//! # Design
//!
//! - **Vertex pulling.** The mesh-colors pipeline has no vertex buffer: it draws `3·F`
//!   vertices; the vertex shader takes `face = vertex_index / 3`, `corner = vertex_index % 3`
//!   and reads the corner's vertex id, its position and the face record from RGBA32 data
//!   textures (4096 texels wide; on lavapipe a texel fetch is cheaper than a storage-buffer
//!   load, and textures lift the 128 MiB binding limit). It decodes everything per-face once
//!   and passes it to the fragment shader as flat varyings, with the barycentrics
//!   `(1,0,0)`, `(0,1,0)`, `(0,0,1)` interpolated perspective-correct, so a fragment reads
//!   only colour-atlas texels. No `primitive_index` feature is needed: it runs on every
//!   backend. Filter and level mode are pipeline constants (one pipeline per mode): a CPU
//!   rasteriser executes both sides of a branch, so one uber-shader paid for every filter.
//! - **Colour atlas.** The colour buffer (all samples with their MIP chains) is a 2D
//!   texture of width `W` used as an array: sample `index` is texel `(index % W, index / W)`.
//!   One storage binding is limited to 128 MiB on lavapipe and WebGPU defaults while a
//!   16384² atlas holds `2^28` samples, exactly [`meshpaint_core::packing::linear::MAX_SAMPLES`]. RGBA8 sRGB
//!   samples go into an `Rgba8UnormSrgb` texture, so `textureLoad` returns linear colour.
//! - **Render origin.** Positions are uploaded relative to the mesh's bounding-sphere
//!   centre, subtracted in `f64` on the CPU, and the camera matrix is built relative to
//!   the same origin ([`meshpaint_core::camera::OrbitCamera::clip_from_world_relative`]): a mesh at
//!   `1e6` renders without jitter.
//! - **Exactness.** `shaders/mesh_colors.wgsl` mirrors [`meshpaint_core::packing::sampler::packed_sample_index`]
//!   and [`meshpaint_core::colors::layout::linear_samples_uv`] operation for operation; `tests/app/gpu_render.rs`
//!   compares GPU pixels with [`meshpaint_core::packing::sampler::sample`].
//! - **Colour.** Samples are linear; shaders output linear colour into an `Rgba8UnormSrgb`
//!   target (or an sRGB view of a window surface), which encodes it.
//!
//! The renderer is target-agnostic: [`Renderer::draw`] records into any colour view of the
//! format the renderer was built for; [`Renderer::render_image`] is the offscreen path
//! (render, copy, read back into an [`image::RgbaImage`]). [`Gpu`] bundles a device with the
//! renderer and is the one upload path ([`Gpu::upload`]). The GPU layer never opens files:
//! it draws what [`meshpaint_core::io::display::open_for_display`] opened.

mod baseline;
mod context;
mod gpu;
mod heat;
mod htex;
mod layouts;
mod mct;
mod mesh_gpu;
mod partial;
mod ptex;
mod readback;
mod renderer;
mod uniforms;

pub use baseline::{BaselineMesh, BaselineSource, BaselineVertex, mip_chain_linear};
pub use context::{GpuContext, backends_from_env};
pub use gpu::{Gpu, PaintStart, PaintUpload};
pub use heat::{HEAT_COLORS, heat_color};
pub use htex::GpuHtex;
pub use layouts::BindLayouts;
pub use mct::GpuMct;
pub use mesh_gpu::{
    AtlasLayout, AtlasWriter, GpuMesh, MeshGeometry, MeshUploadOptions, atlas_texture_format, default_atlas_width,
};
pub use partial::{FaceSubset, Scissor};
pub use ptex::{GpuPtex, GpuPtexSlice, gpu_tables};
pub use readback::read_texture;
pub use renderer::{
    DrawItem, FRAME_WGSL, FilterMode, HTEX_WGSL, MCT_WGSL, MESH_COLORS_WGSL, Overlays, PTEX_WGSL, RenderSettings,
    RenderTarget, Renderer, Shading, UV_BASELINE_WGSL,
};
pub use uniforms::FrameUniforms;

use thiserror::Error;

/// Colour format of offscreen render targets (and of [`Renderer::render_image`]).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Depth format of every render pass.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Errors of the GPU renderer.
#[derive(Debug, Error)]
pub enum RenderError {
    /// No GPU adapter (not even a software one such as lavapipe) was found.
    #[error("no GPU adapter found (backends {backends}): {reason}; install mesa-vulkan-drivers for lavapipe")]
    NoAdapter {
        /// The backends that were searched.
        backends: String,
        /// Why the request failed.
        reason: String,
    },
    /// The adapter refused to create a device.
    #[error("cannot create a GPU device on {adapter}: {reason}")]
    RequestDevice {
        /// The adapter's name.
        adapter: String,
        /// Why the request failed.
        reason: String,
    },
    /// The colour buffer does not fit in an atlas of the requested width.
    #[error(
        "colour buffer of {samples} samples needs {rows} rows at atlas width {width}, \
         but textures are limited to {max_dimension} texels per side"
    )]
    AtlasTooLarge {
        /// Samples in the colour buffer.
        samples: u64,
        /// Atlas width.
        width: u32,
        /// Rows needed.
        rows: u64,
        /// The device's `max_texture_dimension_2d`.
        max_dimension: u32,
    },
    /// An atlas width of zero or beyond the device limit was requested.
    #[error("atlas width {width} is outside 1..={max_dimension}")]
    InvalidAtlasWidth {
        /// The requested width.
        width: u32,
        /// The device's `max_texture_dimension_2d`.
        max_dimension: u32,
    },
    /// A storage buffer would exceed the device's binding limit.
    #[error("{what} needs {bytes} bytes, more than the device's storage binding limit of {limit} bytes")]
    BufferTooLarge {
        /// Which buffer.
        what: &'static str,
        /// Bytes needed.
        bytes: u64,
        /// The device's `max_storage_buffer_binding_size`.
        limit: u64,
    },
    /// A render target size of zero or beyond the device limit.
    #[error("render size {width}×{height} is outside 1..={max_dimension} per side")]
    InvalidTargetSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The device's `max_texture_dimension_2d`.
        max_dimension: u32,
    },
    /// Mesh data that cannot be drawn (mismatched lengths, indices out of range…).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// A texture whose size and data disagree.
    #[error("invalid texture: {0}")]
    InvalidTexture(String),
    /// Mapping the readback buffer failed.
    #[error("reading the rendered image back failed: {0}")]
    Readback(String),
    /// wgpu reported an error (validation, out of memory) while rendering.
    #[error("GPU error: {0}")]
    Gpu(String),
}
