//! Samples wider than f32 holds exactly (32-bit integers, float64), brought to the f32 the engine
//! draws from: each value rounds to the nearest f32, except that an integer type's ends stay within
//! its range (u32's maximum rounds down, not up to 2^32), and a file whose values f32 cannot tell
//! apart is refused rather than drawn as a constant.
use super::bad;
use crate::error::Result;

/// Steps of its span that a volume's values must keep in f32: finer than the 8-bit transfer
/// function and the 16-bit values most scanners write.
const STEPS_KEPT: f64 = 4096.0;

/// u32's range, for `held`.
pub(crate) const U32: Option<[f64; 2]> = Some([0.0, u32::MAX as f64]);
/// i32's range, for `held`.
pub(crate) const I32: Option<[f64; 2]> = Some([i32::MIN as f64, i32::MAX as f64]);

/// `values` as f32, each the nearest, or the nearest within `range` (an integer type's least and
/// greatest values). Refused when the values' span is less than `STEPS_KEPT` f32 steps at their
/// magnitude (an f64 volume of 1e10 + a ball reads as the constant 1e10 otherwise); a constant
/// volume is kept. A value past f32's range reads as infinity, which the loaders refuse naming
/// the sample.
pub(crate) fn held(values: impl Iterator<Item = f64>, range: Option<[f64; 2]>, what: &str) -> Result<Vec<f32>> {
    let (lo, hi) = values.size_hint();
    let mut out = Vec::with_capacity(hi.unwrap_or(lo));
    let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        if v.is_finite() {
            (min, max) = (min.min(v), max.max(v));
        }
        let mut f = v as f32;
        if range.is_some_and(|[lo, hi]| (f as f64) < lo || (f as f64) > hi) {
            f = toward_zero(f);
        }
        out.push(f);
    }
    let biggest = min.abs().max(max.abs());
    if !min.is_finite() || biggest > f32::MAX as f64 {
        return Ok(out);
    }
    // One f32 step at the values' magnitude.
    let top = biggest as f32;
    let step = (top - toward_zero(top)) as f64;
    let span = max - min;
    if span > 0.0 && span < step * STEPS_KEPT {
        return Err(bad(
            what,
            format!(
                "values {min} .. {max} differ by {span:e}, which f32 (the engine's sample type) holds in steps of \
                 {step:e} at that magnitude: fewer than {STEPS_KEPT} steps, and the volume would draw flat. Subtract \
                 their offset (for example {min}) before saving, or save them as float32 relative to it"
            ),
        ));
    }
    Ok(out)
}

/// The f32 next to `f` toward zero (`f` itself at zero).
fn toward_zero(f: f32) -> f32 {
    if f == 0.0 {
        f
    } else {
        f32::from_bits(f.to_bits() - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wide_integers_stay_within_their_type_and_others_round_to_the_nearest() {
        let u32s = U32;
        let v = held([u32::MAX as f64, 0.0].into_iter(), u32s, "t").unwrap();
        assert!((v[0] as f64) <= u32::MAX as f64 && v[0] as f64 > u32::MAX as f64 - 512.0, "{}", v[0]);
        let i32s = I32;
        let v = held([i32::MIN as f64, i32::MAX as f64].into_iter(), i32s, "t").unwrap();
        assert!(v[0] as f64 >= i32::MIN as f64 && v[1] as f64 <= i32::MAX as f64, "{v:?}");
        // Within the range, and for f64, the nearest f32, as numpy's astype(float32) gives.
        let (a, b) = (33554435.0, 0.1f64 * 3.0);
        assert_eq!(held([a, 0.0].into_iter(), i32s, "t").unwrap()[0], a as f32);
        assert_eq!(held([b, 0.0].into_iter(), None, "t").unwrap()[0], b as f32);
    }

    #[test]
    fn values_f32_cannot_tell_apart_are_refused_and_a_constant_is_kept() {
        let e = held([1e10, 1e10 + 1.0, 1e10 + 0.5].into_iter(), None, "ball.nii").unwrap_err().to_string();
        assert!(e.contains("ball.nii") && e.contains("10000000000") && e.contains("Subtract"), "{e}");
        assert!(held([2e9, 2e9 + 100.0].into_iter(), I32, "t").is_err());
        assert_eq!(held([1e10; 3].into_iter(), None, "t").unwrap(), vec![1e10f32; 3]);
        // A wide span at a large magnitude keeps its picture.
        assert!(held([0.0, 4e9, 2e9 + 1.0].into_iter(), None, "t").is_ok());
        // Past f32's range: infinity, for the loaders' finiteness check to refuse by sample.
        assert!(held([0.0, 1e300].into_iter(), None, "t").unwrap()[1].is_infinite());
        assert!(held([f64::NAN, 1.0].into_iter(), None, "t").unwrap()[0].is_nan());
    }
}
