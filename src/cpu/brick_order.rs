//! Mirror of `glsl/brick_order.comp` (the `brick_order` stage); shared helpers in `brick.rs`.
use super::bindings::Bindings;
use super::brick::*;
use crate::bricks::{local_cell, BrickStore, BRICK};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::BrickPush;

/// Pass 2: the batch's voxels (grid index, stored value) in two-level PBTF order from each
/// brick's first position; each brick's records from its entry's first record in `records` (the
/// store's, or the batch's when the store streams).
pub fn brick_order(
    inputs: &BrickInputs<'_>,
    list: &[[u32; 4]],
    records: &[u32],
    push: &BrickPush,
    voxels: &mut [[u32; 2]],
    order: &mut [u32],
) {
    let (store, frame) = (inputs.store, inputs.frame);
    for entry in &list[push.first as usize..(push.first + push.count) as usize] {
        let hd = store.headers[entry[0] as usize];
        let b = hd.coords();
        // Coarse bricks are brick_cells'.
        if entry[3] >> 16 != 0 {
            continue;
        }
        let morphs = inputs.morph_bit(entry[0]);
        let split = [0, 1, 2].map(|a| (frame.split[a] as i64 - (b[a] * BRICK) as i64).clamp(0, BRICK as i64) as u32);
        let records = &*BrickStore::records_of(records, entry[2], &hd);
        let mut cells = [0u32; CELL_WORDS];
        let position = |rec: u32| dense_pbtf(local_cell(rec & 511), [BRICK; 3], split);
        for &rec in records {
            if inputs.emits(rec >> 16) {
                let p = position(rec);
                cells[p as usize / 32] |= 1 << (p % 32);
            }
        }
        let mut below = [0u32; CELL_WORDS + 1];
        for w in 0..CELL_WORDS {
            below[w + 1] = below[w] + cells[w].count_ones();
        }
        let total = below[CELL_WORDS];
        for &rec in records.iter().filter(|&&rec| inputs.emits(rec >> 16)) {
            let p = position(rec);
            let rank = below[p as usize / 32] + (cells[p as usize / 32] & ((1u32 << (p % 32)) - 1)).count_ones();
            let rank = if frame.split[3] != 0 { total - 1 - rank } else { rank };
            let pos = (entry[1] + rank) as usize;
            let lc = local_cell(rec & 511);
            let ijk = [0, 1, 2].map(|a| b[a] * BRICK + lc[a]);
            voxels[pos] = [ijk[0] | ijk[1] << 16, ijk[2] | morphs | (rec & 0xffff_0000)];
            order[pos] = pos as u32;
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let (mut voxels, mut order) = (b.take(Res::BrickVoxels), b.take(Res::Order));
    let inputs = inputs(b)?;
    let records = if streamed(v) { b.get(Res::BatchRecords) } else { &inputs.store.records[..] };
    brick_order(
        &inputs,
        b.get(Res::BrickList),
        records,
        &args.push_as(),
        bytemuck::cast_slice_mut(&mut voxels),
        &mut order,
    );
    b.put(Res::BrickVoxels, voxels);
    b.put(Res::Order, order);
    Ok(())
}
