#![no_main]
// Animation files, transfer functions and raw sidecars share this target.
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = voxsplat::animate::Animation::from_toml(text);
        let _ = voxsplat::classify::TransferFunction::from_toml(text);
        let _ = voxsplat::loaders::sidecar_hints(text, "fuzz");
    }
});
