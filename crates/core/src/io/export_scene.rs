//! A whole imported [`Scene`] written back as a binary glTF: every mesh with its own
//! attributes (POSITION, NORMAL, TEXCOORD_0 where its material has a texture, COLOR_0 where
//! the mesh has vertex colours), one primitive per material, one node per instance, every
//! material's base colour factor and texture, every texture as a PNG in the binary chunk.
//! The writer of the production-like test assets ([`crate::synth::production`]); the
//! importer reads its files back into the same scene (up to welding).
//!
//! Deterministic: the same scene gives the same bytes (primitives in material order,
//! `None` last; no time stamps).

use std::borrow::Cow;
use std::collections::BTreeMap;

use gltf::json;
use gltf::json::validation::Checked::Valid;
use gltf::json::validation::USize64;

use super::export_gltf::{ExportError, GENERATOR};
use crate::mesh::scene::{Scene, SourceMesh, Texture};

/// The binary glTF of `scene` (see the module docs).
pub fn scene_glb(scene: &Scene) -> Result<Vec<u8>, ExportError> {
    let mut writer = Writer { root: json::Root::default(), bin: Vec::new() };
    writer.root.asset = json::Asset { generator: Some(GENERATOR.to_owned()), ..json::Asset::default() };
    let textures: Vec<json::Index<json::Texture>> =
        scene.textures.iter().map(|texture| writer.texture(texture)).collect::<Result<_, _>>()?;
    let materials: Vec<json::Index<json::Material>> =
        scene.materials.iter().map(|material| writer.material(material, &textures)).collect::<Result<_, _>>()?;
    let textured: Vec<bool> = scene.materials.iter().map(|m| m.base_color_texture.is_some()).collect();
    let meshes: Vec<json::Index<json::Mesh>> =
        scene.meshes.iter().map(|mesh| writer.mesh(mesh, &materials, &textured)).collect::<Result<_, _>>()?;
    let mut nodes = Vec::new();
    for instance in &scene.instances {
        let mesh = *meshes.get(instance.mesh as usize).ok_or(ExportError::Empty)?;
        let matrix = instance.world_from_local.to_cols_array();
        let identity = instance.world_from_local == glam::Mat4::IDENTITY;
        nodes.push(writer.root.push(json::Node {
            mesh: Some(mesh),
            matrix: (!identity).then_some(matrix),
            name: scene.meshes.get(instance.mesh as usize).map(|m| m.name.clone()),
            ..Default::default()
        }));
    }
    if nodes.is_empty() {
        return Err(ExportError::Empty);
    }
    let scene_index = writer.root.push(json::Scene { extensions: None, extras: Default::default(), name: None, nodes });
    writer.root.scene = Some(scene_index);
    writer.finish()
}

struct Writer {
    root: json::Root,
    bin: Vec<u8>,
}

impl Writer {
    /// Appends `bytes` at a 4-byte aligned offset and returns its view.
    fn view(&mut self, bytes: &[u8], target: Option<json::buffer::Target>) -> json::Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            extensions: None,
            extras: Default::default(),
            name: None,
            target: target.map(Valid),
        })
    }

    fn accessor(
        &mut self,
        bytes: &[u8],
        count: usize,
        component: json::accessor::ComponentType,
        ty: json::accessor::Type,
        bounds: Option<([f32; 3], [f32; 3])>,
    ) -> json::Index<json::Accessor> {
        use json::buffer::Target;
        let target = if ty == json::accessor::Type::Scalar { Target::ElementArrayBuffer } else { Target::ArrayBuffer };
        let view = self.view(bytes, Some(target));
        self.root.push(super::export_gltf::accessor(view, count, component, ty, bounds))
    }

    fn texture(&mut self, texture: &Texture) -> Result<json::Index<json::Texture>, ExportError> {
        use image::ImageEncoder;
        use json::texture::{MagFilter, MinFilter, WrappingMode};
        let mut png = Vec::new();
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(&texture.rgba8_srgb, texture.width, texture.height, image::ExtendedColorType::Rgba8)
            .map_err(|err| ExportError::Encode(format!("PNG: {err}")))?;
        let view = self.view(&png, None);
        let image = self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType("image/png".to_owned())),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        let sampler = self.root.push(json::texture::Sampler {
            mag_filter: Some(Valid(MagFilter::Linear)),
            min_filter: Some(Valid(MinFilter::LinearMipmapLinear)),
            name: None,
            wrap_s: Valid(WrappingMode::Repeat),
            wrap_t: Valid(WrappingMode::Repeat),
            extensions: None,
            extras: Default::default(),
        });
        Ok(self.root.push(json::Texture {
            name: None,
            sampler: Some(sampler),
            source: image,
            extensions: None,
            extras: Default::default(),
        }))
    }

    fn material(
        &mut self,
        material: &crate::mesh::scene::Material,
        textures: &[json::Index<json::Texture>],
    ) -> Result<json::Index<json::Material>, ExportError> {
        let texture =
            match material.base_color_texture {
                Some(t) => Some(*textures.get(t as usize).ok_or_else(|| {
                    ExportError::Encode(format!("a material names texture {t} of {}", textures.len()))
                })?),
                None => None,
            };
        Ok(self.root.push(json::Material {
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(material.base_color_factor),
                base_color_texture: texture.map(|index| json::texture::Info {
                    index,
                    tex_coord: 0,
                    extensions: None,
                    extras: Default::default(),
                }),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.8),
                ..Default::default()
            },
            ..Default::default()
        }))
    }

    /// One primitive per material of `mesh`'s triangles, each with only the vertices it uses.
    fn mesh(
        &mut self,
        mesh: &SourceMesh,
        materials: &[json::Index<json::Material>],
        textured: &[bool],
    ) -> Result<json::Index<json::Mesh>, ExportError> {
        use json::accessor::{ComponentType, Type};
        // Some(m) in ascending order, then None (BTreeMap orders None first: key it last).
        let mut groups: BTreeMap<(bool, u32), Vec<[u32; 3]>> = BTreeMap::new();
        for (face, triangle) in mesh.triangles.iter().enumerate() {
            let material = mesh.triangle_materials.get(face).copied().flatten();
            groups.entry((material.is_none(), material.unwrap_or(0))).or_default().push(*triangle);
        }
        let mut primitives = Vec::new();
        for ((untextured_default, material), triangles) in groups {
            let material = (!untextured_default).then_some(material);
            let mut remap: BTreeMap<u32, u32> = BTreeMap::new();
            let mut indices = Vec::with_capacity(triangles.len() * 3);
            for &vertex in triangles.iter().flatten() {
                let next = remap.len() as u32;
                indices.push(*remap.entry(vertex).or_insert(next));
            }
            let mut order = vec![0u32; remap.len()];
            for (&source, &id) in &remap {
                order[id as usize] = source;
            }
            let pick = |values: &[[f32; 3]]| -> Result<Vec<[f32; 3]>, ExportError> {
                order.iter().map(|&v| values.get(v as usize).copied().ok_or_else(|| missing(&mesh.name, v))).collect()
            };
            let positions = pick(&mesh.positions_local)?;
            let normals = pick(&mesh.normals_local)?;
            let mut min = [f32::INFINITY; 3];
            let mut max = [f32::NEG_INFINITY; 3];
            for p in &positions {
                for a in 0..3 {
                    min[a] = min[a].min(p[a]);
                    max[a] = max[a].max(p[a]);
                }
            }
            let mut attributes = BTreeMap::new();
            let count = positions.len();
            let position_accessor = self.accessor(
                bytemuck::cast_slice(&positions),
                count,
                ComponentType::F32,
                Type::Vec3,
                Some((min, max)),
            );
            attributes.insert(Valid(json::mesh::Semantic::Positions), position_accessor);
            let normal_accessor =
                self.accessor(bytemuck::cast_slice(&normals), count, ComponentType::F32, Type::Vec3, None);
            attributes.insert(Valid(json::mesh::Semantic::Normals), normal_accessor);
            if material.is_some_and(|m| textured.get(m as usize).copied().unwrap_or(false)) {
                let uvs: Vec<[f32; 2]> =
                    order.iter().map(|&v| mesh.uvs.get(v as usize).copied().unwrap_or([0.0; 2])).collect();
                let accessor = self.accessor(bytemuck::cast_slice(&uvs), count, ComponentType::F32, Type::Vec2, None);
                attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), accessor);
            }
            if !mesh.colors.is_empty() {
                let colors: Vec<[f32; 4]> =
                    order.iter().map(|&v| mesh.colors.get(v as usize).copied().unwrap_or([1.0; 4])).collect();
                let accessor =
                    self.accessor(bytemuck::cast_slice(&colors), count, ComponentType::F32, Type::Vec4, None);
                attributes.insert(Valid(json::mesh::Semantic::Colors(0)), accessor);
            }
            let index_accessor =
                self.accessor(bytemuck::cast_slice(&indices), indices.len(), ComponentType::U32, Type::Scalar, None);
            let material = match material {
                Some(m) => Some(*materials.get(m as usize).ok_or_else(|| missing(&mesh.name, m))?),
                None => None,
            };
            primitives.push(json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(index_accessor),
                material,
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            });
        }
        if primitives.is_empty() {
            return Err(ExportError::Empty);
        }
        Ok(self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(mesh.name.clone()),
            primitives,
            weights: None,
        }))
    }

    fn finish(mut self) -> Result<Vec<u8>, ExportError> {
        let buffer_length = self.bin.len();
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.root.push(json::Buffer {
            byte_length: USize64::from(buffer_length),
            extensions: None,
            extras: Default::default(),
            name: None,
            uri: None,
        });
        let json_string = json::serialize::to_string(&self.root).map_err(|err| ExportError::Encode(err.to_string()))?;
        let total = 12 + 8 + json_string.len().next_multiple_of(4) + 8 + self.bin.len();
        let length = u32::try_from(total)
            .map_err(|_| ExportError::Encode(format!("{total} bytes: a GLB file holds at most 2^32 - 1")))?;
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header { magic: *b"glTF", version: 2, length },
            json: Cow::Owned(json_string.into_bytes()),
            bin: Some(Cow::Owned(self.bin)),
        };
        glb.to_vec().map_err(|err| ExportError::Encode(err.to_string()))
    }
}

fn missing(mesh: &str, index: u32) -> ExportError {
    ExportError::Encode(format!("mesh '{mesh}' refers to a missing vertex or material {index}"))
}
