//! Mirror of `iso_cells.comp`: each row's crossed cells listed at its first position.
use super::bindings::Bindings;
use super::iso_count::IsoInputs;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use rayon::prelude::*;

/// Every row's crossed cells (i + 1 | (j + 1) << 16, k + 1 | inside bits << 16) from its first
/// position (`counts`, scanned).
pub fn iso_cells(inputs: &IsoInputs<'_>, counts: &[u32], cells: &mut [[u32; 2]]) {
    let rows = inputs.push.rows as usize;
    // Rows own disjoint runs of the list: split it at the rows' first positions.
    let mut runs = Vec::with_capacity(rows);
    let mut rest = cells;
    for r in 0..rows {
        let (run, more) = rest.split_at_mut((counts[r + 1] - counts[r]) as usize);
        rest = more;
        if !run.is_empty() {
            runs.push((r as u32, run));
        }
    }
    runs.into_par_iter().for_each(|(r, run)| {
        let (j, k) = inputs.cell_row(r);
        let mut at = 0;
        inputs.crossed(r, |i, _, _, m| {
            run[at] = [(i + 1) as u32 | ((j + 1) as u32) << 16, (k + 1) as u32 | m << 16];
            at += 1;
        });
    });
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let counts = b.take(Res::IsoCounts);
    let mut words = b.take(Res::IsoCells);
    {
        let inputs =
            IsoInputs { field: b.get(Res::IsoField), rows: b.get(Res::IsoRows), frame: &b.frame, push: d.push_as() };
        let n = counts[inputs.push.rows as usize] as usize;
        iso_cells(&inputs, &counts, bytemuck::cast_slice_mut(&mut words[..2 * n]));
    }
    b.put(Res::IsoCounts, counts);
    b.put(Res::IsoCells, words);
    Ok(())
}
