//! The baked-texture export: mesh colors baked into UVs ([`crate::convert::bake_uv`]), the
//! model's own or a generated atlas ([`crate::convert::unwrap`]), written as a textured
//! binary glTF ([`super::export_textured`]) or a PNG. The command line (`export --texture`)
//! and the editor (File → Export…) both call [`bake_export`].
//!
//! **Which UVs.** [`UvSource::Auto`] takes the model's own UVs when every face has UV area
//! and no two faces' UV triangles share a texel, else generates new ones
//! ([`crate::convert::unwrap::choose_uvs`]); [`UvSource::New`] always generates them;
//! [`UvSource::Own`] always takes the model's.
//!
//! **Normals.** With the model's UVs the file's normals are kept; with generated UVs each
//! corner gets the normal the mesh-colors view shades it with
//! ([`crate::mesh::normals::smooth_corner_normal`]: the area-weighted vertex normal within
//! the 45° crease angle, else the face normal). Vertices are split where UVs or normals
//! differ, so chart borders split them.

use thiserror::Error;

use crate::colors::budget::Budget;
use crate::convert::bake_uv::{BakeUvError, UvBake, bake_bytes, bake_uv_texture, default_padding};
use crate::convert::unwrap::{AtlasOptions, DensityStats, GeneratedUvs, UnwrapError, UvChoice};
use crate::convert::unwrap::{choose_uvs, density, generate_uvs};
use crate::io::document::Document;
use crate::io::export_gltf::ExportError;
use crate::io::export_textured::{TexturedMesh, encode_png, textured_glb};
use crate::mesh::normals::{face_cross, smooth_corner_normal, unit_or_zero, vertex_normals};

/// Errors of the baked export.
#[derive(Debug, Error)]
pub enum BakedExportError {
    /// The texture would not fit the memory budget.
    #[error("a {size}×{size} bake needs {needed} bytes, over the memory budget of {budget} bytes")]
    Memory {
        /// Texture side.
        size: u32,
        /// Bytes the bake needs.
        needed: u64,
        /// The budget.
        budget: u64,
    },
    /// The model's UVs were asked for but the document keeps none.
    #[error("the document keeps no UVs (a packed file): name the model it came from, or use new UVs")]
    NoOwnUvs,
    /// Generating UVs failed.
    #[error(transparent)]
    Unwrap(#[from] UnwrapError),
    /// Baking failed.
    #[error(transparent)]
    Bake(#[from] BakeUvError),
    /// Encoding the file failed.
    #[error(transparent)]
    Export(#[from] ExportError),
}

/// Which UVs to bake into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UvSource {
    /// The model's own when usable, else new ones (module docs).
    #[default]
    Auto,
    /// Generated ones.
    New,
    /// The model's own, even when they overlap.
    Own,
}

/// The model's own UVs and normals, per face of the document (from
/// [`crate::mesh::weld::WeldedMesh`] of its source file).
#[derive(Debug, Clone, Copy)]
pub struct OwnMesh<'a> {
    /// Per face, the UV of each corner.
    pub corner_uvs: &'a [[[f32; 2]; 3]],
    /// Per face, the unit normal of each corner.
    pub corner_normals: &'a [[[f32; 3]; 3]],
}

/// What to write.
#[derive(Debug, Clone, Copy)]
pub struct BakeRequest<'a> {
    /// Texture side in texels.
    pub size: u32,
    /// Which UVs.
    pub uvs: UvSource,
    /// The model's UVs and normals (`None`: the document keeps none).
    pub own: Option<OwnMesh<'a>>,
    /// A PNG of the texture alone instead of a textured .glb.
    pub png_only: bool,
}

/// What [`bake_export`] produced.
#[derive(Debug, Clone)]
pub struct BakedExport {
    /// The file's bytes (.glb or .png).
    pub bytes: Vec<u8>,
    /// Which UVs were used and why.
    pub choice: UvChoice,
    /// The generated layout, when one was made.
    pub generated: Option<GeneratedUvs>,
    /// Texel density of the UVs used over the surface.
    pub density: DensityStats,
    /// The bake's counts (its texels are in `bytes`).
    pub covered_texels: u64,
    /// Faces without UV area.
    pub faces_without_uvs: u64,
    /// Texels strictly inside two faces' UVs whose colours differ (paint lost).
    pub conflicting_texels: u64,
    /// glTF vertices (0 for a PNG).
    pub vertices: u64,
    /// Triangles (0 for a PNG).
    pub triangles: u64,
}

/// Bakes `document` as `request` says within `budget` (module docs); `progress(stage,
/// fraction)` reports the stages.
pub fn bake_export(
    document: &Document,
    request: &BakeRequest<'_>,
    budget: &Budget,
    progress: &(dyn Fn(&str, f32) + Sync),
) -> Result<BakedExport, BakedExportError> {
    let size = request.size;
    let needed = bake_bytes(size);
    if needed > budget.memory_bytes {
        return Err(BakedExportError::Memory { size, needed, budget: budget.memory_bytes });
    }
    let triangles = &document.store.topology().face_vertices;
    let own_uvs = request.own.map(|own| own.corner_uvs);
    progress("checking the model's UVs", 0.02);
    let choice = match request.uvs {
        UvSource::New => UvChoice::NewAsked,
        UvSource::Own => match own_uvs {
            Some(uvs) => UvChoice::OwnAsked(crate::convert::unwrap::check_own_uvs(uvs, size)),
            None => return Err(BakedExportError::NoOwnUvs),
        },
        UvSource::Auto => choose_uvs(own_uvs, size),
    };
    let (generated, corner_uvs, corner_normals) = match (choice.is_new(), request.own) {
        (false, Some(own)) => (None, own.corner_uvs.to_vec(), own.corner_normals.to_vec()),
        _ => {
            let unwrap_progress = |stage: &str, f: f32| progress(stage, 0.05 + 0.5 * f);
            let generated = generate_uvs(&document.positions, triangles, AtlasOptions::new(size), &unwrap_progress)?;
            let uvs = generated.corner_uvs.clone();
            (Some(generated), uvs, smooth_corner_normals(&document.positions, triangles))
        }
    };
    progress("baking the texture", 0.6);
    let bake = bake_uv_texture(&document.store, &corner_uvs, size, default_padding(size))?;
    let density = density(&document.positions, triangles, &corner_uvs, size);
    progress("encoding the PNG", 0.8);
    let png = encode_png(&bake)?;
    let UvBake { covered_texels, faces_without_uvs, conflicting_texels, .. } = bake;
    let (bytes, vertices, triangle_count) = if request.png_only {
        (png, 0, 0)
    } else {
        progress("writing the glTF", 0.95);
        let mesh = TexturedMesh {
            positions: &document.positions,
            triangles,
            corner_uvs: &corner_uvs,
            corner_normals: &corner_normals,
        };
        let glb = textured_glb(&mesh, &png)?;
        (glb.bytes, glb.vertices, glb.triangles)
    };
    Ok(BakedExport {
        bytes,
        choice,
        generated,
        density,
        covered_texels,
        faces_without_uvs: faces_without_uvs.len() as u64,
        conflicting_texels,
        vertices,
        triangles: triangle_count,
    })
}

/// Per face, the normal smooth shading gives each corner (module docs).
pub fn smooth_corner_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[[f32; 3]; 3]> {
    let vertex = vertex_normals(positions, triangles);
    triangles
        .iter()
        .map(|corners| {
            let p = corners.map(|v| positions.get(v as usize).copied().unwrap_or([0.0; 3]));
            let face = unit_or_zero(face_cross(p[0], p[1], p[2])).map(|x| x as f32);
            let face = if face == [0.0; 3] { [0.0, 0.0, 1.0] } else { face };
            corners.map(|v| {
                let n = vertex.get(v as usize).copied().unwrap_or([0.0; 3]).map(|x| x as f32);
                smooth_corner_normal(n, face)
            })
        })
        .collect()
}
