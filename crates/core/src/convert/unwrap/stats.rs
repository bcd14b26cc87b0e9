//! What a UV layout gives each face: its UV area, and the texel density over the surface.

use crate::mesh::normals::face_cross;

/// The unsigned area of a UV triangle in UV units (`[0, 1]²` has area 1).
pub fn uv_area(uvs: &[[f32; 2]; 3]) -> f64 {
    let p = uvs.map(|uv| uv.map(f64::from));
    0.5 * ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1])).abs()
}

/// Texel density of a layout over the surface: per face, `sqrt(texels of UV area / surface
/// area)` (texels per unit of length), summarised weighted by surface area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DensityStats {
    /// The density below which 5 % of the surface lies.
    pub p5: f64,
    /// The median over the surface.
    pub median: f64,
    /// The density below which 95 % of the surface lies.
    pub p95: f64,
    /// Faces with surface area (the others carry no weight).
    pub faces: u64,
}

impl DensityStats {
    /// `p95 / p5`: 1 for a perfectly even layout.
    pub fn spread(&self) -> f64 {
        if self.p5 > 0.0 { self.p95 / self.p5 } else { f64::INFINITY }
    }
}

/// The texel density of `corner_uvs` (one UV triangle per face of `triangles`) in a
/// `size × size` texture (see [`DensityStats`]).
pub fn density(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    corner_uvs: &[[[f32; 2]; 3]],
    size: u32,
) -> DensityStats {
    let texels = f64::from(size) * f64::from(size);
    let mut faces: Vec<(f64, f64)> = triangles
        .iter()
        .zip(corner_uvs)
        .filter_map(|(corners, uvs)| {
            let p = corners.map(|v| positions.get(v as usize).copied().unwrap_or([0.0; 3]));
            let cross = face_cross(p[0], p[1], p[2]);
            let area = 0.5 * (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
            (area > 0.0 && area.is_finite()).then(|| ((uv_area(uvs) * texels / area).sqrt(), area))
        })
        .collect();
    faces.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = faces.iter().map(|f| f.1).sum();
    let quantile = |q: f64| {
        let mut seen = 0.0;
        for &(value, weight) in &faces {
            seen += weight;
            if seen >= q * total {
                return value;
            }
        }
        faces.last().map_or(0.0, |f| f.0)
    };
    DensityStats { p5: quantile(0.05), median: quantile(0.5), p95: quantile(0.95), faces: faces.len() as u64 }
}
