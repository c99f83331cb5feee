#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = voxsplat::loaders::nrrd_from_bytes(data, None, "fuzz");
});
