//! The resolution choices of `bench trade` and what is made of each: a pack per colour format
//! (best of three), its GPU mesh, the Mesh Color Texture built from that very pack and its
//! upload, the RGBA32F reference mesh of an untextured input, and the dab throughput.

use std::path::Path;
use std::time::Instant;

use super::TradeOptions;
use crate::bench::BenchRenderError;
use crate::bench::pack::Timing;
use crate::bench::paint;
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::document::Document;
use meshpaint_core::mct::MeshColorTexture;
use meshpaint_core::mesh::scene::Scene;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::ptex::PackedPtex;
use meshpaint_render::{Gpu, GpuMct, GpuMesh, GpuPtex};

/// One resolution choice: a document, its JSON label, and the meshes packed from it.
pub(super) struct Choice {
    /// `R` (uniform), `"R a..b"` (a packed file's mixed resolutions) or `"error<=E"`.
    pub(super) label: serde_json::Value,
    pub(super) error_bound: Option<f32>,
    pub(super) document: Document,
    pub(super) convert_seconds: f64,
    /// One per measured format, in the options' order.
    pub(super) packs: Vec<Packed>,
    /// `bench paint`'s dab throughput on this document (or `{"error": …}`).
    pub(super) dab: serde_json::Value,
    /// Without a textured baseline: this document at RGBA32F, the reference of its rows.
    pub(super) reference: Option<GpuMesh>,
}

/// One format of a choice: the pack, its GPU mesh and its Mesh Color Texture.
pub(super) struct Packed {
    pub(super) format: ColorFormat,
    pub(super) packed: PackedMesh,
    pub(super) mesh: GpuMesh,
    pub(super) pack_seconds: f64,
    /// The MCT built from `packed`, or why it could not be built or uploaded.
    pub(super) mct: Result<MctPack, String>,
    /// The Htex built from `packed`, or why it could not be built or uploaded.
    pub(super) htex: Result<HtexPack, String>,
    /// The packed Ptex built from `packed`, or why it could not be built or uploaded.
    pub(super) ptex: Result<PtexPack, String>,
}

/// An Htex of one pack, on the CPU (for the seam evaluation) and the GPU.
pub(super) struct HtexPack {
    pub(super) texture: meshpaint_core::htex::HtexTexture,
    pub(super) gpu: meshpaint_render::GpuHtex,
    /// Best of three builds from the packed buffers.
    pub(super) build_seconds: f64,
}

/// A packed Ptex of one pack, on the CPU (for the seam evaluation) and the GPU.
pub(super) struct PtexPack {
    pub(super) texture: PackedPtex,
    pub(super) gpu: GpuPtex,
    /// Best of three builds from the packed buffers.
    pub(super) build_seconds: f64,
}

/// A Mesh Color Texture of one pack, on the CPU (for the seam evaluation) and the GPU.
pub(super) struct MctPack {
    pub(super) texture: MeshColorTexture,
    pub(super) gpu: GpuMct,
    /// Best of three builds from the packed buffers.
    pub(super) build_seconds: f64,
}

impl Packed {
    /// GPU bytes of the mesh's geometry textures (positions, vertex ids, normals), which
    /// both representations draw with.
    pub(super) fn geometry_bytes(&self) -> u64 {
        self.mesh.gpu_bytes().saturating_sub(self.mesh.atlas_bytes() + self.mesh.face_record_bytes())
    }

    /// Bytes of the packed face records and colours (the CPU sizes MCT is compared with).
    pub(super) fn mesh_colors_bytes(&self) -> u64 {
        self.packed.face_record_bytes() + self.packed.color_bytes()
    }
}

/// The resolution choices: a glTF `scene` is swept over uniform R (and, with a texture, the
/// error bounds); any other file is measured as it is.
pub(super) fn resolution_choices(
    path: &Path,
    scene: Option<&Scene>,
    textured: bool,
    options: &TradeOptions,
    budget: &Budget,
) -> Result<Vec<Choice>, BenchRenderError> {
    let choice = |label, error_bound, document, convert_seconds| Choice {
        label,
        error_bound,
        document,
        convert_seconds,
        packs: Vec::new(),
        dab: 0.into(),
        reference: None,
    };
    let Some(scene) = scene else {
        let started = Instant::now();
        let document = Document::open_within(path, Resolution::from_log2(3).unwrap_or(Resolution::MAX), budget)?;
        return Ok(vec![choice(rule_resolution(&document), None, document, started.elapsed().as_secs_f64())]);
    };
    let mut rules: Vec<ResolutionRule> = options.uniform.iter().copied().map(ResolutionRule::Uniform).collect();
    // Error bounds fit a texture: only with one.
    let bounds: &[f32] = if textured { &options.error_bounds } else { &[] };
    rules.extend(bounds.iter().map(|&bound| ResolutionRule::ErrorBound { bound, max: options.max_resolution }));
    let mut choices = Vec::new();
    for rule in rules {
        let started = Instant::now();
        let document = Document::from_scene_within(scene.clone(), rule, path, budget)?;
        let convert_seconds = started.elapsed().as_secs_f64();
        let (label, error_bound) = match rule {
            ResolutionRule::ErrorBound { bound, .. } => (format!("error<={bound}").into(), Some(bound)),
            _ => (rule_resolution(&document), None),
        };
        choices.push(choice(label, error_bound, document, convert_seconds));
    }
    Ok(choices)
}

/// Packs and uploads every choice in every format (best of three packs), builds and uploads
/// the MCT of each pack when asked (best of three builds), its RGBA32F reference when there
/// is no texture, and times a dab on it.
pub(super) fn prepare(
    gpu: &Gpu,
    choices: &mut [Choice],
    textured: bool,
    options: &TradeOptions,
) -> Result<(), BenchRenderError> {
    for choice in choices {
        for &format in &options.formats {
            let (timing, packed) = Timing::measure(3, || choice.document.pack(format));
            let packed = packed?;
            let mesh = gpu.upload(&packed)?;
            let mct = if options.mct { build_mct(gpu, &packed, &mesh) } else { Err("not asked (--no-mct)".into()) };
            let htex = if options.htex { build_htex(gpu, &packed, &mesh) } else { Err("not asked".into()) };
            let ptex = if options.ptex { build_ptex(gpu, &packed, &mesh) } else { Err("not asked (--no-ptex)".into()) };
            let pack_seconds = timing.best_seconds;
            choice.packs.push(Packed { format, packed, mesh, pack_seconds, mct, htex, ptex });
        }
        if !textured {
            choice.reference = Some(gpu.upload(&choice.document.pack(ColorFormat::Rgba32F)?)?);
        }
        // A brush of a tenth of the samples (at least 64: a brush at the rim of one sample
        // paints nothing), at most 10k as `bench paint`'s middle size.
        let target = (choice.document.store.sample_count() / 10).clamp(64, 10_000);
        choice.dab = paint::dab_throughput(&choice.document, target, options.dabs)
            .unwrap_or_else(|error| serde_json::json!({ "error": error.to_string() }));
    }
    Ok(())
}

/// The MCT of `packed` (best of three builds, atlas sides up to the device's largest
/// texture) uploaded with `mesh`'s geometry, or why not.
fn build_mct(gpu: &Gpu, packed: &PackedMesh, mesh: &GpuMesh) -> Result<MctPack, String> {
    let max_dimension = gpu.ctx.limits().max_texture_dimension_2d;
    let (timing, texture) = Timing::measure(3, || meshpaint_core::mct::build(packed, max_dimension, u64::MAX));
    let texture = texture.map_err(|e| e.to_string())?;
    let gpu_mct = gpu.upload_mct(&mesh.geometry(), &texture).map_err(|e| e.to_string())?;
    Ok(MctPack { texture, gpu: gpu_mct, build_seconds: timing.best_seconds })
}

/// The Htex of `packed` (best of three builds, pages up to the device's largest texture and
/// array) uploaded with `mesh`'s geometry, or why not.
fn build_htex(gpu: &Gpu, packed: &PackedMesh, mesh: &GpuMesh) -> Result<HtexPack, String> {
    let limits = gpu.ctx.limits();
    let options = meshpaint_core::htex::HtexOptions::within(
        limits.max_texture_dimension_2d,
        limits.max_texture_array_layers,
        u64::MAX,
    );
    let (timing, texture) = Timing::measure(3, || meshpaint_core::htex::build(packed, &options));
    let texture = texture.map_err(|e| e.to_string())?;
    let gpu_htex = gpu.upload_htex(&mesh.geometry(), &texture).map_err(|e| e.to_string())?;
    Ok(HtexPack { texture, gpu: gpu_htex, build_seconds: timing.best_seconds })
}

/// The packed Ptex of `packed` (best of three builds, sides up to the device's largest
/// texture) uploaded with `mesh`'s geometry, or why not.
fn build_ptex(gpu: &Gpu, packed: &PackedMesh, mesh: &GpuMesh) -> Result<PtexPack, String> {
    let max_dimension = gpu.ctx.limits().max_texture_dimension_2d;
    let (timing, texture) = Timing::measure(3, || meshpaint_core::ptex::build(packed, max_dimension, u64::MAX));
    let texture = texture.map_err(|e| e.to_string())?;
    let gpu_ptex = gpu.upload_ptex(&mesh.geometry(), &texture).map_err(|e| e.to_string())?;
    Ok(PtexPack { texture, gpu: gpu_ptex, build_seconds: timing.best_seconds })
}

/// The `resolution` of a document: its R when uniform, else `"R a..b"`.
pub(super) fn rule_resolution(document: &Document) -> serde_json::Value {
    let resolutions = document.store.face_resolutions();
    let min = resolutions.iter().map(|r| r.get()).min().unwrap_or(1);
    let max = resolutions.iter().map(|r| r.get()).max().unwrap_or(1);
    if min == max { min.into() } else { format!("R {min}..{max}").into() }
}
