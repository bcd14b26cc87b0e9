//! The bind-group layouts of the three pipelines (keep in sync with `@group(0)` of
//! shaders/mesh_colors.wgsl, shaders/mct.wgsl and shaders/uv_baseline.wgsl): meshes make their bind groups
//! against them and the renderer builds its pipelines with them, so neither needs the other.

use super::uniforms::FrameUniforms;

/// The bind-group layouts of the mesh-colors and the UV-baseline pipelines.
#[derive(Debug)]
pub struct BindLayouts {
    mesh: wgpu::BindGroupLayout,
    baseline: wgpu::BindGroupLayout,
    mct: wgpu::BindGroupLayout,
}

impl BindLayouts {
    /// Creates both layouts on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        // Positions, vertex ids and face records: RGBA32 data textures read by the vertex stage
        // only (it passes everything per face to the fragment stage as flat varyings), so
        // fragments read nothing but the atlas. See crates/render/src/mesh_gpu.rs for why textures.
        let data = |binding, sample_type| {
            layout_entry(
                binding,
                wgpu::ShaderStages::VERTEX,
                wgpu::BindingType::Texture {
                    sample_type,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            )
        };
        let mesh_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mesh colors layout"),
            entries: &[
                uniform_entry(0),
                data(1, wgpu::TextureSampleType::Float { filterable: false }),
                data(2, wgpu::TextureSampleType::Uint),
                data(3, wgpu::TextureSampleType::Uint),
                data(5, wgpu::TextureSampleType::Float { filterable: false }),
                layout_entry(
                    4,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
            ],
        });
        let baseline_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("uv baseline layout"),
            entries: &[
                uniform_entry(0),
                layout_entry(
                    1,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                layout_entry(
                    2,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
            ],
        });
        // Mesh Color Textures (shaders/mct.wgsl): the mesh's geometry textures as above, the
        // face records (R32Uint) for the vertex stage, the filterable atlas and its sampler for
        // the fragment stage, the band table for both.
        let mct_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mesh color textures layout"),
            entries: &[
                uniform_entry(0),
                data(1, wgpu::TextureSampleType::Float { filterable: false }),
                data(2, wgpu::TextureSampleType::Uint),
                data(3, wgpu::TextureSampleType::Uint),
                data(5, wgpu::TextureSampleType::Float { filterable: false }),
                layout_entry(
                    4,
                    wgpu::ShaderStages::VERTEX_FRAGMENT,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                layout_entry(
                    6,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
                // The anisotropic sampler (`LEVEL_MODE` 2; anisotropy 1 where the adapter has none).
                layout_entry(
                    8,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
                layout_entry(
                    7,
                    wgpu::ShaderStages::VERTEX_FRAGMENT,
                    // The band table's entries in use (crates/render/src/mct.rs `gpu_bands`).
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(16),
                    },
                ),
            ],
        });
        BindLayouts { mesh: mesh_layout, baseline: baseline_layout, mct: mct_layout }
    }

    /// The mesh-colors pipeline's layout (uniforms; positions, vertex ids and face records
    /// for the vertex stage; the colour atlas for the fragment stage).
    pub fn mesh(&self) -> &wgpu::BindGroupLayout {
        &self.mesh
    }

    /// The Mesh Color Textures pipeline's layout (the mesh layout's geometry, MCT records,
    /// the filterable atlas, its sampler and the band table).
    pub fn mct(&self) -> &wgpu::BindGroupLayout {
        &self.mct
    }

    /// The baseline pipeline's layout (uniforms, texture, sampler).
    pub fn baseline(&self) -> &wgpu::BindGroupLayout {
        &self.baseline
    }
}

fn layout_entry(binding: u32, visibility: wgpu::ShaderStages, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None }
}

fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    layout_entry(
        binding,
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<FrameUniforms>() as u64),
        },
    )
}
