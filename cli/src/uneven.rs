//! A DICOM --volume whose slice gaps are uneven: resampled onto even slices (the loaders' default,
//! said on stderr), or, when its gaps are too far apart for that, drawn as a rectilinear grid of
//! host splats at the slices' own positions.
use voxsplat::loaders::{even_slices, file_positions, slice_offsets, VolumeHints};
use voxsplat::Result;

/// The slices' positions of `path` when it is an unevenly spaced DICOM series (`hints` as the
/// scene reads it).
fn offsets(path: &std::path::Path, hints: &VolumeHints) -> Result<Option<Vec<f64>>> {
    slice_offsets(path, &VolumeHints { rectilinear: true, ..hints.clone() })
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
