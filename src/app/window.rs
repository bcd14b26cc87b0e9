//! The window shell: winit event loop, wgpu surface, egui-winit input, egui-wgpu drawing,
//! and the 3D view rendered offscreen into a texture that egui shows in the view's area.
//!
//! # Frame
//!
//! 1. egui runs [`Editor::ui`], which lays out the panels and records the 3D view's area.
//! 2. The offscreen target follows that area's size in physical pixels (high-DPI aware);
//!    the mesh is drawn into it through an sRGB view (linear shader output, sRGB bytes).
//! 3. egui draws everything onto the window's surface; the 3D view is an egui image of the
//!    target's non-sRGB view (egui treats texture bytes as sRGB-encoded, which they are).
//!
//! # Redraws
//!
//! Frames are drawn only when egui asks (input, animation, a job's progress or completion
//! through the repaint callback), or every frame with "Redraw continuously". A minimised
//! window (zero size) draws nothing; a lost or outdated surface is configured again.

use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::window::{Window, WindowId};

use meshpaint_render::{DEPTH_FORMAT, GpuContext, OFFSCREEN_FORMAT, RenderTarget, Renderer};

use super::editor::Editor;
use super::view_draw::ViewDrawer;
use meshpaint_core::io::document::Source;
use meshpaint_render::Gpu;

/// How the application starts.
#[derive(Debug, Clone, Default)]
pub struct AppOptions {
    /// A file to open; `None` opens the built-in Duck.
    pub file: Option<std::path::PathBuf>,
}

/// Events sent to the event loop from other threads.
#[derive(Debug, Clone, Copy)]
enum UserEvent {
    /// egui wants a repaint after this delay (zero: now).
    Repaint(Duration),
}

/// Opens the window and runs the editor until it is closed.
pub fn run(options: AppOptions) -> Result<()> {
    let event_loop = EventLoop::<UserEvent>::with_user_event()
        .build()
        .context("cannot open a window: no display (set DISPLAY, or run under Xvfb)")?;
    let mut shell = Shell { options, proxy: event_loop.create_proxy(), running: None, fatal: None, next_repaint: None };
    event_loop.run_app(&mut shell).context("the event loop failed")?;
    match shell.fatal.take() {
        Some(error) => Err(error),
        None => Ok(()),
    }
}

/// The application handler.
struct Shell {
    options: AppOptions,
    proxy: EventLoopProxy<UserEvent>,
    running: Option<Running>,
    fatal: Option<anyhow::Error>,
    /// When a delayed repaint is due.
    next_repaint: Option<Instant>,
}

/// The 3D view's offscreen target: an RGBA8 texture written through its sRGB view and
/// shown by egui through its plain view, plus depth.
struct ViewTarget {
    size: [u32; 2],
    srgb_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    texture_id: egui::TextureId,
}

impl ViewTarget {
    fn views(ctx: &GpuContext, size: [u32; 2]) -> (wgpu::TextureView, wgpu::TextureView, wgpu::TextureView) {
        let color = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("3D view"),
            size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[OFFSCREEN_FORMAT],
        });
        let srgb_view =
            color.create_view(&wgpu::TextureViewDescriptor { format: Some(OFFSCREEN_FORMAT), ..Default::default() });
        let plain_view = color.create_view(&wgpu::TextureViewDescriptor::default());
        let depth = Renderer::create_depth_texture(ctx, size[0], size[1]);
        let depth_view = depth.create_view(&wgpu::TextureViewDescriptor::default());
        (srgb_view, plain_view, depth_view)
    }

    fn new(ctx: &GpuContext, egui_renderer: &mut egui_wgpu::Renderer, size: [u32; 2]) -> Self {
        let (srgb_view, plain_view, depth_view) = Self::views(ctx, size);
        let texture_id = egui_renderer.register_native_texture(&ctx.device, &plain_view, wgpu::FilterMode::Nearest);
        ViewTarget { size, srgb_view, depth_view, texture_id }
    }

    /// Follows `size` (clamped to the device's texture limit).
    fn resize(&mut self, ctx: &GpuContext, egui_renderer: &mut egui_wgpu::Renderer, size: [u32; 2]) {
        let max = ctx.limits().max_texture_dimension_2d;
        let size = [size[0].clamp(1, max), size[1].clamp(1, max)];
        if size == self.size {
            return;
        }
        let (srgb_view, plain_view, depth_view) = Self::views(ctx, size);
        egui_renderer.update_egui_texture_from_wgpu_texture(
            &ctx.device,
            &plain_view,
            wgpu::FilterMode::Nearest,
            self.texture_id,
        );
        *self = ViewTarget { size, srgb_view, depth_view, texture_id: self.texture_id };
    }

    /// Bytes of colour and depth.
    fn gpu_bytes(&self) -> u64 {
        let pixels = u64::from(self.size[0]) * u64::from(self.size[1]);
        let depth = DEPTH_FORMAT.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)).unwrap_or(4);
        pixels * (4 + u64::from(depth))
    }
}

/// Everything that exists while the window does.
struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// Device and queue (the window and egui need them even when the 3D view failed).
    ctx: Arc<GpuContext>,
    /// The 3D renderer (`None` when its pipelines could not be built: the UI still runs).
    gpu: Option<Arc<Gpu>>,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    view: ViewTarget,
    editor: Editor,
    last_logged_viewport: Option<([i32; 2], [u32; 2])>,
    /// What the 3D view's target holds, and its partial redraws.
    drawer: ViewDrawer,
    /// UI passes run so far, and where to write that count after each one
    /// (`MESHPAINT_FRAME_COUNT_FILE`, for the idle test: at rest the count must not grow).
    frame_count: (u64, Option<std::path::PathBuf>),
    /// The window title last set.
    title: String,
}

impl Shell {
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<Running> {
        let attributes = Window::default_attributes()
            .with_title("meshpaint")
            .with_inner_size(winit::dpi::LogicalSize::new(1280.0, 800.0))
            .with_min_inner_size(winit::dpi::LogicalSize::new(480.0, 320.0));
        let window = Arc::new(event_loop.create_window(attributes).context("creating the window")?);

        let mut descriptor =
            wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(event_loop.owned_display_handle()));
        descriptor.backends = meshpaint_render::backends_from_env();
        let instance = wgpu::Instance::new(descriptor);
        let surface = instance.create_surface(Arc::clone(&window)).context("creating the window surface")?;
        let ctx = Arc::new(pollster::block_on(GpuContext::with_instance(instance, Some(&surface)))?);
        log::info!("GPU: {}", ctx.describe());
        let caps = surface.get_capabilities(&ctx.adapter);
        let format = egui_wgpu::preferred_framebuffer_format(&caps.formats)
            .map_err(|error| anyhow::anyhow!("the window surface offers no usable format: {error}"))?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: Vec::new(),
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        if size.width > 0 && size.height > 0 {
            surface.configure(&ctx.device, &config);
        }
        let (gpu, gpu_error) = match Gpu::new(Arc::clone(&ctx)) {
            Ok(gpu) => (Some(Arc::new(gpu)), None),
            Err(error) => (None, Some(format!("building the render pipelines: {error}"))),
        };

        let egui_ctx = egui::Context::default();
        let proxy = self.proxy.clone();
        egui_ctx.set_request_repaint_callback(move |info| {
            // Fails only when the event loop is gone (closing).
            let _ = proxy.send_event(UserEvent::Repaint(info.delay));
        });
        let max_texture_side = ctx.limits().max_texture_dimension_2d as usize;
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            event_loop,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(max_texture_side),
        );
        let mut egui_renderer = egui_wgpu::Renderer::new(&ctx.device, format, egui_wgpu::RendererOptions::default());
        let view = ViewTarget::new(&ctx, &mut egui_renderer, [1, 1]);

        let waker_ctx = egui_ctx.clone();
        let mut editor = Editor::new(gpu.clone(), Arc::new(move || waker_ctx.request_repaint()));
        editor.viewport.texture = Some(view.texture_id);
        // Before the first document opens: the up axis applies to it.
        editor.load_settings(super::settings::settings_path());
        editor.open(match &self.options.file {
            Some(path) => Source::File(path.clone()),
            None => Source::BuiltIn,
        });
        if let Some(error) = gpu_error {
            // The panels still work (open, save, export); only the 3D view is off.
            editor.set_status(super::state::Severity::Error, format!("The 3D view is off: {error}"));
        }
        Ok(Running {
            window,
            surface,
            config,
            ctx,
            gpu,
            egui_ctx,
            egui_state,
            egui_renderer,
            view,
            editor,
            last_logged_viewport: None,
            drawer: ViewDrawer::new(),
            frame_count: (0, std::env::var_os("MESHPAINT_FRAME_COUNT_FILE").map(std::path::PathBuf::from)),
            title: "meshpaint".to_owned(),
        })
    }
}

impl Running {
    /// Configures the surface for the window's current size (skipped while minimised).
    fn configure(&mut self) {
        let size = self.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return;
        }
        self.config.width = size.width;
        self.config.height = size.height;
        self.surface.configure(&self.ctx.device, &self.config);
    }

    /// Creates the surface again (after `Lost`).
    fn recreate_surface(&mut self) -> Result<()> {
        self.surface = self.ctx.instance.create_surface(Arc::clone(&self.window)).context("re-creating the surface")?;
        self.configure();
        Ok(())
    }

    /// Runs the UI and draws one frame.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<Option<Duration>> {
        let started = Instant::now();
        let raw_input = self.egui_state.take_egui_input(&self.window);
        let editor = &mut self.editor;
        let mut full_output = self.egui_ctx.run_ui(raw_input, |ui| editor.ui(ui));
        let pointer_down = self.egui_ctx.input(|input| input.pointer.any_down());
        editor.save_settings_if_changed(pointer_down);
        self.egui_state.handle_platform_output(&self.window, full_output.platform_output);
        // Compared with what we last set: winit's `Window::title` is always empty on X11,
        // so comparing with it re-set WM_NAME on every frame.
        let title = self.editor.window_title();
        if self.title != title {
            self.window.set_title(&title);
            self.title = title;
        }
        if self.editor.quit_requested {
            event_loop.exit();
            // Nothing more is drawn: the frame's texture changes are dropped on purpose
            // (epaint panics in debug builds when a delta is dropped unapplied; seen in CI
            // when the quitting frame carried a font-atlas update).
            full_output.textures_delta.clear();
            return Ok(None);
        }
        let repaint_delay = full_output.viewport_output.get(&egui::ViewportId::ROOT).map(|output| output.repaint_delay);

        let ctx = &self.ctx;
        let mut textures = full_output.textures_delta;
        for (id, deltas) in textures.set.drain() {
            for delta in &deltas {
                self.egui_renderer.update_texture(&ctx.device, &ctx.queue, id, delta);
            }
        }
        let size = self.window.inner_size();
        let drawn = if size.width == 0 || size.height == 0 {
            false
        } else {
            let paint_jobs = self.egui_ctx.tessellate(full_output.shapes, full_output.pixels_per_point);
            self.draw(&paint_jobs, full_output.pixels_per_point)?
        };
        for id in std::mem::take(&mut textures.free) {
            self.egui_renderer.free_texture(&id);
        }
        if drawn {
            self.editor.viewport.frame_stats.record(started.elapsed());
        }
        self.frame_count.0 += 1;
        if let Some(path) = &self.frame_count.1 {
            // Written in place (not atomically): the test only reads a number that grows.
            let _ = std::fs::write(path, self.frame_count.0.to_string());
        }
        Ok(repaint_delay)
    }

    /// Draws the 3D view and egui onto the surface; `false` when no frame was available.
    fn draw(&mut self, paint_jobs: &[egui::ClippedPrimitive], pixels_per_point: f32) -> Result<bool> {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                self.window.request_redraw();
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Outdated => {
                self.configure();
                self.window.request_redraw();
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                log::warn!("the window surface was lost; re-creating it");
                self.recreate_surface()?;
                self.window.request_redraw();
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                log::error!("the window surface reported a validation error; configuring it again");
                self.configure();
                return Ok(false);
            }
        };
        let ctx = Arc::clone(&self.ctx);
        let ctx = &*ctx;
        let view_size = self.editor.viewport.size_px();
        self.view.resize(ctx, &mut self.egui_renderer, view_size);
        self.editor.viewport.gpu_bytes = self.view.gpu_bytes();
        let logged = (self.editor.viewport.min_px(), view_size);
        if self.last_logged_viewport != Some(logged) {
            log::info!(
                "3D view at {},{} size {}x{} px (window {}x{})",
                logged.0[0],
                logged.0[1],
                view_size[0],
                view_size[1],
                self.config.width,
                self.config.height
            );
            self.last_logged_viewport = Some(logged);
        }

        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        if self.editor.panels.scene.continuous_redraw {
            self.drawer.invalidate();
        }
        if let Some(gpu) = &self.gpu {
            let target = RenderTarget {
                color: &self.view.srgb_view,
                depth: &self.view.depth_view,
                width: self.view.size[0],
                height: self.view.size[1],
            };
            self.drawer.draw((ctx, gpu), &mut encoder, &target, self.view.size, &mut self.editor);
        }

        let screen =
            egui_wgpu::ScreenDescriptor { size_in_pixels: [self.config.width, self.config.height], pixels_per_point };
        let user_buffers =
            self.egui_renderer.update_buffers(&ctx.device, &ctx.queue, &mut encoder, paint_jobs, &screen);
        let surface_view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &surface_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.1, g: 0.1, b: 0.1, a: 1.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.egui_renderer.render(&mut pass.forget_lifetime(), paint_jobs, &screen);
        }
        ctx.queue.submit(user_buffers.into_iter().chain([encoder.finish()]));
        ctx.queue.present(frame);
        Ok(true)
    }
}

impl ApplicationHandler<UserEvent> for Shell {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(running) => {
                running.window.request_redraw();
                self.running = Some(running);
            }
            Err(error) => {
                self.fatal = Some(error);
                event_loop.exit();
            }
        }
    }

    fn user_event(&mut self, _event_loop: &ActiveEventLoop, event: UserEvent) {
        let UserEvent::Repaint(delay) = event;
        self.schedule(delay);
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, window_id: WindowId, event: WindowEvent) {
        let Some(running) = self.running.as_mut() else {
            return;
        };
        if window_id != running.window.id() {
            return;
        }
        let response = running.egui_state.on_window_event(&running.window, &event);
        // egui-winit answers `repaint: true` to RedrawRequested itself: asking for another
        // redraw then drew frame after frame for ever (the idle editor's busy CPU).
        if response.repaint && !matches!(event, WindowEvent::RedrawRequested) {
            running.window.request_redraw();
        }
        match event {
            // Closing the window is quitting: it asks first when changes are unsaved.
            WindowEvent::CloseRequested => {
                running.editor.perform(crate::app::Action::Quit);
                running.window.request_redraw();
            }
            WindowEvent::Resized(_) => {
                running.configure();
                running.window.request_redraw();
            }
            WindowEvent::ScaleFactorChanged { .. } => running.window.request_redraw(),
            WindowEvent::RedrawRequested => {
                self.next_repaint = None;
                match running.frame(event_loop) {
                    Ok(Some(delay)) => self.schedule(delay),
                    Ok(None) => {}
                    Err(error) => {
                        self.fatal = Some(error);
                        event_loop.exit();
                    }
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        match self.next_repaint {
            Some(when) if when <= Instant::now() => {
                self.next_repaint = None;
                if let Some(running) = &self.running {
                    running.window.request_redraw();
                }
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Some(when) => event_loop.set_control_flow(ControlFlow::WaitUntil(when)),
            None => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }

    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        // Let a running save or export finish writing (its file is renamed into place
        // atomically, so an interrupted job would leave nothing behind either).
        if let Some(running) = self.running.as_mut()
            && running.editor.jobs.is_busy()
        {
            log::info!("waiting for the running job before exiting");
            running.editor.wait_for_job(Duration::from_secs(60));
        }
    }
}

impl Shell {
    /// Asks for a redraw after `delay` (an earlier request wins).
    fn schedule(&mut self, delay: Duration) {
        if delay == Duration::ZERO {
            if let Some(running) = &self.running {
                running.window.request_redraw();
            }
            return;
        }
        // egui uses Duration::MAX for "no repaint needed".
        let Some(when) = Instant::now().checked_add(delay) else {
            return;
        };
        if self.next_repaint.is_none_or(|current| when < current) {
            self.next_repaint = Some(when);
        }
    }
}
