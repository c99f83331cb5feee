//! A plane of a store's voxels through the grid: what a viewer's axial, coronal and sagittal panes
//! show of the data beside the frame, and what `voxsplat slice` writes.
use super::BrickStore;
use crate::error::{Error, Result};

/// The values of one plane of voxels, row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    /// Voxels along a row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The file's values (as the store holds them: quantised to 1/65,535 of its range; an empty
    /// voxel reads as the range's start, the value it had), `width` per row.
    pub values: Vec<f32>,
}

impl BrickStore {
    /// The plane of voxels whose index along `axis` (0: x, 1: y, 2: z) is `index`. Its rows run
    /// along the lower of the other two axes, one row per index of the higher, row 0 first: the
    /// plane k = 5 is `width` = x by `height` = y, as `volume[5]` of a z, y, x array.
    pub fn plane(&self, axis: usize, index: u32) -> Result<Plane> {
        if axis > 2 || index >= self.dims[axis] {
            return Err(Error::InvalidArgument(format!(
                "no plane {index} along axis {axis} of a {:?} grid (axes 0 to 2, indices from 0)",
                self.dims
            )));
        }
        let [u, v] = match axis {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        let (width, height) = (self.dims[u], self.dims[v]);
        let (lo, hi) = self.range;
        let span = hi as f64 - lo as f64;
        let mut values = Vec::with_capacity(width as usize * height as usize);
        for row in 0..height {
            for col in 0..width {
                let mut at = [0i64; 3];
                (at[axis], at[u], at[v]) = (index as i64, col as i64, row as i64);
                let n = self.value_at(at[0], at[1], at[2]) as f64;
                values.push((lo as f64 + n * span) as f32);
            }
        }
        Ok(Plane { width, height, values })
    }
}
