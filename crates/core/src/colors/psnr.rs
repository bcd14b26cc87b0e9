//! The peak signal-to-noise ratio of two 8-bit images: how the editor's view panel and
//! `meshpaint bench` compare a render of the mesh colors with a render of the source.

use image::RgbaImage;

/// PSNR in dB over RGB of the pixels either image covers (alpha > 0); `inf` when equal.
pub fn psnr(a: &RgbaImage, b: &RgbaImage) -> f64 {
    let covered: Vec<bool> = a.pixels().zip(b.pixels()).map(|(pa, pb)| pa.0[3] > 0 || pb.0[3] > 0).collect();
    psnr_over(a, b, &covered)
}

/// PSNR in dB over RGB of the pixels where `mask` (row-major) is true; `inf` when they are
/// equal there or the mask is empty.
pub fn psnr_over(a: &RgbaImage, b: &RgbaImage, mask: &[bool]) -> f64 {
    let (mut sum, mut count) = (0.0f64, 0u64);
    for ((pa, pb), &keep) in a.pixels().zip(b.pixels()).zip(mask) {
        if !keep {
            continue;
        }
        for c in 0..3 {
            sum += (f64::from(pa.0[c]) - f64::from(pb.0[c])).powi(2);
        }
        count += 3;
    }
    if count == 0 || sum == 0.0 {
        return f64::INFINITY;
    }
    10.0 * (255.0f64 * 255.0 / (sum / count as f64)).log10()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed form: one channel of one of four covered pixels off by 16 steps is an MSE of
    /// 16² / 12, so the PSNR is 10·log10(255² · 12 / 256).
    #[test]
    fn psnr_matches_the_closed_form() {
        let a = RgbaImage::from_pixel(2, 2, image::Rgba([100, 100, 100, 255]));
        let mut b = a.clone();
        b.put_pixel(1, 0, image::Rgba([116, 100, 100, 255]));
        let expected = 10.0 * (255.0f64 * 255.0 * 12.0 / 256.0).log10();
        assert!((psnr(&a, &b) - expected).abs() < 1e-12);
        assert_eq!(psnr(&a, &a), f64::INFINITY);
        // Uncovered pixels (alpha 0 in both) do not count.
        let mut c = a.clone();
        c.put_pixel(0, 1, image::Rgba([0, 0, 0, 0]));
        let mut d = c.clone();
        d.put_pixel(0, 1, image::Rgba([255, 0, 0, 0]));
        assert_eq!(psnr(&c, &d), f64::INFINITY);
    }
}
