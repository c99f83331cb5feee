//! Mirrors of `glsl/shared/brick.glsl`'s word codecs that the brick stages (brick.rs) and the
//! pyramid (lod.rs) both read: a summary's level counts and a cell's 16-bit optical depth.
use crate::plan::SUMMARY_WORDS;

/// Mirror of `tau_code`: a cell's optical depth in 16 bits (exponent 2^-23..2^7, 11 bits of
/// mantissa, rounded; 0 for none).
pub fn tau_code(t: f32) -> u32 {
    // NaN too.
    if t.partial_cmp(&1.192_092_9e-7).is_none_or(|o| o == std::cmp::Ordering::Less) {
        return 0;
    }
    let b = t.min(255.0).to_bits();
    ((b + 0x800) >> 12) - (103 << 11)
}

/// Mirror of `tau_decode`.
pub fn tau_decode(code: u32) -> f32 {
    if code == 0 {
        0.0
    } else {
        f32::from_bits((code + (103 << 11)) << 12)
    }
}

/// Mirror of `level_count`.
pub fn level_count(summary: &[u32], h: u32, l: u32) -> u32 {
    let x = summary[h as usize * SUMMARY_WORDS];
    match l {
        0 => x >> 16,
        1 => x & 255,
        2 => x >> 8 & 15,
        _ => x >> 12 & 1,
    }
}
