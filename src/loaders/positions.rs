//! Voxel positions of a rectilinear grid: a TOML sidecar whose `x`, `y`, `z`
//! arrays give the world coordinate of every voxel along that axis (e.g. a CT series' slice
//! positions, which a header's one spacing cannot hold). An axis left out keeps the grid's even
//! spacing.
use super::bad;
use super::bounded::read_bounded;
use crate::error::Result;
use crate::volume::Grid;
use std::path::Path;

/// Largest positions file read (a coordinate takes a dozen bytes of text; 65,536 voxels per axis).
pub const MAX_POSITIONS_BYTES: u64 = 8 << 20;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PositionsFile {
    x: Option<Vec<f64>>,
    y: Option<Vec<f64>>,
    z: Option<Vec<f64>>,
}

/// The per-axis coordinates `path` gives for `grid` (for `SplatSet::with_coordinates`, which
/// checks that they increase): one per voxel along each axis named, the grid's own elsewhere.
pub fn load_positions(path: &Path, grid: &Grid) -> Result<[Vec<f32>; 3]> {
    let what = path.display().to_string();
    let bytes = read_bounded(path, MAX_POSITIONS_BYTES, &what)?;
    let text = std::str::from_utf8(&bytes).map_err(|_| bad(&what, "positions: not UTF-8 text"))?;
    positions_from_text(text, grid, &what)
}

/// `load_positions` of a positions file's text (`what` names it in errors).
pub fn positions_from_text(text: &str, grid: &Grid, what: &str) -> Result<[Vec<f32>; 3]> {
    let what = what.to_string();
    let file: PositionsFile = toml::from_str(text).map_err(|e| bad(&what, format!("positions: {}", e.message())))?;
    let mut out: [Vec<f32>; 3] = Default::default();
    for (a, given) in [file.x, file.y, file.z].into_iter().enumerate() {
        let axis = ["x", "y", "z"][a];
        let n = grid.dims[a] as usize;
        out[a] = match given {
            Some(v) if v.len() != n => {
                return Err(bad(&what, format!("positions: {} {axis} values for {n} voxels along {axis}", v.len())))
            }
            Some(v) => {
                if let Some(i) = v.iter().position(|c| !c.is_finite() || c.abs() > crate::camera::MAX_WORLD as f64) {
                    return Err(bad(&what, format!("positions: {axis}[{i}] = {} is not a finite coordinate", v[i])));
                }
                v.into_iter().map(|c| c as f32).collect()
            }
            None => (0..n as u32).map(|i| grid.origin[a] + i as f32 * grid.spacing[a]).collect(),
        };
    }
    Ok(out)
}
