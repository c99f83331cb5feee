#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = voxsplat::loaders::npy_from_bytes(data, "fuzz");
});
