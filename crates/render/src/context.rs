//! The wgpu instance, adapter, device and queue.

use super::RenderError;

/// A wgpu device and queue with the adapter they came from.
///
/// Headless rendering needs nothing else; a window additionally creates a surface from
/// [`GpuContext::instance`] (see [`GpuContext::with_instance`]).
#[derive(Debug)]
pub struct GpuContext {
    /// The wgpu instance (Vulkan and GL backends unless `WGPU_BACKEND` says otherwise).
    pub instance: wgpu::Instance,
    /// The adapter; on a machine without a GPU this is lavapipe (`DeviceType::Cpu`).
    pub adapter: wgpu::Adapter,
    /// The device, created with the adapter's own limits (not `Limits::default()`).
    pub device: wgpu::Device,
    /// The device's queue.
    pub queue: wgpu::Queue,
    /// Name, backend and type of the adapter.
    pub adapter_info: wgpu::AdapterInfo,
}

/// The backends searched: `WGPU_BACKEND` (e.g. `vulkan`, `gl`) when set, else Vulkan + GL.
pub fn backends_from_env() -> wgpu::Backends {
    wgpu::Backends::from_env().unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::GL)
}

impl GpuContext {
    /// A context for offscreen rendering: an instance over [`backends_from_env`], the first
    /// adapter that wgpu offers (CPU adapters such as lavapipe are accepted), and a device
    /// with the adapter's limits. Fails (never falls back silently) when no adapter exists.
    ///
    /// Without `WGPU_BACKEND`, Vulkan (lavapipe on a machine without a GPU) is tried first
    /// and GL only when Vulkan offers no adapter: initialising EGL when it is not needed
    /// costs time and prints warnings.
    pub fn new_headless() -> Result<Self, RenderError> {
        let from_env = wgpu::Backends::from_env();
        let attempts = match from_env {
            Some(backends) => vec![backends],
            None => vec![wgpu::Backends::VULKAN, wgpu::Backends::GL],
        };
        let mut last_error = None;
        for backends in attempts {
            let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            descriptor.backends = backends;
            let instance = wgpu::Instance::new(descriptor);
            match pollster::block_on(Self::with_instance(instance, None)) {
                Ok(context) => return Ok(context),
                Err(error) => last_error = Some(error),
            }
        }
        Err(last_error.unwrap_or(RenderError::NoAdapter {
            backends: format!("{:?}", backends_from_env()),
            reason: "no backend to try".into(),
        }))
    }

    /// A context on `instance`, with an adapter able to present to `surface` when given.
    pub async fn with_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Self, RenderError> {
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: surface,
                apply_limit_buckets: false,
            })
            .await
            .map_err(|error| RenderError::NoAdapter {
                backends: format!("{:?}", backends_from_env()),
                reason: error.to_string(),
            })?;
        let adapter_info = adapter.get_info();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("meshpaint device"),
                // Filtering RGBA32F Mesh Color Textures, where the adapter can.
                required_features: adapter.features() & wgpu::Features::FLOAT32_FILTERABLE,
                required_limits: adapter.limits(),
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|error| RenderError::RequestDevice {
                adapter: adapter_info.name.clone(),
                reason: error.to_string(),
            })?;
        // Everything the renderer does runs inside error scopes (`checked`); an error that
        // escapes them is logged instead of wgpu's default panic.
        device.on_uncaptured_error(std::sync::Arc::new(|error: wgpu::Error| {
            log::error!("uncaptured GPU error: {error}");
        }));
        Ok(GpuContext { instance, adapter, device, queue, adapter_info })
    }

    /// The device's limits (equal to the adapter's).
    pub fn limits(&self) -> wgpu::Limits {
        self.device.limits()
    }

    /// Whether the adapter filters anisotropically (wgpu's `ANISOTROPIC_FILTERING`; without
    /// it a sampler's anisotropy clamp is 1).
    pub fn anisotropic(&self) -> bool {
        self.adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::ANISOTROPIC_FILTERING)
    }

    /// One line describing the adapter, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)`.
    pub fn describe(&self) -> String {
        format!("{} ({:?}, {:?})", self.adapter_info.name, self.adapter_info.backend, self.adapter_info.device_type)
    }

    /// Runs `work` inside validation, out-of-memory and internal error scopes and turns a
    /// captured wgpu error into [`RenderError::Gpu`].
    pub fn checked<T>(&self, work: impl FnOnce() -> Result<T, RenderError>) -> Result<T, RenderError> {
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let result = work();
        // Scopes pop in reverse order of pushing.
        let validation_error = pollster::block_on(validation.pop());
        let oom_error = pollster::block_on(oom.pop());
        let internal_error = pollster::block_on(internal.pop());
        if let Some(error) = validation_error.or(oom_error).or(internal_error) {
            return Err(RenderError::Gpu(error.to_string()));
        }
        result
    }
}
