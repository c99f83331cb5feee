//! A DICOM --volume whose slice gaps are uneven: resampled onto even slices (the loaders' default,
//! said on stderr), or, when its gaps are too far apart for that, drawn as a rectilinear grid of
//! host splats at the slices' own positions.
use voxsplat::loaders::{even_slices, file_positions, left_out, slice_offsets, VolumeHints};
use voxsplat::Result;

/// The series whose offsets were found last (path, its modification time, --series, --time) and
/// its offsets: a scene asks up to four times while it opens, and each scan reads every file of the
/// folder. The time keeps a viewer that reopens a folder whose files changed from stale offsets.
type Key = (std::path::PathBuf, Option<std::time::SystemTime>, Option<String>, Option<u32>);
static LAST: std::sync::Mutex<Option<(Key, Option<Vec<f64>>)>> = std::sync::Mutex::new(None);

/// The slices' positions of `path` when it is an unevenly spaced DICOM series (`hints` as the
/// scene reads it), scanned once for the same series.
fn offsets(path: &std::path::Path, hints: &VolumeHints) -> Result<Option<Vec<f64>>> {
    let modified = std::fs::metadata(path).and_then(|m| m.modified()).ok();
    let key = (path.to_path_buf(), modified, hints.series.clone(), hints.time);
    let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, found)) = last.as_ref().filter(|(k, _)| *k == key) {
        return Ok(found.clone());
    }
    let found = slice_offsets(path, &VolumeHints { rectilinear: true, ..hints.clone() })?;
    *last = Some((key, found.clone()));
    Ok(found)
}

/// Whether `path` is a DICOM series drawn at its slices' own positions: its gaps are uneven and
/// too far apart to resample evenly (`loaders::even_slices`).
pub fn at_positions(path: &std::path::Path, hints: &VolumeHints) -> Result<bool> {
    Ok(offsets(path, hints)?.is_some_and(|o| even_slices(&o).is_none()))
}

/// `at_positions`, and a resampled series said on stderr.
pub fn report(path: &std::path::Path, hints: &VolumeHints) -> Result<bool> {
    let Some(o) = offsets(path, hints)? else { return Ok(false) };
    let Some(m) = even_slices(&o) else { return Ok(true) };
    eprintln!(
        "uneven slice gaps: resampled to {m} even slices {:.4} apart from {} images (each linear between the two \
         around it)",
        o.last().unwrap_or(&0.0) / (m - 1).max(1) as f64,
        o.len()
    );
    Ok(false)
}

/// The voxel positions of `path`, a series drawn at its slices' positions (`at_positions`), on
/// `grid` (`loaders::file_positions`), said on stderr.
pub fn positions(path: &std::path::Path, hints: &VolumeHints, grid: &voxsplat::Grid) -> Result<Option<[Vec<f32>; 3]>> {
    let coords = file_positions(path, &VolumeHints { rectilinear: true, ..hints.clone() }, grid)?;
    eprintln!(
        "uneven slice gaps, too far apart to resample evenly: drawn as a rectilinear grid at the slices' positions \
         (host splats)"
    );
    Ok(coords)
}

/// Says on stderr what reading `path`, a DICOM series, left out (a localizer, a slice far from the
/// rest); nothing for any other file.
pub fn say_left_out(path: &std::path::Path, hints: &VolumeHints) -> Result<()> {
    for line in left_out(path, hints)? {
        eprintln!("note: {line}");
    }
    Ok(())
}
