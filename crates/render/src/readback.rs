//! Reading a mesh's data back from the GPU: the colour atlas and the face records as the
//! shaders see them, for tests that compare the GPU copy with the store after partial
//! uploads ([`GpuMesh::write_samples`], [`GpuMesh::write_face_records`]).

use meshpaint_core::packing::linear::FaceRecord;

use super::RenderError;
use super::context::GpuContext;
use super::mesh_gpu::{DATA_TEXEL_BYTES, GpuMesh};

/// The first `texels` texels of `texture` (rows of `width` texels of `bytes_per_texel`
/// bytes), copied to a mappable buffer and read back.
fn read_texels(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    bytes_per_texel: u64,
    texels: u64,
) -> Result<Vec<u8>, RenderError> {
    let (width, height) = (texture.width(), texture.height());
    let row = u64::from(width) * bytes_per_texel;
    let padded_row = row.next_multiple_of(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT));
    let buffer = ctx.checked(|| {
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture readback"),
            size: padded_row * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder =
            ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
        let bytes_per_row = u32::try_from(padded_row).map_err(|_| RenderError::Readback("row too long".into()))?;
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(bytes_per_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        );
        ctx.queue.submit([encoder.finish()]);
        Ok(buffer)
    })?;
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |result| {
        let _ = sender.send(result);
    });
    ctx.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|error| RenderError::Readback(error.to_string()))?;
    receiver
        .recv()
        .map_err(|error| RenderError::Readback(error.to_string()))?
        .map_err(|error| RenderError::Readback(error.to_string()))?;
    let wanted = usize::try_from(texels * bytes_per_texel).map_err(|_| RenderError::Readback("too large".into()))?;
    let mut out = Vec::with_capacity(wanted);
    {
        let mapped = buffer.get_mapped_range(..).map_err(|error| RenderError::Readback(error.to_string()))?;
        for chunk in mapped.chunks_exact(padded_row as usize) {
            let take = (wanted - out.len()).min(row as usize);
            out.extend_from_slice(&chunk[..take]);
            if out.len() == wanted {
                break;
            }
        }
    }
    buffer.unmap();
    Ok(out)
}

impl GpuMesh {
    /// The colour atlas's samples as the GPU holds them (encoded in the mesh's format).
    pub fn read_samples(&self, ctx: &GpuContext) -> Result<Vec<u8>, RenderError> {
        read_texels(ctx, self.atlas_texture(), self.format.bytes_per_sample() as u64, self.atlas.samples)
    }

    /// The face records as the GPU holds them.
    pub fn read_face_records(&self, ctx: &GpuContext) -> Result<Vec<FaceRecord>, RenderError> {
        let bytes = read_texels(ctx, self.face_record_texture(), DATA_TEXEL_BYTES, u64::from(self.face_count))?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

/// Every texel of `texture` (its first mip level; `bytes_per_texel` bytes each, rows without
/// padding), read back: e.g. a view target to compare two drawings pixel for pixel. The
/// texture needs `COPY_SRC` usage.
pub fn read_texture(ctx: &GpuContext, texture: &wgpu::Texture, bytes_per_texel: u64) -> Result<Vec<u8>, RenderError> {
    read_texels(ctx, texture, bytes_per_texel, u64::from(texture.width()) * u64::from(texture.height()))
}
