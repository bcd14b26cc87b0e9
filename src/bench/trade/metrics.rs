//! Image error of a test render against its reference (PSNR, largest error, FLIP) and the
//! small JSON helpers every row goes through.

use image::RgbaImage;

use meshpaint_core::colors::psnr::psnr_over;

/// Error of a test image against a reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// PSNR over RGB, dB (`inf` when equal).
    pub psnr_db: f64,
    /// Largest absolute difference of an RGB channel, 8-bit steps.
    pub max_error_steps: u8,
    /// Mean FLIP error over the compared pixels (0..1).
    pub flip_mean: f64,
    /// Pixels compared.
    pub pixels: u64,
}

/// Compares `test` with `reference` on the pixels where `mask` (row-major) is true: PSNR,
/// largest error and the mean FLIP error (computed on the whole images, averaged over the mask).
pub fn compare(reference: &RgbaImage, test: &RgbaImage, mask: &[bool]) -> ImageError {
    let psnr_db = psnr_over(reference, test, mask);
    let mut max_error_steps = 0u8;
    let mut pixels = 0u64;
    for ((a, b), &keep) in reference.pixels().zip(test.pixels()).zip(mask) {
        if keep {
            pixels += 1;
            for c in 0..3 {
                max_error_steps = max_error_steps.max(a.0[c].abs_diff(b.0[c]));
            }
        }
    }
    let rgb = |image: &RgbaImage| -> Vec<u8> { image.pixels().flat_map(|p| [p.0[0], p.0[1], p.0[2]]).collect() };
    let (w, h) = reference.dimensions();
    let flip_mean = if pixels == 0 || test.dimensions() != (w, h) {
        f64::NAN
    } else {
        let map = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(w, h, &rgb(reference)),
            nv_flip::FlipImageRgb8::with_data(w, h, &rgb(test)),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        )
        .to_vec();
        let sum: f64 = map.iter().zip(mask).filter(|(_, keep)| **keep).map(|(e, _)| f64::from(*e)).sum();
        sum / pixels as f64
    };
    ImageError { psnr_db, max_error_steps, flip_mean, pixels }
}

/// The error columns of a row. JSON has no infinity: identical images report PSNR null.
pub(super) fn error_json(error: &ImageError) -> serde_json::Value {
    let psnr = if error.psnr_db.is_finite() { Some(error.psnr_db) } else { None };
    serde_json::json!({
        "psnr_db": psnr, "max_error_steps": error.max_error_steps,
        "flip_mean": if error.flip_mean.is_finite() { Some(error.flip_mean) } else { None },
        "pixels_compared": error.pixels,
    })
}

/// Adds (or overwrites) every key of the object `more` to the object `row`.
pub(super) fn merge(row: &mut serde_json::Value, more: &serde_json::Value) {
    if let (Some(row), Some(more)) = (row.as_object_mut(), more.as_object()) {
        for (k, v) in more {
            row.insert(k.clone(), v.clone());
        }
    }
}

/// The median (upper middle) of `values`, NaN when empty.
pub(super) fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}
