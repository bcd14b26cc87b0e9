//! The headless GPU (lavapipe on machines without one). Tests FAIL, never skip, without an
//! adapter.

use std::path::Path;
use std::sync::OnceLock;

use meshpaint_render::{BaselineMesh, GpuContext, OFFSCREEN_FORMAT, Renderer};

/// A wgpu context and a renderer for [`OFFSCREEN_FORMAT`] targets.
pub struct Gpu {
    pub ctx: GpuContext,
    pub renderer: Renderer,
}

impl Gpu {
    /// A new context and renderer, or why there is none.
    pub fn try_new() -> Result<Gpu, String> {
        let ctx = GpuContext::new_headless().map_err(|error| error.to_string())?;
        // A wgpu error outside the renderer's error scopes fails the test (the editor only
        // logs it): tests must not pass with a broken upload.
        ctx.device.on_uncaptured_error(std::sync::Arc::new(|error: wgpu::Error| {
            panic!("uncaptured wgpu error (outside the renderer's error scopes): {error}")
        }));
        let renderer = Renderer::new(&ctx, OFFSCREEN_FORMAT).map_err(|error| error.to_string())?;
        Ok(Gpu { ctx, renderer })
    }

    /// A new context and renderer; panics (with what to install) without an adapter.
    pub fn create() -> Gpu {
        Gpu::try_new().unwrap_or_else(|error| panic!("{NO_ADAPTER}: {error}"))
    }
}

const NO_ADAPTER: &str = "GPU tests need an adapter (lavapipe: apt-get install mesa-vulkan-drivers)";

/// One context and renderer for all tests of a test binary (created on first use; the
/// adapter is logged once).
pub fn shared() -> &'static Gpu {
    static GPU: OnceLock<Result<Gpu, String>> = OnceLock::new();
    let gpu = GPU.get_or_init(|| {
        let gpu = Gpu::try_new()?;
        eprintln!("adapter: {}", gpu.ctx.describe());
        Ok(gpu)
    });
    match gpu {
        Ok(gpu) => gpu,
        Err(error) => panic!("{NO_ADAPTER}: {error}"),
    }
}

/// The UV baseline of a glTF file: its welded triangles with the glTF UVs, textured with the
/// first material that has a base-colour texture (and that material's factor).
pub fn textured_baseline(gpu: &Gpu, path: &Path) -> BaselineMesh {
    let scene = meshpaint_core::mesh::import::import_gltf(path).unwrap();
    let welded = meshpaint_core::mesh::weld::weld_scene(&scene);
    let (material, texture) =
        scene.materials.iter().find_map(|m| Some((m, scene.textures.get(m.base_color_texture? as usize)?))).unwrap();
    BaselineMesh::new(
        &gpu.ctx,
        gpu.renderer.layouts(),
        &welded.positions_world,
        &welded.triangles,
        &welded.corner_uvs,
        texture,
        material.base_color_factor,
    )
    .unwrap()
}
