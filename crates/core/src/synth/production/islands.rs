//! A dense mesh whose UV islands have very different texel densities: a boulder, a
//! cuboid lattice of `nx × ny × nz` cells projected onto a sphere, displaced by fractal
//! noise and stretched (1.3 × 0.9 × 1.0). Each of the six lattice faces is split into 2 × 2
//! UV islands (24), packed on shelves into one texture with islands scaled by
//! [`SCALES`] (2× … 1/8: a 16× spread of texel density) and a 4-texel gutter.
//!
//! The triangle count is exact: `4 (nx ny + ny nz + nz nx) + 2 k` for the most cube-like
//! lattice that reaches it, with `k` (0–3 typically) triangles split at their centroid.
//! The texture evaluates a 3D rock colour (noise, fine grain, thin dark cracks, two sharp
//! painted bands anti-aliased to each island's texel footprint) at the surface point
//! under each texel, so islands of low density show the same surface blurred.

use glam::DVec3;

use super::builder::{MeshBuilder, PatchVertex};
use super::canvas::{Srgb, coverage, fractal_noise, mix, paint};
use super::{Asset, SynthError};
use crate::mesh::scene::{Instance, Material, Scene, SourceMesh};

/// Texel density of each island relative to the others, cycled over the 24 islands.
pub const SCALES: [f64; 8] = [2.0, 1.0, 0.5, 0.125, 1.5, 0.25, 1.0, 0.75];
/// Texels between islands.
const GUTTER: u32 = 4;
/// The stretch applied after displacement.
const STRETCH: DVec3 = DVec3::new(1.3, 0.9, 1.0);

/// One UV island: a rectangle of lattice cells on one cube face, and its texel rectangle.
#[derive(Debug, Clone, Copy)]
struct Island {
    /// The fixed axis and whether it is at the far side.
    axis: usize,
    far: bool,
    /// Lattice cell ranges along the face's two other axes (`axes(axis)`).
    start: [u32; 2],
    cells: [u32; 2],
    /// Texel rectangle: x, y, width, height.
    rect: [u32; 4],
    scale: f64,
}

/// The two axes of a face perpendicular to `axis`.
fn axes(axis: usize) -> [usize; 2] {
    [(axis + 1) % 3, (axis + 2) % 3]
}

/// The lattice (and centroid splits) with exactly `triangles` triangles (module docs).
fn lattice(triangles: u32) -> Result<([u32; 3], u32), SynthError> {
    if !triangles.is_multiple_of(2) || triangles < 200 {
        return Err(SynthError::Options(format!("islands needs an even triangle count ≥ 200, got {triangles}")));
    }
    let n0 = (f64::from(triangles) / 12.0).sqrt();
    let (lo, hi) = (((n0 * 0.6) as u32).max(2), (n0 * 1.5) as u32 + 2);
    for splits in 0..64u32 {
        let rest = triangles - 2 * splits;
        if !rest.is_multiple_of(4) {
            continue;
        }
        let target = rest / 4;
        let mut best: Option<([u32; 3], f64)> = None;
        for nx in lo..=hi {
            for ny in nx..=hi {
                let Some(left) = target.checked_sub(nx * ny) else { continue };
                if left % (nx + ny) != 0 {
                    continue;
                }
                let nz = left / (nx + ny);
                if nz < ny || nz > hi {
                    continue;
                }
                let spread = f64::from(nz) / f64::from(nx);
                if best.is_none_or(|(_, s)| spread < s) {
                    best = Some(([nx, ny, nz], spread));
                }
            }
        }
        if let Some((n, _)) = best {
            return Ok((n, splits));
        }
    }
    Err(SynthError::Options(format!("no lattice reaches {triangles} triangles")))
}

/// The cube point of lattice coordinates `c` (exact for integers: shared edges weld).
fn cube_point(c: [f64; 3], n: [u32; 3]) -> DVec3 {
    let q = |a: usize| (2.0 * c[a] - f64::from(n[a])) / f64::from(n[a]);
    DVec3::new(q(0), q(1), q(2))
}

/// The displaced, stretched surface point over cube point `q`.
fn surface(q: DVec3) -> DVec3 {
    let dir = q.normalize();
    let bumps = fractal_noise((dir * 1.6 + 10.0).to_array(), 4, 31) - 0.5;
    let ridges = fractal_noise((dir * 5.0 + 20.0).to_array(), 2, 32) - 0.5;
    dir * (1.0 + 0.35 * bumps + 0.06 * ridges) * STRETCH
}

/// Lattice coordinates of the point `(a, b)` (continuous) of `island`.
fn coords(island: &Island, n: [u32; 3], a: f64, b: f64) -> [f64; 3] {
    let mut c = [0.0; 3];
    c[island.axis] = if island.far { f64::from(n[island.axis]) } else { 0.0 };
    let [u, v] = axes(island.axis);
    c[u] = f64::from(island.start[0]) + a;
    c[v] = f64::from(island.start[1]) + b;
    c
}

/// The 24 islands, packed into a `size`² texture.
fn islands_of(n: [u32; 3], size: u32) -> Result<Vec<Island>, SynthError> {
    let mut islands = Vec::new();
    for axis in 0..3 {
        let [u, v] = axes(axis);
        for far in [false, true] {
            for (ju, jv) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let half = [n[u] / 2, n[v] / 2];
                let start = [if ju == 0 { 0 } else { half[0] }, if jv == 0 { 0 } else { half[1] }];
                let cells =
                    [if ju == 0 { half[0] } else { n[u] - half[0] }, if jv == 0 { half[1] } else { n[v] - half[1] }];
                let scale = SCALES[islands.len() % SCALES.len()];
                islands.push(Island { axis, far, start, cells, rect: [0; 4], scale });
            }
        }
    }
    // The largest density that packs: shrink until the shelves fit.
    let mut base = f64::from(size);
    for _ in 0..200 {
        if pack(&mut islands, n, base, size) {
            return Ok(islands);
        }
        base *= 0.97;
    }
    Err(SynthError::Options(format!("the islands do not fit a {size}² texture")))
}

/// Shelf packing at `base` texels per unit of face (islands sorted by height); whether it fits.
fn pack(islands: &mut [Island], n: [u32; 3], base: f64, size: u32) -> bool {
    for island in islands.iter_mut() {
        let [u, v] = axes(island.axis);
        let extent =
            |k: usize, axis: usize| (base * island.scale * f64::from(island.cells[k]) / f64::from(n[axis])).ceil();
        island.rect[2] = (extent(0, u) as u32).max(2);
        island.rect[3] = (extent(1, v) as u32).max(2);
    }
    let mut order: Vec<usize> = (0..islands.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(islands[i].rect[3]), i));
    let (mut x, mut y, mut row) = (GUTTER, GUTTER, 0);
    for i in order {
        let [_, _, w, h] = islands[i].rect;
        if x + w + GUTTER > size {
            (x, y, row) = (GUTTER, y + row + GUTTER, 0);
        }
        if x + w + GUTTER > size || y + h + GUTTER > size {
            return false;
        }
        islands[i].rect[0] = x;
        islands[i].rect[1] = y;
        x += w + GUTTER;
        row = row.max(h);
    }
    true
}

/// The boulder with exactly `triangles` triangles (even, ≥ 200) and a `size`² texture.
pub fn islands(triangles: u32, size: u32) -> Result<Asset, SynthError> {
    let (n, splits) = lattice(triangles)?;
    let islands = islands_of(n, size)?;
    let s = f64::from(size);
    let mut mesh = MeshBuilder::new("boulder");
    for island in &islands {
        let [x0, y0, w, h] = island.rect.map(f64::from);
        let [cu, cv] = island.cells;
        mesh.patch(cu, cv, Some(0), |fu, fv| {
            let (a, b) = ((fu * f64::from(cu)).round(), (fv * f64::from(cv)).round());
            let q = cube_point(coords(island, n, a, b), n);
            let uv = [((x0 + fu * w) / s) as f32, ((y0 + fv * h) / s) as f32];
            PatchVertex { position: surface(q), normal: q, uv, color: None }
        });
    }
    let mut mesh = mesh.finish();
    split_centroids(&mut mesh, splits, &islands);
    smooth_normals(&mut mesh);
    let texture = paint(size, size, island_texture(&islands, n));
    let scene = Scene {
        meshes: vec![mesh],
        instances: vec![Instance { mesh: 0, world_from_local: glam::Mat4::IDENTITY }],
        materials: vec![Material { base_color_factor: [1.0; 4], base_color_texture: Some(0) }],
        textures: vec![texture],
        warnings: Vec::new(),
    };
    Ok(Asset { scene, regions: Vec::new() })
}

/// Splits the first triangle of the first `count` islands at its centroid (+2 triangles each).
fn split_centroids(mesh: &mut SourceMesh, count: u32, islands: &[Island]) {
    let mut firsts = Vec::new();
    let mut first = 0usize;
    for island in islands {
        firsts.push(first);
        first += 2 * (island.cells[0] * island.cells[1]) as usize;
    }
    for i in 0..count as usize {
        // The first triangle of a different quad each time: island i mod 24, its quad i / 24.
        let face = firsts[i % firsts.len()] + 2 * (i / firsts.len());
        let corners = mesh.triangles[face];
        let mean3 = |values: &[[f32; 3]]| {
            let sum = corners.iter().fold([0.0f32; 3], |acc, &v| {
                let p = values[v as usize];
                [acc[0] + p[0], acc[1] + p[1], acc[2] + p[2]]
            });
            sum.map(|x| x / 3.0)
        };
        let position = mean3(&mesh.positions_local);
        let normal = mean3(&mesh.normals_local);
        let uv = corners.iter().fold([0.0f32; 2], |acc, &v| {
            [acc[0] + mesh.uvs[v as usize][0] / 3.0, acc[1] + mesh.uvs[v as usize][1] / 3.0]
        });
        let centre = mesh.positions_local.len() as u32;
        mesh.positions_local.push(position);
        mesh.normals_local.push(normal);
        mesh.uvs.push(uv);
        let [a, b, c] = corners;
        mesh.triangles[face] = [a, b, centre];
        mesh.triangles.push([b, c, centre]);
        mesh.triangles.push([c, a, centre]);
        let material = mesh.triangle_materials[face];
        mesh.triangle_materials.extend([material, material]);
    }
}

/// Area-weighted normals shared by every vertex at one position (smooth across islands).
fn smooth_normals(mesh: &mut SourceMesh) {
    let mut sums: std::collections::HashMap<[u32; 3], DVec3> = std::collections::HashMap::new();
    let key = |p: [f32; 3]| p.map(f32::to_bits);
    let point = |p: [f32; 3]| glam::Vec3::from_array(p).as_dvec3();
    for t in &mesh.triangles {
        let p = t.map(|v| point(mesh.positions_local[v as usize]));
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        for &v in t {
            *sums.entry(key(mesh.positions_local[v as usize])).or_default() += cross;
        }
    }
    for (v, normal) in mesh.normals_local.iter_mut().enumerate() {
        let sum = sums.get(&key(mesh.positions_local[v])).copied().unwrap_or(DVec3::Y);
        *normal = sum.normalize_or(DVec3::Y).as_vec3().to_array();
    }
}

/// The colour of each texel: the rock under it, for the island whose rectangle (with half
/// the gutter) holds it; dark grey elsewhere.
fn island_texture(islands: &[Island], n: [u32; 3]) -> impl Fn(f64, f64) -> Srgb + Sync + '_ {
    let grow = f64::from(GUTTER) / 2.0;
    move |x, y| {
        let hit = islands.iter().find(|island| {
            let [x0, y0, w, h] = island.rect.map(f64::from);
            x >= x0 - grow && x < x0 + w + grow && y >= y0 - grow && y < y0 + h + grow
        });
        let Some(island) = hit else { return [0.2, 0.2, 0.2] };
        let [x0, y0, w, h] = island.rect.map(f64::from);
        let a = (x - x0) / w * f64::from(island.cells[0]);
        let b = (y - y0) / h * f64::from(island.cells[1]);
        let p = surface(cube_point(coords(island, n, a, b), n));
        // One texel's size on the surface: the island spans about one unit per half face.
        let footprint = 1.0 / w.min(h).max(1.0);
        rock(p, footprint)
    }
}

/// The rock colour at surface point `p`; `footprint` is one texel in world units.
fn rock(p: DVec3, footprint: f64) -> Srgb {
    let large = fractal_noise((p * 2.0).to_array(), 5, 41) as f32;
    let grain = fractal_noise((p * 40.0).to_array(), 2, 42) as f32;
    let mut colour = mix([0.42, 0.38, 0.33], [0.62, 0.58, 0.50], large);
    colour = colour.map(|c| c * (0.85 + 0.3 * grain));
    let crack = (fractal_noise((p * 3.0).to_array(), 3, 43) - 0.5).abs() - 0.008;
    colour = mix(colour, [0.12, 0.11, 0.10], coverage(crack / 1.5, footprint) * 0.9);
    for (height, colour_of_band) in [(0.15, [0.95, 0.75, 0.05]), (-0.35, [0.85, 0.15, 0.10])] {
        let band = (p.y - height).abs() - 0.06;
        colour = mix(colour, colour_of_band, coverage(band, footprint));
    }
    colour
}
