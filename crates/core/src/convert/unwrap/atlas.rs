//! A generated UV atlas ([`generate_uvs`]).
//!
//! The unwrapper is the `uvunwrap` crate (pure Rust, in the manner of xatlas): faces grow
//! into charts within a normal cone, each chart is flattened (planar projection when flat,
//! else least-squares conformal maps evened out by as-rigid-as-possible iterations; a chart
//! that folds, overlaps itself or distorts area more than 4× is split and tried again), and
//! the charts are packed by shape into one page at the highest density that fits, `padding`
//! texels from every page edge and at least `2 · padding` texels from each other.
//!
//! When the charts do not fit one page (very many charts: each needs its gutter), the gutter
//! is halved until they do, down to one texel; [`GeneratedUvs::padding`] is the one used.
//!
//! The page is `size` texels wide and at most `size` high (the unwrapper crops unused rows);
//! its UVs are rescaled into the square `size × size` texture, so texel boundaries stay
//! where the packer put them. UVs follow glTF's convention (`(0, 0)` is the image's top-left
//! corner), as the unwrapper's do.
//!
//! **Slivers.** A face thinner than a millionth of the mesh's bounding diagonal has no place
//! in a chart (the unwrapper collapses its corners onto one UV; it has no visible area
//! either). Each gets a chart of its own here: a right triangle with legs of two texels in a
//! free block of the page (`2 + 2 · padding` texels a side, away from every chart's bounding
//! box grown by the gutter), so it still has texels of its own. Faces left without area when
//! no block is free are listed in [`GeneratedUvs::faces_without_area`].

use std::time::{Duration, Instant};

use thiserror::Error;

use crate::convert::bake_uv::MAX_TEXTURE_SIZE;

/// The smallest texture side an atlas is generated for.
pub const MIN_ATLAS_SIZE: u32 = 16;

/// Errors of generating UVs.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum UnwrapError {
    /// A texture side outside [`MIN_ATLAS_SIZE`]`..=`[`MAX_TEXTURE_SIZE`].
    #[error("texture size {0} is outside {MIN_ATLAS_SIZE}..={MAX_TEXTURE_SIZE} for generated UVs")]
    Size(u32),
    /// The unwrapper refused the mesh or the options.
    #[error("generating UVs: {0}")]
    Unwrapper(String),
    /// The charts did not fit one page of the texture.
    #[error(
        "generating UVs: {charts} charts need {pages} pages of {size}×{size} texels with a gutter of {padding}; \
         use a larger texture"
    )]
    Pages {
        /// Charts.
        charts: u32,
        /// Pages the packer needed.
        pages: u32,
        /// The texture side.
        size: u32,
        /// The padding asked for.
        padding: u32,
    },
}

/// How to lay the atlas out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AtlasOptions {
    /// Width = height of the texture in texels.
    pub size: u32,
    /// Empty texels around each chart (charts are at least twice this apart).
    pub padding: u32,
}

impl AtlasOptions {
    /// `size` with [`default_atlas_padding`].
    pub fn new(size: u32) -> Self {
        AtlasOptions { size, padding: default_atlas_padding(size) }
    }
}

/// The default gutter for a `size` texture: `size / 128` texels, 2 to 16. Charts are then
/// `size / 64` texels apart, so bilinear filtering and the MIP levels down to 1/32 of the
/// texture (where a texel spans 32 of level 0's) reach only their own chart's dilated
/// colours ([`super::super::bake_uv::default_padding`] fills the gutters).
pub fn default_atlas_padding(size: u32) -> u32 {
    (size / 128).clamp(2, 16)
}

/// A generated layout: one UV triangle per face, in the mesh's face order.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedUvs {
    /// Per face, the UV of each corner (glTF convention, inside `[0, 1]²`).
    pub corner_uvs: Vec<[[f32; 2]; 3]>,
    /// The texture side the layout was made for.
    pub size: u32,
    /// The gutter used (the one asked for, or narrower when the charts did not fit).
    pub padding: u32,
    /// Charts (connected pieces of the layout).
    pub charts: u32,
    /// Fraction of the square texture the charts' surface covers.
    pub utilization: f64,
    /// Texels per unit of length on the surface (the packer's density).
    pub texels_per_unit: f64,
    /// Faces the layout gives no area (module docs), ascending.
    pub faces_without_area: Vec<u32>,
    /// How long the unwrapper ran.
    pub elapsed: Duration,
}

/// Generates a non-overlapping UV layout of the triangles `triangles` over `positions` for a
/// `size × size` texture with the gutter `padding` (module docs). `progress(stage, fraction)`
/// is called as the unwrapper goes (from worker threads, never concurrently).
pub fn generate_uvs(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    options: AtlasOptions,
    progress: &(dyn Fn(&str, f32) + Sync),
) -> Result<GeneratedUvs, UnwrapError> {
    if !(MIN_ATLAS_SIZE..=MAX_TEXTURE_SIZE).contains(&options.size) {
        return Err(UnwrapError::Size(options.size));
    }
    let started = Instant::now();
    let mut generated = generate_with_gutter(positions, triangles, options, progress)?;
    generated.elapsed = started.elapsed();
    Ok(generated)
}

/// [`generate_uvs`] with the gutter `options.padding`, halved while the charts do not fit.
fn generate_with_gutter(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    options: AtlasOptions,
    progress: &(dyn Fn(&str, f32) + Sync),
) -> Result<GeneratedUvs, UnwrapError> {
    let AtlasOptions { size, padding } = options;
    let indices: &[u32] = bytemuck::cast_slice(triangles);
    let input = uvunwrap::MeshInput::new(positions, indices);
    let unwrap_options = uvunwrap::Options {
        density: uvunwrap::Density::Auto { page_size: size },
        padding,
        ..uvunwrap::Options::default()
    };
    let report = |p: uvunwrap::Progress| {
        let fraction = p.total.map_or(0.5, |total| p.done as f32 / total.max(1) as f32);
        let stage = match p.stage {
            uvunwrap::Stage::Segmenting => "generating UVs: growing charts",
            uvunwrap::Stage::Parameterizing => "generating UVs: flattening charts",
            uvunwrap::Stage::Packing => "generating UVs: packing charts",
            _ => "generating UVs",
        };
        progress(stage, fraction);
        true
    };
    let atlas = uvunwrap::generate_with_progress(&[input], &unwrap_options, report)
        .map_err(|error| UnwrapError::Unwrapper(error.to_string()))?;
    if atlas.page_count > 1 || atlas.width > size || atlas.height > size {
        if padding > 1 {
            // Very many charts: a narrower gutter (fewer MIP levels stay clean) before refusing.
            return generate_with_gutter(positions, triangles, AtlasOptions { size, padding: padding / 2 }, progress);
        }
        return Err(UnwrapError::Pages { charts: atlas.chart_count, pages: atlas.page_count, size, padding });
    }
    let Some(mesh) = atlas.meshes.first() else {
        return Err(UnwrapError::Unwrapper("no output mesh".to_owned()));
    };
    if mesh.indices.len() != indices.len() {
        return Err(UnwrapError::Unwrapper(format!(
            "{} output corners for {} input corners",
            mesh.indices.len(),
            indices.len()
        )));
    }
    let scale = [atlas.width as f32 / size as f32, atlas.height as f32 / size as f32];
    let uv_of =
        |index: u32| mesh.vertices.get(index as usize).map_or([0.0; 2], |v| [v.uv[0] * scale[0], v.uv[1] * scale[1]]);
    let corner_uvs: Vec<[[f32; 2]; 3]> =
        mesh.indices.chunks_exact(3).map(|corners| [uv_of(corners[0]), uv_of(corners[1]), uv_of(corners[2])]).collect();
    let mut corner_uvs = corner_uvs;
    let texels = f64::from(size);
    let slivers: Vec<u32> = corner_uvs
        .iter()
        .enumerate()
        .filter(|(_, uvs)| super::stats::uv_area(uvs) * texels * texels <= 1e-9)
        .map(|(face, _)| face as u32)
        .collect();
    let faces_without_area = place_slivers(&mut corner_uvs, &slivers, size, padding);
    let page_texels = f64::from(atlas.width) * f64::from(atlas.height);
    Ok(GeneratedUvs {
        corner_uvs,
        size,
        padding,
        charts: atlas.chart_count,
        utilization: f64::from(atlas.utilization) * page_texels / (texels * texels),
        texels_per_unit: f64::from(atlas.texels_per_unit),
        faces_without_area,
        elapsed: Duration::ZERO,
    })
}

/// Gives each face of `slivers` a chart of its own in a free block of the page (module
/// docs); returns those that found no free block.
fn place_slivers(corner_uvs: &mut [[[f32; 2]; 3]], slivers: &[u32], size: u32, padding: u32) -> Vec<u32> {
    if slivers.is_empty() {
        return Vec::new();
    }
    let n = size as usize;
    let mut used = vec![false; n * n];
    let grow = padding as i64;
    for uvs in corner_uvs.iter() {
        let bound = |axis: usize, f: fn(f32, f32) -> f32, start: f32| uvs.iter().map(|uv| uv[axis]).fold(start, f);
        let lo = |axis| ((bound(axis, f32::min, f32::INFINITY) * size as f32).floor() as i64 - grow).max(0) as usize;
        let hi = |axis| {
            ((bound(axis, f32::max, f32::NEG_INFINITY) * size as f32).ceil() as i64 + grow).clamp(0, n as i64) as usize
        };
        for y in lo(1)..hi(1) {
            used[y * n + lo(0)..y * n + hi(0).max(lo(0))].iter_mut().for_each(|u| *u = true);
        }
    }
    let block = 2 + 2 * padding as usize;
    let mut left = Vec::new();
    let mut free_blocks = (0..n / block).flat_map(|by| (0..n / block).map(move |bx| (bx * block, by * block)));
    for &face in slivers {
        let free = free_blocks
            .find(|&(x0, y0)| (y0..y0 + block).all(|y| used[y * n + x0..y * n + x0 + block].iter().all(|u| !u)));
        let (Some((x0, y0)), Some(uvs)) = (free, corner_uvs.get_mut(face as usize)) else {
            left.push(face);
            continue;
        };
        let (x, y) = ((x0 + padding as usize) as f32, (y0 + padding as usize) as f32);
        let unit = |px: f32, py: f32| [px / size as f32, py / size as f32];
        *uvs = [unit(x, y), unit(x + 2.0, y), unit(x, y + 2.0)];
    }
    left
}
