#![no_main]
include!("../cli_bodies.rs");
libfuzzer_sys::fuzz_target!(|data: &[u8]| report(data));
