//! Mirror of `glsl/brick_cells.comp` (the `brick_cells` stage); shared helpers in `lod.rs`.
use super::bindings::Bindings;
use super::brick::{inputs_for, BrickInputs};
use super::lod::*;
use super::order::side_count;
use crate::bricks::BRICK;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::BrickPush;
use crate::plan::LOD_LEVELS;

/// Mirror of `brick_cells.comp`: each coarse brick of the batch writes its level's drawn cells in
/// PBTF order over the brick's cells.
pub fn brick_cells(
    inputs: &BrickInputs<'_>,
    list: &[[u32; 4]],
    push: &BrickPush,
    voxels: &mut [[u32; 2]],
    order: &mut [u32],
) {
    for entry in &list[push.first as usize..(push.first + push.count) as usize] {
        let level = entry[3] >> 16;
        if level == 0 {
            continue;
        }
        let b = inputs.store.headers[entry[0] as usize].coords();
        if level > LOD_LEVELS {
            // Mirror of the node branch.
            let k = level - LOD_LEVELS;
            let ijk = b.map(|c| (c >> k << k) * BRICK);
            voxels[entry[1] as usize] = [ijk[0] | k << 13 | ijk[1] << 16, ijk[2] | LOD_LEVELS << 13];
            order[entry[1] as usize] = entry[1];
            continue;
        }
        let n = BRICK >> level;
        let off = level_offset(level);
        let split = level_split(inputs.frame.split, b, level);
        let morphs = inputs.morph_bit(entry[0]);
        let total = entry[3] & 0xffff;
        let mut rank = 0;
        let axis = |side: u32, s: u32, t: u32| if side == 0 { s - 1 - t } else { s + t };
        for o in 0..8u32 {
            let side = [o & 1, o >> 1 & 1, o >> 2 & 1];
            let len = [0, 1, 2].map(|a| side_count(n, split[a], side[a]));
            for tk in 0..len[2] {
                for tj in 0..len[1] {
                    for ti in 0..len[0] {
                        let cc =
                            [axis(side[0], split[0], ti), axis(side[1], split[1], tj), axis(side[2], split[2], tk)];
                        let c = cc[0] + n * (cc[1] + n * cc[2]);
                        if inputs.cell_tau(entry[0], off + c).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                            continue;
                        }
                        let pos = entry[1] + if inputs.frame.split[3] != 0 { total - 1 - rank } else { rank };
                        let ijk = [0, 1, 2].map(|a| b[a] * BRICK + (cc[a] << level));
                        voxels[pos as usize] = [ijk[0] | ijk[1] << 16, ijk[2] | level << 13 | morphs | (off + c) << 16];
                        order[pos as usize] = pos;
                        rank += 1;
                    }
                }
            }
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let (mut voxels, mut order) = (b.take(Res::BrickVoxels), b.take(Res::Order));
    brick_cells(
        &inputs_for(b, v)?,
        b.get(Res::BrickList),
        &args.push_as(),
        bytemuck::cast_slice_mut(&mut voxels),
        &mut order,
    );
    b.put(Res::BrickVoxels, voxels);
    b.put(Res::Order, order);
    Ok(())
}
