//! Vertex normals and smooth shading's crease rule, shared by the CPU and the GPU paths.
//!
//! A vertex's normal is the unit sum of the cross products `(b − a) × (c − a)` of the faces
//! around it (area-weighted, wound as the file winds them), accumulated in `f64`. Smooth
//! shading gives each face corner its vertex's normal when that is within the crease angle
//! of the face normal ([`SMOOTH_CREASE_COSINE`]), else the face normal, so hard edges stay
//! hard: a cube's corners (54.7° from each face) shade flat, a sphere's faces blend.

/// Cosine of the crease angle (45°). Keep in sync with `SMOOTH_CREASE_COSINE` in
/// shaders/mesh_colors.wgsl (crates/render/tests/gpu/shaders.rs compares them).
pub const SMOOTH_CREASE_COSINE: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// Twice the area vector of triangle `(a, b, c)`: `(b − a) × (c − a)`, in `f64`.
pub fn face_cross(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [f64; 3] {
    let (a, b, c) = (a.map(f64::from), b.map(f64::from), c.map(f64::from));
    let (e1, e2) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
    [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
}

/// `v / |v|`, or zero when `v` has no finite, positive length.
pub fn unit_or_zero(v: [f64; 3]) -> [f64; 3] {
    let length = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if length.is_finite() && length > 0.0 { v.map(|x| x / length) } else { [0.0; 3] }
}

/// The unit area-weighted normal of each vertex (zero where the faces around it have no
/// finite area); triangles with an index out of range are skipped.
pub fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut sums = vec![[0.0f64; 3]; positions.len()];
    for corners in triangles {
        let Some(p) = corners.iter().map(|&v| positions.get(v as usize).copied()).collect::<Option<Vec<_>>>() else {
            continue;
        };
        let cross = face_cross(p[0], p[1], p[2]);
        if !cross.iter().all(|x| x.is_finite()) {
            continue;
        }
        for &v in corners {
            for (sum, value) in sums[v as usize].iter_mut().zip(cross) {
                *sum += value;
            }
        }
    }
    sums.into_iter().map(unit_or_zero).collect()
}

/// The normal smooth shading gives a corner: `vertex_normal` (unit or zero) when it is
/// within the crease angle of the unit `face_normal`, else `face_normal`.
pub fn smooth_corner_normal(vertex_normal: [f32; 3], face_normal: [f32; 3]) -> [f32; 3] {
    let length = (vertex_normal.iter().map(|x| x * x).sum::<f32>()).sqrt();
    let cosine = vertex_normal.iter().zip(face_normal).map(|(a, b)| a * b).sum::<f32>();
    if length > 0.0 && cosine >= SMOOTH_CREASE_COSINE * length {
        vertex_normal.map(|x| x / length)
    } else {
        face_normal
    }
}

/// The smooth normal at barycentric `w` of a face whose corners have the vertex normals
/// `corners` (unit or zero): their weighted sum made unit, or `face_normal` where that sum
/// vanishes (opposite normals, zero vertex normals).
pub fn interpolated_normal(corners: &[[f64; 3]; 3], w: [f64; 3], face_normal: [f64; 3]) -> [f32; 3] {
    let sum = std::array::from_fn(|a| w[0] * corners[0][a] + w[1] * corners[1][a] + w[2] * corners[2][a]);
    let unit = unit_or_zero(sum);
    let unit = if unit == [0.0; 3] { face_normal } else { unit };
    let unit = if unit == [0.0; 3] { [0.0, 0.0, 1.0] } else { unit };
    unit.map(|x| x as f32)
}
