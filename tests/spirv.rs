//! The SPIR-V shipped in `glsl/spirv/` (what a dependent crate builds with, no shaderc needed) is a
//! fresh compile of `glsl/`, byte for byte. Runs with the `shaderc` feature, which the core's tests
//! turn on (its dev-dependency on itself, so `cargo test` at the top level runs it);
//! `VOXSPLAT_BLESS_SPIRV=1` rewrites the shipped copies after a shader changes.
#![cfg(feature = "shaderc")]
use std::collections::BTreeMap;
use std::path::Path;

#[test]
fn shipped_spirv_equals_a_fresh_compile() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl/spirv");
    let fresh: BTreeMap<&str, &[u8]> = crate::shaders::spirv_builds().iter().copied().collect();
    assert!(fresh.len() > 20, "every stage and variant is built ({})", fresh.len());
    if std::env::var_os("VOXSPLAT_BLESS_SPIRV").is_some() {
        std::fs::create_dir_all(&dir).unwrap();
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "spv") {
                std::fs::remove_file(p).unwrap();
            }
        }
        for (name, bytes) in &fresh {
            std::fs::write(dir.join(format!("{name}.spv")), bytes).unwrap();
        }
        eprintln!("wrote {} builds to {}", fresh.len(), dir.display());
        return;
    }
    let mut shipped = BTreeMap::new();
    for e in std::fs::read_dir(&dir).expect("glsl/spirv exists") {
        let p = e.unwrap().path();
        if let Some(name) = p.file_name().unwrap().to_str().unwrap().strip_suffix(".spv") {
            shipped.insert(name.to_string(), std::fs::read(&p).unwrap());
        }
    }
    let stale: Vec<_> = shipped.keys().filter(|n| !fresh.contains_key(n.as_str())).collect();
    let missing: Vec<_> = fresh.keys().filter(|n| !shipped.contains_key(**n)).collect();
    let differ: Vec<_> =
        fresh.iter().filter(|(n, b)| shipped.get(**n).is_some_and(|s| s != *b)).map(|(n, _)| n).collect();
    assert!(
        stale.is_empty() && missing.is_empty() && differ.is_empty(),
        "glsl/spirv/ is out of date (stale {stale:?}, missing {missing:?}, different {differ:?}): run \
         VOXSPLAT_BLESS_SPIRV=1 cargo test --release -p voxsplat --lib tests::spirv"
    );
}
