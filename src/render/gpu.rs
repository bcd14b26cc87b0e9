//! [`Gpu`]: a device with the renderer's pipelines, and the one path that puts packed
//! buffers on it ([`Gpu::upload`]). The editor shares one between its jobs; `render`,
//! `bench render` and the examples make a headless one.

use std::sync::Arc;

use image::RgbaImage;

use super::{BaselineMesh, DrawItem, GpuContext, GpuMesh, MeshUploadOptions, OFFSCREEN_FORMAT, RenderError};
use super::{RenderSettings, Renderer};
use crate::mesh::scene::Scene;
use crate::mesh::weld::weld_scene;
use crate::packing::linear::PackedMesh;

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
        GpuMesh::upload(&self.ctx, &self.renderer, packed, &MeshUploadOptions::default())
    }

    /// Uploads the UV-texture baseline of `scene`: its welded mesh with the first material
    /// that has a base-colour texture. `None` when no material has one.
    pub fn upload_baseline(&self, scene: &Scene) -> Result<Option<BaselineMesh>, RenderError> {
        let Some((material, texture)) = scene.materials.iter().find_map(|material| {
            let texture = scene.textures.get(material.base_color_texture? as usize)?;
            Some((material, texture))
        }) else {
            return Ok(None);
        };
        let welded = weld_scene(scene);
        let mesh = BaselineMesh::new(
            &self.ctx,
            &self.renderer,
            &welded.positions_world,
            &welded.triangles,
            &welded.corner_uvs,
            texture,
            material.base_color_factor,
        )?;
        Ok(Some(mesh))
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
    /// ([`crate::colors::budget::Budget::with_gpu`]).
    pub fn budget_limits(&self) -> crate::colors::budget::GpuLimits {
        crate::colors::budget::GpuLimits { max_texture_dimension_2d: self.ctx.limits().max_texture_dimension_2d }
    }

    /// A one-line description of the adapter.
    pub fn describe(&self) -> String {
        self.ctx.describe()
    }
}
