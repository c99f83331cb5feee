//! Helpers of the brick stages' mirrors (`brick_cull.rs`, `brick_order.rs`, `brick_params.rs`, and
//! the levels of detail's): `glsl/shared/brick.glsl`'s helpers over the scene's `BrickStore`, the
//! frame's `BrickFrame` and TF buffer (`BrickInputs`).
use super::bindings::Bindings;
use super::order::{outward, side_count};
use super::splat_params::{frame_grid, CULL_RADII};
use crate::bricks::{BrickStore, BRICK};
use crate::dispatch::{Res, Variant};
use crate::error::{Error, Result};
use crate::gpu_types::{BrickFrame, Frame};
use crate::plan::cell_footprint_scale;
use glam::{Mat4, Vec3, Vec4};

pub(crate) const CELL_WORDS: usize = (BRICK * BRICK * BRICK / 32) as usize;

/// Mirror of `dense_pbtf`: cell `c`'s position in the PBTF sequence of a dense `n`-cell grid split
/// at `s`.
pub fn dense_pbtf(c: [u32; 3], n: [u32; 3], s: [u32; 3]) -> u32 {
    let side = |a: usize| u32::from(c[a] >= s[a]);
    let (si, sj, sk) = (side(0), side(1), side(2));
    let octant = si + 2 * sj + 4 * sk;
    let mut base = 0;
    for o in 0..octant {
        base +=
            side_count(n[0], s[0], o & 1) * side_count(n[1], s[1], (o >> 1) & 1) * side_count(n[2], s[2], (o >> 2) & 1);
    }
    let (ni, nj) = (side_count(n[0], s[0], si), side_count(n[1], s[1], sj));
    base + (outward(c[2], s[2], sk) * nj + outward(c[1], s[1], sj)) * ni + outward(c[0], s[0], si)
}

/// Mirror of `tree_pbtf`: brick `b`'s position in the order of a `grid` of bricks that `tree`
/// (`kdtree`) cuts, front to back: every node's near side first (for the eye's brick split
/// `split`), its leaves' boxes as octrees (`octree_pbtf`).
pub fn tree_pbtf(tree: &[crate::kdtree::Node], grid: [u32; 3], split: [u32; 3], b: [u32; 3]) -> u32 {
    let (mut lo, mut hi, mut p) = ([0u32; 3], grid, 0u32);
    let mut n = if tree.is_empty() { crate::kdtree::LEAF } else { 0 };
    while n != crate::kdtree::LEAF {
        let node = &tree[n as usize];
        let (axis, plane) = crate::kdtree::cut(node);
        let high = b[axis] >= plane;
        if high == crate::kdtree::lower_in_front(node, split) {
            // b lies on the far side: after every brick of the near one (front to back, as PBTF).
            let mut e = [0, 1, 2].map(|a| hi[a] - lo[a]);
            e[axis] = if high { plane - lo[axis] } else { hi[axis] - plane };
            p += e[0] * e[1] * e[2];
        }
        if high {
            lo[axis] = plane;
        } else {
            hi[axis] = plane;
        }
        n = if high { node[2] } else { node[1] };
    }
    p + octree_pbtf(b, lo, hi, split)
}

/// Mirror of `octree_pbtf`: brick `b`'s position among the bricks of the box `lo..hi` visited front
/// to back as an octree of aligned blocks (`order::octree_descent`): per block on the way down, the
/// bricks of the box in its children drawn before the one holding `b`.
pub fn octree_pbtf(b: [u32; 3], lo: [u32; 3], hi: [u32; 3], s: [u32; 3]) -> u32 {
    let mut p = 0;
    for step in crate::order::octree_descent(b, lo, hi, s) {
        let (o, half) = (step.origin, step.half);
        let rank = dense_pbtf(step.child, [2; 3], step.split);
        for d in 0..8u32 {
            let c = [d & 1, d >> 1 & 1, d >> 2 & 1];
            if dense_pbtf(c, [2; 3], step.split) >= rank {
                continue;
            }
            let clo = [0, 1, 2].map(|a| (o[a] + c[a] * half).max(lo[a]));
            let chi = [0, 1, 2].map(|a| (o[a] + (c[a] + 1) * half).min(hi[a]));
            if (0..3).all(|a| clo[a] < chi[a]) {
                p += (0..3).map(|a| chi[a] - clo[a]).product::<u32>();
            }
        }
    }
    p
}

/// What the brick stages read: the frame, its brick uniforms, the TF table and the store.
pub struct BrickInputs<'a> {
    /// The frame's uniforms.
    pub frame: &'a Frame,
    /// The brick stages' uniforms.
    pub bf: BrickFrame,
    /// `BrickScene::tf_words`.
    pub tf: &'a [u32],
    /// The bricked store.
    pub store: &'a BrickStore,
    /// Levels of detail: the pyramid cells and per-brick summaries (empty when off).
    pub pyramid: &'a [u32],
    /// See `pyramid`.
    pub summary: &'a [u32],
    /// Per brick its splats' morph this frame (`brick_cull`).
    pub morphs: &'a [f32],
    /// The k-d tree that orders the bricks (`BrickScene::tree`).
    pub tree: &'a [crate::kdtree::Node],
    /// A streamed store's pyramid holds one batch's bricks: per header its slot (STREAMED_STORE
    /// builds), or `None`: the pyramid is indexed by header.
    pub pyramid_slot: Option<&'a [u32]>,
    /// `BrickStore::gradient_words` (GRADIENTS builds), or `None`: gradients read through the store.
    pub gradients: Option<(&'a [u32], &'a [u32])>,
}

impl BrickInputs<'_> {
    /// Mirror of `pyramid_index`.
    pub fn pyramid_index(&self, h: u32) -> u32 {
        self.pyramid_slot.map_or(h, |s| s[h as usize])
    }
}

impl BrickInputs<'_> {
    /// Mirror of `emits`.
    pub(crate) fn emits(&self, q: u32) -> bool {
        crate::bricks::emits(self.tf, q)
    }

    /// Mirror of `tf_empty`.
    pub fn tf_empty(&self, lo: u32, hi: u32) -> bool {
        !crate::bricks::draws_any(self.tf, lo, hi)
    }

    pub(crate) fn density_at(&self, i: i64, j: i64, k: i64) -> f32 {
        self.store.value_at(i, j, k) * self.bf.tf[0] + self.bf.tf[1]
    }

    /// Mirror of `gradient_at`.
    pub(crate) fn gradient_at(&self, v: [i64; 3]) -> Vec3 {
        let [i, j, k] = v;
        Vec3::from(frame_grid(self.frame).gradient([
            self.density_at(i + 1, j, k) - self.density_at(i - 1, j, k),
            self.density_at(i, j + 1, k) - self.density_at(i, j - 1, k),
            self.density_at(i, j, k + 1) - self.density_at(i, j, k - 1),
        ]))
    }

    /// Mirror of `differences_at`: the density's central differences at header `h`'s stored voxel
    /// of rank `rank`.
    pub(crate) fn differences_at(&self, words: (&[u32], &[u32]), h: u32, rank: u32) -> Vec3 {
        let i = (words.0[h as usize] + rank) as usize;
        let d = crate::bricks::unpack_differences([words.0[i], words.1[i]], self.bf.tf[0] / 65535.0);
        Vec3::from(frame_grid(self.frame).gradient(d))
    }

    /// Mirror of `stored_differences`: the same at stored voxel `v`.
    pub(crate) fn stored_differences(&self, words: (&[u32], &[u32]), v: [i64; 3]) -> Vec3 {
        let c = v.map(|c| c as u32);
        let h = self.store.header_of(c);
        let l = (c[0] % BRICK + BRICK * (c[1] % BRICK) + BRICK * BRICK * (c[2] % BRICK)) as usize;
        self.differences_at(words, h, self.store.stored_below(h, l))
    }

    /// The world gradient at stored voxel `v`, of rank `rank` in header `h`'s brick: from its
    /// differences (GRADIENTS builds) or its neighbours through the store.
    pub(crate) fn voxel_gradient(&self, v: [i64; 3], h: u32, rank: u32) -> Vec3 {
        match self.gradients {
            Some(words) => self.differences_at(words, h, rank),
            None => self.gradient_at(v),
        }
    }

    /// Mirror of `shade`.
    pub(crate) fn shade(&self, c: &mut [f32; 4], g: Vec3) {
        let len = g.length();
        let n = if len > 0.0 { g / len } else { Vec3::ZERO };
        let light = Vec3::new(self.bf.light[0], self.bf.light[1], self.bf.light[2]);
        let ndl = n.dot(-light).abs();
        let lit = self.bf.shade[0] + self.bf.shade[1] * ndl;
        let spec = self.bf.shade[2] * ndl.powf(self.bf.shade[3]);
        for ch in c.iter_mut().take(3) {
            *ch = (*ch * lit + spec).min(1.0);
        }
    }

    /// Mirror of `tf_color[q]`: the transfer function's straight colour and opacity at code `q`.
    pub(crate) fn tf_color(&self, q: u32) -> [f32; 4] {
        [0, 1, 2, 3].map(|i| f32::from_bits(self.tf[4 * q as usize + i]))
    }

    /// Mirror of `classify_voxel`.
    pub(crate) fn classify_voxel(&self, v: [i64; 3], q: u32, shaded: bool) -> [f32; 4] {
        let mut c = self.tf_color(q);
        let weighted = self.bf.tf[3] > 0.0;
        if weighted || shaded {
            let g = match self.gradients {
                Some(words) => self.stored_differences(words, v),
                None => self.gradient_at(v),
            };
            if weighted {
                c[3] *= (g.length() / self.bf.grad[0]).powf(self.bf.tf[3]);
            }
            if shaded {
                self.shade(&mut c, g);
            }
        }
        c
    }

    /// Mirror of `voxel_box`: the world box of the voxel centres of brick `b`'s node of tree
    /// level `k` (0: the brick).
    pub(crate) fn voxel_box(&self, b: [u32; 3], k: u32) -> (Vec3, Vec3) {
        let f = self.frame;
        let first_voxel = b.map(|c| (c >> k << k) * BRICK);
        let first = Vec3::from(first_voxel.map(|c| c as f32));
        let last = [0, 1, 2].map(|a| ((first_voxel[a] + (BRICK << k)).min(f.dims[a]) - 1) as f32);
        let [lo, hi] = frame_grid(f).world_box(first, Vec3::from(last));
        (lo, hi)
    }

    /// Mirror of `box_depths`: the depths along the view of the box's nearest and farthest corners.
    pub(crate) fn box_depths(&self, lo: Vec3, hi: Vec3) -> (f32, f32) {
        let f = self.frame;
        let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
        let (eye, forward) = (v3(f.eye), v3(f.forward));
        let depths = (0..8).map(|c| (corner(lo, hi, c) - eye).dot(forward));
        depths.fold((1e30f32, -1e30f32), |(n, x), d| (n.min(d), x.max(d)))
    }

    /// Mirror of `cull_reach`: how far a splat `cell` voxels a side at `depth` reaches.
    pub(crate) fn cull_reach(&self, depth: f32, cell: f32) -> f32 {
        let f = self.frame;
        CULL_RADII * cell * f.spacing[3] * cell_footprint_scale(f, depth.max(1e-6), cell)
    }

    /// Mirror of `footprint_box`.
    pub(crate) fn footprint_box(&self, b: [u32; 3], k: u32, cell: f32) -> (Vec3, Vec3) {
        let (lo, hi) = self.voxel_box(b, k);
        let reach = self.cull_reach(self.box_depths(lo, hi).1, cell);
        (lo - Vec3::splat(reach), hi + Vec3::splat(reach))
    }

    /// Mirror of `outside_view`.
    pub(crate) fn outside_view(&self, b: [u32; 3], k: u32, cell: f32) -> bool {
        let f = self.frame;
        if f.blur[0] > 0.0 {
            return false;
        }
        let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
        let (eye, forward) = (v3(f.eye), v3(f.forward));
        let (lo, hi) = self.footprint_box(b, k, cell);
        let vp = Mat4::from_cols_array_2d(&f.view_proj);
        let (mut dmin, mut dmax, mut front) = (1e30f32, -1e30f32, true);
        let mut out = [true; 4];
        for c in 0..8 {
            let p = corner(lo, hi, c);
            let d = (p - eye).dot(forward);
            (dmin, dmax) = (dmin.min(d), dmax.max(d));
            let q: Vec4 = vp * p.extend(1.0);
            front &= q.w > 0.0;
            let beyond = [q.x < -q.w, q.x > q.w, q.y < -q.w, q.y > q.w];
            for (o, b) in out.iter_mut().zip(beyond) {
                *o &= b;
            }
        }
        if dmax < f.forward[3] || dmin > f.right[3] {
            return true;
        }
        // Mirror of the clipping-plane test.
        let clipped =
            f.clip[..f.rect[1] as usize].iter().any(|q| (0..8).all(|c| v3(*q).dot(corner(lo, hi, c)) + q[3] < 0.0));
        if clipped {
            return true;
        }
        front && out.iter().any(|&o| o)
    }

    /// Mirror of `brick_slot`.
    pub(crate) fn brick_slot(&self, b: [u32; 3]) -> u32 {
        let g = self.bf.grid;
        let split = [self.bf.split[0], self.bf.split[1], self.bf.split[2]];
        let p = tree_pbtf(self.tree, [g[0], g[1], g[2]], split, b);
        if self.frame.split[3] != 0 {
            g[0] * g[1] * g[2] - 1 - p
        } else {
            p
        }
    }
}

/// Corner `c` (bit a: the high end along axis a) of the box `lo`..`hi`.
pub(crate) fn corner(lo: Vec3, hi: Vec3, c: u32) -> Vec3 {
    Vec3::new(
        if c & 1 == 1 { hi.x } else { lo.x },
        if c >> 1 & 1 == 1 { hi.y } else { lo.y },
        if c >> 2 & 1 == 1 { hi.z } else { lo.z },
    )
}

/// Mirror of `slot_code`: a brick's slot code for `n` splats at level `l` (`bricks::slot_entry`).
pub fn slot_code(l: u32, n: u32) -> u32 {
    match l {
        0 => n,
        1 => 512 + n,
        2 => 576 + n,
        _ => 582 + l,
    }
}

/// Mirror of `VOXEL_MORPHS` (types.glsl): set in a bricked voxel whose brick morphs.
pub const VOXEL_MORPHS: u32 = 0x8000;

impl BrickInputs<'_> {
    /// Mirror of `morph_bit`: `VOXEL_MORPHS` when header `h`'s brick morphs this frame (levels of
    /// detail on).
    pub fn morph_bit(&self, h: u32) -> u32 {
        if self.bf.grad[1] > 0.0 && self.morphs[h as usize] > 0.0 {
            VOXEL_MORPHS
        } else {
            0
        }
    }
}

/// Mirror of `voxel_ijk` (types.glsl): the grid index of a voxel as `brick_order` writes it.
pub fn voxel_ijk(v: [u32; 2]) -> [u32; 3] {
    [v[0] & 0x1fff, v[0] >> 16 & 0x1fff, v[1] & 0x1fff]
}

/// Mirror of `voxel_level`: 0 for a voxel, l for a cell of 2^l voxels a side (a node k levels
/// above the brick: 3 + k).
pub fn voxel_level(v: [u32; 2]) -> u32 {
    (v[1] >> 13 & 3) + (v[0] >> 13 & 7)
}

pub(crate) fn inputs<'a>(b: &'a Bindings<'_>) -> Result<BrickInputs<'a>> {
    let scene = b.prep.bricks.as_ref().ok_or_else(|| Error::InvalidArgument("the scene is not bricked".into()))?;
    let bf: &[BrickFrame] = b.get(Res::BrickFrame);
    Ok(BrickInputs {
        frame: &b.frame,
        bf: bf[0],
        tf: b.get(Res::Tf),
        store: &scene.store,
        tree: scene.tree(),
        pyramid: b.get(Res::Pyramid),
        summary: b.get(Res::LodSummary),
        morphs: b.get(Res::BrickMorph),
        gradients: None,
        pyramid_slot: None,
    })
}

/// `inputs`, with a streamed build's pyramid slots.
pub(crate) fn inputs_for<'a>(b: &'a Bindings<'_>, v: &Variant) -> Result<BrickInputs<'a>> {
    let mut i = inputs(b)?;
    if streamed(v) {
        i.pyramid_slot = Some(b.get(Res::PyramidSlot));
    }
    if v.defines.contains("GRADIENTS") {
        i.gradients = Some((b.get(Res::BrickGradients), b.get(Res::BrickGradientsHi)));
    }
    Ok(i)
}

/// Whether a brick stage's build reads streamed records.
pub(crate) fn streamed(v: &Variant) -> bool {
    v.defines.contains("STREAMED_STORE")
}
