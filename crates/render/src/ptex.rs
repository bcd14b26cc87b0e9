//! A packed Ptex on the GPU (crates/core/src/ptex): the packed texture as one filterable
//! texture (clamp-to-edge: every block carries its own border), the 4-byte face records as an
//! R32Uint data texture, the `nRes` / `nRow` tables as a 13-entry storage buffer; positions,
//! vertex ids and normals are the [`GpuMesh`](super::GpuMesh)'s own textures. It binds
//! against the MCT bind-group layout (same bindings: uniforms, geometry, records, a
//! filterable texture, its sampler, a storage table; the anisotropic sampler slot gets the
//! bilinear one), so the Ptex pipeline adds no layout.

use glam::DVec3;

use super::layouts::BindLayouts;
use super::mesh_gpu::{atlas_texture_format, data_texture};
use super::{GpuContext, MeshGeometry, RenderError};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::ptex::{PackedPtex, PtexFaceRecord, PtexTables, SLICES};

/// One slice's entry of the tables as shaders/ptex.wgsl reads it (`ptex_tables`):
/// `nRes[k]`, `nRow[k]`, blocks per row, 0. Keep in sync with the shader.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuPtexSlice {
    /// First block with level-0 resolution `2^k` or more.
    pub n_res: u32,
    /// First texture row of the slice.
    pub n_row: u32,
    /// Blocks per row (at least 1).
    pub per_row: u32,
    /// Padding to 16 bytes.
    pub pad: u32,
}

const _: () = assert!(std::mem::size_of::<GpuPtexSlice>() == 16);

/// The tables as the shader reads them, one entry per slice.
pub fn gpu_tables(tables: &PtexTables) -> [GpuPtexSlice; SLICES] {
    std::array::from_fn(|k| GpuPtexSlice {
        n_res: tables.n_res[k],
        n_row: tables.n_row[k],
        per_row: tables.per_row[k].max(1),
        pad: 0,
    })
}

/// A packed Ptex uploaded for the Ptex pipeline, drawn with its mesh's geometry.
#[derive(Debug)]
pub struct GpuPtex {
    /// The mesh's render origin.
    pub origin: DVec3,
    /// Number of faces.
    pub face_count: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Levels trilinear filtering clamps to.
    pub levels: u32,
    /// Texel encoding.
    pub format: ColorFormat,
    /// Texture size in texels.
    pub size: [u32; 2],
    texture: wgpu::Texture,
    records: wgpu::Texture,
    tables: wgpu::Buffer,
    pub(crate) uniforms: wgpu::Buffer,
    pub(crate) bind_group: wgpu::BindGroup,
}

impl GpuPtex {
    /// Uploads `ptex` (built from the packed mesh whose GPU mesh has the geometry `mesh`)
    /// against the renderer's `layouts`. RGBA32F textures need the adapter's
    /// `FLOAT32_FILTERABLE`. [`super::Gpu::upload_ptex`] is the short form.
    pub fn upload(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        mesh: &MeshGeometry,
        ptex: &PackedPtex,
    ) -> Result<Self, RenderError> {
        ctx.checked(|| Self::upload_unchecked(ctx, layouts, mesh, ptex))
    }

    fn upload_unchecked(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        mesh: &MeshGeometry,
        ptex: &PackedPtex,
    ) -> Result<Self, RenderError> {
        let (width, height) = check(ctx, mesh, ptex)?;
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("packed Ptex"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: atlas_texture_format(ptex.format),
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        write_texture(ctx, &texture, ptex);
        let records = data_texture(
            ctx,
            "Ptex face records",
            wgpu::TextureFormat::R32Uint,
            bytemuck::cast_slice::<PtexFaceRecord, u8>(&ptex.layout.records),
        )?;
        let table = gpu_tables(&ptex.layout.tables);
        let tables = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("Ptex nRes / nRow"),
            size: std::mem::size_of_val(&table) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&tables, 0, bytemuck::cast_slice(&table));
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("Ptex bilinear"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        });
        let uniforms = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("Ptex uniforms"),
            size: std::mem::size_of::<super::FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view = |texture: &wgpu::Texture| texture.create_view(&wgpu::TextureViewDescriptor::default());
        let (positions, indices, normals) = (&mesh.positions, &mesh.indices, &mesh.normals);
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("Ptex bind group"),
            layout: layouts.mct(),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view(positions)) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&view(indices)) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&view(&records)) },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&view(&texture)) },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&view(normals)) },
                wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::Sampler(&sampler) },
                wgpu::BindGroupEntry { binding: 7, resource: tables.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 8, resource: wgpu::BindingResource::Sampler(&sampler) },
            ],
        });
        Ok(GpuPtex {
            origin: mesh.origin,
            face_count: mesh.face_count,
            vertex_count: mesh.vertex_count,
            levels: ptex.layout.levels,
            format: ptex.format,
            size: [width, height],
            texture,
            records,
            tables,
            uniforms,
            bind_group,
        })
    }

    /// GPU memory the packed Ptex adds to its mesh's geometry: the texture, the records'
    /// data texture and the tables, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        let texture =
            u64::from(self.texture.width()) * u64::from(self.texture.height()) * self.format.bytes_per_sample() as u64;
        let records = u64::from(self.records.width()) * u64::from(self.records.height()) * 4;
        texture + records + self.tables.size()
    }
}

/// The texture size, or why `ptex` cannot be drawn with `mesh` on this device.
fn check(ctx: &GpuContext, mesh: &MeshGeometry, ptex: &PackedPtex) -> Result<(u32, u32), RenderError> {
    let (width, height) = (ptex.layout.width, ptex.layout.height);
    let max_dimension = ctx.limits().max_texture_dimension_2d;
    if width == 0 || height == 0 || width > max_dimension || height > max_dimension {
        return Err(RenderError::InvalidTexture(format!(
            "packed Ptex texture {width}×{height} is outside 1..={max_dimension} per side"
        )));
    }
    if ptex.layout.records.len() != mesh.face_count as usize {
        return Err(RenderError::InvalidMesh(format!(
            "{} Ptex face records for {} faces",
            ptex.layout.records.len(),
            mesh.face_count
        )));
    }
    let bpp = ptex.format.bytes_per_sample() as u64;
    if ptex.texels.len() as u64 != u64::from(width) * u64::from(height) * bpp {
        return Err(RenderError::InvalidTexture(format!(
            "{} texture bytes for {width}×{height} texels of {bpp} bytes",
            ptex.texels.len()
        )));
    }
    if ptex.format == ColorFormat::Rgba32F && !ctx.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
        return Err(RenderError::InvalidTexture(
            "an RGBA32F packed Ptex needs a GPU that filters 32-bit float textures \
             (FLOAT32_FILTERABLE); pack with RGBA16F or RGBA8"
                .into(),
        ));
    }
    Ok((width, height))
}

/// Uploads the texels in bands of rows, so that no single write stages the whole texture.
fn write_texture(ctx: &GpuContext, texture: &wgpu::Texture, ptex: &PackedPtex) {
    let (width, height) = (ptex.layout.width, ptex.layout.height);
    let bpp = ptex.format.bytes_per_sample() as u64;
    let row_bytes = u64::from(width) * bpp;
    let band_rows = ((64u64 << 20) / row_bytes).max(1);
    let mut y = 0u64;
    while y < u64::from(height) {
        let rows = band_rows.min(u64::from(height) - y);
        let start = (y * row_bytes) as usize;
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: y as u32, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            &ptex.texels[start..start + (rows * row_bytes) as usize],
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
