//! OBJ, PLY (ASCII and binary) and STL importers: each file becomes a [`Scene`] with one
//! [`SourceMesh`] placed once at the identity, so it goes through the same weld → topology
//! path as glTF (bitwise-equal positions become one vertex there).
//!
//! The common rules, whatever the format:
//! - **Polygons** with n > 3 corners are cut into the fan `(c0, c[i], c[i+1])` for
//!   `i = 1..n-1` (n − 2 triangles, the rule tobj uses for OBJ); faces with fewer than three
//!   corners (OBJ points and lines, degenerate PLY faces) are skipped and counted in a warning.
//! - **Vertex colours** (OBJ `v x y z r g b`, PLY `red green blue [alpha]`) are display
//!   (sRGB-encoded) values as MeshLab and scanners write them; they are decoded to linear
//!   RGBA, which the document takes as the initial colours. PLY integer channels are divided by
//!   their type's maximum (255 for `uchar`).
//! - **Normals** from the file are used when every vertex has one, else computed from the
//!   faces (area-weighted). UVs (OBJ `vt`, PLY `u v` / `s t`) are kept when every vertex has one.
//! - **Refused**, with an [`FormatError`] naming the file and the problem: unreadable files,
//!   non-numeric or non-finite numbers, indices out of range, truncated data, and headers
//!   that declare more data than the file holds (checked before anything is allocated).
//!
//! Files: `obj` (tobj), `ply` (ply-rs-bw), `stl` (a small reader of our own: see its docs).

use std::path::Path;

use glam::{Mat4, Vec3};

use crate::mesh::scene::{Instance, Material, Scene, SourceMesh, Texture};

mod obj;
mod ply;
mod stl;

/// The mesh formats beside glTF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Wavefront OBJ (with its MTL's diffuse colour).
    Obj,
    /// Stanford PLY, ASCII or binary (either byte order).
    Ply,
    /// STL, ASCII or binary.
    Stl,
}

/// File-name extensions (lower case) of the formats above, for file dialogs and drops.
pub const EXTENSIONS: [&str; 3] = ["obj", "ply", "stl"];

impl MeshFormat {
    /// The format's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::Stl => "STL",
        }
    }

    /// The format of a file: PLY by its `ply` magic line whatever the name, else by the
    /// extension (OBJ and STL have no magic). `None`: not one of these (glTF or packed).
    pub fn detect(path: &Path, head: &[u8]) -> Option<Self> {
        if head.starts_with(b"ply\n") || head.starts_with(b"ply\r\n") {
            return Some(MeshFormat::Ply);
        }
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "obj" => Some(MeshFormat::Obj),
            "ply" => Some(MeshFormat::Ply),
            "stl" => Some(MeshFormat::Stl),
            _ => None,
        }
    }
}

/// Errors of the OBJ / PLY / STL importers; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// The file could not be read.
    #[error("{path}: cannot read the file: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The content is not a valid file of the format, or cannot be used.
    #[error("{path}: not a valid {format} file: {message}")]
    Invalid {
        /// The file.
        path: String,
        /// The format's name.
        format: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// Reads `path` as `format`. External MTL files of an OBJ are resolved beside it.
pub fn import_mesh_file(path: &Path, format: MeshFormat) -> Result<Scene, FormatError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| FormatError::Io { path: name.clone(), source })?;
    import_mesh_slice(&bytes, format, path.parent(), &name)
}

/// Reads a file of `format` from memory; `base_dir` resolves an OBJ's MTL files (`None`
/// ignores them); `name` names the file in errors and warnings.
pub fn import_mesh_slice(
    bytes: &[u8],
    format: MeshFormat,
    base_dir: Option<&Path>,
    name: &str,
) -> Result<Scene, FormatError> {
    let read = match format {
        MeshFormat::Obj => obj::read(bytes, base_dir),
        MeshFormat::Ply => ply::read(bytes),
        MeshFormat::Stl => stl::read(bytes),
    };
    let read =
        read.map_err(|message| FormatError::Invalid { path: name.to_owned(), format: format.name(), message })?;
    for warning in &read.warnings {
        if warning.starts_with("ignored:") {
            log::info!("{name}: {warning}");
        } else {
            log::warn!("{name}: {warning}");
        }
    }
    Ok(read.into_scene())
}

/// What a reader returns: one mesh in the file's own space.
#[derive(Debug, Default)]
struct ReadMesh {
    positions: Vec<[f32; 3]>,
    /// Per vertex, or empty (computed from the faces).
    normals: Vec<[f32; 3]>,
    /// Per vertex, or empty (zeros).
    uvs: Vec<[f32; 2]>,
    /// Per vertex linear RGBA, or empty.
    colors: Vec<[f32; 4]>,
    triangles: Vec<[u32; 3]>,
    /// The material of every triangle (an OBJ's MTL diffuse colour), if any.
    triangle_materials: Vec<Option<u32>>,
    materials: Vec<Material>,
    /// Decoded base-colour textures the materials name.
    textures: Vec<Texture>,
    warnings: Vec<String>,
}

impl ReadMesh {
    fn into_scene(self) -> Scene {
        let count = self.positions.len();
        let normals =
            if self.normals.len() == count { self.normals } else { computed_normals(&self.positions, &self.triangles) };
        let uvs = if self.uvs.len() == count { self.uvs } else { vec![[0.0; 2]; count] };
        let colors = if self.colors.len() == count { self.colors } else { Vec::new() };
        let triangle_materials = if self.triangle_materials.len() == self.triangles.len() {
            self.triangle_materials
        } else {
            vec![None; self.triangles.len()]
        };
        let mesh = SourceMesh {
            name: "mesh 0".to_owned(),
            positions_local: self.positions,
            normals_local: normals,
            uvs,
            colors,
            triangles: self.triangles,
            triangle_materials,
        };
        Scene {
            meshes: vec![mesh],
            instances: vec![Instance { mesh: 0, world_from_local: Mat4::IDENTITY }],
            materials: self.materials,
            textures: self.textures,
            warnings: self.warnings,
        }
    }
}

/// Area-weighted vertex normals, normalised; a vertex with no area around it gets +Z.
fn computed_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for triangle in triangles {
        let [a, b, c] = triangle.map(|v| positions.get(v as usize).map_or(Vec3::ZERO, |&p| Vec3::from_array(p)));
        let weighted = (b - a).cross(c - a);
        if weighted.is_finite() {
            for &v in triangle {
                if let Some(sum) = sums.get_mut(v as usize) {
                    *sum += weighted;
                }
            }
        }
    }
    sums.into_iter()
        .map(|sum| {
            let unit = sum.normalize_or_zero();
            if unit == Vec3::ZERO || !unit.is_finite() { [0.0, 0.0, 1.0] } else { unit.to_array() }
        })
        .collect()
}

/// sRGB → linear (IEC 61966-2-1) of a display value in `[0, 1]` (clamped; NaN → 0).
fn srgb_to_linear(encoded: f32) -> f32 {
    let x = if encoded.is_nan() { 0.0 } else { encoded.clamp(0.0, 1.0) };
    if x <= 0.040_45 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

/// Appends the fan of `corners` (see the module docs) to `triangles`; returns false (and
/// appends nothing) when there are fewer than three corners.
fn push_fan(corners: &[u32], triangles: &mut Vec<[u32; 3]>) -> bool {
    let Some((&first, rest)) = corners.split_first() else {
        return false;
    };
    if rest.len() < 2 {
        return false;
    }
    triangles.extend(rest.windows(2).map(|pair| [first, pair[0], pair[1]]));
    true
}

/// "N things" with the plural when N ≠ 1.
fn count_of(count: usize, one: &str, many: &str) -> String {
    format!("{count} {}", if count == 1 { one } else { many })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fan_of_a_pentagon() {
        let mut triangles = Vec::new();
        assert!(push_fan(&[10, 11, 12, 13, 14], &mut triangles));
        assert_eq!(triangles, vec![[10, 11, 12], [10, 12, 13], [10, 13, 14]]);
        assert!(!push_fan(&[1, 2], &mut triangles));
        assert_eq!(triangles.len(), 3);
    }

    #[test]
    fn detection() {
        assert_eq!(MeshFormat::detect(Path::new("a.OBJ"), b"v 0 0 0"), Some(MeshFormat::Obj));
        assert_eq!(MeshFormat::detect(Path::new("a.bin"), b"ply\nformat"), Some(MeshFormat::Ply));
        assert_eq!(MeshFormat::detect(Path::new("a.stl"), b"solid x"), Some(MeshFormat::Stl));
        assert_eq!(MeshFormat::detect(Path::new("a.glb"), b"glTF"), None);
    }
}
