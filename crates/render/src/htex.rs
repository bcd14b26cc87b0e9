//! Htex on the GPU (crates/core/src/htex): the atlas pages as one filterable 2D texture
//! array, the border-normalisation blocks as a small R8 texture, the face records and
//! block origins as one R32Uint data texture; positions, vertex ids and normals are the
//! [`GpuMesh`](super::GpuMesh)'s own textures, so switching representation uploads only
//! what Htex adds. The pipelines are the renderer's (crates/render/src/renderer.rs
//! `HtexPipelines`), the bind-group layout is in crates/render/src/layouts.rs.

use glam::DVec3;

use super::layouts::BindLayouts;
use super::mesh_gpu::{atlas_texture_format, data_texture};
use super::uniforms::FrameUniforms;
use super::{GpuContext, MeshGeometry, RenderError};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::htex::HtexTexture;

/// An Htex uploaded for the Htex pipeline, drawn with its mesh's geometry.
#[derive(Debug)]
pub struct GpuHtex {
    /// The mesh's render origin.
    pub origin: DVec3,
    /// Number of faces.
    pub face_count: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// MIP levels.
    pub levels: u32,
    /// Page encoding.
    pub format: ColorFormat,
    pages: wgpu::Texture,
    weights: wgpu::Texture,
    records: wgpu::Texture,
    pub(crate) uniforms: wgpu::Buffer,
    pub(crate) bind_group: wgpu::BindGroup,
}

impl GpuHtex {
    /// Uploads `htex` (built from the packed mesh whose GPU mesh has the geometry `mesh`)
    /// against the renderer's `layouts`. RGBA32F pages need the adapter's
    /// `FLOAT32_FILTERABLE`.
    pub fn upload(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        mesh: &MeshGeometry,
        htex: &HtexTexture,
    ) -> Result<Self, RenderError> {
        ctx.checked(|| Self::upload_unchecked(ctx, layouts, mesh, htex))
    }

    fn upload_unchecked(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        mesh: &MeshGeometry,
        htex: &HtexTexture,
    ) -> Result<Self, RenderError> {
        check(ctx, mesh, htex)?;
        let layout = &htex.layout;
        let (side, height, pages_count) = (layout.page_size, layout.page_height, layout.pages);
        let pages = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("htex pages"),
            size: wgpu::Extent3d { width: side, height, depth_or_array_layers: pages_count },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: atlas_texture_format(htex.format),
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        write_pages(ctx, &pages, htex);
        let [ww, wh] = layout.weight_size;
        let weights = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("htex border normalisation"),
            size: wgpu::Extent3d { width: ww, height: wh, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        write(ctx, &weights, [0, 0, 0], &htex.weights, u64::from(ww), [ww, wh]);
        let mut words: Vec<u32> = layout.face_records.iter().flatten().copied().collect();
        words.extend_from_slice(&layout.origins);
        let records =
            data_texture(ctx, "Htex records and origins", wgpu::TextureFormat::R32Uint, bytemuck::cast_slice(&words))?;
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("htex bilinear"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        });
        let uniforms = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("htex uniforms"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view = |texture: &wgpu::Texture| texture.create_view(&wgpu::TextureViewDescriptor::default());
        let pages_view = pages.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let tv = wgpu::BindingResource::TextureView;
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("htex bind group"),
            layout: layouts.htex(),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: tv(&view(&mesh.positions)) },
                wgpu::BindGroupEntry { binding: 2, resource: tv(&view(&mesh.indices)) },
                wgpu::BindGroupEntry { binding: 3, resource: tv(&view(&records)) },
                wgpu::BindGroupEntry { binding: 4, resource: tv(&pages_view) },
                wgpu::BindGroupEntry { binding: 5, resource: tv(&view(&mesh.normals)) },
                wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::Sampler(&sampler) },
                wgpu::BindGroupEntry { binding: 7, resource: tv(&view(&weights)) },
            ],
        });
        Ok(GpuHtex {
            origin: mesh.origin,
            face_count: mesh.face_count,
            vertex_count: mesh.vertex_count,
            levels: layout.levels,
            format: htex.format,
            pages,
            weights,
            records,
            uniforms,
            bind_group,
        })
    }

    /// GPU memory Htex adds to its mesh's geometry: pages, weight texture and records.
    pub fn gpu_bytes(&self) -> u64 {
        let size = |t: &wgpu::Texture, bpp: u64| {
            u64::from(t.width()) * u64::from(t.height()) * u64::from(t.depth_or_array_layers()) * bpp
        };
        size(&self.pages, self.format.bytes_per_sample() as u64) + size(&self.weights, 1) + size(&self.records, 4)
    }
}

/// Uploads every page in bands of rows, so that no single write stages a whole page.
fn write_pages(ctx: &GpuContext, pages: &wgpu::Texture, htex: &HtexTexture) {
    let (side, height) = (htex.layout.page_size, u64::from(htex.layout.page_height));
    let bpp = htex.format.bytes_per_sample() as u64;
    let row_bytes = u64::from(side) * bpp;
    let band_rows = ((64u64 << 20) / row_bytes).clamp(1, height);
    for page in 0..htex.layout.pages {
        let mut y = 0u64;
        while y < height {
            let rows = band_rows.min(height - y);
            let start = ((u64::from(page) * height + y) * row_bytes) as usize;
            let bytes = &htex.texels[start..start + (rows * row_bytes) as usize];
            write(ctx, pages, [0, y as u32, page], bytes, row_bytes, [side, rows as u32]);
            y += rows;
        }
    }
}

fn write(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    [x, y, z]: [u32; 3],
    bytes: &[u8],
    row_bytes: u64,
    [w, h]: [u32; 2],
) {
    ctx.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d { x, y, z },
            aspect: wgpu::TextureAspect::All,
        },
        bytes,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row_bytes as u32), rows_per_image: Some(h) },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
}

/// Why `htex` cannot be drawn with `mesh` on this device.
fn check(ctx: &GpuContext, mesh: &MeshGeometry, htex: &HtexTexture) -> Result<(), RenderError> {
    let layout = &htex.layout;
    let limits = ctx.limits();
    let side = layout.page_size.max(layout.page_height);
    if side == 0 || side > limits.max_texture_dimension_2d || layout.pages > limits.max_texture_array_layers {
        return Err(RenderError::InvalidTexture(format!(
            "{} Htex pages of {side}² texels exceed the device ({} per side, {} layers)",
            layout.pages, limits.max_texture_dimension_2d, limits.max_texture_array_layers
        )));
    }
    if layout.face_records.len() != mesh.face_count as usize {
        return Err(RenderError::InvalidMesh(format!(
            "{} Htex face records for {} faces",
            layout.face_records.len(),
            mesh.face_count
        )));
    }
    let bpp = htex.format.bytes_per_sample() as u64;
    if htex.texels.len() as u64 != layout.texel_count() * bpp
        || htex.weights.len() as u64 != u64::from(layout.weight_size[0]) * u64::from(layout.weight_size[1])
    {
        return Err(RenderError::InvalidTexture("Htex texel or weight bytes do not match the layout".into()));
    }
    if htex.format == ColorFormat::Rgba32F && !ctx.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
        return Err(RenderError::InvalidTexture(
            "an RGBA32F Htex needs a GPU that filters 32-bit float textures (FLOAT32_FILTERABLE); pack with RGBA16F or RGBA8"
                .into(),
        ));
    }
    Ok(())
}
