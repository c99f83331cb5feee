//! Samples wider than f32 holds exactly (32-bit integers, float64), brought to the f32 the engine
//! draws from: each value rounds toward zero, so a u32's maximum stays within the type's range,
//! and a file whose values f32 cannot tell apart is refused rather than drawn as a constant.
use super::bad;
use crate::error::{Error, Result};

/// Steps of its span that a volume's values must keep in f32: finer than the 8-bit transfer
/// function and the 16-bit values most scanners write.
const STEPS_KEPT: f64 = 4096.0;

/// `values` as f32, each rounded toward zero. Refused when a value lies past f32's range, or when
/// the values' span is less than `STEPS_KEPT` f32 steps at their magnitude (an f64 volume of
/// 1e10 + a ball reads as the constant 1e10 otherwise); a constant volume is kept.
pub(crate) fn held(values: impl Iterator<Item = f64>, what: &str) -> Result<Vec<f32>> {
    let (lo, hi) = values.size_hint();
    let mut out = Vec::with_capacity(hi.unwrap_or(lo));
    let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        if v.is_finite() {
            (min, max) = (min.min(v), max.max(v));
        }
        out.push(toward_zero(v));
    }
    if !min.is_finite() {
        return Ok(out);
    }
    let biggest = min.abs().max(max.abs());
    if biggest > f32::MAX as f64 {
        return Err(Error::Unsupported(format!(
            "{what}: values {min} .. {max} lie past what f32 holds (±3.4e38); rescale them into that range"
        )));
    }
    // One f32 step at the values' magnitude.
    let step = (toward_zero(biggest) as f64 - next_down(toward_zero(biggest)) as f64).abs();
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

/// `v` in f32, rounded toward zero (past f32's range: its largest finite value of that sign).
fn toward_zero(v: f64) -> f32 {
    let f = v as f32;
    if f.is_infinite() && v.is_finite() {
        return f32::MAX.copysign(f);
    }
    if (f as f64).abs() > v.abs() {
        next_down_abs(f)
    } else {
        f
    }
}

/// The f32 next to `f` toward zero (`f` finite, nonzero).
fn next_down_abs(f: f32) -> f32 {
    f32::from_bits(f.to_bits() - 1)
}

/// The f32 below `f` in magnitude, or `f` itself at zero.
fn next_down(f: f32) -> f32 {
    if f == 0.0 {
        f
    } else {
        next_down_abs(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wide_integers_stay_within_their_type() {
        let v = held([u32::MAX as f64, 0.0].into_iter(), "t").unwrap();
        assert!((v[0] as f64) <= u32::MAX as f64 && v[0] as f64 > u32::MAX as f64 - 512.0, "{}", v[0]);
        let v = held([i32::MIN as f64, i32::MAX as f64].into_iter(), "t").unwrap();
        assert!(v[0] as f64 >= i32::MIN as f64 && v[1] as f64 <= i32::MAX as f64, "{v:?}");
    }

    #[test]
    fn values_f32_cannot_tell_apart_are_refused_and_a_constant_is_kept() {
        let e = held([1e10, 1e10 + 1.0, 1e10 + 0.5].into_iter(), "ball.nii").unwrap_err().to_string();
        assert!(e.contains("ball.nii") && e.contains("10000000000") && e.contains("Subtract"), "{e}");
        assert!(held([2e9, 2e9 + 100.0].into_iter(), "t").is_err());
        assert_eq!(held([1e10; 3].into_iter(), "t").unwrap(), vec![1e10f32; 3]);
        // A wide span at a large magnitude keeps its picture.
        assert!(held([0.0, 4e9, 2e9 + 1.0].into_iter(), "t").is_ok());
        let e = held([0.0, 1e300].into_iter(), "t").unwrap_err().to_string();
        assert!(e.contains("past what f32 holds"), "{e}");
        // Non-finite values pass through for the loaders' own finiteness check.
        assert!(held([f64::NAN, 1.0].into_iter(), "t").unwrap()[0].is_nan());
    }
}
