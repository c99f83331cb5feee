//! Running the built binary from the CLI's integration tests.
#![allow(dead_code)]
use std::process::{Command, Output};

/// `voxsplat ARGS`, waited for.
pub fn voxsplat(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_voxsplat")).args(args).output().expect("run voxsplat")
}

/// A path in this test process's own temporary directory (`tag` names the test file).
pub fn tmp_in(tag: &str, name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("voxsplat-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// `voxsplat ARGS`, which must fail with a typed error (no panic); its stderr.
pub fn refused(args: &[&str]) -> String {
    let out = voxsplat(args);
    let text = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success() && text.starts_with("error:"), "voxsplat {args:?} should fail: {text}");
    assert!(!text.contains("panicked"), "{text}");
    text
}
