//! OBJ through `tobj`: every object and group of the file in one mesh (they share the
//! file's vertex list), polygons fanned by tobj (`(c0, c[i], c[i+1])`), points and lines
//! skipped, `v x y z r g b` colours as display values, `vt` flipped to glTF's top-left
//! origin (`v' = 1 − v`), and each MTL's diffuse colour `Kd` (display values) with its
//! dissolve `d` and its `map_Kd` image (PNG or JPEG, sRGB) as the base colour of the
//! triangles that use it; a map that cannot be read is named in a warning.
//!
//! tobj is wrapped in `catch_unwind`: a short `Kd` line in an MTL makes tobj 4.0.5 panic.
//! MTL and texture files are read only when they are regular files of bounded size inside the
//! OBJ's folder (a relative name), so an OBJ cannot make the reader open devices or absolute
//! paths.

use std::io::BufReader;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Component, Path, PathBuf};

use super::{ReadMesh, count_of, srgb_to_linear};
use crate::mesh::scene::{Material, Texture};

/// Largest MTL file read.
const MAX_MTL_BYTES: u64 = 16 << 20;
/// Largest texture file read, and texture side decoded (as the glTF importer).
const MAX_TEXTURE_BYTES: u64 = 256 << 20;
const MAX_TEXTURE_SIDE: u32 = 16384;

pub(super) fn read(bytes: &[u8], base_dir: Option<&Path>) -> Result<ReadMesh, String> {
    check_vertex_colors(bytes)?;
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let loaded = catch_unwind(AssertUnwindSafe(|| {
        let mut reader = BufReader::new(bytes);
        tobj::load_obj_buf(&mut reader, &options, |name| load_mtl(base_dir, name))
    }));
    let (models, materials) = match loaded {
        Ok(Ok(result)) => result,
        Ok(Err(err)) => return Err(err.to_string()),
        Err(_) => return Err("the OBJ reader (tobj) failed on this file (caught panic)".to_owned()),
    };
    let mut mesh = ReadMesh::default();
    match materials {
        Ok(materials) => {
            let mut missing = Vec::new();
            for source in &materials {
                let mut base = material(source);
                if let Some(name) = &source.diffuse_texture {
                    match load_texture(base_dir, name) {
                        Ok(texture) => {
                            base.base_color_texture = Some(mesh.textures.len() as u32);
                            mesh.textures.push(texture);
                        }
                        Err(why) => missing.push(format!("{name} ({why})")),
                    }
                }
                mesh.materials.push(base);
            }
            if !missing.is_empty() {
                let what = count_of(missing.len(), "texture map", "texture maps");
                mesh.warnings.push(format!("{what} not loaded: {}", missing.join(", ")));
            }
        }
        Err(err) => mesh.warnings.push(format!("materials not loaded: {err}")),
    }
    let (mut uv_complete, mut normal_complete) = (true, true);
    for model in &models {
        append_model(&mut mesh, &model.mesh)?;
        let vertices = model.mesh.positions.len() / 3;
        uv_complete &= model.mesh.texcoords.len() == 2 * vertices;
        normal_complete &= model.mesh.normals.len() == 3 * vertices;
    }
    if !uv_complete {
        mesh.uvs.clear();
    }
    if !normal_complete {
        mesh.normals.clear();
    }
    if mesh.colors.len() != mesh.positions.len() {
        mesh.colors.clear();
    }
    Ok(mesh)
}

/// tobj shifts colours when only some `v` lines carry them: refuse such files up front.
fn check_vertex_colors(bytes: &[u8]) -> Result<(), String> {
    let (mut with, mut without) = (None, None);
    for (number, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let Some(rest) = line.strip_prefix(b"v ").or_else(|| line.strip_prefix(b"v\t")) else {
            continue;
        };
        let words = rest.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty()).count();
        if words == 6 {
            with.get_or_insert(number + 1);
        } else {
            without.get_or_insert(number + 1);
        }
        if let (Some(with), Some(without)) = (with, without) {
            return Err(format!(
                "vertex colours on only some 'v' lines (line {with} has one, line {without} has none)"
            ));
        }
    }
    Ok(())
}

fn append_model(out: &mut ReadMesh, mesh: &tobj::Mesh) -> Result<(), String> {
    let base = u32::try_from(out.positions.len()).map_err(|_| "more than 2^32 vertices".to_owned())?;
    for (k, p) in mesh.positions.chunks_exact(3).enumerate() {
        if !p.iter().all(|x| x.is_finite()) {
            return Err(format!("vertex {} has a non-finite coordinate {p:?}", out.positions.len() + k));
        }
    }
    out.positions.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
    out.normals.extend(mesh.normals.chunks_exact(3).map(|n| [n[0], n[1], n[2]]));
    out.uvs.extend(mesh.texcoords.chunks_exact(2).map(|t| [t[0], 1.0 - t[1]]));
    out.colors.extend(
        mesh.vertex_color
            .chunks_exact(3)
            .map(|c| [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), 1.0]),
    );
    let material = mesh.material_id.filter(|&id| id < out.materials.len()).and_then(|id| u32::try_from(id).ok());
    for corners in mesh.indices.chunks_exact(3) {
        let triangle = [corners[0], corners[1], corners[2]].map(|c| c.saturating_add(base));
        out.triangles.push(triangle);
        out.triangle_materials.push(material);
    }
    Ok(())
}

fn material(source: &tobj::Material) -> Material {
    let [r, g, b] = source.diffuse.unwrap_or([1.0; 3]).map(srgb_to_linear);
    let alpha = source.dissolve.map_or(1.0, |d| if d.is_finite() { d.clamp(0.0, 1.0) } else { 1.0 });
    Material { base_color_factor: [r, g, b, alpha], base_color_texture: None }
}

/// Reads an MTL named by `mtllib` ([`beside`]).
fn load_mtl(base_dir: Option<&Path>, name: &Path) -> tobj::MTLLoadResult {
    let bytes = beside(base_dir, name, MAX_MTL_BYTES).map_err(|_| tobj::LoadError::OpenFileFailed)?;
    tobj::load_mtl_buf(&mut BufReader::new(bytes.as_slice()))
}

/// The bytes of a file an OBJ or MTL names: relative (`\` read as `/`, as Windows exporters
/// write it), inside the OBJ's folder (no `..`), a regular file of at most `max_bytes`.
fn beside(base_dir: Option<&Path>, name: &Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    let base_dir = base_dir.ok_or("no folder to look in")?;
    let name = PathBuf::from(name.to_string_lossy().replace('\\', "/"));
    if name.components().any(|c| !matches!(c, Component::Normal(_) | Component::CurDir)) {
        return Err("not a relative path inside the folder".to_owned());
    }
    let path = base_dir.join(&name);
    let metadata = std::fs::metadata(&path).map_err(|err| err.to_string())?;
    if !metadata.is_file() || metadata.len() > max_bytes {
        return Err(format!("not a regular file of at most {max_bytes} bytes"));
    }
    std::fs::read(&path).map_err(|err| err.to_string())
}

/// Decodes a `map_Kd` image (PNG or JPEG, at most [`MAX_TEXTURE_SIDE`] per side).
fn load_texture(base_dir: Option<&Path>, name: &str) -> Result<Texture, String> {
    let bytes = beside(base_dir, Path::new(name), MAX_TEXTURE_BYTES)?;
    let mut reader =
        image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format().map_err(|err| err.to_string())?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    reader.limits(limits);
    let rgba = reader.decode().map_err(|err| err.to_string())?.to_rgba8();
    Ok(Texture { width: rgba.width(), height: rgba.height(), rgba8_srgb: rgba.into_raw() })
}
