//! The WGSL sources the pipelines compile (`meshpaint_render::{MESH_COLORS_WGSL,
//! UV_BASELINE_WGSL}`: shaders/frame.wgsl prepended to each shader) parse and validate with
//! naga (the same naga wgpu uses), declare what the renderer binds, and agree with the Rust
//! side of the shared uniform block: no GPU needed.

use std::path::Path;

use meshpaint_render::{FRAME_WGSL, FrameUniforms, HTEX_WGSL, MCT_WGSL, MESH_COLORS_WGSL, PTEX_WGSL, UV_BASELINE_WGSL};

/// The assembled sources, by the name of the file each one ends with.
const SOURCES: [(&str, &str); 5] = [
    ("mesh_colors.wgsl", MESH_COLORS_WGSL),
    ("uv_baseline.wgsl", UV_BASELINE_WGSL),
    ("mct.wgsl", MCT_WGSL),
    ("htex.wgsl", HTEX_WGSL),
    ("ptex.wgsl", PTEX_WGSL),
];

fn validate(name: &str, source: &str) -> (naga::Module, naga::valid::ModuleInfo) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|error| panic!("{}", error.emit_to_string_with_path(source, name)));
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|error| panic!("{}", error.emit_to_string_with_path(source, name)));
    (module, info)
}

#[test]
fn every_shader_parses_and_validates() {
    // shaders/ holds the shared parts and the shaders the library assembles, nothing
    // that would go unvalidated.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|error| panic!("{}: {error}", dir.display()))
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".wgsl"))
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "frame.wgsl",
            "htex.wgsl",
            "mct.wgsl",
            "mesh_colors.wgsl",
            "mesh_common.wgsl",
            "ptex.wgsl",
            "uv_baseline.wgsl"
        ]
    );
    for (name, source) in SOURCES {
        assert!(source.starts_with(FRAME_WGSL), "{name} does not start with shaders/frame.wgsl");
        validate(name, source);
    }
    // The shared part stands on its own too (it only declares; no entry points).
    let (frame, _) = validate("frame.wgsl", FRAME_WGSL);
    assert!(frame.entry_points.is_empty());
}

#[test]
fn shaders_have_the_entry_points_and_bindings_the_renderer_uses() {
    for ((name, source), bindings) in SOURCES.into_iter().zip([0..6u32, 0..3u32, 0..9u32, 0..8u32]) {
        let (module, _) = validate(name, source);
        let entry_points: Vec<&str> = module.entry_points.iter().map(|entry| entry.name.as_str()).collect();
        assert!(entry_points.contains(&"vs_main") && entry_points.contains(&"fs_main"), "{name}: {entry_points:?}");
        let mut found: Vec<u32> = module
            .global_variables
            .iter()
            .filter_map(|(_, global)| global.binding.as_ref())
            .inspect(|binding| assert_eq!(binding.group, 0, "{name}"))
            .map(|binding| binding.binding)
            .collect();
        found.sort_unstable();
        assert_eq!(found, bindings.collect::<Vec<_>>(), "{name}");
        // The uniform block is 176 bytes, as `FrameUniforms` on the Rust side.
        let uniform = module
            .global_variables
            .iter()
            .find(|(_, global)| global.space == naga::AddressSpace::Uniform && global.name.as_deref() == Some("u"))
            .map(|(_, global)| global.ty)
            .unwrap();
        let size = module.types[uniform].inner.size(module.to_ctx());
        assert_eq!(size as usize, std::mem::size_of::<FrameUniforms>(), "{name}");
    }
}

/// `(name, offset)` of every field of the Rust `FrameUniforms`, in the order given. The
/// exhaustive pattern makes a field added to or removed from the struct a compile error here.
macro_rules! rust_fields {
    ($($field:ident),* $(,)?) => {{
        let FrameUniforms { $($field: _),* } = <FrameUniforms as bytemuck::Zeroable>::zeroed();
        vec![$((stringify!($field).to_owned(), std::mem::offset_of!(FrameUniforms, $field))),*]
    }};
}

#[test]
fn the_wgsl_frame_struct_matches_the_rust_struct_field_by_field() {
    let rust = rust_fields!(
        clip_from_world,
        light,
        wire_color,
        tint,
        lod_eye,
        filter_kind,
        level_mode,
        level,
        flags,
        atlas_width,
        sample_count,
        vertex_levels,
        wire_width,
        face_count,
        vertex_count,
        _pad0,
        _pad1,
    );
    let (module, _) = validate("frame.wgsl", FRAME_WGSL);
    let (members, span) = module
        .types
        .iter()
        .find_map(|(_, ty)| match (&ty.name, &ty.inner) {
            (Some(name), naga::TypeInner::Struct { members, span }) if name == "FrameUniforms" => {
                Some((members, *span))
            }
            _ => None,
        })
        .expect("no struct FrameUniforms in shaders/frame.wgsl");
    let wgsl: Vec<(String, usize)> =
        members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize)).collect();
    assert_eq!(wgsl, rust, "shaders/frame.wgsl and crates/render/src/uniforms.rs disagree (name, offset)");
    assert_eq!(span as usize, std::mem::size_of::<FrameUniforms>());
}

#[test]
fn the_wgsl_flag_bits_match_the_rust_constants() {
    let (module, _) = validate("frame.wgsl", FRAME_WGSL);
    let value = |name: &str| -> u32 {
        let (_, constant) = module
            .constants
            .iter()
            .find(|(_, constant)| constant.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no const {name} in shaders/frame.wgsl"));
        match module.global_expressions[constant.init] {
            naga::Expression::Literal(naga::Literal::U32(value)) => value,
            ref other => panic!("{name} is not a u32 literal: {other:?}"),
        }
    };
    assert_eq!(value("FLAG_LIT"), FrameUniforms::FLAG_LIT);
    assert_eq!(value("FLAG_WIREFRAME"), FrameUniforms::FLAG_WIREFRAME);
    assert_eq!(value("FLAG_HEATMAP"), FrameUniforms::FLAG_HEATMAP);
    assert_eq!(value("FLAG_SMOOTH"), FrameUniforms::FLAG_SMOOTH);
    let flags: Vec<&str> = module.constants.iter().filter_map(|(_, c)| c.name.as_deref()).collect();
    assert_eq!(flags.iter().filter(|name| name.starts_with("FLAG_")).count(), 4, "{flags:?}");
}

#[test]
fn the_smooth_shading_crease_matches_the_rust_constant() {
    let (module, _) = validate("mesh_colors.wgsl", MESH_COLORS_WGSL);
    let (_, constant) = module
        .constants
        .iter()
        .find(|(_, constant)| constant.name.as_deref() == Some("SMOOTH_CREASE_COSINE"))
        .expect("no const SMOOTH_CREASE_COSINE in shaders/mesh_colors.wgsl");
    match module.global_expressions[constant.init] {
        naga::Expression::Literal(naga::Literal::F32(value)) => {
            assert_eq!(value, meshpaint_core::mesh::normals::SMOOTH_CREASE_COSINE);
            assert!((value - 45f32.to_radians().cos()).abs() < 1e-6, "the crease is 45°");
        }
        ref other => panic!("SMOOTH_CREASE_COSINE is not an f32 literal: {other:?}"),
    }
}

/// The shader's band table is a runtime-sized array of the 16-byte entries
/// crates/render/src/mct.rs `gpu_bands` uploads (`[u32; 4]` each, as `MctBands` entries).
#[test]
fn the_wgsl_mct_band_table_matches_the_rust_entries() {
    let (module, _) = validate("mct.wgsl", MCT_WGSL);
    let bands = module
        .global_variables
        .iter()
        .find(|(_, global)| global.name.as_deref() == Some("mct_bands"))
        .map(|(_, global)| global.ty)
        .unwrap();
    match module.types[bands].inner {
        naga::TypeInner::Array { size: naga::ArraySize::Dynamic, stride, .. } => {
            assert_eq!(stride as usize, std::mem::size_of::<[u32; 4]>());
            assert_eq!(
                std::mem::size_of::<meshpaint_core::mct::MctBands>(),
                std::mem::size_of::<[u32; 4]>() * meshpaint_core::mct::layout::GROUPS.pow(2)
            );
        }
        ref other => panic!("mct_bands is not a runtime-sized array: {other:?}"),
    }
    // The shader's group count is the core's.
    assert!(MCT_WGSL.contains(&format!("const MCT_GROUPS: u32 = {}u;", meshpaint_core::mct::layout::GROUPS)));
}

/// The Ptex shader's tables are a runtime-sized array of the 16-byte entries
/// crates/render/src/ptex.rs `gpu_tables` uploads, one per slice of the core's.
#[test]
fn the_wgsl_ptex_tables_match_the_rust_entries() {
    let (module, _) = validate("ptex.wgsl", PTEX_WGSL);
    let tables = module
        .global_variables
        .iter()
        .find(|(_, global)| global.name.as_deref() == Some("ptex_tables"))
        .map(|(_, global)| global.ty)
        .unwrap();
    match module.types[tables].inner {
        naga::TypeInner::Array { size: naga::ArraySize::Dynamic, stride, .. } => {
            assert_eq!(stride as usize, std::mem::size_of::<meshpaint_render::GpuPtexSlice>());
        }
        ref other => panic!("ptex_tables is not a runtime-sized array: {other:?}"),
    }
    assert!(PTEX_WGSL.contains(&format!("const PTEX_SLICES: u32 = {}u;", meshpaint_core::ptex::SLICES)));
}

/// The f32 literals of a constant expression, in order (vectors and arrays flattened).
fn literals(
    arena: &naga::Arena<naga::Expression>,
    module: &naga::Module,
    expr: naga::Handle<naga::Expression>,
) -> Vec<f32> {
    match &arena[expr] {
        naga::Expression::Literal(naga::Literal::F32(value)) => vec![*value],
        naga::Expression::Compose { components, .. } => {
            components.iter().flat_map(|&c| literals(arena, module, c)).collect()
        }
        naga::Expression::Splat { size, value } => literals(arena, module, *value).repeat(*size as usize),
        naga::Expression::Constant(constant) => {
            literals(&module.global_expressions, module, module.constants[*constant].init)
        }
        other => panic!("unexpected expression in the heat map table: {other:?}"),
    }
}

/// The legend's colours (`meshpaint_render::HEAT_COLORS`) are the shader's: the table that
/// `heat_color` in the compiled mesh-colors shader initialises, read from naga's IR, equals
/// the CPU copy value for value (13 entries, log2 R = 0..=12).
#[test]
fn the_heat_map_colours_on_the_cpu_are_the_shaders() {
    let (module, _) = validate("mesh_colors.wgsl", MESH_COLORS_WGSL);
    let (_, function) = module
        .functions
        .iter()
        .find(|(_, f)| f.name.as_deref() == Some("heat_color"))
        .expect("mesh_colors.wgsl has no heat_color");
    let tables: Vec<Vec<f32>> = function
        .local_variables
        .iter()
        .filter_map(|(_, var)| var.init)
        .map(|init| literals(&function.expressions, &module, init))
        .collect();
    assert_eq!(tables.len(), 1, "heat_color has one table");
    let cpu: Vec<f32> = meshpaint_render::HEAT_COLORS.iter().flatten().copied().collect();
    assert_eq!(tables[0], cpu);
    assert_eq!(meshpaint_render::heat_color(20), meshpaint_render::HEAT_COLORS[12], "R past 4096 clamps");
}
