//! Texture → mesh colors against independent truths: the closed form of a gradient, the
//! average of a checker, the owner-face rule across a UV seam, the image's V axis, and
//! real textured models against the texture's own average over the mapped area.

// Colour channels are indexed 0..4 in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use meshpaint_core::colors::format::{Rgba, decode_rgba8_srgb, linear_to_srgb};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::convert::bake::{TexturePyramid, bake_texture, has_base_color};
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::scene::{Material, Scene, Texture};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::mesh::weld::{WeldedMesh, weld_scene};

use crate::common;
use common::model;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// A texture from a function of the texel centre's UV returning sRGB-encoded bytes.
fn texture(width: u32, height: u32, texel: impl Fn(f64, f64) -> [u8; 4]) -> Texture {
    let mut rgba8_srgb = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height {
        for x in 0..width {
            let u = (f64::from(x) + 0.5) / f64::from(width);
            let v = (f64::from(y) + 0.5) / f64::from(height);
            rgba8_srgb.extend_from_slice(&texel(u, v));
        }
    }
    Texture { width, height, rgba8_srgb }
}

fn srgb_byte(linear: f64) -> u8 {
    (f64::from(linear_to_srgb(linear as f32)) * 255.0).round() as u8
}

/// The unit quad `(0,0) (1,0) (1,1) (0,1)` in z = 0 as faces `[0, 1, 2]` and `[0, 2, 3]`,
/// with per-face corner UVs and material 0.
fn quad(corner_uvs: [[[f32; 2]; 3]; 2]) -> WeldedMesh {
    WeldedMesh {
        positions_world: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        corner_uvs: corner_uvs.to_vec(),
        corner_normals_world: vec![[[0.0, 0.0, 1.0]; 3]; 2],
        triangle_materials: vec![Some(0), Some(0)],
        ..WeldedMesh::default()
    }
}

/// The quad with UV = `offset + scale · position` on both faces (no seam).
fn mapped_quad(offset: f32, scale: f32) -> WeldedMesh {
    let uv = |x: f32, y: f32| [offset + scale * x, offset + scale * y];
    quad([[uv(0.0, 0.0), uv(1.0, 0.0), uv(1.0, 1.0)], [uv(0.0, 0.0), uv(1.0, 1.0), uv(0.0, 1.0)]])
}

fn scene_with(texture: Texture, factor: Rgba) -> Scene {
    Scene {
        materials: vec![Material { base_color_factor: factor, base_color_texture: Some(0) }],
        textures: vec![texture],
        ..Scene::default()
    }
}

fn baked(mesh: &WeldedMesh, scene: &Scene, resolution: u64) -> ColorStore {
    let topology = Topology::build(mesh.positions_world.len() as u32, &mesh.triangles).unwrap();
    let mut store = ColorStore::uniform(topology, r(resolution), [f32::NAN; 4]);
    bake_texture(&mut store, mesh, scene);
    store
}

/// Every sample with its site's UV (from the owner face) and its baked colour.
fn samples_with_uv(store: &ColorStore, mesh: &WeldedMesh) -> Vec<(SampleRef, u32, [f64; 2], Rgba)> {
    let mut out = Vec::new();
    store.for_each_site(|site| {
        let uvs = mesh.corner_uvs[site.face as usize];
        let uv: [f64; 2] =
            std::array::from_fn(|a| (0..3).map(|k| f64::from(site.barycentric[k]) * f64::from(uvs[k][a])).sum());
        out.push((site.sample, site.face, uv, store.get(site.sample).unwrap()));
    });
    out
}

/// (a) A gradient linear in linear light is reproduced at every sample: mipmapping and
/// bilinear filtering keep linear functions exact, so only the texture's 8-bit rounding
/// remains (≤ ½ step in sRGB).
#[test]
fn linear_gradient_is_reproduced_at_every_sample() {
    let gradient = |u: f64, v: f64| [0.05 + 0.9 * u, 0.1 + 0.8 * v, 0.2 + 0.3 * u + 0.4 * v];
    let tex = texture(256, 256, |u, v| {
        let g = gradient(u, v);
        [srgb_byte(g[0]), srgb_byte(g[1]), srgb_byte(g[2]), 255]
    });
    let mesh = mapped_quad(0.1, 0.8);
    for (factor, resolution) in [([1.0, 1.0, 1.0, 1.0], 16), ([0.5, 1.0, 0.25, 0.75], 16), ([1.0; 4], 64)] {
        let store = baked(&mesh, &scene_with(tex.clone(), factor), resolution);
        let samples = samples_with_uv(&store, &mesh);
        assert_eq!(samples.len() as u64, store.sample_count());
        for (sample, _, uv, color) in samples {
            let g = gradient(uv[0], uv[1]);
            for c in 0..3 {
                let expected = linear_to_srgb((f64::from(factor[c]) * g[c]) as f32);
                let got = linear_to_srgb(color[c]);
                assert!(
                    (got - expected).abs() <= 1.0 / 255.0,
                    "R={resolution} {sample:?} uv {uv:?} channel {c}: {got} vs {expected}"
                );
            }
            assert!((color[3] - factor[3]).abs() < 1e-6, "alpha {}", color[3]);
        }
    }
}

fn checker_texture() -> Texture {
    // 64 × 64 texels, squares of 8 × 8 texels: black and white.
    texture(64, 64, |u, v| {
        let (x, y) = ((u * 64.0) as u32 / 8, (v * 64.0) as u32 / 8);
        if (x + y) % 2 == 0 { [255, 255, 255, 255] } else { [0, 0, 0, 255] }
    })
}

/// (b) At a low resolution a sample stands for many checker squares and must be their
/// average (grey in linear light), not a point sample of black or white.
#[test]
fn fine_checker_at_low_resolution_averages_to_grey() {
    let mesh = mapped_quad(0.0, 1.0);
    let scene = scene_with(checker_texture(), [1.0; 4]);
    for resolution in [1, 2, 4] {
        let store = baked(&mesh, &scene, resolution);
        for (sample, _, _, color) in samples_with_uv(&store, &mesh) {
            for c in 0..3 {
                assert!((color[c] - 0.5).abs() < 1e-3, "R={resolution} {sample:?}: {color:?}");
            }
        }
    }
}

/// (b) At a resolution finer than the texels the checker comes back: every sample more
/// than a texel away from a square's border is exactly black or white.
#[test]
fn checker_at_high_resolution_is_reproduced() {
    let mesh = mapped_quad(0.0, 1.0);
    let scene = scene_with(checker_texture(), [1.0; 4]);
    let store = baked(&mesh, &scene, 128);
    let (mut inside, mut total) = (0, 0);
    for (sample, _, uv, color) in samples_with_uv(&store, &mesh) {
        total += 1;
        let texel = [uv[0] * 64.0, uv[1] * 64.0];
        let away = texel.iter().all(|t| {
            let m = t.rem_euclid(8.0);
            (1.0..=7.0).contains(&m)
        });
        if !away {
            continue;
        }
        inside += 1;
        let white = ((texel[0] / 8.0).floor() as i64 + (texel[1] / 8.0).floor() as i64) % 2 == 0;
        let expected = if white { 1.0 } else { 0.0 };
        for c in 0..3 {
            assert!((color[c] - expected).abs() < 1e-5, "{sample:?} at uv {uv:?}: {color:?}, expected {expected}");
        }
    }
    assert!(inside * 2 > total, "{inside} of {total} samples away from borders");
}

/// (c) A seam: the quad's diagonal (vertices 0 and 2) is shared by faces 0 and 1, which map
/// it to different texels (red half and blue half of the image). Every shared sample is
/// owned by face 0 (the lower id) and takes face 0's UVs: red.
#[test]
fn uv_seam_takes_the_owner_faces_uvs() {
    let tex = texture(64, 64, |u, _| if u < 0.5 { [255, 0, 0, 255] } else { [0, 0, 255, 255] });
    let mesh = quad([
        [[0.15, 0.15], [0.35, 0.15], [0.35, 0.35]], // red half
        [[0.65, 0.15], [0.85, 0.35], [0.65, 0.35]], // blue half
    ]);
    let scene = scene_with(tex, [1.0; 4]);
    let store = baked(&mesh, &scene, 4);
    let red = [1.0, 0.0, 0.0, 1.0];
    let blue = [0.0, 0.0, 1.0, 1.0];
    let close = |a: Rgba, b: Rgba| (0..4).all(|c| (a[c] - b[c]).abs() < 1e-5);
    let topology = store.topology().clone();
    let diagonal = (0..topology.edge_count()).find(|&e| topology.edge_vertices[e as usize] == [0, 2]).unwrap();
    let mut shared = 0;
    for (sample, face, _, color) in samples_with_uv(&store, &mesh) {
        let expected = if face == 0 { red } else { blue };
        assert!(close(color, expected), "{sample:?} (owner {face}): {color:?}");
        let on_diagonal = match sample {
            SampleRef::Vertex(v) => v == 0 || v == 2,
            SampleRef::Edge { edge, .. } => edge == diagonal,
            SampleRef::Interior { .. } => false,
        };
        if on_diagonal {
            assert_eq!(face, 0, "{sample:?}: a shared sample's owner is the lowest face id");
            shared += 1;
        }
    }
    assert_eq!(shared, 2 + 3, "two vertices and R − 1 = 3 edge samples");
    // Face 1 reads the diagonal with its own lattice: red there, blue inside.
    assert!(close(store.face_sample(1, 0, 0).unwrap(), red));
    assert!(close(store.face_sample(1, 2, 0).unwrap(), red));
    assert!(close(store.face_sample(1, 1, 1).unwrap(), blue));
}

/// UV (0, 0) is the top-left of the image: a face mapped to small `v` reads the top rows.
#[test]
fn v_axis_runs_down_the_image() {
    // Top half (rows 0..32) green, bottom half magenta.
    let tex = texture(64, 64, |_, v| if v < 0.5 { [0, 255, 0, 255] } else { [255, 0, 255, 255] });
    let top = quad([[[0.3, 0.15], [0.5, 0.15], [0.5, 0.3]], [[0.3, 0.15], [0.5, 0.3], [0.3, 0.3]]]);
    let store = baked(&top, &scene_with(tex.clone(), [1.0; 4]), 8);
    for (sample, _, _, color) in samples_with_uv(&store, &top) {
        assert!(color[1] > 0.999 && color[0] < 1e-3, "{sample:?}: {color:?}");
    }
    let bottom = quad([[[0.3, 0.7], [0.5, 0.7], [0.5, 0.85]], [[0.3, 0.7], [0.5, 0.85], [0.3, 0.85]]]);
    let store = baked(&bottom, &scene_with(tex, [1.0; 4]), 8);
    for (sample, _, _, color) in samples_with_uv(&store, &bottom) {
        assert!(color[0] > 0.999 && color[1] < 1e-3, "{sample:?}: {color:?}");
    }
}

/// REPEAT wrapping: UVs outside [0, 1] read the image periodically.
#[test]
fn uvs_wrap_with_repeat() {
    let gradient = |u: f64, v: f64| [0.1 + 0.8 * u, 0.1 + 0.8 * v, 0.5];
    let tex = texture(128, 128, |u, v| {
        let g = gradient(u, v);
        [srgb_byte(g[0]), srgb_byte(g[1]), srgb_byte(g[2]), 255]
    });
    // UVs in [3.2, 3.8] × [−1.8, −1.2] ≡ [0.2, 0.8]².
    let shifted = quad([[[3.2, -1.8], [3.8, -1.8], [3.8, -1.2]], [[3.2, -1.8], [3.8, -1.2], [3.2, -1.2]]]);
    let store = baked(&shifted, &scene_with(tex, [1.0; 4]), 16);
    for (sample, _, uv, color) in samples_with_uv(&store, &shifted) {
        let g = gradient(uv[0].rem_euclid(1.0), uv[1].rem_euclid(1.0));
        for c in 0..3 {
            let (got, expected) = (linear_to_srgb(color[c]), linear_to_srgb(g[c] as f32));
            assert!((got - expected).abs() <= 1.0 / 255.0, "{sample:?} uv {uv:?}: {got} vs {expected}");
        }
    }
}

/// Faces without a texture get the factor; faces without a material get white.
#[test]
fn factor_only_and_default_materials() {
    let mut mesh = mapped_quad(0.0, 1.0);
    mesh.triangle_materials = vec![Some(0), None];
    let scene = Scene {
        materials: vec![Material { base_color_factor: [0.2, 0.4, 0.6, 0.8], base_color_texture: None }],
        ..Scene::default()
    };
    assert!(has_base_color(&mesh, &scene));
    let store = baked(&mesh, &scene, 4);
    for (sample, face, _, color) in samples_with_uv(&store, &mesh) {
        let expected = if face == 0 { [0.2, 0.4, 0.6, 0.8] } else { [1.0; 4] };
        assert_eq!(color, expected, "{sample:?}");
    }
    // A white factor without texture is nothing to bake.
    let white = Scene {
        materials: vec![Material { base_color_factor: [1.0; 4], base_color_texture: None }],
        ..Scene::default()
    };
    assert!(!has_base_color(&mesh, &white));
    // One uniform factor over the whole mesh (Bunny's flat grey) is not a signal either.
    let mut uniform = mesh.clone();
    uniform.triangle_materials = vec![Some(0), Some(0)];
    assert!(!has_base_color(&uniform, &scene));
    // A texture index that does not exist falls back to the factor.
    let missing = Scene {
        materials: vec![Material { base_color_factor: [0.5; 4], base_color_texture: Some(7) }],
        ..Scene::default()
    };
    let store = baked(&mesh, &missing, 2);
    assert_eq!(store.vertex_color(1), Some([0.5; 4]));
}

#[test]
fn pyramid_levels_are_box_filtered_in_linear_light() {
    // 5 × 3 (odd sizes): levels 2 × 1, then 1 × 1; the last level is the image mean.
    let tex = texture(5, 3, |u, v| [((u * 5.0) as u8) * 50, ((v * 3.0) as u8) * 100, 7, 255]);
    let pyramid = TexturePyramid::new(&tex).unwrap();
    let sizes: Vec<(u32, u32)> = pyramid.levels().iter().map(|l| (l.width, l.height)).collect();
    assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
    let mut mean = [0.0f64; 4];
    for p in tex.rgba8_srgb.chunks_exact(4) {
        let linear = decode_rgba8_srgb([p[0], p[1], p[2], p[3]]);
        for c in 0..4 {
            mean[c] += f64::from(linear[c]) / 15.0;
        }
    }
    let last = pyramid.levels()[2].texels[0];
    for c in 0..4 {
        assert!((f64::from(last[c]) - mean[c]).abs() < 1e-6, "{last:?} vs {mean:?}");
    }
    // A texture whose data does not match its size has no pyramid.
    assert!(TexturePyramid::new(&Texture { width: 2, height: 2, rgba8_srgb: vec![0; 15] }).is_none());
    assert!(TexturePyramid::new(&Texture { width: 0, height: 2, rgba8_srgb: vec![] }).is_none());
}

/// The texture's average over the mapped area, computed independently: for every face,
/// nearest-texel reads at a fixed set of barycentric points of its UV triangle, times the
/// factor; faces weighted equally (as the uniform-resolution samples are).
fn reference_mean(mesh: &WeldedMesh, scene: &Scene) -> [f64; 3] {
    let points = 48;
    let mut sum = [0.0f64; 3];
    for (face, uvs) in mesh.corner_uvs.iter().enumerate() {
        let material = mesh.triangle_materials[face].and_then(|m| scene.materials.get(m as usize));
        let factor = material.map_or([1.0; 4], |m| m.base_color_factor);
        let tex = material.and_then(|m| m.base_color_texture).and_then(|t| scene.textures.get(t as usize));
        let mut face_sum = [0.0f64; 3];
        let mut count = 0.0;
        for i in 0..=points {
            for j in 0..=points - i {
                let w = [(points - i - j) as f64 / points as f64, i as f64 / points as f64, j as f64 / points as f64];
                let uv: [f64; 2] = std::array::from_fn(|a| (0..3).map(|k| w[k] * f64::from(uvs[k][a])).sum());
                let texel = match tex {
                    Some(t) => {
                        let x = ((uv[0] * f64::from(t.width)).floor() as i64).rem_euclid(i64::from(t.width)) as usize;
                        let y = ((uv[1] * f64::from(t.height)).floor() as i64).rem_euclid(i64::from(t.height)) as usize;
                        let k = (y * t.width as usize + x) * 4;
                        let p = &t.rgba8_srgb[k..k + 4];
                        decode_rgba8_srgb([p[0], p[1], p[2], p[3]])
                    }
                    None => [1.0; 4],
                };
                for c in 0..3 {
                    face_sum[c] += f64::from(texel[c] * factor[c]);
                }
                count += 1.0;
            }
        }
        for c in 0..3 {
            sum[c] += face_sum[c] / count;
        }
    }
    sum.map(|s| s / mesh.corner_uvs.len() as f64)
}

/// Per face, the mean of its baked lattice (faces weighted equally).
fn baked_mean(store: &ColorStore) -> [f64; 3] {
    let faces = store.topology().face_count();
    let mut sum = [0.0f64; 3];
    for face in 0..faces {
        let lattice_r = store.face_resolution(face).unwrap().get();
        let mut face_sum = [0.0f64; 3];
        let mut count = 0.0;
        for i in 0..=lattice_r {
            for j in 0..=lattice_r - i {
                let color = store.face_sample(face, i, j).unwrap();
                for c in 0..3 {
                    face_sum[c] += f64::from(color[c]);
                }
                count += 1.0;
            }
        }
        for c in 0..3 {
            sum[c] += face_sum[c] / count;
        }
    }
    sum.map(|s| s / f64::from(faces))
}

fn bake_asset(relative: &str, resolution: u64) -> (WeldedMesh, Scene, ColorStore) {
    let scene = meshpaint_core::mesh::import::import_gltf(&model(relative)).unwrap();
    let mesh = weld_scene(&scene);
    let store = baked(&mesh, &scene, resolution);
    (mesh, scene, store)
}

/// (d) Real textured models bake to finite, varied colours whose mean matches the
/// texture's mean over the mapped area.
#[test]
fn textured_models_bake_to_their_textures_average() {
    for (name, relative) in [("BoxTextured", "BoxTextured/BoxTextured.glb"), ("Duck", "Duck/Duck.glb")] {
        let (mesh, scene, store) = bake_asset(relative, 8);
        assert!(has_base_color(&mesh, &scene), "{name}");
        let mut all = Vec::new();
        store.for_each_site(|site| all.push(store.get(site.sample).unwrap()));
        assert!(all.iter().flatten().all(|x| x.is_finite() && (0.0..=1.0 + 1e-6).contains(x)), "{name}: NaN or range");
        let luminance: Vec<f64> = all
            .iter()
            .map(|c| 0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2]))
            .collect();
        let mean_l = luminance.iter().sum::<f64>() / luminance.len() as f64;
        let var = luminance.iter().map(|l| (l - mean_l).powi(2)).sum::<f64>() / luminance.len() as f64;
        assert!(var.sqrt() > 0.02, "{name}: nearly uniform (σ = {})", var.sqrt());
        let got = baked_mean(&store);
        let expected = reference_mean(&mesh, &scene);
        for c in 0..3 {
            assert!((got[c] - expected[c]).abs() < 0.02, "{name}: mean {got:?} vs texture {expected:?}");
        }
        if name == "Duck" {
            assert!(got[0] > 3.0 * got[2] && got[1] > 3.0 * got[2], "Duck is yellow: {got:?}");
        }
    }
}

/// `Document::open` bakes textured files, gives factor-only materials their colour and plain
/// meshes the neutral grey.
#[test]
fn document_open_bakes_textured_models() {
    let document = Document::open(&model("Duck/Duck.glb"), r(4)).unwrap();
    let (mesh, scene, mut store) = bake_asset("Duck/Duck.glb", 4);
    meshpaint_core::convert::least_squares::refine(&mut store, &mesh, &scene).unwrap();
    let mut same = true;
    store.for_each_site(|site| same &= document.store.get(site.sample) == store.get(site.sample));
    assert!(same, "the opened Duck is the baked and fitted Duck");
    assert!(document.store.clone().take_dirty().is_empty(), "opening leaves nothing dirty");

    // Cubes: factor-only materials, one colour per face.
    let path = model("Cubes/Cubes.glb");
    let document = Document::open(&path, r(2)).unwrap();
    let scene = meshpaint_core::mesh::import::import_gltf(&path).unwrap();
    let mesh = weld_scene(&scene);
    document.store.for_each_site(|site| {
        let material = mesh.triangle_materials[site.face as usize].unwrap();
        let factor = scene.materials[material as usize].base_color_factor;
        assert_eq!(document.store.get(site.sample), Some(factor), "{site:?}");
    });

    // Suzanne has no material: every sample is the neutral light grey (8-bit sRGB 203).
    let path = model("Suzanne/monkey.glb");
    let document = Document::open(&path, r(2)).unwrap();
    document.store.for_each_site(|site| {
        let got = document.store.get(site.sample).unwrap();
        assert_eq!(got, meshpaint_core::io::document::NEUTRAL_BASE_COLOR, "{site:?}");
        assert_eq!(meshpaint_core::colors::format::encode_rgba8_srgb(got), [203, 203, 203, 255], "{site:?}");
    });
    // The position colour field is a view of it, computed from the positions alone.
    let view = meshpaint_core::io::document::position_colored(&document.store, &document.positions);
    let (min, size) = meshpaint_core::io::document::bounds(&document.positions);
    for v in 0..document.positions.len() as u32 {
        let expected = meshpaint_core::io::document::position_color(document.positions[v as usize], min, size);
        let got = view.vertex_color(v).unwrap();
        assert!((0..4).all(|c| (got[c] - expected[c]).abs() < 1e-6), "vertex {v}: {got:?} vs {expected:?}");
    }
}

/// (d) The level a sample is read at follows the lattice's spacing, not the longest edge:
/// the quad's faces are right triangles whose legs span 64 texels, so at R = 64 the lattice
/// is a square grid of one texel (its diagonal neighbours 1.41 texels away) and must read
/// level 0 unblurred, at R = 32 exactly level 1 (2 texels). The truth is this test's own
/// bilinear lookup on levels it box-filters itself from a random texture.
#[test]
fn the_mip_level_follows_the_lattice_spacing_of_a_right_triangle() {
    let state = std::cell::Cell::new(0x9e37_79b9_u32);
    let next = || {
        let mut s = state.get();
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        state.set(s);
        (s >> 24) as u8
    };
    let tex = texture(64, 64, |_, _| [next(), next(), next(), 255]);
    let level0: Vec<[f64; 3]> = tex
        .rgba8_srgb
        .chunks_exact(4)
        .map(|p| {
            let l = decode_rgba8_srgb([p[0], p[1], p[2], p[3]]);
            [f64::from(l[0]), f64::from(l[1]), f64::from(l[2])]
        })
        .collect();
    // Level 1: 2 × 2 box averages.
    let level1: Vec<[f64; 3]> = (0..32 * 32)
        .map(|k| {
            let (x, y) = (k % 32, k / 32);
            let mut sum = [0.0; 3];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let t = level0[(2 * y + dy) * 64 + 2 * x + dx];
                for c in 0..3 {
                    sum[c] += t[c] / 4.0;
                }
            }
            sum
        })
        .collect();
    let bilinear = |texels: &[[f64; 3]], size: usize, uv: [f64; 2]| -> [f64; 3] {
        let (x, y) = (uv[0] * size as f64 - 0.5, uv[1] * size as f64 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at =
            |xi: i64, yi: i64| texels[yi.rem_euclid(size as i64) as usize * size + xi.rem_euclid(size as i64) as usize];
        let mut out = [0.0; 3];
        for (dx, dy, w) in
            [(0, 0, (1.0 - fx) * (1.0 - fy)), (1, 0, fx * (1.0 - fy)), (0, 1, (1.0 - fx) * fy), (1, 1, fx * fy)]
        {
            let t = at(x0 as i64 + dx, y0 as i64 + dy);
            for c in 0..3 {
                out[c] += w * t[c];
            }
        }
        out
    };
    let mesh = mapped_quad(0.0, 1.0);
    let scene = scene_with(tex, [1.0; 4]);
    for (resolution, texels, size) in [(64u64, &level0, 64usize), (32, &level1, 32)] {
        let store = baked(&mesh, &scene, resolution);
        let mut worst = 0.0f64;
        for (_, _, uv, color) in samples_with_uv(&store, &mesh) {
            let expected = bilinear(texels, size, uv);
            for c in 0..3 {
                worst = worst.max((f64::from(color[c]) - expected[c]).abs());
            }
        }
        assert!(worst < 1e-5, "R = {resolution}: largest difference {worst} from level {}", 64 / size - 1);
    }
}

/// The table encode the error measures use, against the IEC 61966-2-1 formula in f64 written
/// here: every 61st float in [0, 1] (a stride that visits every interval at many offsets),
/// both ends and the knee; within 2·10⁻⁷ and never decreasing.
#[test]
fn the_table_srgb_encode_is_within_2e_7_of_the_formula_and_monotonic() {
    use meshpaint_core::colors::format::linear_to_srgb_table;
    let formula = |x: f64| if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    let (mut worst, mut previous) = (0.0f64, f32::NEG_INFINITY);
    let mut check = |x: f32| {
        let y = linear_to_srgb_table(x);
        worst = worst.max((f64::from(y) - formula(f64::from(x))).abs());
        y
    };
    for bits in (0..=1.0f32.to_bits()).step_by(61).chain([1.0f32.to_bits()]) {
        let y = check(f32::from_bits(bits));
        assert!(y >= previous, "decreasing at {}", f32::from_bits(bits));
        previous = y;
    }
    for x in [0.0, 0.003_130_8, 1.0 / 512.0, 0.5, 1.0] {
        check(x);
    }
    assert!(worst <= 2e-7, "worst {worst:e}");
    assert_eq!(linear_to_srgb_table(f32::NAN), 0.0);
    assert_eq!(linear_to_srgb_table(-1.0), 0.0);
    assert_eq!(linear_to_srgb_table(7.0), linear_to_srgb_table(1.0));
}
