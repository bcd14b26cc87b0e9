//! What a conversion shows when it ends: the error of the converted store against the
//! texture it came from, over the whole textured surface, as a PSNR.
//!
//! Each textured face's error is the metric of the module docs in [`super`] (the RMS over its
//! test points — an area quadrature of the face — and the four channels, colour channels
//! sRGB-encoded, against the texture's level 0 read bilinearly: what a magnified UV render
//! shows), as the store shows the face (shared samples and fans towards finer edges
//! included). The faces' mean squared errors are averaged weighted by world area, so the
//! figure is the mean squared error over the surface: `PSNR = 10·log10(1 / MSE)`, full range
//! = 1, directly comparable with the PSNR of 8-bit renders of the model up close (a render
//! from afar weights faces by their screen area and filters the texture, so its figure
//! differs). Faces without a texture take no part (their colour is the material's constant).
//!
//! It is an estimate: each face is tested on at most a lattice of [`measure_lattice`] (at
//! least 8, so 64 points a face or more, and about [`MEASURE_POINTS`] over the mesh), not on
//! every texel, so the measure costs a fraction of the conversion (a face's seam strips
//! still get their own points at its `R`).

use rayon::prelude::*;

use crate::colors::layout::Resolution;
use crate::colors::store::ColorStore;
use crate::convert::bake::{face_materials, world_area};
use crate::mesh::scene::Scene;
use crate::mesh::weld::WeldedMesh;
use crate::progress::{Cancelled, Progress};

use super::Faces;
use super::face_fit::shared_uvs;

/// The surface PSNR (module docs) of `store` — a store of `mesh` — against the base-colour
/// textures of `scene`, in dB: `None` when no face with area is textured, `+∞` when the
/// store matches the texture within float rounding everywhere.
pub fn texture_psnr(
    store: &ColorStore,
    mesh: &WeldedMesh,
    scene: &Scene,
    progress: Progress<'_>,
) -> Result<Option<f64>, Cancelled> {
    let face_count = store.topology().face_count() as usize;
    let (materials, pyramids) = face_materials(mesh, scene, face_count);
    let shared = shared_uvs(mesh);
    if shared.len() != face_count {
        return Ok(None);
    }
    // No cached test points: each face is measured once. A face's test lattice is at most
    // `2·max` (`dense_lattice`).
    let lattice = measure_lattice(face_count);
    let max = Resolution::new(u64::from(lattice / 2)).unwrap_or(Resolution::ONE);
    let faces = Faces { mesh, materials: &materials, shared: &shared, pyramids: &pyramids, max, cache: Vec::new() };
    let counter = progress.counter("measuring the conversion against the texture", "faces", face_count);
    let (squared, area) = (0..face_count)
        .into_par_iter()
        .map(|face| {
            counter.add(1);
            if counter.is_cancelled() {
                return (0.0, 0.0);
            }
            match faces.shown_error(store, face) {
                Some(error) => {
                    let area = world_area(mesh, face);
                    (f64::from(error).powi(2) * area, area)
                }
                None => (0.0, 0.0),
            }
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    progress.check()?;
    if area.is_nan() || area <= 0.0 {
        return Ok(None);
    }
    let mse = squared / area;
    Ok(Some(if mse > 0.0 { -10.0 * mse.log10() } else { f64::INFINITY }))
}

/// Test points the measure spends over a mesh, about (module docs).
pub const MEASURE_POINTS: u64 = 4 << 20;

/// The largest test lattice of a face in a mesh of `face_count` faces: the largest power of
/// two `D` with `face_count·D² ≤` [`MEASURE_POINTS`], at least 8 and at most 256.
pub fn measure_lattice(face_count: usize) -> u32 {
    (3..=8u32)
        .map(|log2| 1u32 << log2)
        .take_while(|&d| (face_count as u64) * u64::from(d).pow(2) <= MEASURE_POINTS)
        .last()
        .unwrap_or(8)
}
