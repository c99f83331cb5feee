//! Image and animation error metrics, used by tests, the bench and `voxsplat compare`. All work on
//! premultiplied RGBA with values clamped to [0, 1].
//!
//! ```
//! use voxsplat::{image::ImageF32, metrics::compare};
//! // A frame against a reference, over the pixels either covers.
//! let mut a = ImageF32::new(8, 8);
//! a.pixels[0] = [1.0, 1.0, 1.0, 1.0];
//! let m = compare(&a, &a.clone())?;
//! assert!(m.rmse == 0.0);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
use crate::image::ImageF32;

/// How far one image is from a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageMetrics {
    /// Root mean square error over all RGBA channels.
    pub rmse: f64,
    /// 20 log10(1 / rmse) in dB; infinite for identical images.
    pub psnr: f64,
    /// Largest absolute channel difference.
    pub max_abs: f64,
    /// Structural similarity of the luminance (colour composited over black).
    pub ssim_luma: f64,
    /// Structural similarity of the alpha channel.
    pub ssim_alpha: f64,
    /// RMSE over the covered pixels only: those where either image's alpha exceeds
    /// `COVERED_ALPHA` (the empty background both agree on is not counted as right). 0 when no
    /// pixel is covered.
    pub covered_rmse: f64,
    /// 20 log10(1 / covered_rmse) in dB: the figure to quote (infinite when identical or empty).
    pub covered_psnr: f64,
    /// How many pixels are covered.
    pub covered_pixels: usize,
}

/// A pixel is covered when either image's alpha exceeds this: one 8-bit step.
pub const COVERED_ALPHA: f32 = 1.0 / 255.0;

/// Whether pixel `i` is covered in either image (`COVERED_ALPHA`).
pub fn is_covered(img: &ImageF32, truth: &ImageF32, i: usize) -> bool {
    img.pixels[i][3] > COVERED_ALPHA || truth.pixels[i][3] > COVERED_ALPHA
}

fn clamp01(v: f32) -> f64 {
    (v as f64).clamp(0.0, 1.0)
}

/// Compare `img` against the reference `truth`.
pub fn compare(img: &ImageF32, truth: &ImageF32) -> Result<ImageMetrics> {
    if (img.width, img.height) != (truth.width, truth.height) {
        return Err(Error::InvalidArgument(format!(
            "images differ in size: {}x{} and {}x{}",
            img.width, img.height, truth.width, truth.height
        )));
    }
    let (mut se, mut max_abs) = (0.0f64, 0.0f64);
    for (a, b) in img.pixels.iter().zip(&truth.pixels) {
        for c in 0..4 {
            let d = clamp01(a[c]) - clamp01(b[c]);
            se += d * d;
            max_abs = max_abs.max(d.abs());
        }
    }
    let n = (img.pixels.len() * 4).max(1) as f64;
    let rmse = (se / n).sqrt();
    let whole = psnr(rmse);
    let covered: Vec<bool> = (0..img.pixels.len()).map(|i| is_covered(img, truth, i)).collect();
    let covered_pixels = covered.iter().filter(|&&c| c).count();
    let covered_rmse = rmse_masked(img, truth, |i| covered[i]).unwrap_or(0.0);
    let luma = |p: &[f32; 4]| 0.2126 * clamp01(p[0]) + 0.7152 * clamp01(p[1]) + 0.0722 * clamp01(p[2]);
    Ok(ImageMetrics {
        rmse,
        psnr: whole,
        max_abs,
        ssim_luma: ssim_banded(img, truth, luma),
        ssim_alpha: ssim_banded(img, truth, |p| clamp01(p[3])),
        covered_rmse,
        covered_psnr: psnr(covered_rmse),
        covered_pixels,
    })
}

/// Rows per band of `ssim_banded`.
const SSIM_BAND: usize = 64;

/// `ssim` of the channel `f` of two images of one size, band by band of rows with the window's
/// 5-row halo: the same value (the window never reaches past a band's halo), with memory that
/// follows a band instead of the image (an 8192² comparison held gigabytes of whole-image
/// buffers), and bands in parallel.
fn ssim_banded(a: &ImageF32, b: &ImageF32, f: impl Fn(&[f32; 4]) -> f64 + Sync) -> f64 {
    use rayon::prelude::*;
    let (w, h) = (a.width as usize, a.height as usize);
    if w * h == 0 {
        return 1.0;
    }
    let sum: f64 = (0..h.div_ceil(SSIM_BAND))
        .into_par_iter()
        .map(|band| {
            let (y0, y1) = (band * SSIM_BAND, ((band + 1) * SSIM_BAND).min(h));
            let (h0, h1) = (y0.saturating_sub(5), (y1 + 5).min(h));
            let take = |im: &ImageF32| -> Vec<f64> { im.pixels[h0 * w..h1 * w].iter().map(&f).collect() };
            ssim_map_sum(&take(a), &take(b), w, h1 - h0, y0 - h0..y1 - h0)
        })
        .sum();
    sum / (w * h) as f64
}

/// Separable Gaussian blur (sigma 1.5, 11 taps, edges clamped), the SSIM window of Wang et al.
fn blur(v: &[f64], w: usize, h: usize) -> Vec<f64> {
    let taps: Vec<f64> = (-5i32..=5).map(|i| (-(i * i) as f64 / (2.0 * 1.5 * 1.5)).exp()).collect();
    let norm: f64 = taps.iter().sum();
    let mut tmp = vec![0.0; v.len()];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for (k, t) in taps.iter().enumerate() {
                let xx = (x as i64 + k as i64 - 5).clamp(0, w as i64 - 1) as usize;
                s += t * v[y * w + xx];
            }
            tmp[y * w + x] = s / norm;
        }
    }
    let mut out = vec![0.0; v.len()];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for (k, t) in taps.iter().enumerate() {
                let yy = (y as i64 + k as i64 - 5).clamp(0, h as i64 - 1) as usize;
                s += t * tmp[yy * w + x];
            }
            out[y * w + x] = s / norm;
        }
    }
    out
}

/// Mean SSIM with constants for a dynamic range of 1.
pub fn ssim(a: &[f64], b: &[f64], w: usize, h: usize) -> f64 {
    if a.is_empty() {
        return 1.0;
    }
    ssim_map_sum(a, b, w, h, 0..h) / a.len() as f64
}

/// The SSIM map of `a` against `b` (`w` x `h`) summed over `rows`.
fn ssim_map_sum(a: &[f64], b: &[f64], w: usize, h: usize, rows: std::ops::Range<usize>) -> f64 {
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    let prod = |x: &[f64], y: &[f64]| -> Vec<f64> { x.iter().zip(y).map(|(p, q)| p * q).collect() };
    let (ma, mb) = (blur(a, w, h), blur(b, w, h));
    let (aa, bb, ab) = (blur(&prod(a, a), w, h), blur(&prod(b, b), w, h), blur(&prod(a, b), w, h));
    let mut sum = 0.0;
    for i in rows.start * w..rows.end * w {
        let (va, vb, cov) = (aa[i] - ma[i] * ma[i], bb[i] - mb[i] * mb[i], ab[i] - ma[i] * mb[i]);
        sum +=
            ((2.0 * ma[i] * mb[i] + c1) * (2.0 * cov + c2)) / ((ma[i] * ma[i] + mb[i] * mb[i] + c1) * (va + vb + c2));
    }
    sum
}

/// RMSE over the pixels where `keep(pixel index)` holds; `None` when no pixel is kept.
pub fn rmse_masked(img: &ImageF32, truth: &ImageF32, keep: impl Fn(usize) -> bool) -> Option<f64> {
    let (mut se, mut n) = (0.0f64, 0usize);
    for (i, (a, b)) in img.pixels.iter().zip(&truth.pixels).enumerate() {
        if keep(i) {
            for c in 0..4 {
                let d = clamp01(a[c]) - clamp01(b[c]);
                se += d * d;
            }
            n += 4;
        }
    }
    (n > 0).then(|| (se / n as f64).sqrt())
}

/// Aliasing energy of `img` against a properly filtered `reference` over the bounding box of the
/// pixels where `keep(pixel index)` holds: the luma power spectra of both (mean removed, Hann
/// window), and the power `img` has in excess of the reference summed over all frequencies,
/// relative to the reference's total. A blur only takes power away (a deficit, not counted);
/// content above the pixels' Nyquist frequency folded back (moire, jaggies, shimmer's frozen
/// frame) adds power the reference lacks. `None` when the box is under 4 pixels a side.
pub fn aliasing_energy(img: &ImageF32, reference: &ImageF32, keep: impl Fn(usize) -> bool) -> Option<f64> {
    let w = img.width as usize;
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for i in (0..img.pixels.len()).filter(|&i| keep(i)) {
        (x0, y0, x1, y1) = (x0.min(i % w), y0.min(i / w), x1.max(i % w), y1.max(i / w));
    }
    if x0 == usize::MAX || x1 - x0 < 3 || y1 - y0 < 3 {
        return None;
    }
    let (bw, bh) = (x1 - x0 + 1, y1 - y0 + 1);
    let hann = |i: usize, n: usize| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64).cos();
    let power = |im: &ImageF32| -> Vec<f64> {
        let luma: Vec<f64> = (0..bw * bh)
            .map(|k| {
                let p = im.pixels[(y0 + k / bw) * w + x0 + k % bw];
                0.2126 * clamp01(p[0]) + 0.7152 * clamp01(p[1]) + 0.0722 * clamp01(p[2])
            })
            .collect();
        let mean = luma.iter().sum::<f64>() / luma.len() as f64;
        let windowed: Vec<f64> =
            luma.iter().enumerate().map(|(k, v)| (v - mean) * hann(k % bw, bw) * hann(k / bw, bh)).collect();
        dft2_power(&windowed, bw, bh)
    };
    let (pi, pr) = (power(img), power(reference));
    let total: f64 = pr.iter().sum();
    let excess: f64 = pi.iter().zip(&pr).map(|(a, b)| (a - b).max(0.0)).sum();
    (total > 0.0).then(|| excess / total)
}

/// |DFT|^2 of a real w x h image (row-major), separably: O(w h (w + h)), enough for crops of a
/// few hundred pixels.
fn dft2_power(v: &[f64], w: usize, h: usize) -> Vec<f64> {
    let twiddles = |n: usize| -> Vec<(f64, f64)> {
        (0..n).map(|k| (2.0 * std::f64::consts::PI * k as f64 / n as f64).sin_cos()).map(|(s, c)| (c, -s)).collect()
    };
    let (tw, th) = (twiddles(w), twiddles(h));
    let mut rows = vec![(0.0f64, 0.0f64); w * h];
    for y in 0..h {
        for u in 0..w {
            let (mut re, mut im) = (0.0, 0.0);
            for x in 0..w {
                let (c, s) = tw[(u * x) % w];
                re += v[y * w + x] * c;
                im += v[y * w + x] * s;
            }
            rows[y * w + u] = (re, im);
        }
    }
    let mut out = vec![0.0f64; w * h];
    for u in 0..w {
        for k in 0..h {
            let (mut re, mut im) = (0.0, 0.0);
            for y in 0..h {
                let (c, s) = th[(k * y) % h];
                let (a, b) = rows[y * w + u];
                re += a * c - b * s;
                im += a * s + b * c;
            }
            out[k * w + u] = re * re + im * im;
        }
    }
    out
}

/// Shimmer of an animation: the mean over consecutive frames of their RMSE over the pixels where
/// `keep(frame, pixel)` holds in both frames (for anti-aliasing: the pixels beyond k). `None` when
/// no pair shares a kept pixel.
pub fn shimmer(frames: &[ImageF32], keep: impl Fn(usize, usize) -> bool) -> Option<f64> {
    let changes: Vec<f64> = (1..frames.len())
        .filter_map(|t| rmse_masked(&frames[t], &frames[t - 1], |i| keep(t, i) && keep(t - 1, i)))
        .collect();
    (!changes.is_empty()).then(|| changes.iter().sum::<f64>() / changes.len() as f64)
}

/// PSNR in dB of an RMSE (dynamic range 1).
pub fn psnr(rmse: f64) -> f64 {
    if rmse > 0.0 {
        20.0 * (1.0 / rmse).log10()
    } else {
        f64::INFINITY
    }
}

/// Frame-to-frame change of an animation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Temporal {
    /// Mean RMSE between consecutive frames.
    pub mean_change: f64,
    /// Largest RMSE between consecutive frames.
    pub max_change: f64,
    /// Largest consecutive change divided by the median one: 1 for a steady animation, large when
    /// one step jumps (a pop). Defined in docs/MODEL.md.
    pub popping: f64,
}

/// Temporal stability of an animation's frames (at least three): changes between frames and popping.
pub fn temporal(frames: &[ImageF32]) -> Result<Temporal> {
    if frames.len() < 3 {
        return Err(Error::InvalidArgument("temporal metrics need at least 3 frames".into()));
    }
    Ok(temporal_of(&frame_changes(frames)?))
}

/// RMSE between each frame and the next.
pub fn frame_changes(frames: &[ImageF32]) -> Result<Vec<f64>> {
    frames.windows(2).map(|w| compare(&w[1], &w[0]).map(|m| m.rmse)).collect()
}

/// `Temporal` from the frame-to-frame changes (at least one).
pub fn temporal_of(changes: &[f64]) -> Temporal {
    let mean_change = changes.iter().sum::<f64>() / changes.len().max(1) as f64;
    let max_change = changes.iter().cloned().fold(0.0, f64::max);
    let mut sorted = changes.to_vec();
    sorted.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let popping = if median > 0.0 {
        max_change / median
    } else if max_change > 0.0 {
        f64::INFINITY
    } else {
        1.0
    };
    Temporal { mean_change, max_change, popping }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covered_figures_leave_out_the_background_both_agree_on() {
        // A 10 x 10 frame, 4 covered pixels: one of them off by 0.1 in every channel.
        let (mut a, mut b) = (ImageF32::new(10, 10), ImageF32::new(10, 10));
        for i in 0..4 {
            (a.pixels[i], b.pixels[i]) = ([0.5; 4], [0.5; 4]);
        }
        a.pixels[0] = [0.6; 4];
        let m = compare(&a, &b).unwrap();
        assert_eq!(m.covered_pixels, 4);
        assert!((m.covered_rmse - (0.01f64 / 4.0).sqrt()).abs() < 1e-6, "{m:?}");
        assert!((m.rmse - (0.01f64 / 100.0).sqrt()).abs() < 1e-6, "{m:?}");
        // 10 log10(100 / 4) = 14 dB higher over the whole frame: the 96 empty pixels counted right.
        assert!((m.psnr - m.covered_psnr - 10.0 * 25f64.log10()).abs() < 1e-3, "{m:?}");
        // A pixel only one image covers counts; alpha at 1/255 or below in both does not.
        b.pixels[50] = [0.0, 0.0, 0.0, 2.0 / 255.0];
        a.pixels[60] = [0.0, 0.0, 0.0, 0.5 / 255.0];
        assert_eq!(compare(&a, &b).unwrap().covered_pixels, 5);
        // Nothing covered: no error, infinitely far from one.
        let empty = ImageF32::new(4, 4);
        let m = compare(&empty, &empty).unwrap();
        assert_eq!((m.covered_pixels, m.covered_rmse), (0, 0.0));
        assert!(m.covered_psnr.is_infinite());
    }
}
