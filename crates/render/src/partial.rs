//! Partial redraws while painting: after a dab, only the faces whose colours changed are
//! drawn again, into the previous frame's colour and depth (same camera, same geometry),
//! inside the screen rectangle they cover.
//!
//! Why this gives the pixels of a full redraw: the geometry did not change, so the depth
//! buffer still holds, at every pixel, the depth of the face a full frame shows there. A
//! changed face drawn again with the depth test `LessEqual` (and no depth write) passes
//! exactly where it is that face — its depth there is the stored one, computed by the same
//! vertex shader from the same data — and fails where a nearer face hides it; every other
//! pixel shows a face whose colours did not change and keeps its colour. Faces are drawn in
//! descending id order, so where two changed faces tie in depth the lower id ends on top,
//! as in a full frame (`Less`: the first drawn wins). The mesh-colors shader pulls its
//! vertices (`face = vertex_index / 3`), so the subset is an index buffer of
//! `3f, 3f + 1, 3f + 2` per face and the shader is the same.

use super::renderer::{DrawItem, RenderSettings, RenderTarget, Renderer};
use super::{GpuContext, GpuMesh};

/// A rectangle of a render target in pixels: `[x, y, width, height]`, origin top left.
pub type Scissor = [u32; 4];

/// The faces a partial redraw draws: an index buffer on the GPU, grown as needed.
#[derive(Debug, Default)]
pub struct FaceSubset {
    buffer: Option<wgpu::Buffer>,
    /// Indices written (three per face).
    count: u32,
}

impl FaceSubset {
    /// An empty subset (no GPU memory yet).
    pub fn new() -> Self {
        Self::default()
    }

    /// Faces in the subset.
    pub fn face_count(&self) -> u32 {
        self.count / 3
    }

    /// Bytes of GPU memory held.
    pub fn gpu_bytes(&self) -> u64 {
        self.buffer.as_ref().map_or(0, wgpu::Buffer::size)
    }

    /// Replaces the subset with `faces` (drawn in descending id order, whatever their order
    /// here; duplicates are drawn once).
    pub fn write(&mut self, ctx: &GpuContext, faces: &[u32]) {
        let mut sorted = faces.to_vec();
        sorted.sort_unstable_by(|a, b| b.cmp(a));
        sorted.dedup();
        let indices: Vec<u32> = sorted.iter().flat_map(|&f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
        let bytes: &[u8] = bytemuck::cast_slice(&indices);
        let size = (bytes.len() as u64).max(4).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
        if self.buffer.as_ref().is_none_or(|buffer| buffer.size() < size) {
            self.buffer = Some(ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("partial redraw faces"),
                size: size.next_power_of_two().max(4096),
                usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        if let Some(buffer) = &self.buffer
            && !bytes.is_empty()
        {
            ctx.queue.write_buffer(buffer, 0, bytes);
        }
        self.count = u32::try_from(indices.len()).unwrap_or(0);
    }
}

impl Renderer {
    /// Records a render pass that draws the faces of `faces` of `mesh` into `target` over
    /// what it holds (the previous full frame of the same `settings` and size, and any
    /// partial redraws since), inside `scissor` (clamped to the target). See the module
    /// documentation for why this equals a full redraw. Uniforms are written through
    /// `ctx.queue`, as [`Renderer::draw`] does.
    pub fn draw_partial(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget<'_>,
        (mesh, settings): (&GpuMesh, &RenderSettings),
        faces: &FaceSubset,
        scissor: Scissor,
    ) {
        let [x, y, w, h] = scissor;
        let (x, y) = (x.min(target.width), y.min(target.height));
        let (w, h) = (w.min(target.width - x), h.min(target.height - y));
        let Some(buffer) = faces.buffer.as_ref().filter(|_| faces.count > 0 && w > 0 && h > 0) else {
            return;
        };
        let uniforms = Self::uniforms(DrawItem::MeshColors(mesh), settings, target.width, target.height);
        ctx.queue.write_buffer(&mesh.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let pipeline = self.partial_pipeline(ctx, &uniforms);
        let load = |view| wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("meshpaint partial redraw"),
            color_attachments: &[Some(load(target.color))],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: target.depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &mesh.bind_group, &[]);
        pass.set_index_buffer(buffer.slice(..u64::from(faces.count) * 4), wgpu::IndexFormat::Uint32);
        pass.set_scissor_rect(x, y, w, h);
        pass.draw_indexed(0..faces.count, 0, 0..1);
    }
}
