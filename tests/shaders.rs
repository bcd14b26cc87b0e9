//! Every WGSL file in shaders/ parses and validates with naga (the same naga wgpu uses),
//! and declares what the renderer binds: no GPU needed.

use std::path::{Path, PathBuf};

fn shader_files() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|error| panic!("{}: {error}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "wgsl"))
        .collect();
    files.sort();
    files
}

fn validate(path: &Path) -> (naga::Module, naga::valid::ModuleInfo) {
    let source = std::fs::read_to_string(path).unwrap();
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|error| panic!("{}", error.emit_to_string_with_path(&source, &path.display().to_string())));
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|error| panic!("{}", error.emit_to_string_with_path(&source, &path.display().to_string())));
    (module, info)
}

#[test]
fn every_shader_parses_and_validates() {
    let files = shader_files();
    let names: Vec<String> =
        files.iter().map(|path| path.file_name().unwrap().to_string_lossy().into_owned()).collect();
    for expected in ["mesh_colors.wgsl", "uv_baseline.wgsl"] {
        assert!(names.iter().any(|name| name == expected), "{expected} missing from {names:?}");
    }
    for path in &files {
        validate(path);
    }
}

#[test]
fn shaders_have_the_entry_points_and_bindings_the_renderer_uses() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    for (file, bindings) in [("mesh_colors.wgsl", 0..5u32), ("uv_baseline.wgsl", 0..3u32)] {
        let (module, _) = validate(&dir.join(file));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|entry| entry.name.as_str()).collect();
        assert!(entry_points.contains(&"vs_main") && entry_points.contains(&"fs_main"), "{file}: {entry_points:?}");
        let mut found: Vec<u32> = module
            .global_variables
            .iter()
            .filter_map(|(_, global)| global.binding.as_ref())
            .inspect(|binding| assert_eq!(binding.group, 0, "{file}"))
            .map(|binding| binding.binding)
            .collect();
        found.sort_unstable();
        assert_eq!(found, bindings.collect::<Vec<_>>(), "{file}");
        // The uniform block is 160 bytes, as `FrameUniforms` on the Rust side.
        let uniform = module
            .global_variables
            .iter()
            .find(|(_, global)| global.space == naga::AddressSpace::Uniform)
            .map(|(_, global)| global.ty)
            .unwrap();
        let size = module.types[uniform].inner.size(module.to_ctx());
        assert_eq!(size as usize, std::mem::size_of::<meshpaint::render::FrameUniforms>(), "{file}");
    }
}
