//! Mirror of `glsl/brick_node_cut.comp` (the `brick_node_cut` stage); shared helpers in `brick_nodes.rs`.
use super::bindings::Bindings;
use super::brick::{inputs, BrickInputs};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::plan::node_grid;

/// Mirror of `brick_node_cut.comp`: per level-1 node, the tree level of the node that draws its
/// bricks this frame, as (index of its cut word in the summary buffer, level).
pub fn brick_node_cut(inputs: &BrickInputs<'_>) -> Vec<(usize, u32)> {
    let bf = &inputs.bf;
    let g = node_grid([bf.grid[0], bf.grid[1], bf.grid[2]], 1);
    let mut cut = Vec::with_capacity((g[0] * g[1] * g[2]) as usize);
    for i in 0..g[0] * g[1] * g[2] {
        let n = [i % g[0], (i / g[0]) % g[1], i / (g[0] * g[1])];
        let b = n.map(|c| c << 1);
        // A level-1 node whose bricks draw nothing: no node above it draws them either.
        let k = if inputs.node_of(1, b)[5] == u32::MAX {
            0
        } else {
            let (lo, hi) = inputs.voxel_box(b, 1);
            inputs.node_level(b, inputs.voxel_pixels(inputs.box_depths(lo, hi).0))
        };
        cut.push((inputs.cut_at(n), k));
    }
    cut
}

pub(crate) fn stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let cut = brick_node_cut(&inputs(b)?);
    let mut summary = b.take(Res::LodSummary);
    for (at, k) in cut {
        summary[at] = k;
    }
    b.put(Res::LodSummary, summary);
    Ok(())
}
