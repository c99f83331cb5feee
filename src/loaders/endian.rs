//! Integers in a file's byte order.

/// The unsigned integer in the first `N` (2, 4 or 8) bytes of `b`, big- or little-endian.
pub(crate) fn word<const N: usize>(b: &[u8], big_endian: bool) -> u64 {
    let mut a = [0u8; 8];
    if big_endian {
        a[8 - N..].copy_from_slice(&b[..N]);
        u64::from_be_bytes(a)
    } else {
        a[..N].copy_from_slice(&b[..N]);
        u64::from_le_bytes(a)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn words_read_in_either_byte_order() {
        let b = [1u8, 2, 3, 4, 5, 6, 7, 8];
        assert_eq!(super::word::<2>(&b, true), 0x0102);
        assert_eq!(super::word::<2>(&b, false), 0x0201);
        assert_eq!(super::word::<4>(&b, true), 0x0102_0304);
        assert_eq!(super::word::<4>(&b, false), 0x0403_0201);
        assert_eq!(super::word::<8>(&b, true), 0x0102_0304_0506_0708);
        assert_eq!(super::word::<8>(&b, false), 0x0807_0605_0403_0201);
    }
}
