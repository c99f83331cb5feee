// The bodies of the fuzz targets that read the command-line tool's own files (issue 76): a bench
// report (`bench --compare`) and a viewer session (`view --session`). Shared by
// fuzz/fuzz_targets/{report,session}.rs and cli/tests/fuzz_corpus.rs, which replays the seeds and
// corpus on every CI run.

/// `data` written to a file of this process named `name`, for readers that take a path.
pub fn cli_file(name: &str, data: &[u8]) -> Option<std::path::PathBuf> {
    let path = std::env::temp_dir().join(format!("voxsplat-fuzz-{name}-{}", std::process::id()));
    std::fs::write(&path, data).ok()?;
    Some(path)
}

/// A bench report's JSON: read and checked, then compared with itself (its ratios print).
pub fn report(data: &[u8]) {
    use voxsplat_cli::suite::{compare, Report};
    if let Some(path) = cli_file("report.json", data) {
        if let Ok(r) = Report::read_json(&path) {
            let _ = compare(&r, &r);
        }
        let _ = std::fs::remove_file(&path);
    }
}

/// A viewer session's TOML: read and checked, then its camera, clip planes and light made.
pub fn session(data: &[u8]) {
    use voxsplat_cli::session::Session;
    if let Some(path) = cli_file("session.toml", data) {
        if let Ok(s) = Session::load(&path) {
            let _ = s.camera(64, 48);
            let _ = s.clip();
            let _ = Session::light_of(s.shading());
        }
        let _ = std::fs::remove_file(&path);
    }
}
