//! Generated UV atlases (`convert::unwrap`), checked independently of the unwrapper's own
//! bookkeeping: every face's UV triangle is rasterised here and
//!
//! - no texel centre lies strictly inside two faces' UV triangles (no paint can be lost);
//! - charts (faces joined through edges whose two UVs they share, found here by union-find)
//!   are apart: every texel a chart's triangles touch, grown by the gutter, belongs to one
//!   chart only, so bilinear filtering and the first MIP levels stay in their chart;
//! - every face of non-zero surface area has non-zero UV area, inside `[0, 1]²`;
//! - texel density (texels per unit length) is measured over the surface and printed, with
//!   its spread p95 / p5 bounded.

use std::collections::HashMap;

use crate::common::model;

use meshpaint_core::convert::unwrap::{AtlasOptions, density, generate_uvs};
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::mesh::weld::weld_scene;

/// Whether the triangle `p` (texel units) and the texel square `[x, x+1] × [y, y+1]`
/// overlap with positive area (separating axes: the square's two, the triangle's three).
fn touches(p: &[[f64; 2]; 3], x: f64, y: f64) -> bool {
    let square = [[x, y], [x + 1.0, y], [x + 1.0, y + 1.0], [x, y + 1.0]];
    let mut axes = vec![[1.0, 0.0], [0.0, 1.0]];
    for k in 0..3 {
        let (a, b) = (p[k], p[(k + 1) % 3]);
        axes.push([b[1] - a[1], a[0] - b[0]]);
    }
    axes.iter().all(|axis| {
        let project = |q: &[f64; 2]| q[0] * axis[0] + q[1] * axis[1];
        let (t0, t1) =
            p.iter().map(project).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let (s0, s1) =
            square.iter().map(project).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        t1 - s0 > 1e-9 && s1 - t0 > 1e-9
    })
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// The faces on each edge (by its two vertices), each with its two corner UVs (as bits).
type EdgeSides = HashMap<(u32, u32), Vec<(usize, [[u32; 2]; 2])>>;

/// Chart of each face: faces joined across edges whose two corner UVs are equal on both sides.
fn charts(triangles: &[[u32; 3]], uvs: &[[[f32; 2]; 3]]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    let mut edges = EdgeSides::new();
    for (face, corners) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (corners[k], corners[(k + 1) % 3]);
            let (ua, ub) = (uvs[face][k].map(f32::to_bits), uvs[face][(k + 1) % 3].map(f32::to_bits));
            let (key, value) = if a < b { ((a, b), [ua, ub]) } else { ((b, a), [ub, ua]) };
            edges.entry(key).or_default().push((face, value));
        }
    }
    for sides in edges.values() {
        for i in 0..sides.len() {
            for j in i + 1..sides.len() {
                if sides[i].1 == sides[j].1 {
                    let (a, b) = (find(&mut parent, sides[i].0), find(&mut parent, sides[j].0));
                    parent[a] = b;
                }
            }
        }
    }
    (0..triangles.len()).map(|f| find(&mut parent, f)).collect()
}

/// Checks one model's generated atlas; returns (charts, density spread).
fn check_model(file: &str, size: u32) -> (usize, f64) {
    let welded = weld_scene(&import_gltf(&model(file)).unwrap());
    check_mesh(file, &welded.positions_world, &welded.triangles, size)
}

/// Checks the generated atlas of a mesh; returns (charts, density spread).
fn check_mesh(file: &str, positions: &[[f32; 3]], triangles: &[[u32; 3]], size: u32) -> (usize, f64) {
    let generated = generate_uvs(positions, triangles, AtlasOptions::new(size), &|_, _| {}).unwrap();
    let options = AtlasOptions { size, padding: generated.padding };
    let uvs = &generated.corner_uvs;
    assert_eq!(uvs.len(), triangles.len());
    assert!(generated.faces_without_area.is_empty(), "{file}: {:?}", generated.faces_without_area);
    let n = size as usize;
    let mut centre_owner = vec![u32::MAX; n * n];
    let mut shared_centres = 0u64;
    let chart_of = charts(triangles, uvs);
    let mut chart_owner = vec![usize::MAX; n * n];
    let mut shared_chart_texels = 0u64;
    let gutter = i64::from(options.padding) - 1;
    for (face, uv) in uvs.iter().enumerate() {
        let p = uv.map(|c| [f64::from(c[0]) * size as f64, f64::from(c[1]) * size as f64]);
        assert!(uv.iter().flatten().all(|c| (0.0..=1.0).contains(c)), "{file}: face {face} UVs {uv:?}");
        let area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        assert!(area.abs() > 1e-9, "{file}: face {face} has no UV area");
        let lo = |a: usize| p.iter().map(|c| c[a]).fold(f64::INFINITY, f64::min).floor() as i64;
        let hi = |a: usize| p.iter().map(|c| c[a]).fold(f64::NEG_INFINITY, f64::max).ceil() as i64;
        for y in lo(1).max(0)..hi(1).min(n as i64) {
            for x in lo(0).max(0)..hi(0).min(n as i64) {
                let t = y as usize * n + x as usize;
                let c = [x as f64 + 0.5, y as f64 + 0.5];
                let w1 = ((c[0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (c[1] - p[0][1])) / area;
                let w2 = ((p[1][0] - p[0][0]) * (c[1] - p[0][1]) - (c[0] - p[0][0]) * (p[1][1] - p[0][1])) / area;
                if w1.min(w2).min(1.0 - w1 - w2) > 1e-7 {
                    if centre_owner[t] != u32::MAX {
                        shared_centres += 1;
                    }
                    centre_owner[t] = face as u32;
                }
                if !touches(&p, x as f64, y as f64) {
                    continue;
                }
                // The texel and its neighbours within the gutter belong to this chart.
                for dy in -gutter..=gutter {
                    for dx in -gutter..=gutter {
                        let (gx, gy) = (x + dx, y + dy);
                        if gx < 0 || gy < 0 || gx >= n as i64 || gy >= n as i64 {
                            continue;
                        }
                        let g = gy as usize * n + gx as usize;
                        if chart_owner[g] != usize::MAX && chart_owner[g] != chart_of[face] {
                            shared_chart_texels += 1;
                        }
                        chart_owner[g] = chart_of[face];
                    }
                }
            }
        }
    }
    assert_eq!(shared_centres, 0, "{file}: texel centres inside two faces' UVs");
    assert_eq!(shared_chart_texels, 0, "{file}: texels (gutter {gutter}) claimed by two charts");
    let stats = density(positions, triangles, uvs, size);
    let mut distinct: Vec<usize> = chart_of.clone();
    distinct.sort_unstable();
    distinct.dedup();
    eprintln!(
        "{file}: {} faces, {} charts ({} by UV connectivity), {size}², gutter {}, {:.1}% used, density p5 / median / \
         p95 = {:.1} / {:.1} / {:.1} texels per unit, spread {:.2}, {:.2} s",
        triangles.len(),
        generated.charts,
        distinct.len(),
        options.padding,
        generated.utilization * 100.0,
        stats.p5,
        stats.median,
        stats.p95,
        stats.spread(),
        generated.elapsed.as_secs_f64()
    );
    (distinct.len(), stats.spread())
}

#[test]
fn generated_atlases_give_every_face_its_own_texels() {
    for (file, size, max_spread) in [
        ("Duck/Duck.glb", 1024, 2.0),
        ("BoxTextured/BoxTextured.glb", 256, 1.2),
        ("Suzanne/monkey.glb", 1024, 2.0),
        ("CakeBirthday/cakeBirthday.glb", 1024, 2.5),
        ("Fox/Fox.glb", 512, 2.0),
    ] {
        let (charts, spread) = check_model(file, size);
        assert!(charts >= 1);
        assert!(spread <= max_spread, "{file}: texel density spread {spread:.2} > {max_spread}");
    }
}

#[test]
fn a_dense_scan_unwraps_in_reasonable_time() {
    let (charts, spread) = check_model("Bunny144k/bunny.glb", 2048);
    assert!(charts >= 1);
    assert!(spread <= 2.0, "texel density spread {spread:.2}");
}

/// A soup of 1,500 separate triangles in a 128² texture: 1,500 charts cannot each keep a
/// gutter of 2 texels (25 texels or more apiece, 16,384 in all), so the gutter narrows to
/// 1 and the checks above still hold.
#[test]
fn very_many_charts_narrow_the_gutter_instead_of_failing() {
    let mut rng = meshpaint_core::synth::rng::SplitMix64(43);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for t in 0..1500u32 {
        let base = [rng.unit_f64() as f32 * 10.0, rng.unit_f64() as f32 * 10.0, rng.unit_f64() as f32 * 10.0];
        for _ in 0..3 {
            positions.push(base.map(|c| c + rng.unit_f64() as f32 * 0.3));
        }
        triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    let generated = generate_uvs(&positions, &triangles, AtlasOptions::new(128), &|_, _| {}).unwrap();
    assert_eq!(generated.padding, 1);
    let (charts, _) = check_mesh("triangle soup", &positions, &triangles, 128);
    assert_eq!(charts, 1500);
}
