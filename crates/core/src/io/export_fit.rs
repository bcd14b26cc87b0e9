//! A vertex-colour export that fits the content: the tessellated glTF
//! ([`crate::io::export_gltf`]) at a coarser level and with compact `COLOR_0`.
//!
//! - **Coarser level `L`**: every face's resolution becomes `max(1, R_f >> L)`, resampled by
//!   the store's own exact 2× reduction ([`ColorStore::set_face_resolution`]), then tessellated
//!   as usual. `--max-vertices N` picks the smallest `L` whose tessellation has at most `N`
//!   vertices ([`tessellation_counts`], exact).
//! - **Its error** is measured on every level-0 sample of the original: the coarse store's
//!   linear filter at the sample's position ([`crate::packing::sampler::sample`], what a viewer
//!   interpolating the coarse vertex colours shows there) against the sample, in 8-bit sRGB
//!   steps (alpha: linear steps of 1/255), as the maximum and the RMS over samples and
//!   channels.
//! - **`COLOR_0` encoding**: normalized `u8` when its rounding error on every channel of every
//!   exported colour is within half the spacing of the document's own format there (sRGB8:
//!   the neighbouring 8-bit codes, decoded; binary16: its 11 significant bits; f32: exact
//!   only), so the document's format could not tell the difference; else normalized `u16`
//!   under the same test; else float. Linear u8 fails on dark sRGB8 colours (sRGB codes are
//!   3·10^-4 apart near black, u8 steps 4·10^-3), u16 (steps 1.5·10^-5) passes on RGBA8 and
//!   RGBA16F documents.

use std::path::Path;

use crate::colors::format::{ColorFormat, decode_srgb8, encode_srgb8};
use crate::colors::layout::Resolution;
use crate::colors::store::ColorStore;
use crate::io::export_gltf::{
    ColorEncoding, ExportError, tessellate, tessellation_counts, tessellation_to_glb_encoded,
};
use crate::packing::sampler::{self, Filter};

/// What to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FitOptions {
    /// Reduce every face by `2^level` (0: the face's own R).
    pub level: u32,
    /// Instead of `level`: the smallest level whose tessellation has at most this many vertices.
    pub max_vertices: Option<u64>,
    /// `None`: the smallest encoding that suffices (module docs); `Some`: this one.
    pub encoding: Option<ColorEncoding>,
}

/// What a fitted export wrote.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSummary {
    /// The level used.
    pub level: u32,
    /// glTF vertices.
    pub vertices: u64,
    /// Triangles.
    pub triangles: u64,
    /// `COLOR_0` encoding.
    pub encoding: ColorEncoding,
    /// Bytes of the file.
    pub bytes: u64,
    /// Bytes `COLOR_0` takes, and would take as float.
    pub color_bytes: (u64, u64),
    /// Error of the level against the original samples: (max, RMS) in 8-bit steps.
    pub error_steps: (f64, f64),
}

/// Errors of a fitted export.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// Even one triangle per face (level where every R is 1) has more vertices than asked.
    #[error("--max-vertices {max}: even one triangle per face needs {needed} vertices")]
    TooFewVertices {
        /// The limit asked for.
        max: u64,
        /// Vertices at R = 1 everywhere.
        needed: u64,
    },
    /// The export itself failed.
    #[error(transparent)]
    Export(#[from] ExportError),
}

/// `store` with every face's R divided by `2^levels` (at least 1).
pub fn coarser(store: &ColorStore, levels: u32) -> ColorStore {
    let mut out = store.clone();
    if levels == 0 {
        return out;
    }
    for face in 0..store.topology().face_count() {
        let r = store.face_resolution(face).map_or(1, Resolution::get);
        let target = Resolution::new(u64::from((r >> levels.min(31)).max(1))).unwrap_or(Resolution::ONE);
        // A valid resolution of an existing face: the store refuses nothing here.
        let _ = out.set_face_resolution(face, target);
    }
    out
}

/// The smallest level whose tessellation fits `max` vertices, with that store.
pub fn level_for(store: &ColorStore, max: u64) -> Result<(u32, ColorStore), FitError> {
    let mut level = 0;
    let mut current = store.clone();
    loop {
        let (vertices, _) = tessellation_counts(&current);
        if vertices <= max {
            return Ok((level, current));
        }
        if current.face_resolutions().iter().all(|r| r.get() == 1) {
            return Err(FitError::TooFewVertices { max, needed: vertices });
        }
        current = coarser(&current, 1);
        level += 1;
    }
}

/// (max, RMS) error in 8-bit steps of `coarse` against every sample of `original`.
pub fn error_steps(original: &ColorStore, coarse: &ColorStore) -> (f64, f64) {
    let (mut max, mut sum, mut count) = (0.0f64, 0.0f64, 0u64);
    original.for_each_site(|site| {
        let (Some(want), Some(got)) =
            (original.get(site.sample), sampler::sample(coarse, site.face, site.barycentric, Filter::Linear, 0))
        else {
            return;
        };
        for c in 0..4 {
            let step = |x: f32| {
                if c < 3 { f64::from(encode_srgb8(x)) } else { (f64::from(x.clamp(0.0, 1.0)) * 255.0).round() }
            };
            let d = (step(want[c]) - step(got[c])).abs();
            max = max.max(d);
            sum += d * d;
            count += 1;
        }
    });
    (max, if count == 0 { 0.0 } else { (sum / count as f64).sqrt() })
}

/// Half the spacing of `format`'s representable values around channel value `c` (channel
/// `channel`: 0..3 colour, 3 alpha): what `format` itself cannot tell apart.
fn half_step(format: ColorFormat, channel: usize, c: f32) -> f32 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    match format {
        ColorFormat::Rgba8Srgb if channel == 3 => 0.5 / 255.0,
        ColorFormat::Rgba8Srgb => {
            let code = encode_srgb8(c);
            let at = decode_srgb8(code);
            let below = if code > 0 { at - decode_srgb8(code - 1) } else { f32::INFINITY };
            let above = if code < 255 { decode_srgb8(code + 1) - at } else { f32::INFINITY };
            0.5 * below.min(above)
        }
        // binary16 keeps 11 significant bits (subnormals: steps of 2^-24).
        ColorFormat::Rgba16F => 0.5 * (c * f32::powi(2.0, -11)).max(f32::powi(2.0, -24)),
        ColorFormat::Rgba32F => 0.0,
    }
}

/// The smallest encoding whose error on every channel of every colour stays within what the
/// document's `format` can resolve there ([`half_step`]): `u8`, else `u16`, else float.
pub fn smallest_encoding(colors: &[[f32; 4]], format: ColorFormat) -> ColorEncoding {
    let suffices = |encoding: ColorEncoding| {
        colors.iter().all(|&color| {
            let (exact, stored) = (ColorEncoding::Float.round_trip(color), encoding.round_trip(color));
            (0..4).all(|k| (stored[k] - exact[k]).abs() <= half_step(format, k, exact[k]))
        })
    };
    [ColorEncoding::Unorm8, ColorEncoding::Unorm16].into_iter().find(|&e| suffices(e)).unwrap_or(ColorEncoding::Float)
}

/// Tessellates `store` on `positions` as `options` say and writes the .glb to `path`
/// atomically; `format` is the document's colour format (for the encoding test).
pub fn write_fitted_glb(
    path: &Path,
    positions: &[[f32; 3]],
    store: &ColorStore,
    format: ColorFormat,
    options: FitOptions,
) -> Result<FitSummary, FitError> {
    let (level, coarse) = match options.max_vertices {
        Some(max) => level_for(store, max)?,
        None => (options.level, coarser(store, options.level)),
    };
    let error = if level == 0 { (0.0, 0.0) } else { error_steps(store, &coarse) };
    let tessellation = tessellate(positions, &coarse)?;
    let encoding = options.encoding.unwrap_or_else(|| smallest_encoding(&tessellation.colors, format));
    let (vertices, triangles) = (tessellation.positions.len() as u64, tessellation.triangles.len() as u64);
    let bytes = tessellation_to_glb_encoded(tessellation, encoding)?;
    crate::atomic_write::write_atomically(path, &bytes).map_err(|error| ExportError::Io {
        path: error.path,
        action: error.action,
        source: error.source,
    })?;
    Ok(FitSummary {
        level,
        vertices,
        triangles,
        encoding,
        bytes: bytes.len() as u64,
        color_bytes: (vertices * encoding.bytes() as u64, vertices * 16),
        error_steps: error,
    })
}
