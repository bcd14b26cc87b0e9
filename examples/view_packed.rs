//! An engine-side reader: a standalone wgpu program that loads a meshpaint packed file
//! through the documented format (docs/FORMAT.md, "Use it in your renderer") and draws it
//! with the shipped WGSL (shaders/frame.wgsl + mesh_common.wgsl + mesh_colors.wgsl, unchanged),
//! offscreen, into a PNG:
//! `cargo run --example view_packed -- painted.mpk out.png [WIDTH HEIGHT [YAW PITCH]]`.
//!
//! It uses nothing of meshpaint's code — only wgpu, glam, bytemuck, crc32fast and image —
//! so it is the proof that the exported buffers are usable outside meshpaint. With the same
//! size and camera it renders the same pixels as `meshpaint render FILE` (lit, trilinear;
//! tests/app/examples.rs compares them): the camera below is meshpaint's default orbit camera.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use glam::{DMat4, DVec3};

/// The shader exactly as meshpaint compiles it: the uniform block, the shared vertex pulling, mesh colors.
const WGSL: &str = concat!(
    include_str!("../crates/render/shaders/frame.wgsl"),
    "\n",
    include_str!("../crates/render/shaders/mesh_common.wgsl"),
    "\n",
    include_str!("../crates/render/shaders/mesh_colors.wgsl")
);

/// A packed file's content (docs/FORMAT.md, "Sections").
pub struct Packed {
    /// `color_format`: 0 RGBA8 sRGB, 1 RGBA16F, 2 RGBA32F.
    pub color_format: u32,
    pub vertex_levels: u32,
    pub sample_count: u64,
    pub positions: Vec<[f32; 3]>,
    /// Section 1 (`[u32; 3]` per face) and section 2 (`[u32; 4]` face records), raw.
    pub indices: Vec<u32>,
    pub face_records: Vec<u32>,
    /// Section 3, encoded samples.
    pub colors: Vec<u8>,
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap_or_default())
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or_default())
}

/// Reads a packed file: magic, version, size, CRC-32 and section bounds are checked (the
/// shader clamps every index it derives, so a reader needs no deeper check to stay in bounds).
pub fn read_packed(path: &Path) -> Result<Packed> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    ensure!(bytes.len() >= 256 && bytes.starts_with(b"MESHPAK\0"), "{}: not a packed file", path.display());
    // Version 2 only adds a layers section after the colours (their composite): ignored here.
    ensure!(matches!(u32_at(&bytes, 8), 1 | 2) && u32_at(&bytes, 12) == 128, "{}: unknown version", path.display());
    ensure!(u64_at(&bytes, 16) == bytes.len() as u64, "{}: truncated", path.display());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes[..124]);
    crc.update(&bytes[128..]);
    ensure!(crc.finalize() == u32_at(&bytes, 124), "{}: checksum mismatch", path.display());
    let (color_format, vertex_count, face_count) = (u32_at(&bytes, 28), u32_at(&bytes, 32), u32_at(&bytes, 36));
    let sample_bytes = match color_format {
        0 => 4,
        1 => 8,
        2 => 16,
        other => bail!("{}: unknown colour format {other}", path.display()),
    };
    let sample_count = u64_at(&bytes, 48);
    let expected = [12 * u64::from(vertex_count), 12 * u64::from(face_count), 16 * u64::from(face_count)];
    let section = |k: usize, length: u64| -> Result<&[u8]> {
        let (offset, len) = (u64_at(&bytes, 56 + 16 * k), u64_at(&bytes, 64 + 16 * k));
        let end = offset.checked_add(len).filter(|&end| end <= bytes.len() as u64 && len == length);
        let end = end.with_context(|| format!("{}: bad section {k}", path.display()))?;
        Ok(&bytes[offset as usize..end as usize])
    };
    let words = |data: &[u8]| data.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let floats: Vec<f32> =
        section(0, expected[0])?.chunks_exact(4).map(|w| f32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    Ok(Packed {
        color_format,
        vertex_levels: u32_at(&bytes, 40),
        sample_count,
        positions: floats.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
        indices: words(section(1, expected[1])?),
        face_records: words(section(2, expected[2])?),
        colors: section(3, sample_count * sample_bytes)?.to_vec(),
    })
}

/// meshpaint's default orbit camera (crates/core/src/camera.rs): a sphere around the axis-aligned bounds,
/// framed at a 40° vertical field of view with a 10 % margin, near/far around the sphere.
/// Returns `(render origin, clip_from_world relative to it, unit vector towards the light,
/// eye relative to the origin)`.
pub fn camera(positions: &[[f32; 3]], yaw: f64, pitch: f64, width: u32, height: u32) -> (DVec3, DMat4, DVec3, DVec3) {
    let points = positions.iter().map(|p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])));
    let (min, max) = points.clone().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let center = if positions.is_empty() { DVec3::ZERO } else { (min + max) * 0.5 };
    let radius = points.map(|p| (p - center).length()).fold(0.0, f64::max);
    let radius = if radius > 0.0 { radius } else { center.length().max(1.0) * 1e-6 };
    let fov = 40.0f64.to_radians();
    let distance = radius / (fov * 0.5).sin() * 1.1;
    let (yaw, pitch) = (yaw.to_radians(), pitch.clamp(-89.0, 89.0).to_radians());
    let towards_eye = DVec3::new(yaw.sin() * pitch.cos(), pitch.sin(), yaw.cos() * pitch.cos());
    let eye = center + towards_eye * distance;
    let center_distance = (center - eye).length().max(distance);
    let far = center_distance + radius * 2.0;
    let near = (center_distance - radius * 2.0).max(far * 1e-5).max(radius * 1e-4);
    // Relative to the render origin (the sphere centre, which is also the target).
    let view = glam::dcamera::rh::view::look_at_mat4(eye - center, DVec3::ZERO, DVec3::Y);
    let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
    let projection = glam::dcamera::rh::proj::directx::perspective(fov, aspect, near, far);
    // The light: from the eye, tilted up and to the left.
    let right = DVec3::Y.cross(towards_eye).normalize_or(DVec3::X);
    let up = towards_eye.cross(right).normalize_or(DVec3::Y);
    let light = (towards_eye + 0.6 * up - 0.4 * right).normalize_or(towards_eye);
    (center, projection * view, light, eye - center)
}

/// The trilinear level of detail's per-vertex inputs (docs/FORMAT.md, "Use it in your
/// renderer"): each vertex's sample density, the largest `R_f / sqrt(2 A_f)` over the faces
/// around it (faces of zero area skipped), and its unit area-weighted normal as f16 bits.
fn vertex_lod(positions: &[[f32; 3]], indices: &[u32], face_records: &[u32]) -> (Vec<f32>, Vec<[u16; 4]>) {
    let mut density = vec![0.0f64; positions.len()];
    let mut normal = vec![DVec3::ZERO; positions.len()];
    let p = |v: u32| {
        positions.get(v as usize).map_or(DVec3::ZERO, |p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
    };
    for (face, c) in indices.chunks_exact(3).enumerate() {
        let cross = (p(c[1]) - p(c[0])).cross(p(c[2]) - p(c[0]));
        let twice_area = cross.length();
        let log2_r = face_records.get(face * 4).map_or(0, |word| word >> 28);
        if !(twice_area.is_finite() && twice_area > 0.0) || log2_r > 12 {
            continue;
        }
        let face_density = f64::from(1u32 << log2_r) / twice_area.sqrt();
        for &v in c {
            if let (Some(d), Some(n)) = (density.get_mut(v as usize), normal.get_mut(v as usize)) {
                *d = d.max(face_density);
                *n += cross;
            }
        }
    }
    let normals = normal
        .iter()
        .map(|n| {
            let unit = if n.length() > 0.0 && n.length().is_finite() { *n / n.length() } else { DVec3::ZERO };
            let bits = unit.to_array().map(|x| half::f16::from_f64(x).to_bits());
            [bits[0], bits[1], bits[2], 0]
        })
        .collect();
    (density.iter().map(|&d| if d.is_finite() { d as f32 } else { f32::MAX }).collect(), normals)
}

/// Levels added to the trilinear level of detail: the pixel size is scaled by `2^LOD_BIAS`.
/// Keep in sync with `LOD_BIAS` in crates/core/src/packing/lod.rs (the renderer applies it).
const LOD_BIAS: f64 = -2.0;

/// `struct FrameUniforms` of shaders/frame.wgsl (176 bytes).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameUniforms {
    clip_from_world: [[f32; 4]; 4],
    light: [f32; 4],
    wire_color: [f32; 4],
    tint: [f32; 4],
    lod_eye: [f32; 4],
    filter_kind: u32,
    level_mode: u32,
    level: u32,
    flags: u32,
    atlas_width: u32,
    sample_count: u32,
    vertex_levels: u32,
    wire_width: f32,
    face_count: u32,
    vertex_count: u32,
    pad: [u32; 2],
}

/// Entries per row of the three data textures (`MESH_DATA_WIDTH_LOG2 = 12` in the shader).
const DATA_WIDTH: u32 = 4096;

/// A texture of `width`-texel rows holding `data` (whole texels of `texel_bytes`), zero-padded.
fn texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    format: wgpu::TextureFormat,
    width: u32,
    texel_bytes: u32,
    data: &[u8],
) -> wgpu::TextureView {
    let texels = data.len() as u64 / u64::from(texel_bytes);
    let height = texels.div_ceil(u64::from(width)).max(1) as u32;
    let mut padded = data.to_vec();
    padded.resize((width * height * texel_bytes) as usize, 0);
    let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let layout =
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * texel_bytes), rows_per_image: None };
    queue.write_texture(texture.as_image_copy(), &padded, layout, size);
    texture.create_view(&Default::default())
}

/// A device on the first adapter (Vulkan first, then GL; lavapipe without a GPU).
fn device() -> Result<(wgpu::Device, wgpu::Queue, String)> {
    for backends in [wgpu::Backends::VULKAN, wgpu::Backends::GL] {
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        descriptor.backends = wgpu::Backends::from_env().unwrap_or(backends);
        let instance = wgpu::Instance::new(descriptor);
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        };
        let Ok(adapter) = pollster::block_on(instance.request_adapter(&options)) else { continue };
        let descriptor = wgpu::DeviceDescriptor { required_limits: adapter.limits(), ..Default::default() };
        let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))?;
        return Ok((device, queue, adapter.get_info().name));
    }
    bail!("no GPU adapter (install mesa-vulkan-drivers for lavapipe)")
}

/// Renders `input` lit and trilinear at `width × height` from `yaw`/`pitch` (degrees) into the
/// PNG `output`. Returns the adapter's name.
pub fn view_packed(input: &Path, output: &Path, size: (u32, u32), yaw: f64, pitch: f64) -> Result<String> {
    let packed = read_packed(input)?;
    let (width, height) = size;
    let (device, queue, adapter) = device()?;
    let (origin, clip_from_world, light, eye) = camera(&packed.positions, yaw, pitch, width, height);
    let (density, normals) = vertex_lod(&packed.positions, &packed.indices, &packed.face_records);

    // Bindings 1..5: positions relative to the render origin (subtracted in f64) with each
    // vertex's sample density in w, vertex ids, face records (one RGBA32 texel each), the
    // colour atlas (one texel per sample) and the vertex normals (Rgba16Float).
    let relative: Vec<[f32; 4]> = packed
        .positions
        .iter()
        .zip(&density)
        .map(|(p, &density)| {
            let p = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) - origin;
            [p.x as f32, p.y as f32, p.z as f32, density]
        })
        .collect();
    let corners: Vec<[u32; 4]> = packed.indices.chunks_exact(3).map(|c| [c[0], c[1], c[2], 0]).collect();
    let face_count = corners.len() as u32;
    let (atlas_format, sample_bytes) = match packed.color_format {
        0 => (wgpu::TextureFormat::Rgba8UnormSrgb, 4),
        1 => (wgpu::TextureFormat::Rgba16Float, 8),
        _ => (wgpu::TextureFormat::Rgba32Float, 16),
    };
    let atlas_width = device.limits().max_texture_dimension_2d.min(16384);
    let data = |format, bytes: &[u8]| texture(&device, &queue, format, DATA_WIDTH, 16, bytes);
    let views = [
        data(wgpu::TextureFormat::Rgba32Float, bytemuck::cast_slice(&relative)),
        data(wgpu::TextureFormat::Rgba32Uint, bytemuck::cast_slice(&corners)),
        data(wgpu::TextureFormat::Rgba32Uint, bytemuck::cast_slice(&packed.face_records)),
        texture(&device, &queue, atlas_format, atlas_width, sample_bytes, &packed.colors),
        texture(&device, &queue, wgpu::TextureFormat::Rgba16Float, DATA_WIDTH, 8, bytemuck::cast_slice(&normals)),
    ];
    let uniforms = FrameUniforms {
        clip_from_world: clip_from_world.as_mat4().to_cols_array_2d(),
        light: [light.x as f32, light.y as f32, light.z as f32, 0.25],
        wire_color: [0.0, 0.0, 0.0, 0.85],
        tint: [1.0; 4],
        // Eye relative to the origin; the world size of a pixel at unit depth (40° fov),
        // scaled by 2^LOD_BIAS (docs/FORMAT.md, the level of detail).
        lod_eye: [
            eye.x as f32,
            eye.y as f32,
            eye.z as f32,
            (2.0 * 20.0f64.to_radians().tan() / f64::from(height.max(1)) * LOD_BIAS.exp2()) as f32,
        ],
        filter_kind: 1, // linear
        level_mode: 1,  // automatic level (trilinear)
        level: 0,
        flags: 1 | 8, // FLAG_LIT | FLAG_SMOOTH: smooth shading from the vertex normals (binding 5)
        atlas_width,
        sample_count: u32::try_from(packed.sample_count).unwrap_or(u32::MAX).max(1),
        vertex_levels: packed.vertex_levels.max(1),
        wire_width: 1.0,
        face_count,
        vertex_count: packed.positions.len() as u32,
        pad: [0; 2],
    };
    let uniform_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: std::mem::size_of::<FrameUniforms>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&uniform_buffer, 0, bytemuck::bytes_of(&uniforms));

    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(WGSL.into()),
    });
    // Layout from the shader (auto): binding 0 uniforms, 1..3 vertex-stage data textures,
    // 4 the atlas (unfilterable float or uint, read with textureLoad).
    let constants = [("FILTER_KIND", 1.0), ("LEVEL_MODE", 1.0)];
    let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    let target_format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: options.clone(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(), // triangle list, no culling
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: options,
            targets: &[Some(target_format.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let mut entries = vec![wgpu::BindGroupEntry { binding: 0, resource: uniform_buffer.as_entire_binding() }];
    for (k, view) in views.iter().enumerate() {
        entries
            .push(wgpu::BindGroupEntry { binding: k as u32 + 1, resource: wgpu::BindingResource::TextureView(view) });
    }
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let image = draw(&device, &queue, &pipeline, &bind_group, face_count, (width, height))?;
    image.save(output).with_context(|| format!("writing {}", output.display()))?;
    Ok(adapter)
}

/// Draws `3 · face_count` pulled vertices into an sRGB target cleared to meshpaint's
/// background and reads the image back.
fn draw(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pipeline: &wgpu::RenderPipeline,
    bind_group: &wgpu::BindGroup,
    face_count: u32,
    (width, height): (u32, u32),
) -> Result<image::RgbaImage> {
    let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
    let target = |format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let color = target(
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let depth = target(wgpu::TextureFormat::Depth32Float, wgpu::TextureUsages::RENDER_ATTACHMENT);
    let (color_view, depth_view) = (color.create_view(&Default::default()), depth.create_view(&Default::default()));
    let row = (width * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row) * u64::from(height),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        // meshpaint's background, linear (f32 values, as its renderer passes them).
        let background = wgpu::Color { r: f64::from(0.05f32), g: f64::from(0.055f32), b: f64::from(0.06f32), a: 1.0 };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(background), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..face_count * 3, 0..1);
    }
    let layout = wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(height) };
    encoder.copy_texture_to_buffer(
        color.as_image_copy(),
        wgpu::TexelCopyBufferInfo { buffer: &readback, layout },
        size,
    );
    queue.submit([encoder.finish()]);
    readback.map_async(wgpu::MapMode::Read, .., |_| {});
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let mut pixels = Vec::with_capacity((width * height * 4) as usize);
    for line in readback.get_mapped_range(..)?.chunks_exact(row as usize) {
        pixels.extend_from_slice(&line[..(width * 4) as usize]);
    }
    image::RgbaImage::from_raw(width, height, pixels).context("readback size")
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(input), Some(output)) = (args.first(), args.get(1)) else {
        bail!("usage: view_packed FILE.mpk OUT.png [WIDTH HEIGHT [YAW PITCH]]");
    };
    let number = |k: usize, default: f64| args.get(k).map_or(Ok(default), |a| a.parse::<f64>().context("a number"));
    let size = (number(2, 1024.0)? as u32, number(3, 768.0)? as u32);
    let adapter = view_packed(&PathBuf::from(input), &PathBuf::from(output), size, number(4, 30.0)?, number(5, 20.0)?)?;
    println!("{input} → {output} ({adapter})");
    Ok(())
}
