//! Triangle assembly (lists, strips, fans) and vertex normals computed from the faces.

use glam::Vec3;
use gltf::json::mesh::Mode;

/// Expands an index list into triangles for the given mode; also returns how many
/// trailing indices of a TRIANGLES list were left over.
pub(super) fn assemble_triangles(corners: &[u32], mode: Mode) -> (Vec<[u32; 3]>, usize) {
    match mode {
        Mode::TriangleStrip => {
            // glTF: p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}
            let triangles = corners
                .windows(3)
                .enumerate()
                .filter_map(|(i, w)| match *w {
                    [a, b, c] => Some(if i % 2 == 0 { [a, b, c] } else { [a, c, b] }),
                    _ => None,
                })
                .collect();
            (triangles, 0)
        }
        Mode::TriangleFan => {
            // glTF: p_i = {v_{i+1}, v_{i+2}, v_0}
            let Some((&first, rest)) = corners.split_first() else {
                return (Vec::new(), 0);
            };
            let triangles = rest
                .windows(2)
                .filter_map(|w| match *w {
                    [b, c] => Some([b, c, first]),
                    _ => None,
                })
                .collect();
            (triangles, 0)
        }
        _ => {
            let chunks = corners.chunks_exact(3);
            let leftover = chunks.remainder().len();
            let triangles = chunks
                .filter_map(|c| match *c {
                    [a, b, c] => Some([a, b, c]),
                    _ => None,
                })
                .collect();
            (triangles, leftover)
        }
    }
}

/// Area-weighted vertex normals (un-normalised sums) of a triangle list.
fn face_normal_sums(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for triangle in triangles {
        let [a, b, c] =
            triangle.map(|vertex| positions.get(vertex as usize).map_or(Vec3::ZERO, |&p| Vec3::from_array(p)));
        let weighted = (b - a).cross(c - a); // length = twice the area
        if !weighted.is_finite() {
            continue;
        }
        for &vertex in triangle {
            if let Some(sum) = sums.get_mut(vertex as usize) {
                *sum += weighted;
            }
        }
    }
    sums
}

fn unit_or_z(v: Vec3) -> [f32; 3] {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() { [0.0, 0.0, 1.0] } else { n.to_array() }
}

/// Normals computed from the faces: area-weighted, normalised, zero → +Z.
pub(super) fn computed_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    face_normal_sums(positions, triangles).into_iter().map(unit_or_z).collect()
}

/// Normalises file normals; zero or non-finite ones are replaced by computed normals.
/// Returns the normals and how many were replaced.
pub(super) fn normalise_or_fill(
    normals: &[[f32; 3]],
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> (Vec<[f32; 3]>, usize) {
    let mut computed: Option<Vec<Vec3>> = None;
    let mut replaced = 0;
    let out = normals
        .iter()
        .enumerate()
        .map(|(i, &n)| {
            let v = Vec3::from_array(n);
            let unit = v.normalize_or_zero();
            if v.is_finite() && unit != Vec3::ZERO && unit.is_finite() {
                unit.to_array()
            } else {
                replaced += 1;
                let sums = computed.get_or_insert_with(|| face_normal_sums(positions, triangles));
                unit_or_z(sums.get(i).copied().unwrap_or(Vec3::ZERO))
            }
        })
        .collect();
    (out, replaced)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans() {
        let (strip, _) = assemble_triangles(&[0, 1, 2, 3, 4], Mode::TriangleStrip);
        assert_eq!(strip, vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
        let (fan, _) = assemble_triangles(&[0, 1, 2, 3], Mode::TriangleFan);
        assert_eq!(fan, vec![[1, 2, 0], [2, 3, 0]]);
        let (list, leftover) = assemble_triangles(&[0, 1, 2, 3], Mode::Triangles);
        assert_eq!((list, leftover), (vec![[0, 1, 2]], 1));
        assert!(assemble_triangles(&[0, 1], Mode::TriangleStrip).0.is_empty());
        assert!(assemble_triangles(&[], Mode::TriangleFan).0.is_empty());
    }
}
