#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = voxsplat::loaders::tiff_heights(data, "fuzz");
});
