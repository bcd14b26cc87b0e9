//! A [`PackedMesh`] on the GPU: positions, indices and face records in RGBA32 "data"
//! textures (one 16-byte entry per texel), the colour buffer in a 2D colour-atlas texture.
//!
//! Why textures and not storage buffers for the vertex-pulling data: the vertex shader
//! reads a whole entry (a position, a face's three vertex ids, a face record) with one
//! texel fetch. On software rasterisers (lavapipe) a storage-buffer load with a per-lane
//! address runs a scalar loop per component, which took a noticeable share of a frame on
//! dense meshes (Bunny, 144 k triangles). Textures also lift the storage binding limit
//! (128 MiB on lavapipe): a data texture holds up to
//! `MESH_DATA_WIDTH × max_texture_dimension_2d` entries (67 M with 16384 rows).

use glam::DVec3;

use super::layouts::BindLayouts;
use super::{GpuContext, RenderError};
use meshpaint_core::camera::BoundingSphere;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::packing::linear::{FaceRecord, PackedMesh};
use meshpaint_core::packing::lod::VertexLod;

/// The default atlas width: `min(16384, max_texture_dimension_2d)`.
///
/// A 16384² atlas holds `2^28` samples, [`meshpaint_core::packing::linear::MAX_SAMPLES`] exactly.
pub fn default_atlas_width(limits: &wgpu::Limits) -> u32 {
    limits.max_texture_dimension_2d.min(16384)
}

/// Bytes written per `write_texture` call when uploading many rows (bounds staging memory).
const UPLOAD_BAND_BYTES: u64 = 64 << 20;

/// Row width of the data textures (positions, indices, face records): entry `k` is texel
/// `(k % MESH_DATA_WIDTH, k / MESH_DATA_WIDTH)`. Keep in sync with `MESH_DATA_WIDTH_LOG2` in
/// shaders/mesh_colors.wgsl.
const MESH_DATA_WIDTH: u32 = 1 << 12;

/// Bytes per data-texture entry (one RGBA32 texel).
pub(super) const DATA_TEXEL_BYTES: u64 = 16;

/// Writes `data` (whole texels of `bytes_per_texel`) into `texture`, whose rows are `width`
/// texels, starting at texel index `first` (texel `(first % width, first / width)`): partial
/// rows at the ends, bands of full rows in between. Each write is staged in a buffer of its
/// own that lives until the GPU has run its copy, so a write of many bands is submitted and
/// waited for band by band: at most one band ([`UPLOAD_BAND_BYTES`]) is staged at a time
/// instead of the whole atlas beside its texture (on lavapipe both are host memory).
fn write_texel_rows(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    width: u32,
    bytes_per_texel: u64,
    first: u64,
    data: &[u8],
) {
    let count = data.len() as u64 / bytes_per_texel;
    let width = u64::from(width);
    let band_rows = (UPLOAD_BAND_BYTES / (width * bytes_per_texel)).max(1);
    let mut done = 0u64;
    let mut staged = 0u64;
    while done < count {
        if staged >= UPLOAD_BAND_BYTES {
            ctx.queue.submit([]);
            // A failed wait leaves the staging to the next submission: only memory is at stake.
            let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
            staged = 0;
        }
        let (x, y) = ((first + done) % width, (first + done) / width);
        let remaining = count - done;
        // A partial row (unaligned start or the tail), else a band of full rows.
        let (texels_per_row, rows) = if x != 0 || remaining < width {
            ((width - x).min(remaining), 1)
        } else {
            (width, (remaining / width).min(band_rows))
        };
        let start = (done * bytes_per_texel) as usize;
        let end = start + (texels_per_row * rows * bytes_per_texel) as usize;
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: x as u32, y: y as u32, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            &data[start..end],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some((texels_per_row * bytes_per_texel) as u32),
                rows_per_image: Some(rows as u32),
            },
            wgpu::Extent3d { width: texels_per_row as u32, height: rows as u32, depth_or_array_layers: 1 },
        );
        done += texels_per_row * rows;
        staged += texels_per_row * rows * bytes_per_texel;
    }
}

/// A data texture of `format` (RGBA32 float or uint) holding `entries` 16-byte entries in
/// rows of [`MESH_DATA_WIDTH`], filled with `bytes`; refused when it needs more rows than
/// the device allows.
pub(super) fn data_texture(
    ctx: &GpuContext,
    what: &'static str,
    format: wgpu::TextureFormat,
    bytes: &[u8],
) -> Result<wgpu::Texture, RenderError> {
    let texel_bytes = texel_bytes(format);
    let entries = bytes.len() as u64 / texel_bytes;
    let rows = entries.div_ceil(u64::from(MESH_DATA_WIDTH)).max(1);
    let max_dimension = ctx.limits().max_texture_dimension_2d;
    let height = u32::try_from(rows).ok().filter(|&rows| rows <= max_dimension).ok_or_else(|| {
        RenderError::InvalidMesh(format!(
            "{entries} {what} need {rows} texture rows of {MESH_DATA_WIDTH}, more than the device's {max_dimension}"
        ))
    })?;
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(what),
        size: wgpu::Extent3d { width: MESH_DATA_WIDTH, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        // COPY_SRC: tests read the GPU copy back (super::readback).
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    write_texel_rows(ctx, &texture, MESH_DATA_WIDTH, texel_bytes, 0, bytes);
    Ok(texture)
}

/// Bytes per texel of a data-texture format (16 for the RGBA32 ones, 8 for the normals).
fn texel_bytes(format: wgpu::TextureFormat) -> u64 {
    format.block_copy_size(None).map_or(DATA_TEXEL_BYTES, u64::from)
}

/// Bytes of a data texture's level 0.
fn data_texture_bytes(texture: &wgpu::Texture) -> u64 {
    u64::from(texture.width()) * u64::from(texture.height()) * texel_bytes(texture.format())
}

/// Where samples live in the colour atlas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AtlasLayout {
    /// Atlas width `W` in texels.
    pub width: u32,
    /// Atlas height: `ceil(samples / W)` rows, at least 1.
    pub height: u32,
    /// Samples stored.
    pub samples: u64,
}

impl AtlasLayout {
    /// The layout of `samples` samples in rows of `width`, checked against `max_dimension`.
    pub fn new(samples: u64, width: u32, max_dimension: u32) -> Result<Self, RenderError> {
        if width == 0 || width > max_dimension {
            return Err(RenderError::InvalidAtlasWidth { width, max_dimension });
        }
        let rows = samples.div_ceil(u64::from(width)).max(1);
        let height = u32::try_from(rows)
            .ok()
            .filter(|&height| height <= max_dimension)
            .ok_or(RenderError::AtlasTooLarge { samples, width, rows, max_dimension })?;
        Ok(AtlasLayout { width, height, samples })
    }

    /// The texel `(x, y)` of sample `index`: `(index % W, index / W)`.
    pub fn texel(&self, index: u64) -> (u32, u32) {
        let width = u64::from(self.width);
        ((index % width) as u32, (index / width) as u32)
    }
}

/// How to upload a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshUploadOptions {
    /// Atlas width; `None` means [`default_atlas_width`]. Tests force tiny widths (e.g. 61)
    /// to prove the wrapping.
    pub atlas_width: Option<u32>,
}

/// The texture format holding samples of `format`: RGBA8 sRGB → `Rgba8UnormSrgb` (decoded
/// to linear by `textureLoad`), RGBA16F → `Rgba16Float`, RGBA32F → `Rgba32Float`.
pub fn atlas_texture_format(format: ColorFormat) -> wgpu::TextureFormat {
    match format {
        ColorFormat::Rgba8Srgb => wgpu::TextureFormat::Rgba8UnormSrgb,
        ColorFormat::Rgba16F => wgpu::TextureFormat::Rgba16Float,
        ColorFormat::Rgba32F => wgpu::TextureFormat::Rgba32Float,
    }
}

/// The geometry of a [`GpuMesh`] that the other representations share
/// ([`GpuMesh::geometry`]): its render origin, counts, and the positions, vertex-id and
/// normal textures.
#[derive(Debug, Clone)]
pub struct MeshGeometry {
    /// The render origin ([`GpuMesh::origin`]).
    pub origin: DVec3,
    /// Number of faces.
    pub face_count: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    pub(crate) positions: wgpu::Texture,
    pub(crate) indices: wgpu::Texture,
    pub(crate) normals: wgpu::Texture,
}

impl MeshGeometry {
    /// Uploads a mesh's geometry alone (an MCT file's: no mesh colors), its vertices' level
    /// of detail and normals `lod` (`VertexLod::with_density`); returns it and its bounding
    /// sphere. Every index must be below the vertex count.
    pub fn upload(
        ctx: &GpuContext,
        positions: &[[f32; 3]],
        indices: &[[u32; 3]],
        lod: &VertexLod,
    ) -> Result<(Self, BoundingSphere), RenderError> {
        let vertex_count = u32::try_from(positions.len())
            .map_err(|_| RenderError::InvalidMesh(format!("{} vertices", positions.len())))?;
        if let Some((face, corners)) =
            indices.iter().enumerate().find(|(_, corners)| corners.iter().any(|&v| v >= vertex_count))
        {
            return Err(RenderError::InvalidMesh(format!(
                "face {face} uses vertex {corners:?}, but there are only {vertex_count} vertices"
            )));
        }
        if lod.density.len() != positions.len() || lod.normal_bits.len() != positions.len() {
            return Err(RenderError::InvalidMesh(format!(
                "{} level-of-detail densities for {} vertices",
                lod.density.len(),
                positions.len()
            )));
        }
        let bounds = BoundingSphere::of_points(positions);
        ctx.checked(|| Self::textures(ctx, positions, indices, lod, bounds)).map(|geometry| (geometry, bounds))
    }

    /// The positions (relative to the centre of `bounds`, with the density in w), vertex ids
    /// and normals as data textures.
    fn textures(
        ctx: &GpuContext,
        positions: &[[f32; 3]],
        indices: &[[u32; 3]],
        lod: &VertexLod,
        bounds: BoundingSphere,
    ) -> Result<Self, RenderError> {
        let origin = DVec3::from_array(bounds.center);
        let relative: Vec<[f32; 4]> = positions
            .iter()
            .zip(&lod.density)
            .map(|(p, &density)| {
                let p = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) - origin;
                [p.x as f32, p.y as f32, p.z as f32, density]
            })
            .collect();
        let corners: Vec<[u32; 4]> = indices.iter().map(|&[c0, c1, c2]| [c0, c1, c2, 0]).collect();
        let positions_texture = data_texture(
            ctx,
            "positions (relative to the render origin)",
            wgpu::TextureFormat::Rgba32Float,
            bytemuck::cast_slice(&relative),
        )?;
        let normals = data_texture(
            ctx,
            "vertex normals",
            wgpu::TextureFormat::Rgba16Float,
            bytemuck::cast_slice(&lod.normal_bits),
        )?;
        let indices_texture =
            data_texture(ctx, "faces' vertex ids", wgpu::TextureFormat::Rgba32Uint, bytemuck::cast_slice(&corners))?;
        Ok(MeshGeometry {
            origin,
            face_count: indices.len() as u32,
            vertex_count: positions.len() as u32,
            positions: positions_texture,
            indices: indices_texture,
            normals,
        })
    }
}

/// A packed mesh uploaded for the mesh-colors pipeline.
#[derive(Debug)]
pub struct GpuMesh {
    /// The render origin (bounding-sphere centre, world space, `f64`): positions on the GPU
    /// are `p − origin`, and cameras must use the same origin.
    pub origin: DVec3,
    /// The mesh's bounding sphere (for framing).
    pub bounds: BoundingSphere,
    /// Number of faces (the draw is `3 · face_count` vertices).
    pub face_count: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Colours per vertex in the colour buffer.
    pub vertex_levels: u32,
    /// Encoding of the colour atlas.
    pub format: ColorFormat,
    /// Where samples live in the atlas.
    pub atlas: AtlasLayout,
    /// Rgba32Float: x, y, z (relative to the origin), sample density per vertex
    /// ([`VertexLod`]).
    positions: wgpu::Texture,
    /// Rgba16Float: the unit vertex normal ([`VertexLod`]), 0.
    normals: wgpu::Texture,
    /// Rgba32Uint: c0, c1, c2, 0 per face.
    indices: wgpu::Texture,
    /// Rgba32Uint: the four words of each face's [`FaceRecord`].
    face_records: wgpu::Texture,
    atlas_texture: wgpu::Texture,
    pub(crate) uniforms: wgpu::Buffer,
    pub(crate) bind_group: wgpu::BindGroup,
}

impl GpuMesh {
    /// Uploads `packed` against the renderer's `layouts`: positions relative to the bounding-sphere
    /// centre (subtracted in `f64`), indices, face records and the colour atlas.
    pub fn upload(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        packed: &PackedMesh,
        options: &MeshUploadOptions,
    ) -> Result<Self, RenderError> {
        ctx.checked(|| Self::upload_unchecked(ctx, layouts, packed, options))
    }

    fn upload_unchecked(
        ctx: &GpuContext,
        layouts: &BindLayouts,
        packed: &PackedMesh,
        options: &MeshUploadOptions,
    ) -> Result<Self, RenderError> {
        let (vertex_count, face_count) = check_packed(packed)?;

        let limits = ctx.limits();
        let width = options.atlas_width.unwrap_or_else(|| default_atlas_width(&limits));
        let atlas = AtlasLayout::new(packed.sample_count(), width, limits.max_texture_dimension_2d)?;

        let bounds = BoundingSphere::of_points(&packed.positions);
        let MeshGeometry { origin, positions, indices, normals, .. } =
            MeshGeometry::textures(ctx, &packed.positions, &packed.indices, &VertexLod::of(packed), bounds)?;
        // A face record is four u32 words: exactly one Rgba32Uint texel.
        let face_records = data_texture(
            ctx,
            "face records",
            wgpu::TextureFormat::Rgba32Uint,
            bytemuck::cast_slice::<FaceRecord, u8>(&packed.face_records),
        )?;

        let atlas_texture = new_atlas_texture(ctx, &atlas, packed.format);
        let uniforms = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mesh colors uniforms"),
            size: std::mem::size_of::<super::FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group =
            mesh_bind_group(ctx, layouts, &uniforms, [&positions, &indices, &face_records, &atlas_texture, &normals]);
        let mesh = GpuMesh {
            origin,
            bounds,
            face_count,
            vertex_count,
            vertex_levels: packed.vertex_levels,
            format: packed.format,
            atlas,
            positions,
            normals,
            indices,
            face_records,
            atlas_texture,
            uniforms,
            bind_group,
        };
        mesh.write_samples(ctx, 0, &packed.colors)?;
        Ok(mesh)
    }

    /// Grows the colour atlas to hold `samples` (rows of the same width): the old texels are
    /// copied on the GPU, the new ones are zero (the encoding of a zero colour), so a paint
    /// layout that outgrew its buffer re-encodes and uploads nothing but its changes. Nothing
    /// happens when the atlas holds `samples` already.
    pub fn grow_atlas(&mut self, ctx: &GpuContext, layouts: &BindLayouts, samples: u64) -> Result<(), RenderError> {
        if samples <= self.atlas.samples {
            return Ok(());
        }
        let atlas = AtlasLayout::new(samples, self.atlas.width, ctx.limits().max_texture_dimension_2d)?;
        let texture = ctx.checked(|| {
            let texture = new_atlas_texture(ctx, &atlas, self.format);
            let mut encoder =
                ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("grow the atlas") });
            encoder.copy_texture_to_texture(
                self.atlas_texture.as_image_copy(),
                texture.as_image_copy(),
                wgpu::Extent3d { width: self.atlas.width, height: self.atlas.height, depth_or_array_layers: 1 },
            );
            ctx.queue.submit([encoder.finish()]);
            Ok(texture)
        })?;
        self.bind_group = mesh_bind_group(
            ctx,
            layouts,
            &self.uniforms,
            [&self.positions, &self.indices, &self.face_records, &texture, &self.normals],
        );
        self.atlas_texture = texture;
        self.atlas = atlas;
        Ok(())
    }

    /// Overwrites samples `first..first + n` of the colour atlas with `encoded` (`n` samples
    /// in the mesh's format), e.g. the dirty range of a paint stroke.
    pub fn write_samples(&self, ctx: &GpuContext, first: u64, encoded: &[u8]) -> Result<(), RenderError> {
        write_atlas_samples(ctx, (&self.atlas_texture, &self.atlas, self.format), first, encoded)
    }

    /// A handle to the colour atlas that another thread can write samples through
    /// ([`AtlasWriter::write_samples`]) while this mesh is drawn: leaving paint mode patches
    /// the mesh the view shows from its repack job. It writes into this atlas, not into one
    /// that [`GpuMesh::grow_atlas`] makes later.
    pub fn atlas_writer(&self) -> AtlasWriter {
        AtlasWriter { texture: self.atlas_texture.clone(), atlas: self.atlas, format: self.format }
    }

    /// Writes one paint-mode upload (the editor's path after a dab): the sample spans
    /// `(first, count)` from `buffer` (the whole encoded paint buffer,
    /// [`meshpaint_core::packing::paint_layout::EncodedBuffer::bytes`]) and the records of `faces`
    /// from `records` (all faces). Returns the bytes written; stops at the first write refused.
    pub fn write_paint_upload(
        &self,
        ctx: &GpuContext,
        spans: &[(u32, u32)],
        buffer: &[u8],
        (faces, records): (&[u32], &[FaceRecord]),
    ) -> Result<u64, RenderError> {
        let size = self.format.bytes_per_sample();
        let mut bytes = 0u64;
        for &(first, count) in spans {
            let (start, end) = (first as usize * size, (first as usize + count as usize) * size);
            let Some(data) = buffer.get(start..end) else {
                return Err(RenderError::InvalidMesh(format!(
                    "the upload span of {count} samples at {first} is past the {} samples encoded",
                    buffer.len() / size.max(1)
                )));
            };
            self.write_samples(ctx, u64::from(first), data)?;
            bytes += data.len() as u64;
        }
        for &face in faces {
            if let Some(record) = records.get(face as usize) {
                self.write_face_records(ctx, face, std::slice::from_ref(record))?;
                bytes += std::mem::size_of_val(record) as u64;
            }
        }
        Ok(bytes)
    }

    /// Overwrites face records `first_face..first_face + records.len()` (e.g. faces whose
    /// paint-layout blocks moved). Refuses writes past the face count.
    pub fn write_face_records(
        &self,
        ctx: &GpuContext,
        first_face: u32,
        records: &[FaceRecord],
    ) -> Result<(), RenderError> {
        if u64::from(first_face) + records.len() as u64 > u64::from(self.face_count) {
            return Err(RenderError::InvalidMesh(format!(
                "writing {} face records at face {first_face} overruns the {} faces",
                records.len(),
                self.face_count
            )));
        }
        if records.is_empty() {
            return Ok(());
        }
        let bytes = bytemuck::cast_slice::<FaceRecord, u8>(records);
        write_texel_rows(ctx, &self.face_records, MESH_DATA_WIDTH, DATA_TEXEL_BYTES, u64::from(first_face), bytes);
        Ok(())
    }

    /// The mesh's geometry on the GPU, which the other representations draw with (handles to
    /// the same textures: nothing is copied, and the handle can go to a worker thread).
    pub fn geometry(&self) -> MeshGeometry {
        MeshGeometry {
            origin: self.origin,
            face_count: self.face_count,
            vertex_count: self.vertex_count,
            positions: self.positions.clone(),
            indices: self.indices.clone(),
            normals: self.normals.clone(),
        }
    }

    pub(super) fn atlas_texture(&self) -> &wgpu::Texture {
        &self.atlas_texture
    }

    pub(super) fn face_record_texture(&self) -> &wgpu::Texture {
        &self.face_records
    }

    /// Bytes of the colour atlas texture.
    pub fn atlas_bytes(&self) -> u64 {
        u64::from(self.atlas.width) * u64::from(self.atlas.height) * self.format.bytes_per_sample() as u64
    }

    /// Bytes of the face-record data texture.
    pub fn face_record_bytes(&self) -> u64 {
        data_texture_bytes(&self.face_records)
    }

    /// GPU memory of the mesh's data textures and atlas, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        let atlas = u64::from(self.atlas.width) * u64::from(self.atlas.height) * self.format.bytes_per_sample() as u64;
        data_texture_bytes(&self.positions)
            + data_texture_bytes(&self.normals)
            + data_texture_bytes(&self.indices)
            + data_texture_bytes(&self.face_records)
            + atlas
    }
}

/// A mesh's colour atlas, writable from any thread ([`GpuMesh::atlas_writer`]).
#[derive(Debug, Clone)]
pub struct AtlasWriter {
    texture: wgpu::Texture,
    atlas: AtlasLayout,
    format: ColorFormat,
}

impl AtlasWriter {
    /// Overwrites samples `first..first + n` with `encoded` ([`GpuMesh::write_samples`]).
    pub fn write_samples(&self, ctx: &GpuContext, first: u64, encoded: &[u8]) -> Result<(), RenderError> {
        write_atlas_samples(ctx, (&self.texture, &self.atlas, self.format), first, encoded)
    }
}

/// Writes `encoded` (whole samples of `format`) into the atlas `texture` laid out as `atlas`
/// from sample `first` on; refuses writes past its samples.
fn write_atlas_samples(
    ctx: &GpuContext,
    (texture, atlas, format): (&wgpu::Texture, &AtlasLayout, ColorFormat),
    first: u64,
    encoded: &[u8],
) -> Result<(), RenderError> {
    let bytes_per_sample = format.bytes_per_sample() as u64;
    let count = encoded.len() as u64 / bytes_per_sample;
    if !(encoded.len() as u64).is_multiple_of(bytes_per_sample) || first.saturating_add(count) > atlas.samples {
        return Err(RenderError::InvalidMesh(format!(
            "writing {} bytes at sample {first} overruns the {} samples of the colour atlas",
            encoded.len(),
            atlas.samples
        )));
    }
    write_texel_rows(ctx, texture, atlas.width, bytes_per_sample, first, encoded);
    Ok(())
}

/// A colour atlas of `atlas`'s size for samples of `format` (new textures are zero).
fn new_atlas_texture(ctx: &GpuContext, atlas: &AtlasLayout, format: ColorFormat) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("colour atlas"),
        size: wgpu::Extent3d { width: atlas.width, height: atlas.height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: atlas_texture_format(format),
        // COPY_SRC: tests read the GPU copy back (super::readback), and a grown atlas copies
        // the old one.
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// The mesh-colors bind group: the uniforms, then positions, indices, face records, atlas
/// and normals (bindings 1–5).
fn mesh_bind_group(
    ctx: &GpuContext,
    layouts: &BindLayouts,
    uniforms: &wgpu::Buffer,
    [positions, indices, face_records, atlas, normals]: [&wgpu::Texture; 5],
) -> wgpu::BindGroup {
    let view = |texture: &wgpu::Texture| texture.create_view(&wgpu::TextureViewDescriptor::default());
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("mesh colors bind group"),
        layout: layouts.mesh(),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view(positions)) },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&view(indices)) },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&view(face_records)) },
            wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&view(atlas)) },
            wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&view(normals)) },
        ],
    })
}

/// Vertex and face counts of `packed`, or why it cannot be drawn: counts beyond `u32`, face
/// records and faces disagreeing, a corner out of range, a partial colour sample.
fn check_packed(packed: &PackedMesh) -> Result<(u32, u32), RenderError> {
    let vertex_count = u32::try_from(packed.positions.len())
        .map_err(|_| RenderError::InvalidMesh(format!("{} vertices", packed.positions.len())))?;
    let face_count = u32::try_from(packed.indices.len())
        .map_err(|_| RenderError::InvalidMesh(format!("{} faces", packed.indices.len())))?;
    if packed.face_records.len() != packed.indices.len() {
        return Err(RenderError::InvalidMesh(format!(
            "{} face records for {} faces",
            packed.face_records.len(),
            packed.indices.len()
        )));
    }
    if let Some((face, corners)) =
        packed.indices.iter().enumerate().find(|(_, corners)| corners.iter().any(|&v| v >= vertex_count))
    {
        return Err(RenderError::InvalidMesh(format!(
            "face {face} uses vertex {corners:?}, but there are only {vertex_count} vertices"
        )));
    }
    let bytes_per_sample = packed.format.bytes_per_sample();
    if !packed.colors.len().is_multiple_of(bytes_per_sample) {
        return Err(RenderError::InvalidMesh(format!(
            "colour buffer of {} bytes is not a whole number of {bytes_per_sample}-byte samples",
            packed.colors.len()
        )));
    }
    Ok((vertex_count, face_count))
}
