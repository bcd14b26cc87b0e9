//! `meshpaint bench render`: frame time of the UV-texture baseline, of every mesh-colors
//! filter mode and of the Mesh Color Textures, packed Ptex and Htex built from the same
//! buffers (the representation axis: every row names its representation) on the same mesh,
//! view and image size, interleaved in one run, as ratios to the baseline; plus the GPU
//! memory each path holds and the MCT's, packed Ptex's and Htex's build times.
//!
//! A frame is one render pass into an offscreen target, submitted and waited for
//! (`poll(wait)`), so on lavapipe it measures the rasteriser's whole work. Modes are
//! interleaved round by round so that machine noise hits all of them alike; the median
//! frame of each mode is reported with the best.
//!
//! The baseline needs UVs and a texture. A mesh without them (e.g. Bunny) gets a synthetic
//! baseline: a planar projection of its bounding box onto a procedural texture with as many
//! texels as the mesh-colors buffer has level-0 samples (at least 256²), so both paths hold
//! a comparable signal; the report says which baseline was used.

use std::time::Instant;

use meshpaint_core::camera::{DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, OrbitCamera, default_camera};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::htex::HtexOptions;
use meshpaint_core::io::document::{Document, bounds};
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::mesh::scene::Texture;

use meshpaint_render::{
    BaselineMesh, DrawItem, FilterMode, Gpu, OFFSCREEN_FORMAT, RenderError, RenderSettings, RenderTarget, Renderer,
    Shading,
};

/// One measured path.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeTiming {
    /// `baseline-uv`, `nearest`, `linear`, `mip-1`, `trilinear`, `mct-linear`, `mct-mip-1`,
    /// `mct-trilinear`, `ptex-linear`, `ptex-mip-1`, `ptex-trilinear`, `htex-linear`,
    /// `htex-mip-1`, `htex-trilinear`, `mct-anisotropic`.
    pub name: String,
    /// `uv-texture`, `mesh-colors`, `mct`, `ptex` or `htex`.
    pub representation: &'static str,
    /// Median frame time, seconds.
    pub median_seconds: f64,
    /// Fastest frame, seconds.
    pub best_seconds: f64,
    /// Median CPU time the process spent on a frame (every thread: lavapipe's rasteriser
    /// threads and the submitting one), seconds; on a software rasteriser sharing the
    /// machine with other work this is steadier than the wall clock.
    pub median_cpu_seconds: f64,
    /// Bytes of GPU buffers and textures this path needs.
    pub gpu_bytes: u64,
}

/// The whole render benchmark.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderBench {
    /// Adapter description.
    pub adapter: String,
    /// Whether the adapter filters anisotropically (else `mct-anisotropic` draws trilinear).
    pub anisotropic: bool,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Frames per mode.
    pub frames: usize,
    /// Triangles drawn.
    pub triangles: u32,
    /// Which baseline was drawn (`gltf texture` or `synthetic planar`).
    pub baseline: String,
    /// Baseline first, then each filter mode.
    pub modes: Vec<ModeTiming>,
    /// Seconds to build the Mesh Color Texture from the packed buffers.
    pub mct_build_seconds: f64,
    /// Seconds to build the Htex from the packed buffers.
    pub htex_build_seconds: f64,
    /// Htex's quad textures (the paper's E) and the faces (F).
    pub htex_textures: (u64, u64),
    /// The largest colour jump across Htex's intrinsic edges per level (equalised corners),
    /// then at level 0 without equalisation.
    pub htex_jumps: Vec<serde_json::Value>,
    /// Seconds to build the packed Ptex from the packed buffers.
    pub ptex_build_seconds: f64,
}

impl RenderBench {
    /// As JSON, with each mode's ratio to the baseline.
    pub fn to_json(&self) -> serde_json::Value {
        let baseline = self.modes.first().map_or(f64::NAN, |m| m.median_seconds);
        let baseline_cpu = self.modes.first().map_or(f64::NAN, |m| m.median_cpu_seconds);
        let modes: Vec<serde_json::Value> = self
            .modes
            .iter()
            .map(|m| {
                serde_json::json!({
                    "representation": m.representation,
                    "mode": m.name,
                    "median_ms": m.median_seconds * 1e3,
                    "best_ms": m.best_seconds * 1e3,
                    "ratio_to_baseline": m.median_seconds / baseline,
                    "median_cpu_ms": m.median_cpu_seconds * 1e3,
                    "cpu_ratio_to_baseline": m.median_cpu_seconds / baseline_cpu,
                    "gpu_bytes": m.gpu_bytes,
                })
            })
            .collect();
        serde_json::json!({
            "bench": "render",
            "adapter": self.adapter,
            "anisotropic": self.anisotropic,
            "width": self.width,
            "height": self.height,
            "frames_per_mode": self.frames,
            "triangles": self.triangles,
            "baseline": self.baseline,
            "mct_build_ms": self.mct_build_seconds * 1e3,
            "htex_build_ms": self.htex_build_seconds * 1e3,
            "htex_textures": self.htex_textures.0,
            "htex_faces": self.htex_textures.1,
            "htex_jumps": self.htex_jumps,
            "ptex_build_ms": self.ptex_build_seconds * 1e3,
            "modes": modes,
        })
    }
}

/// A procedural RGBA8 texture (smooth colour waves with fine detail), `size × size`.
fn synthetic_texture(size: u32) -> Texture {
    let mut rgba8_srgb = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let (u, v) = (x as f32 / size as f32, y as f32 / size as f32);
            let wave = |a: f32, b: f32| (127.5 + 127.5 * (a * 40.0 + b * 23.0).sin()) as u8;
            rgba8_srgb.extend_from_slice(&[wave(u, v), wave(v, 0.7 * u), wave(u + v, 0.3), 255]);
        }
    }
    Texture { width: size, height: size, rgba8_srgb }
}

/// Times frames the way every benchmark does: one unlit render pass into an offscreen
/// target of a fixed size, submitted and waited for (`poll(wait)`).
pub struct FrameTimer<'a> {
    gpu: &'a Gpu,
    color_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    width: u32,
    height: u32,
}

impl<'a> FrameTimer<'a> {
    /// Targets of `width × height` on `gpu`.
    pub fn new(gpu: &'a Gpu, width: u32, height: u32) -> Self {
        let ctx = &*gpu.ctx;
        let color = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("bench colour"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: OFFSCREEN_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let depth = Renderer::create_depth_texture(ctx, width, height);
        let color_view = color.create_view(&wgpu::TextureViewDescriptor::default());
        let depth_view = depth.create_view(&wgpu::TextureViewDescriptor::default());
        FrameTimer { gpu, color_view, depth_view, width, height }
    }

    /// Seconds of one unlit frame of `item` with `filter` seen by `camera`.
    pub fn frame(&self, item: DrawItem<'_>, filter: FilterMode, camera: OrbitCamera) -> f64 {
        self.frame_with_cpu(item, filter, camera).0
    }

    /// [`Self::frame`] and the CPU seconds the process spent on it ([`process_cpu_seconds`]).
    pub fn frame_with_cpu(&self, item: DrawItem<'_>, filter: FilterMode, camera: OrbitCamera) -> (f64, f64) {
        let (ctx, renderer) = (&*self.gpu.ctx, &self.gpu.renderer);
        let target =
            RenderTarget { color: &self.color_view, depth: &self.depth_view, width: self.width, height: self.height };
        let mut settings = RenderSettings::new(camera);
        settings.filter = filter;
        settings.shading = Shading::Unlit;
        let cpu_start = process_cpu_seconds();
        let start = Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        renderer.draw(ctx, &mut encoder, &target, item, &settings);
        ctx.queue.submit([encoder.finish()]);
        // A failed wait leaves the timing as measured so far; the report still compares.
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
        (start.elapsed().as_secs_f64(), process_cpu_seconds() - cpu_start)
    }
}

/// CPU time of the whole process (all threads) so far, seconds; NaN where the clock is
/// unavailable.
pub fn process_cpu_seconds() -> f64 {
    let mut now = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `now` is a valid, writable timespec for the duration of the call.
    let status = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut now) };
    if status != 0 {
        return f64::NAN;
    }
    now.tv_sec as f64 + now.tv_nsec as f64 * 1e-9
}

/// Runs the benchmark on `document` (opened from `path`, which is re-imported for its UVs).
pub fn bench_render(
    path: &std::path::Path,
    document: &Document,
    width: u32,
    height: u32,
    frames: usize,
) -> Result<RenderBench, BenchRenderError> {
    let gpu = Gpu::new_headless()?;
    let ctx = &*gpu.ctx;
    let packed = document.pack(ColorFormat::Rgba8Srgb)?;
    let mesh = gpu.upload(&packed)?;

    let (baseline_name, baseline) = baseline(&gpu, path, document)?;
    let build_start = Instant::now();
    let max_dimension = ctx.limits().max_texture_dimension_2d;
    let texture = meshpaint_core::mct::build(&packed, max_dimension, u64::MAX)?;
    let mct_build_seconds = build_start.elapsed().as_secs_f64();
    let mct = gpu.upload_mct(&mesh.geometry(), &texture)?;
    let (htex, htex_build_seconds, htex_textures, htex_jumps) = build_htex(&gpu, &packed, &mesh)?;
    let build_start = Instant::now();
    let packed_ptex = meshpaint_core::ptex::build(&packed, max_dimension, u64::MAX)?;
    let ptex_build_seconds = build_start.elapsed().as_secs_f64();
    let ptex = gpu.upload_ptex(&mesh.geometry(), &packed_ptex)?;

    let camera: OrbitCamera = default_camera(mesh.bounds, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES, None);
    let timer = FrameTimer::new(&gpu, width, height);

    let geometry_bytes = mesh.gpu_bytes() - mesh.atlas_bytes() - mesh.face_record_bytes();
    let (ptex_bytes, htex_bytes) = (geometry_bytes + ptex.gpu_bytes(), geometry_bytes + htex.gpu_bytes());
    let paths: [(&str, &str, DrawItem<'_>, FilterMode, u64); 15] = [
        ("baseline-uv", "uv-texture", DrawItem::Baseline(&baseline), FilterMode::Linear, baseline.gpu_bytes()),
        ("nearest", "mesh-colors", DrawItem::MeshColors(&mesh), FilterMode::Nearest, mesh.gpu_bytes()),
        ("linear", "mesh-colors", DrawItem::MeshColors(&mesh), FilterMode::Linear, mesh.gpu_bytes()),
        ("mip-1", "mesh-colors", DrawItem::MeshColors(&mesh), FilterMode::MipLevel(1), mesh.gpu_bytes()),
        ("trilinear", "mesh-colors", DrawItem::MeshColors(&mesh), FilterMode::Trilinear, mesh.gpu_bytes()),
        ("mct-linear", "mct", DrawItem::Mct(&mct), FilterMode::Linear, geometry_bytes + mct.gpu_bytes()),
        ("mct-mip-1", "mct", DrawItem::Mct(&mct), FilterMode::MipLevel(1), geometry_bytes + mct.gpu_bytes()),
        ("mct-trilinear", "mct", DrawItem::Mct(&mct), FilterMode::Trilinear, geometry_bytes + mct.gpu_bytes()),
        ("ptex-linear", "ptex", DrawItem::Ptex(&ptex), FilterMode::Linear, ptex_bytes),
        ("ptex-mip-1", "ptex", DrawItem::Ptex(&ptex), FilterMode::MipLevel(1), ptex_bytes),
        ("ptex-trilinear", "ptex", DrawItem::Ptex(&ptex), FilterMode::Trilinear, ptex_bytes),
        ("htex-linear", "htex", DrawItem::Htex(&htex), FilterMode::Linear, htex_bytes),
        ("htex-mip-1", "htex", DrawItem::Htex(&htex), FilterMode::MipLevel(1), htex_bytes),
        ("htex-trilinear", "htex", DrawItem::Htex(&htex), FilterMode::Trilinear, htex_bytes),
        // Trilinear where the adapter has no anisotropic filtering (`anisotropic` in the report).
        // Last and timed after the interleaved rounds (`INTERLEAVED`): on lavapipe it is ~100×
        // the others and would leave the frame after it with cold caches.
        ("mct-anisotropic", "mct", DrawItem::Mct(&mct), FilterMode::Anisotropic, geometry_bytes + mct.gpu_bytes()),
    ];
    let mut times: Vec<Vec<f64>> = vec![Vec::with_capacity(frames); paths.len()];
    let mut cpu_times: Vec<Vec<f64>> = vec![Vec::with_capacity(frames); paths.len()];
    // One warm-up frame per path (pipeline and cache warm-up), then interleaved rounds.
    for &(_, _, item, filter, _) in &paths {
        timer.frame(item, filter, camera);
    }
    const INTERLEAVED: usize = 14;
    for modes in [0..INTERLEAVED, INTERLEAVED..paths.len()] {
        for _ in 0..frames.max(1) {
            for k in modes.clone() {
                let (_, _, item, filter, _) = paths[k];
                let (wall, cpu) = timer.frame_with_cpu(item, filter, camera);
                times[k].push(wall);
                cpu_times[k].push(cpu);
            }
        }
    }
    let modes = paths
        .iter()
        .zip(times.into_iter().zip(cpu_times))
        .map(|(&(name, representation, _, _, gpu_bytes), (mut samples, mut cpu))| {
            samples.sort_by(f64::total_cmp);
            cpu.sort_by(f64::total_cmp);
            ModeTiming {
                name: name.to_owned(),
                representation,
                median_seconds: samples.get(samples.len() / 2).copied().unwrap_or(f64::NAN),
                best_seconds: samples.first().copied().unwrap_or(f64::NAN),
                median_cpu_seconds: cpu.get(cpu.len() / 2).copied().unwrap_or(f64::NAN),
                gpu_bytes,
            }
        })
        .collect();
    Ok(RenderBench {
        adapter: ctx.describe(),
        anisotropic: ctx.anisotropic(),
        width,
        height,
        frames: frames.max(1),
        triangles: mesh.face_count,
        baseline: baseline_name,
        modes,
        mct_build_seconds,
        htex_build_seconds,
        htex_textures,
        htex_jumps,
        ptex_build_seconds,
    })
}

/// [`build_htex`]'s result: the uploaded Htex, build seconds, (E, F) and the jump entries.
type BuiltHtex = (meshpaint_render::GpuHtex, f64, (u64, u64), Vec<serde_json::Value>);

/// The Htex of `packed` uploaded with `mesh`'s geometry, its build time in seconds, its
/// texture count (E, F) and the largest colour jumps across its intrinsic edges per level
/// (CPU evaluation), then at level 0 without corner equalisation (the paper's corner-texel
/// discontinuity).
fn build_htex(
    gpu: &Gpu,
    packed: &meshpaint_core::packing::linear::PackedMesh,
    mesh: &meshpaint_render::GpuMesh,
) -> Result<BuiltHtex, BenchRenderError> {
    let limits = gpu.ctx.limits();
    let options = HtexOptions::within(limits.max_texture_dimension_2d, limits.max_texture_array_layers, u64::MAX);
    let build_start = Instant::now();
    let texture = meshpaint_core::htex::build(packed, &options)?;
    let seconds = build_start.elapsed().as_secs_f64();
    let htex = gpu.upload_htex(&mesh.geometry(), &texture)?;
    let mut jumps: Vec<serde_json::Value> =
        (0..texture.layout.levels).map(|level| jumps_json(level, true, texture.jumps(level, 17))).collect();
    let raw = meshpaint_core::htex::build(packed, &HtexOptions { equalize_corners: false, ..options })?;
    jumps.push(jumps_json(0, false, raw.jumps(0, 17)));
    Ok((htex, seconds, texture.texture_count(), jumps))
}

/// One `htex_jumps` entry: the largest jumps (8-bit steps) at `level`.
fn jumps_json(level: u32, equalized: bool, jumps: meshpaint_core::htex::jumps::Jumps) -> serde_json::Value {
    serde_json::json!({
        "level": level, "corners_equalized": equalized,
        "mesh_edges_steps": jumps.mesh_edges, "spokes_steps": jumps.spokes,
    })
}

/// The baseline of `document`: the file's own UVs and texture when it has them, else a
/// planar projection onto a synthetic texture of as many texels as the document has
/// samples. Returns its name for the report and the mesh.
pub(crate) fn baseline(
    gpu: &Gpu,
    path: &std::path::Path,
    document: &Document,
) -> Result<(String, BaselineMesh), BenchRenderError> {
    let (ctx, renderer) = (&*gpu.ctx, &gpu.renderer);
    // Baseline: the file's own UVs and texture when it has them.
    let textured = match import_gltf(path) {
        Ok(scene) => gpu.upload_baseline(&scene)?,
        Err(_) => None,
    };
    Ok(match textured {
        Some(mesh) => ("gltf texture".to_owned(), mesh),
        None => {
            let (min, size) = bounds(&document.positions);
            let corner_uvs: Vec<[[f32; 2]; 3]> = document
                .store
                .topology()
                .face_vertices
                .iter()
                .map(|face| {
                    face.map(|v| {
                        let p = document.positions[v as usize];
                        let uv = |a: usize| if size[a] > 0.0 { (p[a] - min[a]) / size[a] } else { 0.0 };
                        [uv(0), uv(1)]
                    })
                })
                .collect();
            let texels = (document.store.sample_count() as f64).sqrt().ceil().max(256.0) as u32;
            let side = texels.next_power_of_two().min(ctx.limits().max_texture_dimension_2d);
            (
                format!("synthetic planar {side}x{side}"),
                BaselineMesh::new(
                    ctx,
                    renderer.layouts(),
                    &document.positions,
                    &document.store.topology().face_vertices,
                    &corner_uvs,
                    &synthetic_texture(side),
                    [1.0; 4],
                )?,
            )
        }
    })
}

/// Errors of the render benchmark.
#[derive(Debug, thiserror::Error)]
pub enum BenchRenderError {
    /// The GPU side failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// Packing the document failed.
    #[error(transparent)]
    Pack(#[from] meshpaint_core::packing::packer::PackError),
    /// Converting the scene into a document failed.
    #[error(transparent)]
    Document(#[from] meshpaint_core::io::document::DocumentError),
    /// The Mesh Color Texture cannot be built.
    #[error(transparent)]
    Mct(#[from] meshpaint_core::mct::MctError),
    /// The Htex cannot be built.
    #[error(transparent)]
    Htex(#[from] meshpaint_core::htex::HtexError),
    /// The packed Ptex cannot be built.
    #[error(transparent)]
    Ptex(#[from] meshpaint_core::ptex::PtexError),
    /// The measurement needs a reference the file does not have.
    #[error("{0}")]
    NoReference(String),
}
