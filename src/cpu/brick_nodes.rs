//! Levels of detail above the brick: mirror of `brick_nodes.comp`, and of the node helpers of
//! `glsl/shared/brick.glsl` (`node_word`, `node_color`, `node_level`) that `brick_node_cut.rs`
//! reads too.
use super::bindings::Bindings;
use super::brick::{inputs, BrickInputs};
use super::lod::{
    aligned, axis_opacity, cell_seen, child_error, pack_normal, seen_error, tau_code, tau_decode, unorm10,
    unpack_normal, view_coherence,
};
use crate::bricks::BRICK;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::BrickPush;
use crate::plan::SUMMARY_WORDS;
use crate::plan::{node_grid, node_words, NODE_PIXELS, NODE_WORDS};
use crate::plan::{CELL_WORDS, LOD_CELLS, NO_NORMAL, SLOT_CELLS};
use glam::Vec3;

/// Mirror of `consecutive`: whether the bricks of the aligned block `n0..n1` of a `grid` of bricks
/// are consecutive in the order `tree` gives them (the block is one of the tree's boxes, or lies
/// inside one of its leaves).
pub fn consecutive(tree: &[crate::kdtree::Node], grid: [u32; 3], n0: [u32; 3], n1: [u32; 3]) -> bool {
    let (mut lo, mut hi) = ([0u32; 3], grid);
    let mut n = if tree.is_empty() { crate::kdtree::LEAF } else { 0 };
    loop {
        if lo == n0 && hi == n1 {
            return true;
        }
        if n == crate::kdtree::LEAF {
            return (0..3).all(|a| n0[a] >= lo[a] && n1[a] <= hi[a]);
        }
        let node = &tree[n as usize];
        let (axis, plane) = crate::kdtree::cut(node);
        if plane <= n0[axis] {
            lo[axis] = plane;
            n = node[2];
        } else if plane >= n1[axis] {
            hi[axis] = plane;
            n = node[1];
        } else {
            return false;
        }
    }
}

impl BrickInputs<'_> {
    /// Mirror of `node_word`: the index of word 0 of node `n` (node coordinates) at tree level `k`
    /// in the summary buffer.
    pub(crate) fn node_at(&self, k: u32, n: [u32; 3]) -> usize {
        let grid = [self.bf.grid[0], self.bf.grid[1], self.bf.grid[2]];
        let base = self.bf.grid[3].max(1) as u64 * SUMMARY_WORDS as u64 + node_words(grid, k - 1);
        let g = node_grid(grid, k);
        (base + (n[0] + g[0] * (n[1] + g[1] * n[2])) as u64 * NODE_WORDS as u64) as usize
    }

    /// The words of brick `b`'s node at tree level `k`.
    pub(crate) fn node_of(&self, k: u32, b: [u32; 3]) -> &[u32] {
        &self.summary[self.node_at(k, b.map(|c| c >> k))..][..NODE_WORDS]
    }

    /// Mirror of `cut_word`: the index of level-1 node `n1`'s cut word (one per level-1 node, where
    /// a level past the last would start).
    pub(crate) fn cut_at(&self, n1: [u32; 3]) -> usize {
        let g = node_grid([self.bf.grid[0], self.bf.grid[1], self.bf.grid[2]], 1);
        self.node_at(self.bf.hi[3] + 1, [0; 3]) + (n1[0] + g[0] * (n1[1] + g[1] * n1[2])) as usize
    }

    /// This frame's tree level of the node that draws brick `b` (`brick_cull`'s read of the cut).
    pub(crate) fn node_cut(&self, b: [u32; 3]) -> u32 {
        if self.bf.grad[1] > 0.0 && self.bf.hi[3] > 0 {
            self.summary[self.cut_at(b.map(|c| c >> 1))]
        } else {
            0
        }
    }

    /// Mirror of `node_color`: node `n` (node coordinates) of tree level `k` seen along `view`.
    pub fn node_color(&self, k: u32, n: [u32; 3], view: Vec3) -> ([f32; 4], Vec3) {
        let w = &self.summary[self.node_at(k, n)..];
        cell_seen(w[0], w[1], w[2], view)
    }

    /// Mirror of `node_level`: the tree level of the node that draws brick `b`'s level-1 node this
    /// frame (0: none), `px` being pixels per voxel spacing at that level-1 node's nearest depth.
    pub fn node_level(&self, b: [u32; 3], px: f32) -> u32 {
        let (f, bf) = (self.frame, &self.bf);
        let bound = bf.grad[1].min(NODE_PIXELS);
        if bf.grad[1] <= 0.0 || px * (2 * BRICK) as f32 > bound {
            return 0;
        }
        for k in (1..=bf.hi[3]).rev() {
            // Cheap tests first: the brick's own pixels per voxel bound the node's from below.
            let cell = (BRICK << k) as f32;
            if px * cell > bound {
                continue;
            }
            let node = self.node_of(k, b);
            let err = f32::from_bits(node[3]);
            if seen_error(err, px * cell) > bf.grad[2] || node[6] == 0 {
                continue;
            }
            let (lo, hi) = self.voxel_box(b, k);
            let (near, far) = self.box_depths(lo, hi);
            let size = self.voxel_pixels(near) * cell;
            if size > bound || seen_error(err * view_coherence(self.seen_along(lo, hi)), size) > bf.grad[2] {
                continue;
            }
            if near < f.forward[3] + 2.0 * self.cull_reach(near, cell)
                || far > f.right[3] - 2.0 * self.cull_reach(far, cell)
            {
                continue;
            }
            return k;
        }
        0
    }
}

/// Mirror of `brick_nodes.comp`: the nodes of tree level `push.first` from their children (the
/// bricks' level-3 cells in `summary`, or the level below's nodes), written after the summaries.
pub fn brick_nodes(inputs: &BrickInputs<'_>, push: &BrickPush, summary: &mut [u32]) {
    let k = push.first;
    let bf = &inputs.bf;
    let grid = [bf.grid[0], bf.grid[1], bf.grid[2]];
    let (g, below) = (node_grid(grid, k), node_grid(grid, k - 1));
    let voxels = (1u32 << (3 * (3 + k))) as f32;
    let n1 = |n: [u32; 3]| [0, 1, 2].map(|a| ((n[a] << k) + (1 << k)).min(grid[a]));
    let inside = |n: [u32; 3]| (0..3).all(|a| n[a] << k >= bf.lo[a] && n1(n)[a] <= bf.hi[a]);
    for i in 0..push.count {
        let n = [i % g[0], (i / g[0]) % g[1], i / (g[0] * g[1])];
        let (mut t, mut col, mut grad, mut rep) = (0.0f32, Vec3::ZERO, Vec3::ZERO, u32::MAX);
        let (mut tk, mut ck, mut ek, mut ak) = ([0f32; 8], [Vec3::ZERO; 8], [0f32; 8], [[0f32; 8]; 3]);
        for d in 0..8u32 {
            let c = [0, 1, 2].map(|a| 2 * n[a] + (d >> a & 1));
            let (mut words, mut e, mut tc, mut r) = ([0, NO_NORMAL << 16, 0], 0.0f32, 0.0f32, u32::MAX);
            if (0..3).all(|a| c[a] < below[a]) {
                if k == 1 {
                    let h = inputs.store.index[(c[0] + grid[0] * (c[1] + grid[1] * c[2])) as usize];
                    if h != u32::MAX {
                        let s = h as usize * SUMMARY_WORDS;
                        let cell = s + 4 + (LOD_CELLS - 1 - SLOT_CELLS) * CELL_WORDS;
                        words = [summary[cell], summary[cell + 1], summary[cell + 2]];
                        (e, tc, r) =
                            (f32::from_bits(summary[s + 3]), f32::from_bits(summary[s + SUMMARY_WORDS - 1]), h);
                    }
                } else {
                    let w = inputs.node_at(k - 1, c);
                    words = [summary[w], summary[w + 1], summary[w + 2]];
                    (e, tc, r) = (f32::from_bits(summary[w + 3]), f32::from_bits(summary[w + 4]), summary[w + 5]);
                }
            }
            if words[0] & 0xffff != 0 {
                rep = rep.min(r);
            }
            let straight = Vec3::from([words[2], words[2] >> 10, words[2] >> 20].map(|q| (q & 1023) as f32 / 1023.0));
            let d = d as usize;
            (tk[d], ck[d], ek[d]) = (tc, straight * tc, e);
            let codes = [words[0] & 0xffff, words[0] >> 16, words[1] & 0xffff];
            for x in 0..3 {
                ak[x][d] = 1.0 - (-tau_decode(codes[x])).exp();
            }
            t += tc;
            col += ck[d];
            grad += aligned(unpack_normal(words[1] >> 16) * tc, grad);
        }
        let len = (1u32 << (3 + k)) as f32;
        let a = 1.0 - (-t / voxels * len).exp();
        let straight = if t > 0.0 { col / t } else { Vec3::ZERO };
        let mut err = 0.0f32;
        for d in 0..8 {
            err = err.max(child_error(a, straight, tk[d], ck[d], ek[d], voxels / 8.0, len));
        }
        let codes = [0, 1, 2].map(|x| tau_code(-(1.0 - axis_opacity(ak[x], x).min(0.999_999_9)).ln()));
        let w = inputs.node_at(k, n);
        summary[w..w + NODE_WORDS].copy_from_slice(&[
            codes[0] | codes[1] << 16,
            codes[2] | pack_normal(grad) << 16,
            unorm10(straight.x) | unorm10(straight.y) << 10 | unorm10(straight.z) << 20,
            err.to_bits(),
            t.to_bits(),
            rep,
            u32::from(inside(n) && consecutive(inputs.tree, grid, n.map(|c| c << k), n1(n))),
        ]);
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, _: &Variant) -> Result<()> {
    let mut summary = b.take(Res::LodSummary);
    brick_nodes(&inputs(b)?, &args.push_as(), &mut summary);
    b.put(Res::LodSummary, summary);
    Ok(())
}
