//! Many materials: a cabinet, two crates (one mesh placed twice), a tiled floor, painted
//! bottles and a stray box, with nine materials:
//!
//! | # | material     | base colour texture                | factor            | vertex colours |
//! |---|--------------|------------------------------------|-------------------|----------------|
//! | 0 | wood         | 0: wood grain, 512²                | white             | no             |
//! | 1 | dark wood    | 0 (shared with wood)               | (0.35, 0.25, 0.18)| no             |
//! | 2 | marble       | 1: marble veins, 1024²             | white             | no             |
//! | 3 | label        | 2: a printed label, 256 × 128      | white             | no             |
//! | 4 | metal        | none                               | (0.75, 0.75, 0.78)| no             |
//! | 5 | red paint    | none                               | (0.70, 0.05, 0.04)| no             |
//! | 6 | vertex paint | none                               | white             | yes            |
//! | 7 | floor tiles  | 3: tiles, 128², repeated 4× (UVs 0…4)| white           | no             |
//! | 8 | tinted marble| 1 (shared with marble)             | (0.8, 0.9, 1.0)   | yes            |
//!
//! and one primitive with no material (the stray box). Y is up, units are metres.

use glam::{DVec3, Mat4, Quat, Vec3};

use super::Asset;
use super::builder::{MeshBuilder, PatchVertex};
use super::canvas::{Srgb, fractal_noise, mix, paint, supersample};
use super::font::Text;
use crate::mesh::scene::{Instance, Material, Scene, Texture};

/// Materials in the file (the table above).
pub const MATERIALS: usize = 9;
/// Textures in the file.
pub const TEXTURES: usize = 4;

/// The asset (module docs); it has no options.
pub fn materials() -> Asset {
    let factor = |r: f32, g: f32, b: f32| [r, g, b, 1.0];
    let material =
        |factor: [f32; 4], texture: Option<u32>| Material { base_color_factor: factor, base_color_texture: texture };
    let materials = vec![
        material([1.0; 4], Some(0)),
        material(factor(0.35, 0.25, 0.18), Some(0)),
        material([1.0; 4], Some(1)),
        material([1.0; 4], Some(2)),
        material(factor(0.75, 0.75, 0.78), None),
        material(factor(0.70, 0.05, 0.04), None),
        material([1.0; 4], None),
        material([1.0; 4], Some(3)),
        material(factor(0.8, 0.9, 1.0), Some(1)),
    ];
    let textures = vec![wood(512), marble(1024), label(256, 128), tiles(128)];
    let meshes = vec![cabinet(), crate_mesh(), floor(), bottles(), stray_box()];
    let at = |x: f32, y: f32, z: f32| Mat4::from_translation(Vec3::new(x, y, z));
    let turned = Mat4::from_rotation_translation(Quat::from_rotation_y(0.6), Vec3::new(2.2, 0.0, 1.4));
    let instances = [
        (0, Mat4::IDENTITY),
        (1, at(1.8, 0.0, -0.2)),
        (1, turned),
        (2, Mat4::IDENTITY),
        (3, at(-2.0, 0.0, 1.0)),
        (4, at(-1.6, 0.0, -1.2)),
    ]
    .into_iter()
    .map(|(mesh, world_from_local)| Instance { mesh, world_from_local })
    .collect();
    Asset { scene: Scene { meshes, instances, materials, textures, warnings: Vec::new() }, regions: Vec::new() }
}

const WHOLE: [f32; 4] = [0.0, 1.0, 1.0, 0.0];

fn cabinet() -> crate::mesh::scene::SourceMesh {
    let mut mesh = MeshBuilder::new("cabinet");
    mesh.cuboid(DVec3::new(-1.0, 0.0, -0.5), DVec3::new(1.0, 2.0, 0.5), 4, Some(0), |_| WHOLE);
    mesh.cuboid(DVec3::new(-1.05, 2.0, -0.55), DVec3::new(1.05, 2.08, 0.55), 2, Some(2), |k| {
        [0.0, 1.0, 1.0, if k == 2 { 0.0 } else { 0.95 }]
    });
    for x in [-0.97, 0.01] {
        mesh.cuboid(DVec3::new(x, 0.05, 0.5), DVec3::new(x + 0.96, 1.95, 0.53), 3, Some(1), |_| WHOLE);
        let handle_x = if x < 0.0 { -0.1 } else { 0.1 };
        mesh.cylinder(
            (DVec3::new(handle_x, 0.9, 0.53), DVec3::new(handle_x, 1.1, 0.53)),
            0.02,
            (12, 1),
            WHOLE,
            WHOLE,
            Some(4),
            &|_| None,
        );
        let plate = DVec3::new(x + 0.28, 1.45, 0.531);
        mesh.quad(plate, DVec3::X * 0.4, DVec3::Y * 0.2, (1, 1), WHOLE, Some(3), None);
    }
    mesh.finish()
}

fn crate_mesh() -> crate::mesh::scene::SourceMesh {
    let mut mesh = MeshBuilder::new("crate");
    mesh.cuboid(DVec3::new(-0.4, 0.0, -0.4), DVec3::new(0.4, 0.7, 0.4), 3, Some(0), |_| WHOLE);
    mesh.cuboid(DVec3::new(-0.42, 0.7, -0.42), DVec3::new(0.42, 0.76, 0.42), 2, Some(5), |_| WHOLE);
    mesh.finish()
}

fn floor() -> crate::mesh::scene::SourceMesh {
    let mut mesh = MeshBuilder::new("floor");
    mesh.quad(
        DVec3::new(-3.0, 0.0, 3.0),
        DVec3::X * 6.0,
        DVec3::NEG_Z * 6.0,
        (12, 12),
        [0.0, 4.0, 4.0, 0.0],
        Some(7),
        None,
    );
    mesh.finish()
}

fn bottles() -> crate::mesh::scene::SourceMesh {
    let mut mesh = MeshBuilder::new("bottles");
    let hues: [Srgb; 3] = [[0.1, 0.6, 0.2], [0.1, 0.3, 0.8], [0.8, 0.6, 0.1]];
    for (k, hue) in hues.into_iter().enumerate() {
        let x = k as f64 * 0.35 - 0.35;
        let height = 0.6 + 0.15 * k as f64;
        let colour = move |p: DVec3| {
            let c = mix(hue, [0.95, 0.95, 0.9], (p.y / height).clamp(0.0, 1.0) as f32);
            Some([c[0], c[1], c[2], 1.0])
        };
        mesh.cylinder(
            (DVec3::new(x, 0.0, 0.0), DVec3::new(x, height, 0.0)),
            0.12,
            (24, 6),
            WHOLE,
            WHOLE,
            Some(6),
            &colour,
        );
    }
    // A sphere: marble tinted by vertex colours (poles' degenerate triangles are skipped).
    let (segments, rings) = (32u32, 16u32);
    mesh.patch(segments, rings, Some(8), |s, t| {
        let k = (s * f64::from(segments)).round() as u32 % segments;
        let phi = std::f64::consts::TAU * f64::from(k) / f64::from(segments);
        let theta = std::f64::consts::PI * t;
        let normal = DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
        let position = DVec3::new(0.0, 0.45, 0.5) + normal * 0.25;
        let c = [0.6 + 0.4 * normal.x as f32, 0.7, 0.6 - 0.4 * normal.x as f32, 1.0];
        PatchVertex { position, normal, uv: [s as f32, t as f32], color: Some(c) }
    });
    mesh.finish()
}

fn stray_box() -> crate::mesh::scene::SourceMesh {
    let mut mesh = MeshBuilder::new("stray box");
    mesh.cuboid(DVec3::new(-0.2, 0.0, -0.2), DVec3::new(0.2, 0.4, 0.2), 2, None, |_| WHOLE);
    mesh.finish()
}

fn wood(size: u32) -> Texture {
    let s = f64::from(size);
    paint(size, size, |x, y| {
        let (u, v) = (x / s, y / s);
        let warp = 3.0 * fractal_noise([u * 3.0, v * 12.0, 0.5], 3, 11);
        let ring = (0.5 + 0.5 * ((v * 18.0 + warp) * std::f64::consts::TAU).sin()) as f32;
        let fibre = fractal_noise([u * 40.0, v * 400.0, 1.5], 2, 12) as f32;
        mix([0.72, 0.52, 0.32], [0.48, 0.30, 0.16], ring * ring * 0.8 + 0.2 * fibre)
    })
}

fn marble(size: u32) -> Texture {
    let s = f64::from(size);
    paint(size, size, |x, y| {
        let (u, v) = (x / s, y / s);
        let turbulence = fractal_noise([u * 4.0, v * 4.0, 2.5], 5, 21);
        let vein = ((u * 6.0 + v * 3.0 + 5.0 * turbulence) * std::f64::consts::PI).sin().abs();
        let line = (1.0 - (vein / 0.08).min(1.0)) as f32;
        let base = mix([0.93, 0.92, 0.90], [0.82, 0.82, 0.84], fractal_noise([u * 8.0, v * 8.0, 9.0], 3, 22) as f32);
        mix(base, [0.35, 0.36, 0.40], line * 0.85)
    })
}

fn label(width: u32, height: u32) -> Texture {
    let (w, h) = (f64::from(width), f64::from(height));
    let big = Text::fit("OIL 5L", [0.1 * w, 0.15 * h], 0.8 * w, 0.45 * h);
    let small = Text::fit("SAE 10W-40", [0.1 * w, 0.7 * h], 0.8 * w, 0.15 * h);
    paint(width, height, |x, y| {
        supersample(x, y, 4, |x, y| {
            let border = x < 0.04 * w || x > 0.96 * w || y < 0.06 * h || y > 0.94 * h;
            if border || big.covers(x, y) {
                [0.75, 0.1, 0.08]
            } else if small.covers(x, y) {
                [0.1, 0.1, 0.1]
            } else {
                [0.95, 0.92, 0.80]
            }
        })
    })
}

fn tiles(size: u32) -> Texture {
    let s = f64::from(size);
    paint(size, size, |x, y| {
        supersample(x, y, 4, |x, y| {
            let (u, v) = (x / s * 4.0, y / s * 4.0);
            let (fu, fv) = (u - u.floor(), v - v.floor());
            if fu < 0.04 || fv < 0.04 {
                return [0.55, 0.55, 0.52];
            }
            let odd = (u.floor() as i64 + v.floor() as i64) % 2 != 0;
            if odd { [0.70, 0.35, 0.22] } else { [0.90, 0.86, 0.76] }
        })
    })
}
