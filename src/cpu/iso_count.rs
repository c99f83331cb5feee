//! Mirror of `iso_count.comp` and of `glsl/shared/iso.glsl`: per row of cells, the cells the iso
//! value crosses.
use super::bindings::Bindings;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{Frame, IsoPush};
use crate::iso::ISO_SEGMENT;
use rayon::prelude::*;

/// What the isosurface stages read: the field's words and row ranges, the frame, the push.
pub struct IsoInputs<'a> {
    /// `Res::IsoField`.
    pub field: &'a [u32],
    /// `Res::IsoRows`.
    pub rows: &'a [u32],
    /// The frame's grid.
    pub frame: &'a Frame,
    /// The push constants.
    pub push: IsoPush,
}

impl IsoInputs<'_> {
    /// Mirror of `iso_value`: the quantised value at voxel (x, y, z), 0 outside the grid.
    pub fn value(&self, x: i32, y: i32, z: i32) -> u32 {
        let [nx, ny, nz, _] = self.frame.dims;
        if x < 0 || y < 0 || z < 0 || x >= nx as i32 || y >= ny as i32 || z >= nz as i32 {
            return 0;
        }
        let i = x as usize + nx as usize * (y as usize + ny as usize * z as usize);
        (self.field[i >> 1] >> (16 * (i & 1))) & 0xffff
    }

    /// Mirror of `cell_row`.
    pub fn cell_row(&self, r: u32) -> (i32, i32) {
        let ny1 = self.frame.dims[1] + 1;
        ((r % ny1) as i32 - 1, (r / ny1) as i32 - 1)
    }

    /// Mirror of `segment_max`.
    pub fn segment_max(&self, j: i32, k: i32, s: i32) -> u32 {
        let [nx, ny, nz, _] = self.frame.dims;
        let segments = nx.div_ceil(ISO_SEGMENT);
        if j < 0 || k < 0 || s < 0 || j >= ny as i32 || k >= nz as i32 || s >= segments as i32 {
            return 0;
        }
        self.rows[((j as u32 + ny * k as u32) * segments + s as u32) as usize]
    }

    /// Mirror of `block_crosses`.
    pub fn block_crosses(&self, (j, k): (i32, i32), b: i32) -> bool {
        let hi = (0..4)
            .map(|c| {
                let (y, z) = (j + (c & 1), k + (c >> 1));
                self.segment_max(y, z, b - 1).max(self.segment_max(y, z, b))
            })
            .max()
            .unwrap_or(0);
        self.push.threshold > 0 && hi >= self.push.threshold
    }

    /// Mirror of `iso_face`.
    pub fn face(&self, i: i32, (j, k): (i32, i32)) -> [u32; 4] {
        [self.value(i, j, k), self.value(i, j + 1, k), self.value(i, j, k + 1), self.value(i, j + 1, k + 1)]
    }

    /// Mirror of `inside_bits`.
    pub fn inside_bits(&self, f0: [u32; 4], f1: [u32; 4]) -> u32 {
        let mut m = 0;
        for c in 0..4 {
            let (dy, dz) = (c & 1, c >> 1);
            if f0[c] >= self.push.threshold {
                m |= 1 << (2 * dy + 4 * dz);
            }
            if f1[c] >= self.push.threshold {
                m |= 1 << (1 + 2 * dy + 4 * dz);
            }
        }
        m
    }

    /// Walk row `r`'s cells (mirror of the walks of `iso_count` and `iso_cells`), calling
    /// `f(i, faces, bits)` for each crossed one.
    pub fn crossed(&self, r: u32, mut f: impl FnMut(i32, [u32; 4], [u32; 4], u32)) {
        let jk = self.cell_row(r);
        let (mut f0, cells, seg) = ([0u32; 4], self.frame.dims[0] as i32 + 1, ISO_SEGMENT as i32);
        for b in 0..(cells + seg - 1) / seg {
            if !self.block_crosses(jk, b) {
                f0 = [0; 4];
                continue;
            }
            for c in b * seg..cells.min((b + 1) * seg) {
                let f1 = self.face(c, jk);
                let m = self.inside_bits(f0, f1);
                if m != 0 && m != 255 {
                    f(c - 1, f0, f1, m);
                }
                f0 = f1;
            }
        }
    }
}

/// Per row of cells, its crossed cells.
pub fn iso_count(inputs: &IsoInputs<'_>, counts: &mut [u32]) {
    let rows = inputs.push.rows as usize;
    counts[..rows].par_iter_mut().enumerate().for_each(|(r, c)| {
        let mut n = 0;
        inputs.crossed(r as u32, |_, _, _, _| n += 1);
        *c = n;
    });
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut counts = b.take(Res::IsoCounts);
    let inputs =
        IsoInputs { field: b.get(Res::IsoField), rows: b.get(Res::IsoRows), frame: &b.frame, push: d.push_as() };
    iso_count(&inputs, &mut counts);
    b.put(Res::IsoCounts, counts);
    Ok(())
}
