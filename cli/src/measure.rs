//! What the commands of both binaries measure of themselves: medians of timings, peak memory.

/// The median of `v` (sorted in place; NaN when empty): what the commands quote of repeated
/// timings.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

/// This process's peak resident set in MiB (Linux's VmHWM), if the system says.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// The commit these binaries were built from, as reports name it ("unknown" outside a git
/// checkout; cli/build.rs).
pub const COMMIT: &str = env!("VOXSPLAT_COMMIT");
