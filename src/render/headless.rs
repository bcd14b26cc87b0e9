//! One-shot offscreen rendering of a file: what `meshpaint render` does.

use std::path::{Path, PathBuf};

use image::RgbaImage;
use thiserror::Error;

use super::{BaselineMesh, DrawItem, GpuContext, GpuMesh, MeshUploadOptions, OFFSCREEN_FORMAT, RenderError};
use super::{FilterMode, Overlays, RenderSettings, Renderer, Shading};
use crate::camera::{BoundingSphere, OrbitCamera};
use crate::colors::format::ColorFormat;
use crate::colors::layout::Resolution;
use crate::io::document::{Document, DocumentError, SourceKind};
use crate::mesh::import::{ImportError, import_gltf};
use crate::mesh::weld::weld_scene;
use crate::packing::packer::PackError;

/// Errors of [`render_file`].
#[derive(Debug, Error)]
pub enum RenderFileError {
    /// Opening the document failed.
    #[error(transparent)]
    Document(#[from] DocumentError),
    /// Importing the glTF for the UV baseline failed.
    #[error(transparent)]
    Import(#[from] ImportError),
    /// Packing the document failed.
    #[error("packing {path}: {source}")]
    Pack {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: PackError,
    },
    /// The UV baseline needs a glTF material with a base-colour texture.
    #[error("{0}: --baseline-uv needs a glTF file with a base-colour texture, and no material has one")]
    NoBaseColorTexture(PathBuf),
    /// The GPU side failed.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// Everything `meshpaint render` needs besides the output path.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderRequest {
    /// A glTF or packed file.
    pub path: PathBuf,
    /// Uniform resolution for glTF input.
    pub resolution: Resolution,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Mesh-colors filter.
    pub filter: FilterMode,
    /// Shading.
    pub shading: Shading,
    /// Overlays.
    pub overlays: Overlays,
    /// Camera yaw, degrees.
    pub yaw_degrees: f64,
    /// Camera pitch, degrees.
    pub pitch_degrees: f64,
    /// Eye distance (default: framing the bounding sphere).
    pub distance: Option<f64>,
    /// Draw the glTF UVs and base-colour texture (the baseline) instead of mesh colors.
    pub baseline_uv: bool,
}

/// What [`render_file`] produced.
#[derive(Debug)]
pub struct RenderedFile {
    /// The image (sRGB-encoded RGBA8).
    pub image: RgbaImage,
    /// The adapter that rendered it.
    pub adapter: String,
    /// Triangles drawn.
    pub triangles: u32,
    /// Samples in the colour atlas (0 for the baseline).
    pub samples: u64,
}

/// The default camera: `OrbitCamera::framing` of the positions' bounding sphere at
/// `yaw`/`pitch`, with `distance` overriding the framing distance.
pub fn default_camera(positions: &[[f32; 3]], yaw: f64, pitch: f64, distance: Option<f64>) -> OrbitCamera {
    let mut camera = OrbitCamera::framing(BoundingSphere::of_points(positions), yaw, pitch);
    if let Some(distance) = distance.filter(|d| d.is_finite() && *d > 0.0) {
        camera.distance = distance;
    }
    camera
}

/// Opens `request.path` and renders it offscreen: mesh colors (packed in the file's own
/// format, RGBA8 sRGB for glTF) or, with `baseline_uv`, the glTF's UVs and base-colour texture.
pub fn render_file(request: &RenderRequest) -> Result<RenderedFile, RenderFileError> {
    let ctx = GpuContext::new_headless()?;
    let renderer = Renderer::new(&ctx, OFFSCREEN_FORMAT)?;
    if request.baseline_uv {
        return render_baseline(&ctx, &renderer, request);
    }
    let document = Document::open(&request.path, request.resolution)?;
    for warning in &document.warnings {
        log::warn!("{}: {warning}", request.path.display());
    }
    let format = match document.source {
        SourceKind::Packed(format) => format,
        SourceKind::Gltf => ColorFormat::default(),
    };
    let packed =
        document.pack(format).map_err(|source| RenderFileError::Pack { path: request.path.clone(), source })?;
    let mesh = GpuMesh::upload(&ctx, &renderer, &packed, &MeshUploadOptions::default())?;
    let settings = settings(request, &document.positions);
    let image = renderer.render_image(&ctx, DrawItem::MeshColors(&mesh), &settings, request.width, request.height)?;
    Ok(RenderedFile { image, adapter: ctx.describe(), triangles: mesh.face_count, samples: mesh.atlas.samples })
}

fn settings(request: &RenderRequest, positions: &[[f32; 3]]) -> RenderSettings {
    let camera = default_camera(positions, request.yaw_degrees, request.pitch_degrees, request.distance);
    let mut settings = RenderSettings::new(camera);
    settings.filter = request.filter;
    settings.shading = request.shading;
    settings.overlays = request.overlays;
    settings
}

fn render_baseline(
    ctx: &GpuContext,
    renderer: &Renderer,
    request: &RenderRequest,
) -> Result<RenderedFile, RenderFileError> {
    let path: &Path = &request.path;
    let scene = import_gltf(path)?;
    let (material, texture) = scene
        .materials
        .iter()
        .find_map(|material| {
            let texture = scene.textures.get(material.base_color_texture? as usize)?;
            Some((material, texture))
        })
        .ok_or_else(|| RenderFileError::NoBaseColorTexture(path.to_owned()))?;
    let welded = weld_scene(&scene);
    let mesh = BaselineMesh::new(
        ctx,
        renderer,
        &welded.positions_world,
        &welded.triangles,
        &welded.corner_uvs,
        texture,
        material.base_color_factor,
    )?;
    let settings = settings(request, &welded.positions_world);
    let image = renderer.render_image(ctx, DrawItem::Baseline(&mesh), &settings, request.width, request.height)?;
    Ok(RenderedFile { image, adapter: ctx.describe(), triangles: mesh.vertex_count / 3, samples: 0 })
}
