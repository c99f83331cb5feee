//! The validation layer's extra checks (issue 76): renders through each path under best
//! practices (the NVIDIA-specific ones included) and under GPU-assisted validation, which
//! instruments every shader. The settings are `tests/validation/*.txt`; docs/RELIABILITY.md says
//! why each muted message does not apply. The engine's whole suite was run once under each (the
//! table there); this is the small subset CI keeps.
use crate::cmd;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    cmd::tmp_in("layers", name)
}

/// The committed settings `name`, with the layer's own log written to `log` (its status message
/// names the checks it runs).
fn settings(name: &str, log: &Path) -> PathBuf {
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/validation").join(name);
    let text = std::fs::read_to_string(&committed).unwrap();
    let path = tmp(name);
    let logged = format!(
        "{text}\nkhronos_validation.debug_action = VK_DBG_LAYER_ACTION_LOG_MSG,VK_DBG_LAYER_ACTION_CALLBACK\n\
         khronos_validation.report_flags = error,warn,perf,info\nkhronos_validation.log_filename = {}\n",
        log.display()
    );
    std::fs::write(&path, logged).unwrap();
    path
}

/// `voxsplat render --validation ARGS` under the layer settings `path`: its exit and its output.
fn render(path: &Path, args: &[&str]) -> (bool, String) {
    let out = tmp("layers.png");
    // `voxsplat-lab render`: the user's render with the switches that pick a path (--raster).
    let o = Command::new(crate::cmd::lab_binary())
        .env("VK_LAYER_SETTINGS_PATH", path)
        .args(["render", "--validation", "--size", "48x48", "--out", out.to_str().unwrap()])
        .args(args)
        .output()
        .unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr))
}

/// Each raster and compositing path, a bricked store, a projection and terrain.
const PATHS: &[&[&str]] = &[
    &[],
    &["--raster", "graphics"],
    &["--raster", "points"],
    &["--scene", "bonsai"],
    &["--scene", "bonsai", "--mode", "mip"],
    &["--scene", "rmnp"],
];

#[test]
fn every_path_is_clean_under_best_practices_and_gpu_assisted_validation() {
    for (file, enables) in [
        ("best-practices.txt", "BEST_PRACTICES"),
        ("gpu-assisted.txt", "VK_VALIDATION_FEATURE_ENABLE_GPU_ASSISTED_EXT"),
    ] {
        let log = tmp(&format!("{file}.log"));
        let _ = std::fs::remove_file(&log);
        let path = settings(file, &log);
        for args in PATHS {
            let (ok, said) = render(&path, args);
            assert!(ok && !said.contains("validation:"), "{file}, render {args:?}: {said}");
        }
        // The layer ran the checks asked for: its status message names them.
        let logged = std::fs::read_to_string(&log).unwrap_or_default();
        let status = logged.lines().find(|l| l.contains("Current Enables")).unwrap_or_default().to_string();
        assert!(status.contains(enables), "{file}: the layer says {status:?}");
    }
    // Unmuted, best practices reports what the settings mute: the mute is what keeps them quiet.
    let log = tmp("unmuted.log");
    let unmuted = tmp("unmuted.txt");
    let text = std::fs::read_to_string(settings("best-practices.txt", &log)).unwrap();
    let text: String = text.lines().filter(|l| !l.contains("message_id_filter")).map(|l| format!("{l}\n")).collect();
    std::fs::write(&unmuted, text).unwrap();
    let (ok, said) = render(&unmuted, &[]);
    assert!(!ok && said.contains("BestPractices"), "{said}");
}
