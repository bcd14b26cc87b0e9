//! OBJ, PLY and STL import, through the `meshpaint` binary and `Document::open`.
//!
//! Truths: closed-form counts of meshes this file writes in every format and flavour (a torus
//! of n × m quads: V = nm, F = 2nm, E = 3nm, no boundary; a convex n-gon: F = n − 2,
//! E = 2n − 3, n boundary edges), the counts of the real files in assets/SOURCES.md (from
//! tools/mesh_counts.py, an independent Python reader), the sRGB transfer function for vertex
//! colours, and clean refusals (exit 1, the file named, no panic) of broken files — a huge
//! declared count under a 2 GB address-space limit, so that allocating for it would abort.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::common;
use common::{TempDir, model};

use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::{Document, SourceKind};
use meshpaint_core::mesh::formats::MeshFormat;

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

fn describe(output: &Output) -> String {
    format!(
        "status {:?}\nstdout: {}\nstderr: {}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

fn info(file: &Path, resolution: u64) -> serde_json::Map<String, Value> {
    let output = Command::new(BIN)
        .args(["info", "--json", "-r", &resolution.to_string()])
        .arg(file)
        .output()
        .expect("cannot start meshpaint");
    assert!(output.status.success(), "info {}: {}", file.display(), describe(&output));
    match serde_json::from_slice::<Value>(&output.stdout) {
        Ok(Value::Object(object)) => object,
        other => panic!("info {}: not one JSON object: {other:?}", file.display()),
    }
}

fn get(object: &serde_json::Map<String, Value>, key: &str) -> u64 {
    object.get(key).and_then(Value::as_u64).unwrap_or_else(|| panic!("no '{key}' in {object:?}"))
}

/// `[triangles, vertices, edges, boundary, non-manifold, samples at R]` of `info`.
fn counts(file: &Path, resolution: u64) -> [u64; 6] {
    let object = info(file, resolution);
    ["triangles", "vertices", "edges", "boundary_edges", "nonmanifold_edges", "samples"].map(|k| get(&object, k))
}

/// `V + E(R−1) + F(R−1)(R−2)/2`.
fn samples(v: u64, e: u64, f: u64, r: u64) -> u64 {
    v + e * (r - 1) + f * (r - 1) * r.saturating_sub(2) / 2
}

/// A torus of `n × m` quads (corners counter-clockwise seen from outside).
fn torus(n: usize, m: usize) -> (Vec<[f32; 3]>, Vec<Vec<u32>>) {
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (theta, phi) =
                (i as f32 / n as f32 * std::f32::consts::TAU, j as f32 / m as f32 * std::f32::consts::TAU);
            let ring = 2.0 + 0.7 * phi.cos();
            positions.push([ring * theta.cos(), ring * theta.sin(), 0.7 * phi.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + j % m) as u32;
    let quads = (0..n).flat_map(|i| (0..m).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]));
    (positions, quads.collect())
}

/// Triangles of `polygons` as the fan from each first corner (the rule the importers state).
fn fan(polygons: &[Vec<u32>]) -> Vec<[u32; 3]> {
    polygons.iter().flat_map(|p| (1..p.len() - 1).map(move |i| [p[0], p[i], p[i + 1]])).collect()
}

/// A colour per vertex (uchar, display values).
fn vertex_rgb(v: usize) -> [u8; 3] {
    [(v * 37 % 256) as u8, (v * 91 % 256) as u8, (255 - v * 13 % 256) as u8]
}

fn obj_text(positions: &[[f32; 3]], polygons: &[Vec<u32>], colors: bool) -> String {
    let mut out = String::from("# written by tests/app/formats.rs\no torus\n");
    for (v, p) in positions.iter().enumerate() {
        out += &format!("v {} {} {}", p[0], p[1], p[2]);
        if colors {
            let c = vertex_rgb(v);
            out += &format!(" {} {} {}", c[0] as f32 / 255.0, c[1] as f32 / 255.0, c[2] as f32 / 255.0);
        }
        out += "\n";
    }
    for polygon in polygons {
        out += "f";
        for &c in polygon {
            out += &format!(" {}", c + 1);
        }
        out += "\n";
    }
    out
}

fn ply_header(format: &str, vertices: usize, faces: usize, colors: bool, index_type: &str) -> String {
    let color_lines = if colors { "property uchar red\nproperty uchar green\nproperty uchar blue\n" } else { "" };
    format!(
        "ply\nformat {format} 1.0\ncomment written by tests/app/formats.rs\nelement vertex {vertices}\nproperty float x\n\
         property float y\nproperty float z\n{color_lines}element face {faces}\nproperty list uchar {index_type} \
         vertex_indices\nend_header\n"
    )
}

fn ply_ascii(positions: &[[f32; 3]], polygons: &[Vec<u32>], colors: bool) -> Vec<u8> {
    let mut out = ply_header("ascii", positions.len(), polygons.len(), colors, "int");
    for (v, p) in positions.iter().enumerate() {
        out += &format!("{} {} {}", p[0], p[1], p[2]);
        if colors {
            let c = vertex_rgb(v);
            out += &format!(" {} {} {}", c[0], c[1], c[2]);
        }
        out += "\n";
    }
    for polygon in polygons {
        out += &polygon.len().to_string();
        for &c in polygon {
            out += &format!(" {c}");
        }
        out += "\n";
    }
    out.into_bytes()
}

fn ply_binary(positions: &[[f32; 3]], polygons: &[Vec<u32>], big_endian: bool) -> Vec<u8> {
    let format = if big_endian { "binary_big_endian" } else { "binary_little_endian" };
    let mut out = ply_header(format, positions.len(), polygons.len(), true, "uint").into_bytes();
    let f32_bytes = |x: f32| if big_endian { x.to_be_bytes() } else { x.to_le_bytes() };
    let u32_bytes = |x: u32| if big_endian { x.to_be_bytes() } else { x.to_le_bytes() };
    for (v, p) in positions.iter().enumerate() {
        p.iter().for_each(|&x| out.extend(f32_bytes(x)));
        out.extend(vertex_rgb(v));
    }
    for polygon in polygons {
        out.push(polygon.len() as u8);
        polygon.iter().for_each(|&c| out.extend(u32_bytes(c)));
    }
    out
}

fn stl_ascii(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> String {
    let mut out = String::from("solid torus written by tests/app/formats.rs\n");
    for t in triangles {
        out += "  facet normal 0 0 1\n    outer loop\n";
        for &c in t {
            let p = positions[c as usize];
            out += &format!("      vertex {:e} {:e} {:e}\n", p[0], p[1], p[2]);
        }
        out += "    endloop\n  endfacet\n";
    }
    out + "endsolid torus\n"
}

fn stl_binary(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<u8> {
    // A header starting with "solid", as many CAD exporters write it.
    let mut out = b"solid binary, written by tests/app/formats.rs".to_vec();
    out.resize(80, 0);
    out.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        [0.0f32, 0.0, 1.0].iter().for_each(|x| out.extend(x.to_le_bytes()));
        for &c in t {
            positions[c as usize].iter().for_each(|x| out.extend(x.to_le_bytes()));
        }
        out.extend([0, 0]);
    }
    out
}

/// Every format and flavour of one mesh, written into `dir`.
fn write_all(dir: &TempDir, name: &str, positions: &[[f32; 3]], polygons: &[Vec<u32>]) -> Vec<PathBuf> {
    let triangles = fan(polygons);
    let files: Vec<(String, Vec<u8>)> = vec![
        (format!("{name}.obj"), obj_text(positions, polygons, false).into_bytes()),
        (format!("{name}_colors.obj"), obj_text(positions, polygons, true).into_bytes()),
        (format!("{name}_ascii.ply"), ply_ascii(positions, polygons, true)),
        (format!("{name}_le.ply"), ply_binary(positions, polygons, false)),
        (format!("{name}_be.ply"), ply_binary(positions, polygons, true)),
        (format!("{name}_ascii.stl"), stl_ascii(positions, &triangles).into_bytes()),
        (format!("{name}_binary.stl"), stl_binary(positions, &triangles)),
    ];
    files
        .into_iter()
        .map(|(file, bytes)| {
            let path = dir.join(&file);
            std::fs::write(&path, bytes).unwrap();
            path
        })
        .collect()
}

#[test]
fn torus_counts_match_the_closed_form_in_every_format() {
    let dir = TempDir::new("torus");
    let (n, m) = (7u64, 5u64);
    let (positions, quads) = torus(n as usize, m as usize);
    let (v, f, e) = (n * m, 2 * n * m, 3 * n * m);
    for file in write_all(&dir, "torus", &positions, &quads) {
        for r in [1, 4] {
            assert_eq!(counts(&file, r), [f, v, e, 0, 0, samples(v, e, f, r)], "{} at R = {r}", file.display());
        }
    }
}

#[test]
fn polygons_are_fanned() {
    let dir = TempDir::new("ngon");
    let n = 9u64;
    let positions: Vec<[f32; 3]> = (0..n)
        .map(|k| {
            let a = k as f32 / n as f32 * std::f32::consts::TAU;
            [a.cos(), a.sin(), 0.0]
        })
        .collect();
    let polygon = vec![(0..n as u32).collect::<Vec<u32>>()];
    let (f, e) = (n - 2, 2 * n - 3);
    for file in write_all(&dir, "ngon", &positions, &polygon) {
        assert_eq!(counts(&file, 2), [f, n, e, n, 0, samples(n, e, f, 2)], "{}", file.display());
    }
}

/// One row of assets/SOURCES.md.
const REAL_FILES: &[(&str, [u64; 5])] = &[
    ("AssimpTestModels/spider.obj", [1312, 722, 2004, 72, 0]),
    ("AssimpTestModels/Spider_binary.stl", [1312, 722, 2004, 72, 0]),
    ("AssimpTestModels/cube_with_vertexcolors.obj", [12, 8, 18, 0, 0]),
    ("AssimpTestModels/cube_binary.ply", [12, 8, 18, 0, 0]),
    ("AssimpTestModels/cube_uv.ply", [12, 8, 18, 0, 0]),
    ("AssimpTestModels/float-color.ply", [1, 3, 3, 3, 0]),
    ("AssimpTestModels/sphereWithHole.stl", [285, 146, 432, 9, 0]),
    ("AssimpTestModels/3DSMaxExport.STL", [2000, 1042, 2992, 0, 16]),
    ("PlyExamples/greg_turk_example2_ok_ascii.ply", [12, 8, 18, 0, 0]),
    ("PlyExamples/tetrahedron_big_endian.ply", [4, 4, 6, 0, 0]),
];

#[test]
fn real_files_match_sources_md() {
    for &(file, [f, v, e, b, n]) in REAL_FILES {
        let [cf, cv, ce, cb, cn, cs] = counts(&model(file), 8);
        assert_eq!([cf, cv, ce, cb, cn], [f, v, e, b, n], "{file}");
        assert_eq!(cs, samples(v, e, f, 8), "{file}: samples");
    }
    let spider = info(&model("AssimpTestModels/spider.obj"), 1);
    assert_eq!(get(&spider, "degenerate_triangles_dropped"), 56);
}

fn srgb_to_linear(x: f64) -> f64 {
    if x <= 0.04045 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

/// Vertex colours of OBJ and PLY files are decoded from sRGB and become the vertex samples.
#[test]
fn vertex_colors_become_the_initial_colors() {
    let dir = TempDir::new("colors");
    let (positions, quads) = torus(4, 3);
    let r2 = Resolution::new(2).unwrap();
    for file in write_all(&dir, "torus", &positions, &quads) {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        let colored = name.contains("colors") || name.ends_with(".ply");
        let document = Document::open(&file, r2).unwrap();
        let format = if name.ends_with(".obj") {
            MeshFormat::Obj
        } else if name.ends_with(".ply") {
            MeshFormat::Ply
        } else {
            MeshFormat::Stl
        };
        assert_eq!(document.source, SourceKind::Mesh(format), "{name}");
        assert_eq!(document.positions.len(), positions.len(), "{name}");
        for (welded, p) in document.positions.iter().enumerate() {
            let source = positions.iter().position(|q| q.map(f32::to_bits) == p.map(f32::to_bits)).unwrap();
            let got = document.store.vertex_color(welded as u32).unwrap();
            if colored {
                let expected = vertex_rgb(source).map(|c| srgb_to_linear(c as f64 / 255.0));
                for k in 0..3 {
                    assert!(
                        (got[k] as f64 - expected[k]).abs() < 1e-5,
                        "{name}: vertex {source} {got:?} vs {expected:?}"
                    );
                }
                assert_eq!(got[3], 1.0);
            }
        }
    }
    // The real float-colour PLY: every vertex pure blue, alpha 1.
    let document = Document::open(&model("AssimpTestModels/float-color.ply"), r2).unwrap();
    for v in 0..3 {
        assert_eq!(document.store.vertex_color(v), Some([0.0, 0.0, 1.0, 1.0]));
    }
}

/// Runs `meshpaint info FILE` under a 2 GB address-space limit: it must fail cleanly, naming
/// the file; returns stderr.
fn refused(file: &Path) -> String {
    let script = format!("ulimit -v 2000000 && exec \"{BIN}\" info \"{}\"", file.display());
    let output = Command::new("sh").args(["-c", &script]).output().expect("cannot start sh");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(output.status.code(), Some(1), "{}: {}", file.display(), describe(&output));
    assert!(!stderr.contains("panicked"), "{}: {stderr}", file.display());
    assert!(stderr.contains(&file.display().to_string()), "the message does not name the file: {stderr}");
    stderr
}

#[test]
fn broken_files_are_refused_with_a_clear_message() {
    let dir = TempDir::new("broken");
    let (positions, quads) = torus(3, 3);
    let triangles = fan(&quads);
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let binary_ply = ply_binary(&positions, &quads, false);
    let cases: Vec<(PathBuf, &str)> = vec![
        (write("truncated.ply", &binary_ply[..binary_ply.len() - 7]), "face"),
        (write("truncated.stl", &stl_binary(&positions, &triangles)[..200]), "declares 18 triangles"),
        (write("truncated_ascii.stl", &stl_ascii(&positions, &triangles).as_bytes()[..300]), "truncated"),
        (
            write(
                "non_numeric.ply",
                &String::from_utf8(ply_ascii(&positions, &quads, false))
                    .unwrap()
                    .replacen("end_header\n", "end_header\nzero", 1)
                    .into_bytes(),
            ),
            "zero",
        ),
        (write("non_numeric.obj", b"v 0 0 0\nv 1 one 0\nv 0 1 0\nf 1 2 3\n"), "position"),
        (
            write("non_numeric.stl", stl_ascii(&positions, &triangles).replacen("vertex ", "vertex x", 1).as_bytes()),
            "not a number",
        ),
        (write("out_of_range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), "out of bounds"),
        (
            write(
                "out_of_range.ply",
                &String::from_utf8(ply_ascii(&positions, &quads, false))
                    .unwrap()
                    .replace("\n4 0 3 4 1\n", "\n4 0 3 99 1\n")
                    .into_bytes(),
            ),
            "uses vertex 99",
        ),
        (write("mixed_colors.obj", b"v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 1 0\nf 1 2 3\n"), "only some"),
    ];
    for (file, expected) in &cases {
        let stderr = refused(file);
        assert!(stderr.contains(expected), "{}: expected '{expected}' in: {stderr}", file.display());
    }
}

/// A 1 kB file whose header declares 10^10 faces (or 2^32 − 1 STL triangles) is refused
/// before anything is allocated: under the 2 GB limit, allocating for the count would abort.
#[test]
fn huge_declared_counts_are_refused_before_allocating() {
    let dir = TempDir::new("huge");
    let (positions, quads) = torus(3, 3);
    let mut ply = ply_ascii(&positions, &quads, false);
    let text = String::from_utf8(ply.clone()).unwrap().replace("element face 9", "element face 10000000000");
    ply = text.into_bytes();
    assert!(ply.len() < 1024);
    let ply_path = dir.join("huge.ply");
    std::fs::write(&ply_path, &ply).unwrap();
    assert!(refused(&ply_path).contains("10000000000 'face' elements"));

    let mut binary = ply_binary(&positions, &quads, false);
    let at = binary.windows(7).position(|w| w == b"face 9\n").unwrap();
    binary.splice(at..at + 6, b"face 4000000000".iter().copied());
    let binary_path = dir.join("huge_binary.ply");
    std::fs::write(&binary_path, &binary).unwrap();
    assert!(refused(&binary_path).contains("4000000000 'face' elements"));

    let mut stl = vec![0u8; 80];
    stl.extend(u32::MAX.to_le_bytes());
    stl.resize(1000, 0);
    let stl_path = dir.join("huge.stl");
    std::fs::write(&stl_path, &stl).unwrap();
    assert!(refused(&stl_path).contains("declares 4294967295 triangles"));
}

/// `pack` reads the new formats through the same open path; the packed file holds the mesh.
#[test]
fn pack_accepts_ply_and_the_packed_file_has_the_same_counts() {
    let dir = TempDir::new("pack");
    let input = model("PlyExamples/greg_turk_example2_ok_ascii.ply");
    let output = dir.join("cube.mpk");
    let run = Command::new(BIN).arg("pack").arg(&input).arg("-o").arg(&output).args(["-r", "4"]).output().unwrap();
    assert!(run.status.success(), "{}", describe(&run));
    let packed = info(&output, 4);
    assert_eq!([get(&packed, "triangles"), get(&packed, "vertices"), get(&packed, "edges")], [12, 8, 18]);
}

/// An untextured mesh opens in the neutral grey (every lit mesh pixel has R = G = B);
/// `render --position-colors` shows the position field instead (coloured pixels).
#[test]
fn untextured_meshes_open_grey_and_position_colors_are_a_view() {
    let dir = TempDir::new("neutral");
    let stl = model("AssimpTestModels/sphereWithHole.stl");
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let output = Command::new(BIN)
            .arg("render")
            .arg(&stl)
            .arg("-o")
            .arg(&out)
            .args(["--width", "160", "--height", "120"])
            .args(extra)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", describe(&output));
        image::open(&out).unwrap().to_rgb8()
    };
    let (grey, colored) = (render("grey.png", &[]), render("colored.png", &["--position-colors"]));
    let background = *grey.get_pixel(0, 0);
    let mesh: Vec<_> = grey.pixels().filter(|p| **p != background).collect();
    assert!(mesh.len() > 160 * 120 / 10, "the sphere is visible");
    assert!(mesh.iter().all(|p| p[0] == p[1] && p[1] == p[2]), "a non-grey pixel in the neutral render");
    let tinted = colored.pixels().filter(|p| **p != background && (p[0] != p[1] || p[1] != p[2])).count();
    assert!(tinted > mesh.len() / 2, "only {tinted} coloured pixels with --position-colors");
}

/// An OBJ's `map_Kd` image becomes the base colour (times `Kd`); a map outside the OBJ's
/// folder or missing is named in a warning and the mesh still opens in its `Kd`.
#[test]
fn obj_texture_maps_are_baked_and_unreadable_ones_reported() {
    let dir = TempDir::new("obj-texture");
    let texel = [200u8, 100, 50, 255];
    image::RgbaImage::from_pixel(16, 16, image::Rgba(texel)).save(dir.join("skin.png")).unwrap();
    let obj = "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
               usemtl skin\nf 1/1 2/2 3/3 4/4\n";
    std::fs::write(dir.join("quad.obj"), obj).unwrap();
    let r4 = Resolution::new(4).unwrap();
    let decode = |c: u8| srgb_to_linear(f64::from(c) / 255.0);
    for (mtl, expected, warned) in [
        ("newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n", [decode(200), decode(100), decode(50)], false),
        ("newmtl skin\nKd 1 1 1\nmap_Kd .\\skin.png\n", [decode(200), decode(100), decode(50)], false),
        ("newmtl skin\nKd 0.5 0.5 0.5\nmap_Kd ../skin.png\n", [decode(128); 3], true),
        ("newmtl skin\nKd 0.5 0.5 0.5\nmap_Kd nothing.png\n", [decode(128); 3], true),
    ] {
        std::fs::write(dir.join("quad.mtl"), mtl).unwrap();
        let document = Document::open(&dir.join("quad.obj"), r4).unwrap();
        assert_eq!(
            document.warnings.iter().any(|w| w.contains("not loaded")),
            warned,
            "{mtl}: {:?}",
            document.warnings
        );
        document.store.for_each_site(|site| {
            let got = document.store.get(site.sample).unwrap();
            // Kd 0.5 is a display value: decoded like the texture's 128 within 0.2 %.
            assert!((0..3).all(|k| (f64::from(got[k]) - expected[k]).abs() < 2e-3), "{mtl}: {got:?} vs {expected:?}");
        });
    }
}

/// A binary PLY whose faces are one `tristrips` list (Stanford / VRIP style: `int` ids,
/// strips separated by `-1`) of the `n × m` torus, one strip of `2(m + 1)` ids per ring.
fn ply_tristrips(positions: &[[f32; 3]], n: usize, m: usize, separator: i32) -> Vec<u8> {
    let id = |i: usize, j: usize| ((i % n) * m + j % m) as i32;
    let mut list = Vec::new();
    for i in 0..n {
        if i > 0 {
            list.push(separator);
        }
        for j in 0..=m {
            list.extend([id(i, j), id(i + 1, j)]);
        }
    }
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n",
        positions.len()
    );
    let mut out = header.into_bytes();
    positions.iter().flatten().for_each(|x| out.extend(x.to_le_bytes()));
    out.extend((list.len() as i32).to_le_bytes());
    list.iter().for_each(|v| out.extend(v.to_le_bytes()));
    out
}

/// Triangle strips (older scan archives) read to the torus's closed-form counts — every
/// quad two triangles, closed, manifold and consistently wound (no boundary, no non-manifold
/// edge) — and a strip id other than the `-1` separator is refused with exit 1.
#[test]
fn tristrip_ply_reads_to_the_closed_form_or_is_refused() {
    let dir = TempDir::new("tristrips");
    let (n, m) = (6u64, 4u64);
    let (positions, _) = torus(n as usize, m as usize);
    let (v, f, e) = (n * m, 2 * n * m, 3 * n * m);
    let path = dir.join("strips.ply");
    std::fs::write(&path, ply_tristrips(&positions, n as usize, m as usize, -1)).unwrap();
    assert_eq!(counts(&path, 4), [f, v, e, 0, 0, samples(v, e, f, 4)]);
    let bad = dir.join("bad_separator.ply");
    std::fs::write(&bad, ply_tristrips(&positions, n as usize, m as usize, -2)).unwrap();
    let stderr = refused(&bad);
    assert!(stderr.contains("tristrips") && stderr.contains("-2"), "{stderr}");
}
