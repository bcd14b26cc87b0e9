//! The numerical extremes of the per-face fit (crates/core/src/convert/adaptive.rs, issue 11): textures of
//! 1×1 and 8192², faces with zero UV area, UVs far outside [0, 1] (glTF's default sampler
//! wraps: REPEAT), slivers, non-manifold edges whose faces want different R. Each against
//! an independent expectation: a constant signal needs R = 1 and has zero error, a shift of
//! the UVs by whole periods changes nothing, the texture read here by the test's own
//! bilinear lookup at random points.

use crate::common;

use common::{Rng, model};
use glam::Mat4;
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::{linear_to_srgb, srgb_to_linear};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::mesh::scene::{Instance, Material, Scene, SourceMesh, Texture};
use meshpaint_core::packing::sampler::{Filter, sample};

fn r(value: u32) -> Resolution {
    Resolution::new(u64::from(value)).unwrap()
}

fn convert(scene: &Scene, rule: ResolutionRule) -> Document {
    Document::from_scene_within(scene.clone(), rule, std::path::Path::new("test.glb"), &Budget::from_environment())
        .unwrap()
}

/// Every content rule, with bounds from lossless to loose.
fn content_rules(max: u32) -> Vec<ResolutionRule> {
    vec![
        ResolutionRule::ErrorBound { bound: 0.0, max: r(max) },
        ResolutionRule::ErrorBound { bound: 0.01, max: r(max) },
        ResolutionRule::ErrorBound { bound: 0.2, max: r(max) },
        ResolutionRule::Budget { samples: 1 << 20, max: r(max) },
    ]
}

/// A scene of unwelded triangles (three vertices each, so every corner has its own UV;
/// bitwise-equal positions weld), all with material 0 = `texture` × white.
pub(crate) fn scene_of(corners: &[([f32; 3], [f32; 2])], texture: Texture) -> Scene {
    let mesh = SourceMesh {
        name: "test".into(),
        positions_local: corners.iter().map(|c| c.0).collect(),
        normals_local: vec![[0.0, 0.0, 1.0]; corners.len()],
        uvs: corners.iter().map(|c| c.1).collect(),
        colors: Vec::new(),
        triangles: (0..corners.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        triangle_materials: vec![Some(0); corners.len() / 3],
    };
    Scene {
        meshes: vec![mesh],
        instances: vec![Instance { mesh: 0, world_from_local: Mat4::IDENTITY }],
        materials: vec![Material { base_color_factor: [1.0; 4], base_color_texture: Some(0) }],
        textures: vec![texture],
        warnings: Vec::new(),
    }
}

pub(crate) fn texture_from(width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
    let mut rgba8_srgb = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height {
        for x in 0..width {
            rgba8_srgb.extend_from_slice(&texel(x, y));
        }
    }
    Texture { width, height, rgba8_srgb }
}

/// Deterministic noise texels (every texel independent: the hardest content).
fn noise(width: u32, height: u32, seed: u64) -> Texture {
    texture_from(width, height, |x, y| {
        let mut rng = Rng(seed ^ ((u64::from(y) << 32) | u64::from(x)).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        [0; 4].map(|_| (rng.unit() * 255.0) as u8).map(|c| c.max(1))
    })
}

/// The texture's level 0 at `uv`, bilinear with REPEAT, in linear light (glTF, from the spec).
fn bilinear(texture: &Texture, uv: [f32; 2]) -> [f32; 4] {
    let (w, h) = (i64::from(texture.width), i64::from(texture.height));
    let x = f64::from(uv[0]) * w as f64 - 0.5;
    let y = f64::from(uv[1]) * h as f64 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let texel = |xi: i64, yi: i64| {
        let (xi, yi) = (xi.rem_euclid(w) as usize, yi.rem_euclid(h) as usize);
        let p = &texture.rgba8_srgb[(yi * w as usize + xi) * 4..][..4];
        [0, 1, 2, 3].map(|c| if c < 3 { srgb_to_linear(f32::from(p[c]) / 255.0) } else { f32::from(p[c]) / 255.0 })
    };
    let mut out = [0.0f32; 4];
    for (dx, dy, weight) in
        [(0, 0, (1.0 - fx) * (1.0 - fy)), (1, 0, fx * (1.0 - fy)), (0, 1, (1.0 - fx) * fy), (1, 1, fx * fy)]
    {
        let t = texel(x0 as i64 + dx, y0 as i64 + dy);
        for c in 0..4 {
            out[c] += weight as f32 * t[c];
        }
    }
    out
}

/// Random barycentrics, uniform over the triangle.
fn random_bary(rng: &mut Rng) -> [f32; 3] {
    let (mut u, mut v) = (rng.unit(), rng.unit());
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    [1.0 - u - v, u, v]
}

/// RMS over `points` random points of `face` (sRGB-encoded RGB and alpha, the fit's
/// metric) between the document's linear filter and the texture at the face's UVs.
fn face_error(scene: &Scene, document: &Document, face: u32, uvs: [[f32; 2]; 3], points: usize) -> f32 {
    let texture = &scene.textures[0];
    let mut rng = Rng(0xface ^ u64::from(face));
    let mut sum = 0.0f64;
    for _ in 0..points {
        let b = random_bary(&mut rng);
        let uv = [0, 1].map(|a| (0..3).map(|k| b[k] * uvs[k][a]).sum::<f32>());
        let truth = bilinear(texture, uv);
        let shown = sample(&document.store, face, b, Filter::Linear, 0).unwrap();
        for c in 0..4 {
            let (a, e) =
                if c < 3 { (linear_to_srgb(shown[c]), linear_to_srgb(truth[c])) } else { (shown[c], truth[c]) };
            sum += f64::from(a - e).powi(2);
        }
    }
    (sum / (4 * points) as f64).sqrt() as f32
}

/// The welded corner UVs of each face, as the conversion sees them.
fn corner_uvs(scene: &Scene) -> Vec<[[f32; 2]; 3]> {
    meshpaint_core::mesh::weld::weld_scene(scene).corner_uvs
}

/// A unit quad (two triangles) with UVs over `[0, 1]²` and a separate triangle at z = 1.
fn quad_and_triangle(uv_of_third: [[f32; 2]; 3]) -> Vec<([f32; 3], [f32; 2])> {
    let quad = [
        ([0.0, 0.0, 0.0], [0.0, 1.0]),
        ([1.0, 0.0, 0.0], [1.0, 1.0]),
        ([1.0, 1.0, 0.0], [1.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 1.0]),
        ([1.0, 1.0, 0.0], [1.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0]),
    ];
    let third = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
    quad.into_iter().chain((0..3).map(|k| (third[k], uv_of_third[k]))).collect()
}

#[test]
fn a_one_texel_texture_gives_r1_everywhere_with_zero_error() {
    let texel = [200u8, 100, 50, 255];
    let scene = scene_of(&quad_and_triangle([[0.1, 0.1], [0.9, 0.2], [0.4, 0.8]]), texture_from(1, 1, |_, _| texel));
    let want = [0, 1, 2, 3].map(|c| if c < 3 { srgb_to_linear(f32::from(texel[c]) / 255.0) } else { 1.0 });
    // (Texel density is a closed form of the UV edge length, not of the content: 1.1 texels
    // give R = 2 by its definition, so it is not among these rules.)
    for rule in content_rules(64) {
        let document = convert(&scene, rule);
        let resolutions: Vec<u32> = document.store.face_resolutions().iter().map(|x| x.get()).collect();
        assert!(resolutions.iter().all(|&x| x == 1), "{rule:?}: {resolutions:?}");
        let mut rng = Rng(1);
        for face in 0..document.store.topology().face_count() {
            for _ in 0..50 {
                let got = sample(&document.store, face, random_bary(&mut rng), Filter::Linear, 0).unwrap();
                let error = (0..4).map(|c| (got[c] - want[c]).abs()).fold(0.0f32, f32::max);
                assert!(error <= 1e-6, "{rule:?} face {face}: {got:?} vs {want:?}");
            }
        }
    }
}

#[test]
fn a_face_with_zero_uv_area_is_constant_and_gets_r1() {
    let texture = noise(64, 64, 7);
    // The separate triangle maps all three corners to one UV point: one constant colour.
    let point = [0.3, 0.6];
    let scene = scene_of(&quad_and_triangle([point; 3]), texture.clone());
    let want = bilinear(&texture, point);
    let mut rules = content_rules(64);
    rules.push(ResolutionRule::TexelDensity { max: r(64) });
    for rule in rules {
        let document = convert(&scene, rule);
        let resolutions = document.store.face_resolutions();
        assert_eq!(resolutions[2].get(), 1, "{rule:?}: the zero-UV-area face");
        let mut rng = Rng(2);
        for _ in 0..100 {
            let got = sample(&document.store, 2, random_bary(&mut rng), Filter::Linear, 0).unwrap();
            let error = (0..4).map(|c| (got[c] - want[c]).abs()).fold(0.0f32, f32::max);
            assert!(error <= 1e-5, "{rule:?}: {got:?} vs {want:?}");
        }
        // The noise quad does need samples (the rule is not just giving up).
        if matches!(rule, ResolutionRule::ErrorBound { bound, .. } if bound < 0.1) {
            assert!(resolutions[0].get() > 1 && resolutions[1].get() > 1, "{rule:?}: {resolutions:?}");
        }
    }
}

/// Adds whole periods to every UV.
fn shifted(scene: &Scene, du: f32, dv: f32) -> Scene {
    let mut moved = scene.clone();
    for mesh in &mut moved.meshes {
        for uv in &mut mesh.uvs {
            *uv = [uv[0] + du, uv[1] + dv];
        }
    }
    moved
}

/// Largest channel difference over every stored sample of two documents of the same mesh.
fn largest_sample_difference(a: &Document, b: &Document) -> f32 {
    let mut worst = 0.0f32;
    a.store.for_each_site(|site| {
        let (x, y) = (a.store.get(site.sample).unwrap(), b.store.get(site.sample).unwrap());
        worst = worst.max((0..4).map(|c| (x[c] - y[c]).abs()).fold(0.0, f32::max));
    });
    worst
}

#[test]
fn uvs_shifted_by_whole_periods_give_the_same_resolutions_and_colours() {
    let scene = import_gltf(&model("Duck/Duck.glb")).unwrap();
    for rule in [ResolutionRule::ErrorBound { bound: 0.02, max: r(64) }, ResolutionRule::TexelDensity { max: r(64) }] {
        let reference = convert(&scene, rule);
        // f32 UVs near 7 are spaced 4.8e-7 (0.0005 texels of the Duck's 512² texture); near
        // 1000, 6.1e-5 (0.03 texels): the colours move by rounding only, the fit must not.
        for (du, dv, colour_tolerance) in [(7.0, -3.0, 1e-3f32), (-5.0, 12.0, 1e-3), (1000.0, 0.0, 0.05)] {
            let document = convert(&shifted(&scene, du, dv), rule);
            let flips = (reference.store.face_resolutions().iter())
                .zip(document.store.face_resolutions())
                .filter(|(a, b)| a != b)
                .count();
            let difference = if flips == 0 { largest_sample_difference(&reference, &document) } else { f32::NAN };
            eprintln!("{rule:?} shift ({du}, {dv}): {flips} faces change R, largest sample change {difference}");
            if du.abs() < 100.0 {
                assert_eq!(flips, 0, "{rule:?} shift ({du}, {dv})");
            } else {
                // Near 1000 the UVs themselves are rounded: a face exactly at the bound may move.
                assert!(flips * 200 <= reference.store.topology().face_count() as usize, "{flips} faces");
            }
            if flips == 0 {
                assert!(difference <= colour_tolerance, "{rule:?} shift ({du}, {dv}): {difference}");
            }
        }
    }
}

#[test]
fn a_texture_of_8192_squared_converts_within_the_budget() {
    // Constant but for one texel per 64×64 block: the fit reads the whole texture.
    let texture = texture_from(8192, 8192, |x, y| if x % 64 == 0 && y % 64 == 0 { [90, 90, 90, 255] } else { [90; 4] });
    let scene = scene_of(&quad_and_triangle([[0.1, 0.1], [0.9, 0.2], [0.4, 0.8]]), texture);
    let budget = Budget::from_environment();
    eprintln!("texture 8192² = {} texels; memory budget {} bytes", 8192u64 * 8192, budget.memory_bytes);
    // One rule: a conversion at this size takes ~100 s in a debug build (the texture's
    // pyramid); texel density at this size is the closed form of the Box test.
    let rule = ResolutionRule::ErrorBound { bound: 0.05, max: r(64) };
    let start = std::time::Instant::now();
    let document = convert(&scene, rule);
    let resolutions: Vec<u32> = document.store.face_resolutions().iter().map(|x| x.get()).collect();
    eprintln!(
        "8192² {rule:?}: R {resolutions:?}, {} samples, {:.2} s, peak RSS of this process {} kB",
        document.store.sample_count(),
        start.elapsed().as_secs_f64(),
        peak_rss_kb()
    );
    // One texel in 4096 differs (by 0.5 %): RMS far below 0.05, so R = 1 suffices.
    assert!(resolutions.iter().all(|&x| x == 1), "{resolutions:?}");
}

/// The process's peak resident set (`VmHWM`), kB; 0 when unknown.
fn peak_rss_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM:")).map(str::to_owned))
        .and_then(|l| l.split_whitespace().nth(1).and_then(|v| v.parse().ok()))
        .unwrap_or(0)
}

#[test]
fn sliver_faces_meet_the_bound_at_random_points() {
    // A sine along u, period 64 texels, on a 256² texture: smooth, so some R < 64 meets E.
    let texture = texture_from(256, 256, |x, _| {
        let s = (std::f64::consts::TAU * f64::from(x) / 64.0).sin();
        [(128.0 + 100.0 * s) as u8, (128.0 - 100.0 * s) as u8, 90, 255]
    });
    // Face 0: a sliver in UV space (a line across the stripes, UV area ~1e-9) on a normal
    // world triangle; face 1: a sliver in world space (height 1e-6) with normal UVs; face
    // 2: the same UVs as face 1 on a normal world triangle (the fit reads UVs only).
    let uv_sliver = [[0.05, 0.5], [0.95, 0.5], [0.5, 0.500_01]];
    let normal_uvs = [[0.1, 0.1], [0.7, 0.2], [0.3, 0.9]];
    let corners = vec![
        ([0.0, 0.0, 0.0], uv_sliver[0]),
        ([1.0, 0.0, 0.0], uv_sliver[1]),
        ([0.5, 1.0, 0.0], uv_sliver[2]),
        ([0.0, 0.0, 2.0], normal_uvs[0]),
        ([1.0, 0.0, 2.0], normal_uvs[1]),
        ([0.5, 1e-6, 2.0], normal_uvs[2]),
        ([0.0, 0.0, 4.0], normal_uvs[0]),
        ([1.0, 0.0, 4.0], normal_uvs[1]),
        ([0.5, 1.0, 4.0], normal_uvs[2]),
    ];
    let scene = scene_of(&corners, texture);
    let uvs = corner_uvs(&scene);
    for bound in [0.05f32, 0.02] {
        let document = convert(&scene, ResolutionRule::ErrorBound { bound, max: r(64) });
        let resolutions: Vec<u32> = document.store.face_resolutions().iter().map(|x| x.get()).collect();
        let errors: Vec<f32> = (0..3).map(|f| face_error(&scene, &document, f, uvs[f as usize], 400)).collect();
        eprintln!("sliver E = {bound}: R {resolutions:?}, random-point RMS {errors:?}");
        assert!(resolutions[0] > 1, "the UV sliver crosses the sine's periods");
        if bound >= 0.05 {
            assert!(resolutions[2] < 64, "smooth content fits below the cap");
        }
        assert_eq!(resolutions[1], resolutions[2], "a world sliver is fitted by its UVs like any face");
        for f in 0..3 {
            assert!(resolutions[f] == 64 || errors[f] <= 1.5 * bound, "face {f}: {errors:?} {resolutions:?}");
        }
    }
}

#[test]
fn non_manifold_edges_whose_faces_want_different_resolutions() {
    // Three pages on one spine (0,0,0)–(0,1,0): page 0 maps onto a flat region, page 1 onto a
    // gentle ramp, page 2 onto noise. Page 0 is the spine's owner (lowest face id), so the
    // spine shows its flat colour on every page. The flat region is wide (x < 768 of 1024):
    // the bake reads a face at R = 1 at MIP level log2(longest UV edge in texels), whose
    // bilinear footprint reaches about that far around the face — an island of other colours
    // within it makes a flat face need a higher R (measured: R = 16 with noise 50 texels away,
    // R = 2 with page 0 at u = 0.05, where REPEAT wraps the footprint onto the noise at u ≈ 1).
    let texture = texture_from(1024, 1024, |x, y| match x {
        0..=767 => [120, 160, 90, 255],
        768..=895 => [120, 160, 90u8.saturating_add(((x - 768) / 2) as u8), 255],
        _ => {
            let mut rng = Rng(u64::from(x) * 7919 + u64::from(y));
            [0; 4].map(|_| (rng.unit() * 255.0) as u8)
        }
    });
    let page = |tip: [f32; 3], (u0, u1): (f32, f32)| {
        [([0.0, 0.0, 0.0], [u0, 0.55]), ([0.0, 1.0, 0.0], [u0, 0.45]), (tip, [u1, 0.5])]
    };
    let corners: Vec<([f32; 3], [f32; 2])> = [
        page([1.0, 0.5, 0.0], (0.25, 0.4)),
        page([-0.5, 0.5, 0.8], (0.76, 0.86)),
        page([-0.5, 0.5, -0.8], (0.885, 0.99)),
    ]
    .concat();
    let scene = scene_of(&corners, texture);
    let uvs = corner_uvs(&scene);
    let bound = 0.02f32;
    let document = convert(&scene, ResolutionRule::ErrorBound { bound, max: r(64) });
    let topology = document.store.topology();
    let spine =
        (0..topology.edge_count()).find(|&e| topology.faces_of_edge(e).len() == 3).expect("a non-manifold edge");
    let resolutions: Vec<u32> = document.store.face_resolutions().iter().map(|x| x.get()).collect();
    let errors: Vec<f32> = (0..3).map(|f| face_error(&scene, &document, f, uvs[f as usize], 400)).collect();
    eprintln!("non-manifold pages: R {resolutions:?}, random-point RMS {errors:?}");
    assert_eq!(resolutions[0], 1, "the flat page");
    assert!(resolutions[2] > resolutions[0], "the noise page needs samples");
    assert_eq!(document.store.edge_resolution(spine).unwrap().get(), *resolutions.iter().max().unwrap());
    for f in 0..3 {
        assert!(resolutions[f] == 64 || errors[f] <= 1.5 * bound, "page {f}: {errors:?} {resolutions:?}");
    }
    // The document packs and reads back (every face's edge chains consistent).
    let packed = document.pack(meshpaint_core::colors::format::ColorFormat::Rgba16F).unwrap();
    let bytes = meshpaint_core::packing::file::to_bytes(&packed).unwrap();
    assert_eq!(meshpaint_core::packing::file::from_bytes(&bytes).unwrap(), packed);
}
