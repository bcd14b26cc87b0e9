//! Drawing the 3D view into its offscreen target, whole or in part: what the window shell
//! runs every frame and `meshpaint bench latency` measures.
//!
//! The view is drawn again only when the render settings, what is shown, the size or the
//! scene generation changed. When only paint uploads changed it since the last drawing
//! ([`ViewportState::partial`](super::state::ViewportState::partial) starts at the generation
//! drawn), only the faces whose colours changed are drawn, over the previous frame's colour
//! and depth, inside the screen rectangle their vertices cover
//! ([`meshpaint_render::Renderer::draw_partial`], which says why that is the full frame's
//! pixels). Anything else — the camera, a setting, a new document, a re-upload — draws the
//! whole frame.

use glam::{DVec3, Vec4};

use meshpaint_render::{DrawItem, FaceSubset, Gpu, GpuContext, RenderSettings, RenderTarget, Scissor};

use super::editor::Editor;
use super::state::{Representation, Shown};

/// What the 3D view's last drawing shows: render settings, what is shown and in which
/// representation, view size, scene generation (drawn again only when it changes).
type DrawnView = (RenderSettings, (Shown, Representation), [u32; 2], u64);

/// What [`ViewDrawer::draw`] recorded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewDraw {
    /// Nothing: the target still shows the current view.
    Unchanged,
    /// The whole frame.
    Full,
    /// Only `faces` faces, inside `scissor`.
    Partial {
        /// Faces drawn.
        faces: u32,
        /// The rectangle drawn, pixels.
        scissor: Scissor,
    },
}

/// The 3D view's drawing state between frames.
#[derive(Debug, Default)]
pub struct ViewDrawer {
    /// What the target holds.
    drawn: Option<DrawnView>,
    /// The faces of the last partial redraw, on the GPU.
    faces: FaceSubset,
    /// The pipeline last drawn with (logged when it changes).
    last_logged_pipeline: Option<&'static str>,
    /// Partial redraws off: every change draws the whole frame (the benchmark's baseline).
    pub always_full: bool,
}

impl ViewDrawer {
    /// A drawer whose target holds nothing yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The next drawing is a whole frame (the target was replaced or must be refreshed).
    pub fn invalidate(&mut self) {
        self.drawn = None;
    }

    /// GPU bytes of the partial-redraw face list.
    pub fn gpu_bytes(&self) -> u64 {
        self.faces.gpu_bytes()
    }

    /// Records the drawing of `editor`'s 3D view into `target` (of `size`), whole or in part.
    pub fn draw(
        &mut self,
        (ctx, gpu): (&GpuContext, &Gpu),
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget<'_>,
        size: [u32; 2],
        editor: &mut Editor,
    ) -> ViewDraw {
        let settings = editor.render_settings();
        let shown = (editor.panels.view.settings.shown, editor.shown_representation());
        let generation = editor.viewport.scene_generation;
        let key = (settings, shown, size, generation);
        let partial = editor.viewport.partial.take();
        let Some(item) = editor.shown_item().filter(|_| self.drawn != Some(key)) else {
            return ViewDraw::Unchanged;
        };
        let pipeline = match item {
            DrawItem::MeshColors(_) => "mesh colors",
            DrawItem::Baseline(_) => "the UV-textured source",
            DrawItem::Mct(_) => "Mesh Color Textures",
            DrawItem::Htex(_) => "Htex",
            DrawItem::Ptex(_) => "packed Ptex",
        };
        if self.last_logged_pipeline != Some(pipeline) {
            log::info!("3D view draws {pipeline}");
            self.last_logged_pipeline = Some(pipeline);
        }
        let partial = partial.filter(|p| !self.always_full && p.to == generation);
        let drawn_before = partial.as_ref().map(|p| (settings, shown, size, p.from));
        let drawn = self.drawn.replace(key);
        if let (Some(change), DrawItem::MeshColors(mesh)) = (partial, item)
            && drawn.is_some()
            && drawn == drawn_before
        {
            let positions = editor.document.open.as_ref().map(|open| &open.document);
            let scissor = positions
                .and_then(|document| {
                    faces_scissor(
                        &document.positions,
                        &document.store.topology().face_vertices,
                        &change.faces,
                        (&settings, mesh.origin, size),
                    )
                })
                .unwrap_or([0, 0, size[0], size[1]]);
            self.faces.write(ctx, &change.faces);
            gpu.renderer.draw_partial(ctx, encoder, target, (mesh, &settings), &self.faces, scissor);
            return ViewDraw::Partial { faces: self.faces.face_count(), scissor };
        }
        gpu.renderer.draw(ctx, encoder, target, item, &settings);
        ViewDraw::Full
    }
}

/// The pixel rectangle of a `size` view that the faces `faces` cover (their vertices'
/// bounding box, widened by two pixels for rasterisation and rounding, clamped to the
/// view), or `None` when a vertex is not in front of the camera (then the whole view).
fn faces_scissor(
    positions: &[[f32; 3]],
    face_vertices: &[[u32; 3]],
    faces: &[u32],
    (settings, origin, size): (&RenderSettings, DVec3, [u32; 2]),
) -> Option<Scissor> {
    let clip_from_world = settings.camera.clip_from_world_relative(origin, size[0], size[1]);
    let (w, h) = (size[0] as f32, size[1] as f32);
    let (mut min, mut max) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
    for &face in faces {
        for &v in face_vertices.get(face as usize)? {
            let p = positions.get(v as usize)?;
            let relative = (DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) - origin).as_vec3();
            let clip = clip_from_world * Vec4::new(relative.x, relative.y, relative.z, 1.0);
            if clip.w <= 1e-6 {
                return None;
            }
            let x = (clip.x / clip.w * 0.5 + 0.5) * w;
            let y = (0.5 - clip.y / clip.w * 0.5) * h;
            min = [min[0].min(x), min[1].min(y)];
            max = [max[0].max(x), max[1].max(y)];
        }
    }
    let x0 = (min[0] - 2.0).floor().clamp(0.0, w) as u32;
    let y0 = (min[1] - 2.0).floor().clamp(0.0, h) as u32;
    let x1 = (max[0] + 2.0).ceil().clamp(0.0, w) as u32;
    let y1 = (max[1] + 2.0).ceil().clamp(0.0, h) as u32;
    Some([x0, y0, x1.saturating_sub(x0), y1.saturating_sub(y0)])
}

/// An offscreen 3D-view target like the window's (an RGBA8 texture drawn through its sRGB
/// view, plus depth) that can be read back: for `bench latency` and the tests that compare
/// partial redraws with full ones.
#[derive(Debug)]
pub struct OffscreenView {
    /// Width and height, pixels.
    pub size: [u32; 2],
    color: wgpu::Texture,
    srgb_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
}

impl OffscreenView {
    /// A `size` target.
    pub fn new(ctx: &GpuContext, size: [u32; 2]) -> Self {
        let color = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("offscreen 3D view"),
            size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[meshpaint_render::OFFSCREEN_FORMAT],
        });
        let srgb_view = color.create_view(&wgpu::TextureViewDescriptor {
            format: Some(meshpaint_render::OFFSCREEN_FORMAT),
            ..Default::default()
        });
        let depth = meshpaint_render::Renderer::create_depth_texture(ctx, size[0], size[1]);
        let depth_view = depth.create_view(&wgpu::TextureViewDescriptor::default());
        OffscreenView { size, color, srgb_view, depth_view }
    }

    /// Where to draw.
    pub fn target(&self) -> RenderTarget<'_> {
        RenderTarget { color: &self.srgb_view, depth: &self.depth_view, width: self.size[0], height: self.size[1] }
    }

    /// The pixels (sRGB-encoded RGBA8, rows top to bottom).
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<u8>, meshpaint_render::RenderError> {
        meshpaint_render::read_texture(ctx, &self.color, 4)
    }

    /// Draws `editor`'s view with `drawer`, submits and waits until the GPU finished.
    pub fn draw_and_wait(
        &self,
        (ctx, gpu): (&GpuContext, &Gpu),
        drawer: &mut ViewDrawer,
        editor: &mut Editor,
    ) -> Result<ViewDraw, meshpaint_render::RenderError> {
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("view") });
        let drawn = drawer.draw((ctx, gpu), &mut encoder, &self.target(), self.size, editor);
        ctx.queue.submit([encoder.finish()]);
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|error| meshpaint_render::RenderError::Gpu(error.to_string()))?;
        Ok(drawn)
    }
}
