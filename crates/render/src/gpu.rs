//! [`Gpu`]: a device with the renderer's pipelines, and the one path that puts packed
//! buffers on it ([`Gpu::upload`]). The editor shares one between its jobs; `render`,
//! `bench render` and the examples make a headless one.

use std::sync::Arc;

use image::RgbaImage;

use super::{
    BaselineMesh, BaselineSource, DrawItem, GpuContext, GpuMesh, MeshUploadOptions, OFFSCREEN_FORMAT, RenderError,
};
use super::{GpuMct, GpuPtex, MeshGeometry, RenderSettings, Renderer};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mct::MeshColorTexture;
use meshpaint_core::mesh::scene::Scene;
use meshpaint_core::mesh::weld::weld_scene;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::PackCache;
use meshpaint_core::packing::paint_layout::{EncodedBuffer, PaintLayout};
use meshpaint_core::ptex::PackedPtex;

/// A paint layout's buffers on the GPU ([`Gpu::upload_paint_layout`]).
#[derive(Debug)]
pub struct PaintUpload {
    /// The layout's level-0 packing on the GPU.
    pub mesh: GpuMesh,
    /// The CPU copy of the encoded buffer that a dab's uploads copy their spans from.
    pub encoded: EncodedBuffer,
    /// Bytes uploaded: colours and face records.
    pub bytes: u64,
}

/// What entering paint mode put in place ([`Gpu::enter_paint`]).
#[derive(Debug)]
pub struct PaintStart {
    /// Where every element's level-0 samples are in the GPU's colour buffer.
    pub layout: PaintLayout,
    /// The CPU copy of that buffer, which a dab's uploads copy their spans from.
    pub encoded: EncodedBuffer,
    /// A new GPU mesh holding the paint layout, or `None`: the mesh the view shows (the
    /// compact packing's) is painted in place, and `encoded` holds the bytes lent by the
    /// packing ([`PackCache::lend_colors`]), to be given back on leaving.
    pub mesh: Option<GpuMesh>,
    /// Bytes uploaded: colours and face records.
    pub bytes: u64,
}

/// A GPU context with the renderer built for offscreen targets ([`OFFSCREEN_FORMAT`]).
#[derive(Debug)]
pub struct Gpu {
    /// Device and queue.
    pub ctx: Arc<GpuContext>,
    /// The pipelines.
    pub renderer: Renderer,
}

impl Gpu {
    /// Builds the renderer on `ctx`.
    pub fn new(ctx: Arc<GpuContext>) -> Result<Self, RenderError> {
        let renderer = Renderer::new(&ctx, OFFSCREEN_FORMAT)?;
        Ok(Gpu { ctx, renderer })
    }

    /// A headless device (lavapipe without a GPU) with the renderer.
    pub fn new_headless() -> Result<Self, RenderError> {
        Self::new(Arc::new(GpuContext::new_headless()?))
    }

    /// Uploads packed buffers (face records, positions, colour atlas with MIP chains).
    pub fn upload(&self, packed: &PackedMesh) -> Result<GpuMesh, RenderError> {
        GpuMesh::upload(&self.ctx, self.renderer.layouts(), packed, &MeshUploadOptions::default())
    }

    /// Uploads the Mesh Color Texture `mct`, built from the packed mesh whose GPU mesh has
    /// the geometry `geometry` ([`GpuMesh::geometry`]).
    pub fn upload_mct(&self, geometry: &MeshGeometry, mct: &MeshColorTexture) -> Result<GpuMct, RenderError> {
        GpuMct::upload(&self.ctx, self.renderer.layouts(), geometry, mct)
    }

    /// Uploads the Htex `htex`, built from the packed mesh whose GPU mesh has the geometry
    /// `geometry`.
    pub fn upload_htex(
        &self,
        geometry: &MeshGeometry,
        htex: &meshpaint_core::htex::HtexTexture,
    ) -> Result<super::GpuHtex, RenderError> {
        super::GpuHtex::upload(&self.ctx, self.renderer.layouts(), geometry, htex)
    }

    /// Uploads the packed Ptex `ptex`, built from the packed mesh whose GPU mesh has the
    /// geometry `geometry` ([`GpuMesh::geometry`]).
    pub fn upload_ptex(&self, geometry: &MeshGeometry, ptex: &PackedPtex) -> Result<GpuPtex, RenderError> {
        GpuPtex::upload(&self.ctx, self.renderer.layouts(), geometry, ptex)
    }

    /// Puts `store` on the GPU in its paint `layout`, encoded in `format` (the one path of
    /// entering paint mode, of a layout that grew, and of `bench load` / `bench paint`).
    pub fn upload_paint_layout(
        &self,
        layout: &PaintLayout,
        store: &ColorStore,
        positions: &[[f32; 3]],
        format: ColorFormat,
    ) -> Result<PaintUpload, RenderError> {
        let packed = layout.packed(store, positions, format);
        let mesh = self.upload(&packed)?;
        let bytes = packed.color_bytes() + packed.face_record_bytes();
        Ok(PaintUpload { mesh, encoded: EncodedBuffer::from_packed_owned(packed), bytes })
    }

    /// Enters paint mode on `store`. With `compact`, the packing of `store` that the view's
    /// GPU mesh holds ([`Gpu::upload`] of [`PackCache::packed`]), in `format`, nothing is
    /// uploaded or encoded: the paint layout is laid over that packing
    /// ([`PaintLayout::over_packed`]) and its bytes are lent to the encoded copy. Otherwise
    /// (no packing, another format, a packing of other resolutions) the paint layout is built
    /// and uploaded ([`Gpu::upload_paint_layout`]).
    pub fn enter_paint(
        &self,
        store: &ColorStore,
        positions: &[[f32; 3]],
        format: ColorFormat,
        compact: Option<&mut PackCache>,
    ) -> Result<PaintStart, RenderError> {
        if let Some(cache) = compact.filter(|cache| cache.packed().format == format)
            && let Some(layout) = PaintLayout::over_packed(store, cache.packed())
        {
            let encoded = EncodedBuffer::from_bytes(format, cache.lend_colors());
            return Ok(PaintStart { layout, encoded, mesh: None, bytes: 0 });
        }
        let layout = PaintLayout::new(store);
        let upload = self.upload_paint_layout(&layout, store, positions, format)?;
        Ok(PaintStart { layout, encoded: upload.encoded, mesh: Some(upload.mesh), bytes: upload.bytes })
    }

    /// Grows the paint buffer, on the GPU (`mesh`) and its CPU copy (`encoded`), to the
    /// capacity of `layout` after a plan that `grown`: the old samples stay where they are
    /// (copied on the GPU), so only the plan's ranges need uploading afterwards.
    pub fn grow_paint_buffer(
        &self,
        mesh: &mut GpuMesh,
        encoded: &mut EncodedBuffer,
        layout: &PaintLayout,
    ) -> Result<(), RenderError> {
        mesh.grow_atlas(&self.ctx, self.renderer.layouts(), layout.capacity())?;
        encoded.grow(layout.capacity());
        Ok(())
    }

    /// Uploads the UV-texture baseline of `scene`: its welded mesh, every face with its own
    /// material — `baseColorFactor` × base-colour texture (× COLOR_0 where the file has
    /// vertex colours), faces whose material has no texture at their factor, faces without a
    /// material white (glTF's default material). `None` when no material has a texture.
    pub fn upload_baseline(&self, scene: &Scene) -> Result<Option<BaselineMesh>, RenderError> {
        let textured = |m: &meshpaint_core::mesh::scene::Material| {
            m.base_color_texture.filter(|&t| (t as usize) < scene.textures.len())
        };
        if !scene.materials.iter().any(|m| textured(m).is_some()) {
            return Ok(None);
        }
        let welded = weld_scene(scene);
        let material = |face: usize| {
            welded.triangle_materials.get(face).copied().flatten().and_then(|m| scene.materials.get(m as usize))
        };
        let face_textures: Vec<Option<u32>> =
            (0..welded.triangles.len()).map(|face| material(face).and_then(textured)).collect();
        let corner_colors: Vec<[[f32; 4]; 3]> = welded
            .triangles
            .iter()
            .enumerate()
            .map(|(face, corners)| {
                let factor = material(face).map_or([1.0; 4], |m| m.base_color_factor);
                corners.map(|v| {
                    let vertex = welded.vertex_colors.get(v as usize).copied().unwrap_or([1.0; 4]);
                    std::array::from_fn(|c| factor[c] * vertex[c])
                })
            })
            .collect();
        let source = BaselineSource {
            positions: &welded.positions_world,
            triangles: &welded.triangles,
            corner_uvs: &welded.corner_uvs,
            corner_colors: &corner_colors,
            face_textures: &face_textures,
            textures: &scene.textures,
        };
        Ok(Some(BaselineMesh::from_source(&self.ctx, self.renderer.layouts(), &source)?))
    }

    /// Renders `item` offscreen at `width`×`height` and reads it back (sRGB RGBA8).
    pub fn render_image(
        &self,
        item: DrawItem<'_>,
        settings: &RenderSettings,
        width: u32,
        height: u32,
    ) -> Result<RgbaImage, RenderError> {
        self.renderer.render_image(&self.ctx, item, settings, width, height)
    }

    /// The device's limits as the sample budget needs them
    /// ([`meshpaint_core::colors::budget::Budget::with_gpu`]).
    pub fn budget_limits(&self) -> meshpaint_core::colors::budget::GpuLimits {
        meshpaint_core::colors::budget::GpuLimits {
            max_texture_dimension_2d: self.ctx.limits().max_texture_dimension_2d,
        }
    }

    /// A one-line description of the adapter.
    pub fn describe(&self) -> String {
        self.ctx.describe()
    }
}
