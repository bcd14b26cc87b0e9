//! The UV baseline: a mesh drawn with its glTF UVs and base-colour textures through a
//! hardware sampler (linear, trilinear mipmaps built on the CPU in linear light, repeat).
//!
//! It is the visual reference mesh colors are compared with and the baseline every speed
//! ratio is measured against. A mesh with several materials is drawn in one pass, one draw
//! per texture: each corner carries its material's `baseColorFactor` (times COLOR_0 where the
//! file has vertex colours), which multiplies the texel; faces whose material has no texture
//! read a 1×1 white texture, so they show their factor, as glTF and the mesh-colors
//! conversion (crates/core/src/convert/bake.rs) do.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};
use wgpu::util::DeviceExt;

use super::layouts::BindLayouts;
use super::{GpuContext, RenderError};
use meshpaint_core::camera::BoundingSphere;
use meshpaint_core::colors::format::{linear_to_srgb, srgb_to_linear};
use meshpaint_core::mesh::scene::Texture;

/// One vertex of the baseline's vertex buffer (three per face: faces keep their own UVs).
///
/// Keep in sync with `struct VertexIn` in shaders/uv_baseline.wgsl (60 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
pub struct BaselineVertex {
    /// Position relative to the render origin.
    pub position: [f32; 3],
    /// glTF TEXCOORD_0 (origin top-left, v down, as wgpu textures).
    pub uv: [f32; 2],
    /// Unit face normal (counter-clockwise front; +Z for a degenerate face).
    pub normal: [f32; 3],
    /// Multiplies the texel: the material's `baseColorFactor` (× COLOR_0), linear RGBA.
    pub color: [f32; 4],
    /// The corner's normal for smooth shading ([`meshpaint_core::mesh::normals::smooth_corner_normal`]
    /// of the area-weighted vertex normal, as the mesh-colors shader does).
    pub corner_normal: [f32; 3],
}

const _: () = assert!(std::mem::size_of::<BaselineVertex>() == 60);

impl BaselineVertex {
    /// The vertex buffer layout: locations 0 (position), 1 (uv), 2 (normal), 3 (color),
    /// 4 (corner normal).
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<BaselineVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![
            0 => Float32x3,
            1 => Float32x2,
            2 => Float32x3,
            3 => Float32x4,
            4 => Float32x3
        ],
    };
}

/// What the baseline draws, one entry per face where a slice is per face.
#[derive(Debug, Clone, Copy)]
pub struct BaselineSource<'a> {
    /// Vertex positions, world space.
    pub positions: &'a [[f32; 3]],
    /// Faces as vertex ids.
    pub triangles: &'a [[u32; 3]],
    /// One UV per face corner (e.g. [`meshpaint_core::mesh::weld::WeldedMesh::corner_uvs`]).
    pub corner_uvs: &'a [[[f32; 2]; 3]],
    /// One linear RGBA colour per face corner that multiplies the texel (the material's
    /// `baseColorFactor`, times COLOR_0 where there is one).
    pub corner_colors: &'a [[[f32; 4]; 3]],
    /// Per face, the index into `textures` of its base-colour texture; `None` (or an index
    /// out of range) draws the corner colours alone.
    pub face_textures: &'a [Option<u32>],
    /// The base-colour textures (RGBA8 sRGB; mipmaps are generated on upload).
    pub textures: &'a [Texture],
}

/// The faces of one texture: a vertex range and the bind group reading that texture.
#[derive(Debug)]
struct BaselinePart {
    vertices: std::ops::Range<u32>,
    texture: wgpu::Texture,
    bind_group: wgpu::BindGroup,
}

/// The mip chain of an RGBA8 sRGB texture, built in linear light: each level halves each
/// side (down to 1) and averages the 2×2 texels below it (clamped at odd edges) after
/// decoding sRGB; alpha is averaged as is. Level 0 is the input. Returns
/// `(width, height, rgba8_srgb)` per level.
pub fn mip_chain_linear(texture: &Texture) -> Vec<(u32, u32, Vec<u8>)> {
    let decode: Vec<f32> = (0..=255u8).map(|b| srgb_to_linear(f32::from(b) / 255.0)).collect();
    let encode = |linear: f32| (linear_to_srgb(linear) * 255.0).round() as u8;
    let mut levels = vec![(texture.width, texture.height, texture.rgba8_srgb.clone())];
    while let Some((w, h, src)) = levels.last() {
        let (w, h) = (*w, *h);
        if w <= 1 && h <= 1 {
            break;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut out = Vec::with_capacity(nw as usize * nh as usize * 4);
        for y in 0..nh {
            for x in 0..nw {
                let mut sum = [0.0f32; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let sx = (2 * x + dx).min(w - 1) as usize;
                    let sy = (2 * y + dy).min(h - 1) as usize;
                    let k = (sy * w as usize + sx) * 4;
                    for c in 0..3 {
                        sum[c] += decode[usize::from(src[k + c])];
                    }
                    sum[3] += f32::from(src[k + 3]) / 255.0;
                }
                out.extend_from_slice(&[
                    encode(sum[0] * 0.25),
                    encode(sum[1] * 0.25),
                    encode(sum[2] * 0.25),
                    (sum[3] * 0.25 * 255.0).round() as u8,
                ]);
            }
        }
        levels.push((nw, nh, out));
    }
    levels
}

/// A mesh with UVs and base-colour textures on the GPU, for the baseline pipeline.
#[derive(Debug)]
pub struct BaselineMesh {
    /// The render origin (bounding-sphere centre): positions on the GPU are `p − origin`.
    pub origin: DVec3,
    /// The mesh's bounding sphere (for framing).
    pub bounds: BoundingSphere,
    /// Vertices drawn: three per face.
    pub vertex_count: u32,
    vertices: wgpu::Buffer,
    parts: Vec<BaselinePart>,
    pub(crate) uniforms: wgpu::Buffer,
}

impl BaselineMesh {
    /// Uploads a mesh with one texture for the baseline: `positions` (world), `triangles`
    /// (vertex ids), `corner_uvs` (one UV per face corner), the base-colour `texture` (RGBA8
    /// sRGB; mipmaps are generated here) and the `base_color_factor` that multiplies it on
    /// every face (use `[1.0; 4]` for none). Several materials: [`BaselineMesh::from_source`].
    pub fn new(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        corner_uvs: &[[[f32; 2]; 3]],
        texture: &Texture,
        base_color_factor: [f32; 4],
    ) -> Result<Self, RenderError> {
        let corner_colors = vec![[base_color_factor; 3]; triangles.len()];
        let face_textures = vec![Some(0); triangles.len()];
        let source = BaselineSource {
            positions,
            triangles,
            corner_uvs,
            corner_colors: &corner_colors,
            face_textures: &face_textures,
            textures: std::slice::from_ref(texture),
        };
        Self::from_source(ctx, layouts, &source)
    }

    /// Uploads `source`: faces grouped by texture (one draw each), faces without one
    /// drawing their corner colours over a 1×1 white texture.
    pub fn from_source(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        source: &BaselineSource<'_>,
    ) -> Result<Self, RenderError> {
        ctx.checked(|| Self::from_source_unchecked(ctx, layouts, source))
    }

    fn from_source_unchecked(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        source: &BaselineSource<'_>,
    ) -> Result<Self, RenderError> {
        let BaselineSource { positions, triangles, corner_uvs, corner_colors, face_textures, textures } = *source;
        let lengths = [
            ("corner UV triples", corner_uvs.len()),
            ("corner colour triples", corner_colors.len()),
            ("face textures", face_textures.len()),
        ];
        for (what, len) in lengths {
            if len != triangles.len() {
                return Err(RenderError::InvalidMesh(format!("{len} {what} for {} triangles", triangles.len())));
            }
        }
        let limits = ctx.limits();
        // A face's texture, `None` for none or an index out of range.
        let texture_of = |face: usize| face_textures[face].filter(|&t| (t as usize) < textures.len());
        let mut used: Vec<u32> = (0..triangles.len()).filter_map(texture_of).collect();
        used.sort_unstable();
        used.dedup();
        for &t in &used {
            check_texture(&textures[t as usize], limits.max_texture_dimension_2d)?;
        }
        let vertex_total = triangles.len() * 3;
        let vertex_count = u32::try_from(vertex_total)
            .map_err(|_| RenderError::InvalidMesh(format!("{} triangles", triangles.len())))?;

        let bounds = BoundingSphere::of_points(positions);
        let origin = DVec3::from_array(bounds.center);
        let (vertices, ranges) = baseline_vertices(source, origin, texture_of)?;
        let bytes = (vertices.len() * std::mem::size_of::<BaselineVertex>()) as u64;
        if bytes > limits.max_buffer_size {
            return Err(RenderError::BufferTooLarge {
                what: "baseline vertices",
                bytes,
                limit: limits.max_buffer_size,
            });
        }
        let mut contents: Vec<u8> = bytemuck::cast_slice(&vertices).to_vec();
        contents.resize(contents.len().max(std::mem::size_of::<BaselineVertex>()), 0);
        let vertex_buffer = ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("baseline vertices"),
            contents: &contents,
            usage: wgpu::BufferUsages::VERTEX,
        });

        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("baseline trilinear repeat"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            address_mode_w: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let uniforms = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("baseline uniforms"),
            size: std::mem::size_of::<super::FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let white = Texture { width: 1, height: 1, rgba8_srgb: vec![255; 4] };
        let mut parts = Vec::with_capacity(ranges.len());
        for (key, range) in ranges {
            let texture = key.map_or(&white, |t| &textures[t as usize]);
            let gpu_texture = upload_texture(ctx, texture);
            let view = gpu_texture.create_view(&wgpu::TextureViewDescriptor::default());
            let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("baseline bind group"),
                layout: layouts.baseline(),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&sampler) },
                ],
            });
            parts.push(BaselinePart { vertices: range, texture: gpu_texture, bind_group });
        }
        Ok(BaselineMesh { origin, bounds, vertex_count, vertices: vertex_buffer, parts, uniforms })
    }

    /// The draws: each texture's bind group with its vertex range.
    pub(crate) fn draws(&self) -> impl Iterator<Item = (&wgpu::BindGroup, std::ops::Range<u32>)> {
        self.parts.iter().map(|part| (&part.bind_group, part.vertices.clone()))
    }

    /// Number of draws (textures, the white one of untextured faces included).
    pub fn draw_count(&self) -> usize {
        self.parts.len()
    }

    pub(crate) fn vertex_buffer(&self) -> &wgpu::Buffer {
        &self.vertices
    }

    /// GPU memory of the vertex buffer and the textures with their mip chains, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        let mut texels = 0u64;
        for part in &self.parts {
            let size = part.texture.size();
            for level in 0..part.texture.mip_level_count() {
                texels += u64::from((size.width >> level).max(1)) * u64::from((size.height >> level).max(1));
            }
        }
        self.vertices.size() + texels * 4
    }
}

/// Refuses a texture of zero size, beyond `max` texels per side, or whose data length
/// disagrees with its size.
fn check_texture(texture: &Texture, max: u32) -> Result<(), RenderError> {
    if texture.width == 0 || texture.height == 0 || texture.width > max || texture.height > max {
        return Err(RenderError::InvalidTexture(format!(
            "{}×{} is outside 1..={max} per side",
            texture.width, texture.height
        )));
    }
    let expected = texture.width as usize * texture.height as usize * 4;
    if texture.rgba8_srgb.len() != expected {
        return Err(RenderError::InvalidTexture(format!(
            "{}×{} needs {expected} bytes, got {}",
            texture.width,
            texture.height,
            texture.rgba8_srgb.len()
        )));
    }
    Ok(())
}

/// Uploads `texture` (RGBA8 sRGB) with its mipmaps, filtered in linear light.
fn upload_texture(ctx: &GpuContext, texture: &Texture) -> wgpu::Texture {
    let levels = mip_chain_linear(texture);
    let gpu_texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("baseline base colour"),
        size: wgpu::Extent3d { width: texture.width, height: texture.height, depth_or_array_layers: 1 },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (level, (w, h, data)) in levels.iter().enumerate() {
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &gpu_texture,
                mip_level: level as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(w * 4), rows_per_image: Some(*h) },
            wgpu::Extent3d { width: *w, height: *h, depth_or_array_layers: 1 },
        );
    }
    gpu_texture
}

/// The baseline's vertices, three per face in texture order (untextured first), positions
/// relative to `origin`, with the vertex range each texture draws.
#[allow(clippy::type_complexity)]
fn baseline_vertices(
    source: &BaselineSource<'_>,
    origin: DVec3,
    texture_of: impl Fn(usize) -> Option<u32>,
) -> Result<(Vec<BaselineVertex>, Vec<(Option<u32>, std::ops::Range<u32>)>), RenderError> {
    let BaselineSource { positions, triangles, corner_uvs, corner_colors, .. } = *source;
    let relative = |v: u32| -> Result<Vec3, RenderError> {
        let p = positions.get(v as usize).ok_or_else(|| {
            RenderError::InvalidMesh(format!("vertex {v} out of range ({} vertices)", positions.len()))
        })?;
        Ok((DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) - origin).as_vec3())
    };
    let vertex_normals = meshpaint_core::mesh::normals::vertex_normals(positions, triangles);
    // Faces in texture order (untextured first), so each texture draws one vertex range.
    let mut order: Vec<usize> = (0..triangles.len()).collect();
    order.sort_by_key(|&face| texture_of(face));
    let mut vertices = Vec::with_capacity(triangles.len() * 3);
    let mut ranges: Vec<(Option<u32>, std::ops::Range<u32>)> = Vec::new();
    for &face in &order {
        let key = texture_of(face);
        let first = vertices.len() as u32;
        match ranges.last_mut() {
            Some((last, range)) if *last == key => range.end = first + 3,
            _ => ranges.push((key, first..first + 3)),
        }
        let corners = triangles[face];
        let p = [relative(corners[0])?, relative(corners[1])?, relative(corners[2])?];
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let normal = if n.length() > 0.0 && n.length().is_finite() { n.normalize() } else { Vec3::Z };
        for k in 0..3 {
            let vertex_normal = vertex_normals.get(corners[k] as usize).map_or([0.0; 3], |n| n.map(|x| x as f32));
            vertices.push(BaselineVertex {
                position: p[k].to_array(),
                uv: corner_uvs[face][k],
                normal: normal.to_array(),
                color: corner_colors[face][k],
                corner_normal: meshpaint_core::mesh::normals::smooth_corner_normal(vertex_normal, normal.to_array()),
            });
        }
    }
    Ok((vertices, ranges))
}
