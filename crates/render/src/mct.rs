//! A Mesh Color Texture on the GPU (crates/core/src/mct): the atlas as one filterable
//! texture (repeating in x), the 4-byte face records and strip-row masks as an R32Uint data
//! texture, the band table's entries in use as a storage buffer; positions, vertex ids and normals are the [`GpuMesh`]'s own textures,
//! so switching representation uploads only what MCT adds.

use glam::DVec3;

use super::layouts::BindLayouts;
use super::mesh_gpu::{atlas_texture_format, data_texture};
use super::{GpuContext, MeshGeometry, RenderError};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::mct::layout::GROUPS;
use meshpaint_core::mct::{MctFaceRecord, MctLayout, MeshColorTexture};

/// The anisotropic sampler's largest number of taps (wgpu's and Vulkan's usual limit).
/// Keep in sync with `MCT_MAX_ANISOTROPY` in shaders/mct.wgsl.
pub const MAX_ANISOTROPY: u16 = 16;

/// A Mesh Color Texture uploaded for the MCT pipeline, drawn with its mesh's geometry.
#[derive(Debug)]
pub struct GpuMct {
    /// The mesh's render origin.
    pub origin: DVec3,
    /// Number of faces.
    pub face_count: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// MIP levels of every face.
    pub levels: u32,
    /// Atlas encoding.
    pub format: ColorFormat,
    /// Atlas size in texels.
    pub atlas_size: [u32; 2],
    atlas: wgpu::Texture,
    records: wgpu::Texture,
    bands: wgpu::Buffer,
    pub(crate) uniforms: wgpu::Buffer,
    pub(crate) bind_group: wgpu::BindGroup,
}

impl GpuMct {
    /// Uploads `mct` (built from the packed mesh whose GPU mesh has the geometry `mesh`)
    /// against the renderer's `layouts`. RGBA32F atlases need the adapter's
    /// `FLOAT32_FILTERABLE`. [`super::Gpu::upload_mct`] is the short form.
    pub fn upload(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        mesh: &MeshGeometry,
        mct: &MeshColorTexture,
    ) -> Result<Self, RenderError> {
        ctx.checked(|| Self::upload_unchecked(ctx, layouts, mesh, mct))
    }

    fn upload_unchecked(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        mesh: &MeshGeometry,
        mct: &MeshColorTexture,
    ) -> Result<Self, RenderError> {
        let (width, height) = check(ctx, mesh, mct)?;
        let atlas = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("mesh color texture atlas"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: atlas_texture_format(mct.format),
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        write_atlas(ctx, &atlas, mct);
        let mut words: Vec<u32> = bytemuck::cast_slice::<MctFaceRecord, u32>(&mct.layout.records).to_vec();
        words.extend_from_slice(&mct.layout.masks);
        let records = data_texture(
            ctx,
            "MCT face records",
            wgpu::TextureFormat::R32Uint,
            bytemuck::cast_slice::<u32, u8>(&words),
        )?;
        let table = gpu_bands(&mct.layout);
        let bands = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("MCT band table"),
            size: std::mem::size_of_val(table.as_slice()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&bands, 0, bytemuck::cast_slice(&table));
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("MCT bilinear"),
            // Tents cross the atlas's right edge and continue at its left (layout.rs).
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        });
        // All three filters linear, as anisotropy needs (the atlas has one level); wgpu sets
        // the clamp to 1 where the adapter has no anisotropic filtering.
        let anisotropic = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("MCT anisotropic"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            anisotropy_clamp: MAX_ANISOTROPY,
            ..Default::default()
        });
        let uniforms = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("MCT uniforms"),
            size: std::mem::size_of::<super::FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view = |texture: &wgpu::Texture| texture.create_view(&wgpu::TextureViewDescriptor::default());
        let (positions, indices, normals) = (&mesh.positions, &mesh.indices, &mesh.normals);
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("MCT bind group"),
            layout: layouts.mct(),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view(positions)) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&view(indices)) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&view(&records)) },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&view(&atlas)) },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&view(normals)) },
                wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::Sampler(&sampler) },
                wgpu::BindGroupEntry { binding: 7, resource: bands.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 8, resource: wgpu::BindingResource::Sampler(&anisotropic) },
            ],
        });
        Ok(GpuMct {
            origin: mesh.origin,
            face_count: mesh.face_count,
            vertex_count: mesh.vertex_count,
            levels: mct.layout.levels,
            format: mct.format,
            atlas_size: [width, height],
            atlas,
            records,
            bands,
            uniforms,
            bind_group,
        })
    }

    /// GPU memory MCT adds to its mesh's geometry: the atlas, the records' data texture
    /// and the band table, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        let atlas =
            u64::from(self.atlas.width()) * u64::from(self.atlas.height()) * self.format.bytes_per_sample() as u64;
        let records = u64::from(self.records.width()) * u64::from(self.records.height()) * 4;
        atlas + records + self.bands.size()
    }
}

/// The band table as shaders/mct.wgsl reads it (`mct_bands`): at index `g · levels + l`
/// for every group up to the finest ([`MctLayout::gpu_band_entries`] entries), the bands of
/// group `g` at level `l` and at the next level `min(l + 1, levels − 1)`, each
/// `y | per_row << 16` (`per_row` at least 1), their empty leading slots (`l | next << 16`)
/// and the group's strip rows (`log2 S | pieces << 3 | first mask << 9`, the mask's index
/// counted from the first mask: the shader adds the face count), so that one lookup gives a
/// fragment both of its levels. `check` keeps y, per_row and skip below 2^16.
fn gpu_bands(layout: &MctLayout) -> Vec<[u32; 4]> {
    let levels = layout.levels.max(1) as usize;
    let bands = &layout.bands;
    let packed = |g: usize, level: usize| {
        let [y, per_row, ..] = bands.bands[g * GROUPS + level];
        y | (per_row.max(1) << 16)
    };
    let skip = |g: usize, level: usize| bands.bands[g * GROUPS + level][2] & 0xffff;
    (0..layout.gpu_band_entries() as usize)
        .map(|index| {
            let (g, level) = (index / levels, index % levels);
            let next = (level + 1).min(levels - 1);
            [packed(g, level), packed(g, next), skip(g, level) | (skip(g, next) << 16), bands.bands[g * GROUPS][3]]
        })
        .collect()
}

/// The atlas size, or why `mct` cannot be drawn with `mesh` on this device.
fn check(ctx: &GpuContext, mesh: &MeshGeometry, mct: &MeshColorTexture) -> Result<(u32, u32), RenderError> {
    let (width, height) = (mct.layout.width, mct.layout.height);
    // The band table packs rows and blocks per row in 16 bits (`gpu_bands`).
    let max_dimension = ctx.limits().max_texture_dimension_2d.min(u32::from(u16::MAX));
    if width == 0 || height == 0 || width > max_dimension || height > max_dimension {
        return Err(RenderError::InvalidTexture(format!(
            "Mesh Color Texture atlas {width}×{height} is outside 1..={max_dimension} per side"
        )));
    }
    if mct.layout.records.len() != mesh.face_count as usize {
        return Err(RenderError::InvalidMesh(format!(
            "{} MCT face records for {} faces",
            mct.layout.records.len(),
            mesh.face_count
        )));
    }
    let bpp = mct.format.bytes_per_sample() as u64;
    if mct.texels.len() as u64 != u64::from(width) * u64::from(height) * bpp {
        return Err(RenderError::InvalidTexture(format!(
            "{} atlas bytes for {width}×{height} texels of {bpp} bytes",
            mct.texels.len()
        )));
    }
    if mct.format == ColorFormat::Rgba32F && !ctx.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
        return Err(RenderError::InvalidTexture(
            "an RGBA32F Mesh Color Texture needs a GPU that filters 32-bit float textures \
             (FLOAT32_FILTERABLE); pack with RGBA16F or RGBA8"
                .into(),
        ));
    }
    Ok((width, height))
}

/// Uploads the atlas texels in bands of rows, so that no single write stages the whole atlas.
fn write_atlas(ctx: &GpuContext, atlas: &wgpu::Texture, mct: &MeshColorTexture) {
    let (width, height) = (mct.layout.width, mct.layout.height);
    let bpp = mct.format.bytes_per_sample() as u64;
    let row_bytes = u64::from(width) * bpp;
    let band_rows = ((64u64 << 20) / row_bytes).max(1);
    let mut y = 0u64;
    while y < u64::from(height) {
        let rows = band_rows.min(u64::from(height) - y);
        let start = (y * row_bytes) as usize;
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: atlas,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: y as u32, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            &mct.texels[start..start + (rows * row_bytes) as usize],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row_bytes as u32),
                rows_per_image: Some(rows as u32),
            },
            wgpu::Extent3d { width, height: rows as u32, depth_or_array_layers: 1 },
        );
        y += rows;
    }
}
