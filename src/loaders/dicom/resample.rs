//! An unevenly spaced series resampled onto even slices, so that it streams into the bricked store
//! (a uniform grid): slices at the smallest gap, each linear between the two images around it.

/// At most this many even slices per image of the series: a series with one far gap (a scout
/// slice 200 mm off) would swell, and is drawn at its own positions instead.
pub const MAX_GROWTH: usize = 4;

/// How many evenly spaced slices, at most the smallest gap apart, span `offsets` (the images'
/// ascending positions along the normal, from the first); `None` when that exceeds `MAX_GROWTH`
/// slices per image.
pub fn even_slices(offsets: &[f64]) -> Option<u32> {
    let n = offsets.len();
    let extent = offsets.last().copied().unwrap_or(0.0);
    let least = offsets.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
    if n < 2 || least.is_nan() || least <= 0.0 {
        return None;
    }
    // The smallest gap keeps the finest sampling; a hair's tolerance keeps an even series even.
    let m = (extent / least - 1e-6).ceil() as usize + 1;
    (m <= MAX_GROWTH * n).then_some(m as u32)
}

/// For each of `m` even slices over `offsets`, the image below it and the weight of the one above
/// (0 on an image's own position).
pub fn weights(offsets: &[f64], m: u32) -> Vec<(u32, f32)> {
    let extent = offsets.last().copied().unwrap_or(0.0);
    let mut k = 0;
    (0..m)
        .map(|j| {
            let p = extent * j as f64 / (m - 1).max(1) as f64;
            while k + 2 < offsets.len() && offsets[k + 1] <= p {
                k += 1;
            }
            let t = ((p - offsets[k]) / (offsets[k + 1] - offsets[k])).clamp(0.0, 1.0);
            (k as u32, t as f32)
        })
        .collect()
}

/// How a series' slices are spaced.
pub(super) enum Gaps {
    /// Evenly: the orientation's step places them.
    Even,
    /// Unevenly, read as the images lie: their positions along the normal, from the first (mm).
    At(Vec<f64>),
    /// Unevenly, resampled evenly: per slice, the image below it and the weight of the one above
    /// (`weights`).
    Resampled(Vec<(u32, f32)>),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn even_slices_span_the_series_at_its_smallest_gap() {
        assert_eq!(even_slices(&[0.0, 2.0, 4.0, 6.0]), Some(4));
        assert_eq!(even_slices(&[0.0, 2.0, 3.0, 6.0]), Some(7));
        // A scout slice far off: 166 slices for 4 images.
        assert_eq!(even_slices(&[0.0, 202.5, 203.75, 205.0]), None);
        let w = weights(&[0.0, 2.0, 3.0, 6.0], 7);
        let want = [(0, 0.0), (0, 0.5), (1, 0.0), (2, 0.0), (2, 1.0 / 3.0), (2, 2.0 / 3.0), (2, 1.0)];
        for (a, b) in w.iter().zip(want) {
            assert!(a.0 == b.0 && (a.1 - b.1).abs() < 1e-6, "{w:?}");
        }
    }
}
