#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = voxsplat::loaders::nifti_from_bytes(data, "fuzz");
});
