#![no_main]
// The first byte picks the sample type; the rest is the payload of a 4x3x2 grid.
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    use voxsplat::loaders::{raw_from_bytes, DType};
    if let Some((&t, rest)) = data.split_first() {
        let dtype = [DType::U8, DType::U16, DType::I16, DType::F32][t as usize % 4];
        let _ = raw_from_bytes(rest, [4, 3, 2], dtype, t & 4 != 0, [1.0; 3], "fuzz");
    }
});
