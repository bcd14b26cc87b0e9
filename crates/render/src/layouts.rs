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
    htex: wgpu::BindGroupLayout,
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
        let htex = htex_layout(device);
        BindLayouts { mesh: mesh_layout, baseline: baseline_layout, mct: mct_layout, htex }
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

    /// The Htex pipeline's layout (`htex_layout`).
    pub fn htex(&self) -> &wgpu::BindGroupLayout {
        &self.htex
    }

    /// The baseline pipeline's layout (uniforms, texture, sampler).
    pub fn baseline(&self) -> &wgpu::BindGroupLayout {
        &self.baseline
    }
}

/// The bind-group layout of shaders/htex.wgsl (keep in sync with its `@group(0)`): the
/// mesh's geometry (1, 2, 5), records and origins (3, both stages), pages (4), the bilinear
/// sampler (6), the border-normalisation texture (7).
fn htex_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let texture = |binding, stages, sample_type, view_dimension| {
        layout_entry(binding, stages, wgpu::BindingType::Texture { sample_type, view_dimension, multisampled: false })
    };
    let (v, vf, f) = (wgpu::ShaderStages::VERTEX, wgpu::ShaderStages::VERTEX_FRAGMENT, wgpu::ShaderStages::FRAGMENT);
    let d2 = wgpu::TextureViewDimension::D2;
    let unfiltered = wgpu::TextureSampleType::Float { filterable: false };
    let filtered = wgpu::TextureSampleType::Float { filterable: true };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("htex layout"),
        entries: &[
            uniform_entry(0),
            texture(1, v, unfiltered, d2),
            texture(2, v, wgpu::TextureSampleType::Uint, d2),
            texture(3, vf, wgpu::TextureSampleType::Uint, d2),
            texture(5, v, unfiltered, d2),
            texture(4, f, filtered, wgpu::TextureViewDimension::D2Array),
            layout_entry(6, f, wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering)),
            texture(7, f, filtered, d2),
        ],
    })
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
