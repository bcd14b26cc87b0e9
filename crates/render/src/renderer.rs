//! Pipelines, render settings, drawing into any colour view, and offscreen readback.

use std::sync::OnceLock;

use glam::DVec3;
use image::RgbaImage;

use super::layouts::BindLayouts;
use super::uniforms::FrameUniforms;
use super::{BaselineMesh, BaselineVertex, DEPTH_FORMAT, GpuContext, GpuMct, GpuMesh, GpuPtex, RenderError};
use meshpaint_core::camera::OrbitCamera;
use meshpaint_core::colors::format::Rgba;

/// shaders/frame.wgsl: the uniform block ([`FrameUniforms`]), its `FLAG_*` bits and helpers
/// both pipelines share. Not a shader by itself: it is prepended to each shader below.
pub const FRAME_WGSL: &str = include_str!("../shaders/frame.wgsl");
/// The mesh-colors shader exactly as the pipelines compile it: shaders/frame.wgsl,
/// shaders/mesh_common.wgsl and shaders/mesh_colors.wgsl (crates/render/tests/gpu/shaders.rs
/// validates this very string).
pub const MESH_COLORS_WGSL: &str = concat!(
    include_str!("../shaders/frame.wgsl"),
    "\n",
    include_str!("../shaders/mesh_common.wgsl"),
    "\n",
    include_str!("../shaders/mesh_colors.wgsl")
);
/// The Mesh Color Textures shader exactly as its pipelines compile it: shaders/frame.wgsl,
/// shaders/mesh_common.wgsl and shaders/mct.wgsl (crates/render/tests/gpu/shaders.rs validates it).
pub const MCT_WGSL: &str = concat!(
    include_str!("../shaders/frame.wgsl"),
    "\n",
    include_str!("../shaders/mesh_common.wgsl"),
    "\n",
    include_str!("../shaders/mct.wgsl")
);
/// The Htex shader exactly as its pipelines compile it: shaders/frame.wgsl,
/// shaders/mesh_common.wgsl and shaders/htex.wgsl (crates/render/tests/gpu/shaders.rs validates it).
pub const HTEX_WGSL: &str = concat!(
    include_str!("../shaders/frame.wgsl"),
    "\n",
    include_str!("../shaders/mesh_common.wgsl"),
    "\n",
    include_str!("../shaders/htex.wgsl")
);
/// The packed Ptex shader exactly as its pipelines compile it: shaders/frame.wgsl,
/// shaders/mesh_common.wgsl and shaders/ptex.wgsl (crates/render/tests/gpu/shaders.rs validates it).
pub const PTEX_WGSL: &str = concat!(
    include_str!("../shaders/frame.wgsl"),
    "\n",
    include_str!("../shaders/mesh_common.wgsl"),
    "\n",
    include_str!("../shaders/ptex.wgsl")
);
/// The UV-baseline shader exactly as its pipeline compiles it: shaders/frame.wgsl followed
/// by shaders/uv_baseline.wgsl (crates/render/tests/gpu/shaders.rs validates this very string).
pub const UV_BASELINE_WGSL: &str =
    concat!(include_str!("../shaders/frame.wgsl"), "\n", include_str!("../shaders/uv_baseline.wgsl"));

/// How mesh colors are reconstructed and which MIP level is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FilterMode {
    /// The nearest sample at level 0 (hexagonal cells).
    Nearest,
    /// Linear interpolation of three samples at level 0.
    Linear,
    /// Linear interpolation at a fixed MIP level (clamped per face to `log2 R_f`, where only
    /// vertex colours remain).
    MipLevel(u32),
    /// The nearest sample at a fixed MIP level (clamped per face).
    NearestMipLevel(u32),
    /// Automatic level of detail, one continuous function over the mesh (view depth, sample
    /// density and view angle per vertex; crates/core/src/packing/lod.rs), linear within a level and
    /// blended between the two nearest levels.
    #[default]
    Trilinear,
    /// Mesh Color Textures: the GPU's anisotropic sampler (up to 16 taps along the pixel
    /// footprint's long axis) at a level finer than trilinear's by log2 of the taps, where
    /// the adapter offers it ([`GpuContext::anisotropic`]); otherwise, and for mesh colors
    /// (software filter), trilinear.
    Anisotropic,
}

impl FilterMode {
    /// `(filter_kind, level_mode, level)` as the shader's uniforms encode them.
    pub fn uniform_fields(self) -> (u32, u32, u32) {
        match self {
            FilterMode::Nearest => (FrameUniforms::FILTER_NEAREST, FrameUniforms::LEVEL_FIXED, 0),
            FilterMode::Linear => (FrameUniforms::FILTER_LINEAR, FrameUniforms::LEVEL_FIXED, 0),
            FilterMode::MipLevel(level) => (FrameUniforms::FILTER_LINEAR, FrameUniforms::LEVEL_FIXED, level),
            FilterMode::NearestMipLevel(level) => (FrameUniforms::FILTER_NEAREST, FrameUniforms::LEVEL_FIXED, level),
            FilterMode::Trilinear | FilterMode::Anisotropic => {
                (FrameUniforms::FILTER_LINEAR, FrameUniforms::LEVEL_AUTO, 0)
            }
        }
    }
}

/// Surface shading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Shading {
    /// The exact filtered colour (linear), encoded by the sRGB target.
    Unlit,
    /// Lambert + ambient with the face normal (two-sided, flat), light from above-left of
    /// the eye.
    #[default]
    Lit,
    /// Lambert + ambient with smooth normals (two-sided): each corner takes its vertex's
    /// area-weighted normal within 45° of the face normal ([`meshpaint_core::mesh::normals`]), the
    /// lighting is interpolated over the face (Gouraud). The editor's default.
    Smooth,
}

/// Diagnostic overlays.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Overlays {
    /// ~1 px triangle edges.
    pub wireframe: bool,
    /// Per-face resolution heat map (log2 R 0..12: dark blue, blue, cyan, green, yellow,
    /// orange, magenta) instead of the painted colour. Mesh colors only.
    pub heatmap: bool,
}

/// Everything that decides one image besides the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    /// The camera.
    pub camera: OrbitCamera,
    /// Mesh-colors filter (ignored by the baseline, which always samples trilinearly).
    pub filter: FilterMode,
    /// Shading.
    pub shading: Shading,
    /// Overlays.
    pub overlays: Overlays,
    /// Clear colour, linear RGBA.
    pub background: Rgba,
    /// Ambient term of lit shading, `[0, 1]`.
    pub ambient: f32,
    /// Wireframe colour, linear RGBA (alpha = opacity).
    pub wire_color: Rgba,
    /// Wireframe line width in pixels.
    pub wire_width: f32,
}

impl RenderSettings {
    /// Default background: a neutral mid-dark grey (linear).
    pub const DEFAULT_BACKGROUND: Rgba = [0.05, 0.055, 0.06, 1.0];

    /// Trilinear, lit, no overlays, grey background, for `camera`.
    pub fn new(camera: OrbitCamera) -> Self {
        RenderSettings {
            camera,
            filter: FilterMode::default(),
            shading: Shading::default(),
            overlays: Overlays::default(),
            background: Self::DEFAULT_BACKGROUND,
            ambient: 0.25,
            wire_color: [0.0, 0.0, 0.0, 0.85],
            wire_width: 1.0,
        }
    }

    /// Unit vector towards the light, world space: from the eye, tilted up and to the left.
    pub fn light_direction(&self) -> DVec3 {
        let towards_eye = self.camera.eye_direction();
        let (right, up) = self.camera.right_up();
        (towards_eye + 0.6 * up - 0.4 * right).normalize_or(towards_eye)
    }
}

/// What to draw.
#[derive(Debug, Clone, Copy)]
pub enum DrawItem<'a> {
    /// A packed mesh through the mesh-colors pipeline.
    MeshColors(&'a GpuMesh),
    /// A UV-textured mesh through the baseline pipeline.
    Baseline(&'a BaselineMesh),
    /// A Mesh Color Texture through the MCT pipeline (hardware bilinear; nearest filter
    /// modes draw bilinear: MCT has no hexagonal nearest).
    Mct(&'a GpuMct),
    /// An Htex through the Htex pipeline (three bilinear fetches per level; nearest filter
    /// modes draw bilinear, anisotropic draws trilinear).
    Htex(&'a super::GpuHtex),
    /// A packed Ptex through the Ptex pipeline (hardware bilinear; nearest filter modes
    /// draw bilinear, anisotropic draws trilinear).
    Ptex(&'a GpuPtex),
}

impl DrawItem<'_> {
    /// The item's render origin (camera matrices are built relative to it).
    pub fn origin(&self) -> DVec3 {
        match self {
            DrawItem::MeshColors(mesh) => mesh.origin,
            DrawItem::Baseline(mesh) => mesh.origin,
            DrawItem::Mct(mct) => mct.origin,
            DrawItem::Htex(htex) => htex.origin,
            DrawItem::Ptex(ptex) => ptex.origin,
        }
    }
}

/// Where [`Renderer::draw`] renders: a colour view and a depth view of the same size.
#[derive(Debug, Clone, Copy)]
pub struct RenderTarget<'a> {
    /// Colour view in the renderer's colour format (an offscreen texture or a window's
    /// sRGB surface view).
    pub color: &'a wgpu::TextureView,
    /// Depth view in [`DEPTH_FORMAT`] (see [`Renderer::create_depth_texture`]).
    pub depth: &'a wgpu::TextureView,
    /// Width in pixels (for the projection's aspect ratio).
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// The mesh-colors and baseline pipelines for one colour-target format.
#[derive(Debug)]
pub struct Renderer {
    color_format: wgpu::TextureFormat,
    layouts: BindLayouts,
    /// One mesh-colors pipeline per `(filter_kind, level_mode)`, see [`mesh_pipeline_index`].
    mesh_pipelines: Vec<wgpu::RenderPipeline>,
    /// The mesh-colors shader, and its pipelines for partial redraws (one per
    /// `(filter_kind, level_mode)`, built on first use): depth test `LessEqual` against the
    /// previous frame's depth, no depth write ([`crate::partial`]).
    mesh_module: wgpu::ShaderModule,
    partial_pipelines: [OnceLock<wgpu::RenderPipeline>; 4],
    baseline_pipeline: wgpu::RenderPipeline,
    /// The MCT shader and its pipelines, one per `LEVEL_MODE` and set of `FLAG_*` bits (see
    /// [`mct_pipeline_index`]), each built the first time it draws.
    mct_module: wgpu::ShaderModule,
    mct_pipelines: [OnceLock<wgpu::RenderPipeline>; MCT_PIPELINES],
    htex: HtexPipelines,
    /// The packed Ptex shader and its pipelines, one per `LEVEL_MODE` (fixed, automatic) and
    /// set of [`MCT_FLAG_BITS`], each built the first time it draws.
    ptex_module: wgpu::ShaderModule,
    ptex_pipelines: [OnceLock<wgpu::RenderPipeline>; PTEX_PIPELINES],
}

/// Ptex pipelines: `LEVEL_MODE` fixed or automatic, times every set of [`MCT_FLAG_BITS`].
const PTEX_PIPELINES: usize = 2 * (MCT_FLAG_BITS as usize + 1);

/// The `FLAG_*` bits the MCT shader is specialised for (its pipeline-overridable constant
/// `MCT_FLAGS`), so that lighting and overlays that are off cost nothing: a software
/// rasteriser runs the code of a uniform branch for every fragment. Other bits are ignored.
const MCT_FLAG_BITS: u32 =
    FrameUniforms::FLAG_LIT | FrameUniforms::FLAG_WIREFRAME | FrameUniforms::FLAG_HEATMAP | FrameUniforms::FLAG_SMOOTH;

/// MCT pipelines: `LEVEL_MODE` fixed, automatic or anisotropic ([`MCT_LEVEL_ANISOTROPIC`]),
/// times every set of [`MCT_FLAG_BITS`].
const MCT_PIPELINES: usize = 3 * (MCT_FLAG_BITS as usize + 1);

/// The MCT shader's `LEVEL_MODE` for [`FilterMode::Anisotropic`] (shaders/mct.wgsl).
const MCT_LEVEL_ANISOTROPIC: u32 = 2;

/// The index of the MCT pipeline for `level_mode` (fixed, automatic or anisotropic) and `flags`.
fn mct_pipeline_index(level_mode: u32, flags: u32) -> usize {
    level_mode.min(MCT_LEVEL_ANISOTROPIC) as usize * (MCT_FLAG_BITS as usize + 1) + (flags & MCT_FLAG_BITS) as usize
}

/// The `FLAG_*` bits the Htex shader is specialised for (`HTEX_FLAGS`).
const HTEX_FLAG_BITS: u32 =
    FrameUniforms::FLAG_LIT | FrameUniforms::FLAG_WIREFRAME | FrameUniforms::FLAG_HEATMAP | FrameUniforms::FLAG_SMOOTH;

/// The Htex shader and its pipelines (`LEVEL_MODE` fixed or automatic × flag sets).
#[derive(Debug)]
struct HtexPipelines {
    module: wgpu::ShaderModule,
    pipelines: [OnceLock<wgpu::RenderPipeline>; 2 * (HTEX_FLAG_BITS as usize + 1)],
}

impl HtexPipelines {
    fn new(ctx: &GpuContext) -> Self {
        let module = ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("htex"),
            source: wgpu::ShaderSource::Wgsl(HTEX_WGSL.into()),
        });
        HtexPipelines { module, pipelines: std::array::from_fn(|_| OnceLock::new()) }
    }

    /// The pipeline for `level_mode` (0 fixed, else automatic) and `flags`.
    fn get(
        &self,
        ctx: &GpuContext,
        layouts: &BindLayouts,
        target: (wgpu::TextureFormat, (wgpu::CompareFunction, bool)),
        level_mode: u32,
        flags: u32,
    ) -> &wgpu::RenderPipeline {
        let (mode, flags) = (level_mode.min(1), flags & HTEX_FLAG_BITS);
        self.pipelines[(mode * (HTEX_FLAG_BITS + 1) + flags) as usize].get_or_init(|| {
            let constants = [("LEVEL_MODE", f64::from(mode)), ("HTEX_FLAGS", f64::from(flags))];
            let label = format!("htex (level mode {mode}, flags {flags})");
            Renderer::pipeline(ctx, &label, &self.module, &constants, layouts.htex(), &[], target)
        })
    }
}

/// The depth test of a full frame: nearer wins, ties go to the face drawn first.
const FULL_DEPTH: (wgpu::CompareFunction, bool) = (wgpu::CompareFunction::Less, true);

/// The `(filter_kind, level_mode)` combinations the mesh-colors shader is specialised for,
/// as its pipeline-overridable constants `FILTER_KIND` and `LEVEL_MODE` (keep in sync with
/// shaders/mesh_colors.wgsl). Each gets its own pipeline so that a fragment executes only
/// the code of its filter: software rasterisers (lavapipe) run both sides of every branch.
const MESH_PIPELINE_KEYS: [(u32, u32); 4] = [
    (FrameUniforms::FILTER_NEAREST, FrameUniforms::LEVEL_FIXED),
    (FrameUniforms::FILTER_LINEAR, FrameUniforms::LEVEL_FIXED),
    (FrameUniforms::FILTER_NEAREST, FrameUniforms::LEVEL_AUTO),
    (FrameUniforms::FILTER_LINEAR, FrameUniforms::LEVEL_AUTO),
];

/// Index in [`MESH_PIPELINE_KEYS`] of the pipeline for the uniforms' filter and level mode
/// (unknown values fall back to linear / automatic, as the shader's defaults).
fn mesh_pipeline_index(filter_kind: u32, level_mode: u32) -> usize {
    let filter = usize::from(filter_kind != FrameUniforms::FILTER_NEAREST);
    let level = usize::from(level_mode != FrameUniforms::LEVEL_FIXED);
    2 * level + filter
}

impl Renderer {
    /// Builds both pipelines for colour targets of `color_format` (e.g.
    /// [`super::OFFSCREEN_FORMAT`], or a window surface's sRGB view format) and
    /// [`DEPTH_FORMAT`] depth. Shader compilation errors come back as [`RenderError::Gpu`].
    pub fn new(ctx: &GpuContext, color_format: wgpu::TextureFormat) -> Result<Self, RenderError> {
        ctx.checked(|| Ok(Self::build(ctx, color_format)))
    }

    fn build(ctx: &GpuContext, color_format: wgpu::TextureFormat) -> Self {
        let layouts = BindLayouts::new(&ctx.device);
        let mesh_module = Self::module(ctx, "mesh colors", MESH_COLORS_WGSL);
        let mesh_pipelines = MESH_PIPELINE_KEYS
            .iter()
            .enumerate()
            .map(|(index, &(filter_kind, level_mode))| {
                debug_assert_eq!(mesh_pipeline_index(filter_kind, level_mode), index);
                let constants = [("FILTER_KIND", f64::from(filter_kind)), ("LEVEL_MODE", f64::from(level_mode))];
                let label = format!("mesh colors (filter {filter_kind}, level mode {level_mode})");
                Self::pipeline(ctx, &label, &mesh_module, &constants, layouts.mesh(), &[], (color_format, FULL_DEPTH))
            })
            .collect();
        let baseline_module = Self::module(ctx, "uv baseline", UV_BASELINE_WGSL);
        let baseline_pipeline = Self::pipeline(
            ctx,
            "uv baseline",
            &baseline_module,
            &[],
            layouts.baseline(),
            &[Some(BaselineVertex::LAYOUT)],
            (color_format, FULL_DEPTH),
        );
        let mct_module = Self::module(ctx, "mesh color textures", MCT_WGSL);
        let ptex_module = Self::module(ctx, "packed ptex", PTEX_WGSL);
        let renderer = Renderer {
            color_format,
            layouts,
            mesh_pipelines,
            mesh_module,
            partial_pipelines: std::array::from_fn(|_| OnceLock::new()),
            baseline_pipeline,
            mct_module,
            mct_pipelines: std::array::from_fn(|_| OnceLock::new()),
            htex: HtexPipelines::new(ctx),
            ptex_module,
            ptex_pipelines: std::array::from_fn(|_| OnceLock::new()),
        };
        // The unlit ones now, so that shader errors surface here.
        for level_mode in [FrameUniforms::LEVEL_FIXED, FrameUniforms::LEVEL_AUTO] {
            renderer.mct_pipeline(ctx, level_mode, 0);
            renderer.ptex_pipeline(ctx, level_mode, 0);
        }
        renderer
    }

    /// The MCT pipeline for `level_mode` and `flags`, built on first use.
    fn mct_pipeline(&self, ctx: &GpuContext, level_mode: u32, flags: u32) -> &wgpu::RenderPipeline {
        let flags = flags & MCT_FLAG_BITS;
        let level_mode = level_mode.min(MCT_LEVEL_ANISOTROPIC);
        self.mct_pipelines[mct_pipeline_index(level_mode, flags)].get_or_init(|| {
            let constants = [("LEVEL_MODE", f64::from(level_mode)), ("MCT_FLAGS", f64::from(flags))];
            let label = format!("mesh color textures (level mode {level_mode}, flags {flags})");
            let target = (self.color_format, FULL_DEPTH);
            Self::pipeline(ctx, &label, &self.mct_module, &constants, self.layouts.mct(), &[], target)
        })
    }

    /// The packed Ptex pipeline for `level_mode` (fixed or automatic) and `flags`, built on
    /// first use.
    fn ptex_pipeline(&self, ctx: &GpuContext, level_mode: u32, flags: u32) -> &wgpu::RenderPipeline {
        let flags = flags & MCT_FLAG_BITS;
        let level_mode = u32::from(level_mode != FrameUniforms::LEVEL_FIXED);
        self.ptex_pipelines[level_mode as usize * (MCT_FLAG_BITS as usize + 1) + flags as usize].get_or_init(|| {
            let constants = [("LEVEL_MODE", f64::from(level_mode)), ("PTEX_FLAGS", f64::from(flags))];
            let label = format!("packed ptex (level mode {level_mode}, flags {flags})");
            let target = (self.color_format, FULL_DEPTH);
            Self::pipeline(ctx, &label, &self.ptex_module, &constants, self.layouts.mct(), &[], target)
        })
    }

    /// The mesh-colors pipeline of a partial redraw for these uniforms' filter and level
    /// mode (depth test `LessEqual`, no depth write), built on first use.
    pub(crate) fn partial_pipeline(&self, ctx: &GpuContext, uniforms: &FrameUniforms) -> &wgpu::RenderPipeline {
        let index = mesh_pipeline_index(uniforms.filter_kind, uniforms.level_mode);
        self.partial_pipelines[index].get_or_init(|| {
            let (filter_kind, level_mode) = MESH_PIPELINE_KEYS[index];
            let constants = [("FILTER_KIND", f64::from(filter_kind)), ("LEVEL_MODE", f64::from(level_mode))];
            let label = format!("mesh colors, partial redraw (filter {filter_kind}, level mode {level_mode})");
            let target = (self.color_format, (wgpu::CompareFunction::LessEqual, false));
            Self::pipeline(ctx, &label, &self.mesh_module, &constants, self.layouts.mesh(), &[], target)
        })
    }

    fn module(ctx: &GpuContext, label: &str, source: &str) -> wgpu::ShaderModule {
        ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        })
    }

    fn pipeline(
        ctx: &GpuContext,
        label: &str,
        module: &wgpu::ShaderModule,
        constants: &[(&str, f64)],
        bind_group_layout: &wgpu::BindGroupLayout,
        buffers: &[Option<wgpu::VertexBufferLayout<'_>>],
        (color_format, (depth_compare, depth_write)): (wgpu::TextureFormat, (wgpu::CompareFunction, bool)),
    ) -> wgpu::RenderPipeline {
        let device = &ctx.device;
        let compilation_options = wgpu::PipelineCompilationOptions { constants, ..Default::default() };
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(bind_group_layout)],
            immediate_size: 0,
        });
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: compilation_options.clone(),
                buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(depth_write),
                depth_compare: Some(depth_compare),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_main"),
                compilation_options,
                targets: &[Some(wgpu::ColorTargetState {
                    format: color_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// The colour-target format the pipelines were built for.
    pub fn color_format(&self) -> wgpu::TextureFormat {
        self.color_format
    }

    /// The bind-group layouts of both pipelines, which meshes are uploaded against.
    pub fn layouts(&self) -> &BindLayouts {
        &self.layouts
    }

    /// The uniforms of drawing `item` with `settings` into a `width × height` target.
    pub fn uniforms(item: DrawItem<'_>, settings: &RenderSettings, width: u32, height: u32) -> FrameUniforms {
        let clip_from_world = settings.camera.clip_from_world_relative(item.origin(), width, height);
        let light = settings.light_direction().as_vec3();
        let eye = (settings.camera.eye() - item.origin()).as_vec3();
        let pixel_angle =
            (2.0 * (settings.camera.fov_y_degrees.to_radians() * 0.5).tan() / f64::from(height.max(1))) as f32;
        // κ · 2^LOD_BIAS: the level of detail's bias (crates/core/src/packing/lod.rs).
        let pixel_angle = pixel_angle * meshpaint_core::packing::lod::LOD_BIAS.exp2();
        let (filter_kind, level_mode, level) = settings.filter.uniform_fields();
        let mut flags = 0;
        match settings.shading {
            Shading::Unlit => {}
            Shading::Lit => flags |= FrameUniforms::FLAG_LIT,
            Shading::Smooth => flags |= FrameUniforms::FLAG_LIT | FrameUniforms::FLAG_SMOOTH,
        }
        if settings.overlays.wireframe {
            flags |= FrameUniforms::FLAG_WIREFRAME;
        }
        if settings.overlays.heatmap {
            flags |= FrameUniforms::FLAG_HEATMAP;
        }
        let mut uniforms = FrameUniforms {
            clip_from_world: clip_from_world.to_cols_array_2d(),
            light: [light.x, light.y, light.z, settings.ambient.clamp(0.0, 1.0)],
            wire_color: settings.wire_color,
            tint: [1.0; 4],
            lod_eye: [eye.x, eye.y, eye.z, pixel_angle],
            filter_kind,
            level_mode,
            level,
            flags,
            atlas_width: 1,
            sample_count: 1,
            vertex_levels: 1,
            wire_width: settings.wire_width,
            face_count: 0,
            vertex_count: 0,
            _pad0: 0,
            _pad1: 0,
        };
        match item {
            DrawItem::MeshColors(mesh) => {
                uniforms.atlas_width = mesh.atlas.width;
                uniforms.sample_count = u32::try_from(mesh.atlas.samples).unwrap_or(u32::MAX).max(1);
                uniforms.vertex_levels = mesh.vertex_levels.max(1);
                uniforms.face_count = mesh.face_count;
                uniforms.vertex_count = mesh.vertex_count;
            }
            DrawItem::Baseline(mesh) => {
                uniforms.face_count = mesh.vertex_count / 3;
            }
            DrawItem::Mct(mct) => {
                uniforms.vertex_levels = mct.levels.max(1);
                uniforms.face_count = mct.face_count;
                uniforms.vertex_count = mct.vertex_count;
            }
            DrawItem::Htex(htex) => {
                uniforms.vertex_levels = htex.levels.max(1);
                uniforms.face_count = htex.face_count;
                uniforms.vertex_count = htex.vertex_count;
            }
            DrawItem::Ptex(ptex) => {
                uniforms.vertex_levels = ptex.levels.max(1);
                uniforms.face_count = ptex.face_count;
                uniforms.vertex_count = ptex.vertex_count;
            }
        }
        uniforms
    }

    /// Records one render pass drawing `item` into `target` (views of this renderer's colour
    /// format and of [`DEPTH_FORMAT`]), cleared first to the background. Uniforms are written
    /// through `ctx.queue`, so submit before drawing the same item again.
    pub fn draw(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget<'_>,
        item: DrawItem<'_>,
        settings: &RenderSettings,
    ) {
        let (color, depth) = (target.color, target.depth);
        let uniforms = Self::uniforms(item, settings, target.width, target.height);
        let (uniform_buffer, pipeline) = match item {
            DrawItem::MeshColors(mesh) => {
                (&mesh.uniforms, &self.mesh_pipelines[mesh_pipeline_index(uniforms.filter_kind, uniforms.level_mode)])
            }
            DrawItem::Baseline(mesh) => (&mesh.uniforms, &self.baseline_pipeline),
            DrawItem::Mct(mct) => {
                let anisotropic = settings.filter == FilterMode::Anisotropic && ctx.anisotropic();
                let level_mode = if anisotropic { MCT_LEVEL_ANISOTROPIC } else { uniforms.level_mode };
                (&mct.uniforms, self.mct_pipeline(ctx, level_mode, uniforms.flags))
            }
            DrawItem::Htex(htex) => {
                let target = (self.color_format, FULL_DEPTH);
                (&htex.uniforms, self.htex.get(ctx, &self.layouts, target, uniforms.level_mode, uniforms.flags))
            }
            DrawItem::Ptex(ptex) => (&ptex.uniforms, self.ptex_pipeline(ctx, uniforms.level_mode, uniforms.flags)),
        };
        ctx.queue.write_buffer(uniform_buffer, 0, bytemuck::bytes_of(&uniforms));
        let [r, g, b, a] = settings.background.map(f64::from);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("meshpaint render pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        match item {
            DrawItem::MeshColors(mesh) => {
                pass.set_bind_group(0, &mesh.bind_group, &[]);
                let vertex_count = mesh.face_count.saturating_mul(3);
                if vertex_count > 0 {
                    pass.draw(0..vertex_count, 0..1);
                }
            }
            DrawItem::Mct(mct) => {
                pass.set_bind_group(0, &mct.bind_group, &[]);
                let vertex_count = mct.face_count.saturating_mul(3);
                if vertex_count > 0 {
                    pass.draw(0..vertex_count, 0..1);
                }
            }
            DrawItem::Htex(htex) => {
                pass.set_bind_group(0, &htex.bind_group, &[]);
                let vertex_count = htex.face_count.saturating_mul(3);
                if vertex_count > 0 {
                    pass.draw(0..vertex_count, 0..1);
                }
            }
            DrawItem::Ptex(ptex) => {
                pass.set_bind_group(0, &ptex.bind_group, &[]);
                let vertex_count = ptex.face_count.saturating_mul(3);
                if vertex_count > 0 {
                    pass.draw(0..vertex_count, 0..1);
                }
            }
            DrawItem::Baseline(mesh) => {
                pass.set_vertex_buffer(0, mesh.vertex_buffer().slice(..));
                // One draw per texture (the uniforms are shared).
                for (bind_group, vertices) in mesh.draws() {
                    pass.set_bind_group(0, bind_group, &[]);
                    if !vertices.is_empty() {
                        pass.draw(vertices, 0..1);
                    }
                }
            }
        }
    }

    /// A depth texture for `width × height` targets.
    pub fn create_depth_texture(ctx: &GpuContext, width: u32, height: u32) -> wgpu::Texture {
        ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("depth"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
    }

    /// Renders `item` offscreen at `width × height` and reads the image back (RGBA8; with
    /// an sRGB colour format the bytes are sRGB-encoded, as PNG expects).
    pub fn render_image(
        &self,
        ctx: &GpuContext,
        item: DrawItem<'_>,
        settings: &RenderSettings,
        width: u32,
        height: u32,
    ) -> Result<RgbaImage, RenderError> {
        let max_dimension = ctx.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max_dimension || height > max_dimension {
            return Err(RenderError::InvalidTargetSize { width, height, max_dimension });
        }
        if !matches!(self.color_format, wgpu::TextureFormat::Rgba8UnormSrgb | wgpu::TextureFormat::Rgba8Unorm) {
            return Err(RenderError::Gpu(format!(
                "render_image needs an RGBA8 renderer, this one targets {:?}",
                self.color_format
            )));
        }
        let padded_row = (width * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback = ctx.checked(|| {
            let color = ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("offscreen colour"),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.color_format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let depth = Self::create_depth_texture(ctx, width, height);
            let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("readback"),
                size: u64::from(padded_row) * u64::from(height),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let color_view = color.create_view(&wgpu::TextureViewDescriptor::default());
            let depth_view = depth.create_view(&wgpu::TextureViewDescriptor::default());
            let mut encoder =
                ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("render_image") });
            let target = RenderTarget { color: &color_view, depth: &depth_view, width, height };
            self.draw(ctx, &mut encoder, &target, item, settings);
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture: &color,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(padded_row),
                        rows_per_image: Some(height),
                    },
                },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
            ctx.queue.submit([encoder.finish()]);
            Ok(readback)
        })?;
        let (sender, receiver) = std::sync::mpsc::channel();
        readback.map_async(wgpu::MapMode::Read, .., move |result| {
            let _ = sender.send(result);
        });
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|error| RenderError::Readback(error.to_string()))?;
        receiver
            .recv()
            .map_err(|error| RenderError::Readback(error.to_string()))?
            .map_err(|error| RenderError::Readback(error.to_string()))?;
        let mut pixels = Vec::with_capacity(width as usize * height as usize * 4);
        {
            let mapped = readback.get_mapped_range(..).map_err(|error| RenderError::Readback(error.to_string()))?;
            for row in mapped.chunks_exact(padded_row as usize) {
                pixels.extend_from_slice(&row[..width as usize * 4]);
            }
        }
        readback.unmap();
        RgbaImage::from_raw(width, height, pixels)
            .ok_or_else(|| RenderError::Readback("image size does not match the read-back bytes".into()))
    }
}
