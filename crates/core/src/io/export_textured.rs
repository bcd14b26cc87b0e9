//! A textured binary glTF: the welded mesh with its original UVs and normals and a
//! baseColorTexture holding the baked mesh colors ([`crate::convert::bake_uv`]).
//!
//! One glTF vertex per distinct (welded vertex, UV, normal) of the face corners, so UV seams
//! and hard edges stay split as in the source; positions are world space (node transforms
//! are already applied by welding), one node at the identity. The texture is a PNG in the
//! binary chunk with a linear, mip-mapped, `REPEAT` sampler; the material is that texture
//! with a white base colour factor (the factor and the source texture are already in the
//! mesh colours), metallic 0, roughness 1.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};

use gltf::json;
use gltf::json::validation::Checked::Valid;
use gltf::json::validation::USize64;

use super::export_gltf::{ExportError, GENERATOR};
use crate::convert::bake_uv::UvBake;

/// The mesh to write: welded positions and triangles with per-corner UVs and normals.
#[derive(Debug, Clone, Copy)]
pub struct TexturedMesh<'a> {
    /// World-space positions of the welded vertices.
    pub positions: &'a [[f32; 3]],
    /// Triangles as welded vertex ids.
    pub triangles: &'a [[u32; 3]],
    /// Per triangle, the UV of each corner (glTF convention).
    pub corner_uvs: &'a [[[f32; 2]; 3]],
    /// Per triangle, the unit normal of each corner.
    pub corner_normals: &'a [[[f32; 3]; 3]],
}

/// What [`textured_glb`] produced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TexturedGlb {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// glTF vertices written.
    pub vertices: u64,
    /// Triangles written.
    pub triangles: u64,
    /// Bytes of the embedded PNG.
    pub png_bytes: u64,
}

/// Encodes `bake` as a PNG.
pub fn encode_png(bake: &UvBake) -> Result<Vec<u8>, ExportError> {
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(&bake.rgba8_srgb, bake.size, bake.size, image::ExtendedColorType::Rgba8)
        .map_err(|err| ExportError::Encode(format!("PNG: {err}")))?;
    Ok(png)
}

/// Vertex attributes split by (welded vertex, UV, normal), and the triangles over them.
struct Split {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
}

fn split_vertices(mesh: &TexturedMesh<'_>) -> Result<Split, ExportError> {
    let faces = mesh.triangles.len();
    if mesh.corner_uvs.len() != faces || mesh.corner_normals.len() != faces {
        return Err(ExportError::Encode(format!(
            "{faces} triangles but {} UV and {} normal triples",
            mesh.corner_uvs.len(),
            mesh.corner_normals.len()
        )));
    }
    let mut ids: HashMap<(u32, [u32; 2], [u32; 3]), u32> = HashMap::new();
    let mut split = Split { positions: Vec::new(), normals: Vec::new(), uvs: Vec::new(), indices: Vec::new() };
    for (face, corners) in mesh.triangles.iter().enumerate() {
        for (k, &vertex) in corners.iter().enumerate() {
            let position = *mesh
                .positions
                .get(vertex as usize)
                .ok_or_else(|| ExportError::Encode(format!("triangle {face} uses missing vertex {vertex}")))?;
            let (uv, normal) = (mesh.corner_uvs[face][k], mesh.corner_normals[face][k]);
            let next = split.positions.len() as u32;
            let id = *ids.entry((vertex, uv.map(f32::to_bits), normal.map(f32::to_bits))).or_insert(next);
            if id == next {
                split.positions.push(position);
                split.normals.push(normal);
                split.uvs.push(uv);
            }
            split.indices.push(id);
        }
    }
    Ok(split)
}

/// The binary glTF of `mesh` textured with `png` (see the module docs).
pub fn textured_glb(mesh: &TexturedMesh<'_>, png: &[u8]) -> Result<TexturedGlb, ExportError> {
    let split = split_vertices(mesh)?;
    if split.indices.is_empty() {
        return Err(ExportError::Empty);
    }
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &split.positions {
        for a in 0..3 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }
    // Binary chunk: positions, normals, UVs, indices (u32), PNG; every offset a multiple of 4.
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<(usize, usize)> = Vec::new();
    let mut section = |bin: &mut Vec<u8>, bytes: &[u8]| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push((bin.len(), bytes.len()));
        bin.extend_from_slice(bytes);
    };
    section(&mut bin, bytemuck::cast_slice(&split.positions));
    section(&mut bin, bytemuck::cast_slice(&split.normals));
    section(&mut bin, bytemuck::cast_slice(&split.uvs));
    section(&mut bin, bytemuck::cast_slice(&split.indices));
    section(&mut bin, png);
    let buffer_length = bin.len();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let (vertices, index_count) = (split.positions.len(), split.indices.len());
    let root = root(&views, buffer_length, vertices, index_count, (min, max));
    let json_string = json::serialize::to_string(&root).map_err(|err| ExportError::Encode(err.to_string()))?;
    let total = 12 + 8 + json_string.len().next_multiple_of(4) + 8 + bin.len();
    let length = u32::try_from(total).map_err(|_| ExportError::TooLarge {
        vertices: vertices as u64,
        triangles: (index_count / 3) as u64,
        bytes: total as u64,
        limit: "a GLB file holds at most 2^32 - 1 bytes",
    })?;
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header { magic: *b"glTF", version: 2, length },
        json: Cow::Owned(json_string.into_bytes()),
        bin: Some(Cow::Owned(bin)),
    };
    let bytes = glb.to_vec().map_err(|err| ExportError::Encode(err.to_string()))?;
    Ok(TexturedGlb {
        bytes,
        vertices: vertices as u64,
        triangles: (index_count / 3) as u64,
        png_bytes: png.len() as u64,
    })
}

/// The JSON: `views` are (offset, length) of positions, normals, UVs, indices and the PNG.
fn root(
    views: &[(usize, usize)],
    buffer_length: usize,
    vertices: usize,
    indices: usize,
    (min, max): ([f32; 3], [f32; 3]),
) -> json::Root {
    use json::accessor::{ComponentType, Type};
    use json::buffer::Target;

    let mut root = json::Root {
        asset: json::Asset { generator: Some(GENERATOR.to_owned()), ..json::Asset::default() },
        ..json::Root::default()
    };
    let buffer = root.push(json::Buffer {
        byte_length: USize64::from(buffer_length),
        extensions: None,
        extras: Default::default(),
        name: None,
        uri: None,
    });
    let targets = [
        Some(Target::ArrayBuffer),
        Some(Target::ArrayBuffer),
        Some(Target::ArrayBuffer),
        Some(Target::ElementArrayBuffer),
        None,
    ];
    let view_ids: Vec<_> = views
        .iter()
        .zip(targets)
        .map(|(&(offset, length), target)| {
            root.push(json::buffer::View {
                buffer,
                byte_length: USize64::from(length),
                byte_offset: Some(USize64::from(offset)),
                byte_stride: None,
                extensions: None,
                extras: Default::default(),
                name: None,
                target: target.map(Valid),
            })
        })
        .collect();
    let mut accessor =
        |view, count: usize, component: ComponentType, ty: Type, bounds: Option<([f32; 3], [f32; 3])>| {
            root.push(super::export_gltf::accessor(view, count, component, ty, bounds))
        };
    let positions = accessor(view_ids[0], vertices, ComponentType::F32, Type::Vec3, Some((min, max)));
    let normals = accessor(view_ids[1], vertices, ComponentType::F32, Type::Vec3, None);
    let uvs = accessor(view_ids[2], vertices, ComponentType::F32, Type::Vec2, None);
    let index_accessor = accessor(view_ids[3], indices, ComponentType::U32, Type::Scalar, None);
    let material = push_material(&mut root, view_ids[4]);
    let primitive = json::mesh::Primitive {
        attributes: BTreeMap::from([
            (Valid(json::mesh::Semantic::Positions), positions),
            (Valid(json::mesh::Semantic::Normals), normals),
            (Valid(json::mesh::Semantic::TexCoords(0)), uvs),
        ]),
        extensions: None,
        extras: Default::default(),
        indices: Some(index_accessor),
        material: Some(material),
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    };
    let mesh = root.push(json::Mesh {
        extensions: None,
        extras: Default::default(),
        name: Some("meshpaint".to_owned()),
        primitives: vec![primitive],
        weights: None,
    });
    let node = root.push(json::Node { mesh: Some(mesh), name: Some("meshpaint".to_owned()), ..Default::default() });
    let scene = root.push(json::Scene { extensions: None, extras: Default::default(), name: None, nodes: vec![node] });
    root.scene = Some(scene);
    root
}

/// The PNG in `png_view` as image, its linear mip-mapped `REPEAT` sampler, the texture and the
/// material that uses it as base colour.
fn push_material(root: &mut json::Root, png_view: json::Index<json::buffer::View>) -> json::Index<json::Material> {
    use json::texture::{MagFilter, MinFilter, WrappingMode};
    let image = root.push(json::Image {
        buffer_view: Some(png_view),
        mime_type: Some(json::image::MimeType("image/png".to_owned())),
        name: Some("meshpaint bake".to_owned()),
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    let sampler = root.push(json::texture::Sampler {
        mag_filter: Some(Valid(MagFilter::Linear)),
        min_filter: Some(Valid(MinFilter::LinearMipmapLinear)),
        name: None,
        wrap_s: Valid(WrappingMode::Repeat),
        wrap_t: Valid(WrappingMode::Repeat),
        extensions: None,
        extras: Default::default(),
    });
    let texture = root.push(json::Texture {
        name: None,
        sampler: Some(sampler),
        source: image,
        extensions: None,
        extras: Default::default(),
    });
    root.push(json::Material {
        name: Some("meshpaint baked colours".to_owned()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_texture: Some(json::texture::Info {
                index: texture,
                tex_coord: 0,
                extensions: None,
                extras: Default::default(),
            }),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            ..Default::default()
        },
        ..Default::default()
    })
}
