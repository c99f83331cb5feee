//! Levels of detail over a bricked volume: mirror of `brick_pyramid.comp` and of the
//! pyramid helpers of `glsl/shared/brick.glsl` (`level_split`, `brick_level`, `level_count`,
//! `cell_color`; the word codecs the brick mirrors share are in brick_words.rs).
use super::bindings::Bindings;
// Decided by the plan (plan/layout.rs), read here too; kept here for the paths callers already use.
use super::brick::{inputs, inputs_for, streamed, voxel_ijk, voxel_level, BrickInputs, VOXEL_MORPHS};
pub use super::brick_words::{level_count, tau_code, tau_decode, SUMMARY_WORDS};
use super::order::side_count;
use super::splat_params::{optical_depth, params_at};
use crate::bricks::{local_cell, BRICK};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{BrickPush, SplatParams};
pub(crate) use crate::plan::NO_NORMAL;
pub use crate::plan::{
    pyramid_bytes, CELL_WORDS, LOD_BUFFERS, LOD_CELLS, LOD_LEVELS, PYRAMID_BYTES, SLOTTED_LOD_BUFFERS, SLOT_CELLS,
    STREAMED_LOD_BUFFERS, SUMMARY_BYTES,
};
use glam::Vec3;

/// First cell of level `l` (1..3) in a brick's pyramid.
pub fn level_offset(l: u32) -> u32 {
    match l {
        1 => 0,
        2 => 64,
        _ => 72,
    }
}

/// Mirror of `packSnorm4x8`'s low two bytes, rounding as `f32::round` does.
fn snorm8(v: f32) -> u32 {
    ((v.clamp(-1.0, 1.0) * 127.0).round() as i32 as u32) & 0xff
}

/// Mirror of `unorm10` (brick_pyramid.comp).
pub(crate) fn unorm10(v: f32) -> u32 {
    (v.clamp(0.0, 1.0) * 1023.0 + 0.5).floor() as u32
}

/// Mirror of `sign_not_zero` (one component).
fn sign_not_zero(v: f32) -> f32 {
    if v >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Mirror of `pack_normal`: octahedral bytes of gradient `g`.
pub(crate) fn pack_normal(g: Vec3) -> u32 {
    let len = g.x.abs() + g.y.abs() + g.z.abs();
    if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return NO_NORMAL;
    }
    let n = g / len;
    let (ox, oy) = if n.z < 0.0 {
        ((1.0 - n.y.abs()) * sign_not_zero(n.x), (1.0 - n.x.abs()) * sign_not_zero(n.y))
    } else {
        (n.x, n.y)
    };
    snorm8(ox) | snorm8(oy) << 8
}

/// Mirror of `unpack_normal`.
pub(crate) fn unpack_normal(w: u32) -> Vec3 {
    if w == NO_NORMAL {
        return Vec3::ZERO;
    }
    let sn = |b: u32| ((b & 0xff) as u8 as i8 as f32 / 127.0).max(-1.0);
    let (ox, oy) = (sn(w), sn(w >> 8));
    let mut n = Vec3::new(ox, oy, 1.0 - ox.abs() - oy.abs());
    if n.z < 0.0 {
        (n.x, n.y) = ((1.0 - oy.abs()) * sign_not_zero(ox), (1.0 - ox.abs()) * sign_not_zero(oy));
    }
    n.normalize()
}

/// Mirror of `cell_word`: word `k` of cell `i` of the brick of header `h` whose pyramid slot is
/// `slot`: level 1 in `pyramid`, levels 2 and 3 in `summary`.
pub fn cell_word(pyramid: &[u32], summary: &[u32], slot: u32, h: u32, i: u32, k: usize) -> u32 {
    let i = i as usize;
    if i < SLOT_CELLS {
        pyramid[(slot as usize * SLOT_CELLS + i) * CELL_WORDS + k]
    } else {
        summary[h as usize * SUMMARY_WORDS + 4 + (i - SLOT_CELLS) * CELL_WORDS + k]
    }
}

/// Mirror of `cell_seen`: a cell (words `xy`, `zn`, `c`) seen along `view` (index space):
/// straight colour, optical depth per cell length, and its normal (zero when it has none).
pub(crate) fn cell_seen(xy: u32, zn: u32, c: u32, view: Vec3) -> ([f32; 4], Vec3) {
    let w = view * view / view.dot(view).max(1e-30);
    let tau = Vec3::new(tau_decode(xy & 0xffff), tau_decode(xy >> 16), tau_decode(zn & 0xffff));
    let trans = w.dot((-tau.min(Vec3::splat(80.0))).exp());
    let rgb = [c & 1023, c >> 10 & 1023, c >> 20 & 1023].map(|q| q as f32 / 1023.0);
    ([rgb[0], rgb[1], rgb[2], -trans.max(1e-30).ln()], unpack_normal(zn >> 16))
}

impl BrickInputs<'_> {
    /// Mirror of `cell_color`: cell `i` of header `h` seen along `view` (`cell_seen`).
    pub fn cell_color(&self, h: u32, i: u32, view: Vec3) -> ([f32; 4], Vec3) {
        let word = |k| cell_word(self.pyramid, self.summary, self.pyramid_index(h), h, i, k);
        cell_seen(word(0), word(1), word(2), view)
    }

    /// Mirror of `cell_tau`: the optical depth per cell length along x.
    pub fn cell_tau(&self, h: u32, i: u32) -> f32 {
        tau_decode(cell_word(self.pyramid, self.summary, self.pyramid_index(h), h, i, 0) & 0xffff)
    }
}

/// Mirror of `seen_error`: a coarse cell's error as the picture sees it, the cell projecting to
/// `size` pixels (its detail is averaged away by the pixel's filter below a pixel).
pub fn seen_error(err: f32, size: f32) -> f32 {
    let s = size.min(1.0);
    err * s
}

/// Mirror of `level_split`: the eye's PBTF split of level `l`'s cells inside brick `b`.
pub fn level_split(split: [u32; 4], b: [u32; 3], l: u32) -> [u32; 3] {
    let side = BRICK >> l;
    [0, 1, 2].map(|a| {
        let global = ((split[a] + (1 << l) - 1) >> l) as i64;
        (global - (b[a] * side) as i64).clamp(0, side as i64) as u32
    })
}

impl BrickInputs<'_> {
    /// Mirror of `voxel_pixels`.
    pub(crate) fn voxel_pixels(&self, depth: f32) -> f32 {
        let f = self.frame;
        let voxel = f.spacing[3] / f.origin[3];
        if f.eye[3] > 0.5 {
            voxel * f.up[3] / depth.max(f.forward[3])
        } else {
            voxel * f.up[3]
        }
    }

    /// Mirror of `level_octaves`.
    fn level_octaves(&self, depth: f32, l: u32) -> f32 {
        (self.bf.grad[1] / self.voxel_pixels(depth)).log2() - l as f32
    }

    /// Mirror of `splat_growth`.
    pub fn splat_growth(&self, at: Vec3, l: u32) -> f32 {
        let (f, bf) = (self.frame, &self.bf);
        let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
        let center = super::splat_params::frame_grid(f).point(at);
        let octaves = self.level_octaves((center - v3(f.eye)).dot(v3(f.forward)), l);
        1.0 + ((octaves - (1.0 - bf.grad[3])) / bf.grad[3]).clamp(0.0, 1.0)
    }

    /// Mirror of `brick_level`: brick `b`'s (header `h`) level of detail this frame, and 1 when
    /// its splats may morph toward the next.
    pub fn brick_level(&self, h: u32, b: [u32; 3]) -> (u32, f32) {
        let (f, bf) = (self.frame, &self.bf);
        if bf.grad[1] <= 0.0 {
            return (0, 0.0);
        }
        let (lo, hi) = self.voxel_box(b, 0);
        let (near, far) = self.box_depths(lo, hi);
        let px = self.voxel_pixels(near);
        let at = h as usize * SUMMARY_WORDS;
        let s = &self.summary[at..at + 4];
        let mut level = 0;
        for l in 1..=LOD_LEVELS {
            let size = px * (1u32 << l) as f32;
            if size > bf.grad[1] || seen_error(f32::from_bits(s[l as usize]), size) > bf.grad[2] {
                break;
            }
            let cell = (1u32 << l) as f32;
            if near < f.forward[3] + 2.0 * self.cull_reach(near, cell)
                || far > f.right[3] - 2.0 * self.cull_reach(far, cell)
            {
                break;
            }
            level = l;
        }
        let octaves = self.level_octaves(far, level);
        let morph = level < 3
            && bf.grad[3] > 0.0
            && seen_error(f32::from_bits(s[level as usize + 1]), px * (2u32 << level) as f32) <= bf.grad[2]
            && octaves > 1.0 - bf.grad[3];
        (level, if morph { 1.0 } else { 0.0 })
    }
}

/// Per-level sums of a brick's cells: optical depth, tau-weighted colour and gradient
/// (sign-aligned), error, and its opacity along x, y and z (a voxel's: its opacity).
#[derive(Clone, Copy, Default)]
struct Sums {
    tau: f32,
    col: Vec3,
    grad: Vec3,
    err: f32,
    axes: [f32; 3],
}

/// Mirror of `aligned`: `g` turned to agree with `with`.
pub(crate) fn aligned(g: Vec3, with: Vec3) -> Vec3 {
    if g.dot(with) < 0.0 {
        -g
    } else {
        g
    }
}

/// Mirror of `axis_opacity`: the opacity along `axis` of a cell whose children have opacities
/// `a` along it.
pub(crate) fn axis_opacity(a: [f32; 8], axis: usize) -> f32 {
    let mut sum = 0.0;
    for p in 0..4usize {
        let low = (p & ((1 << axis) - 1)) | ((p >> axis) << (axis + 1));
        sum += 1.0 - (1.0 - a[low]) * (1.0 - a[low | 1 << axis]);
    }
    0.25 * sum
}

/// Mirror of `child_error`: the error of a cell of mean opacity `a` and colour `straight` against
/// a child (sums `tk`, `ck`; error `ek`) of `voxels` voxels.
pub(crate) fn child_error(a: f32, straight: Vec3, tk: f32, ck: Vec3, ek: f32, voxels: f32) -> f32 {
    let ak = 1.0 - (-tk / voxels).exp();
    let sk = if tk > 0.0 { ck / tk } else { Vec3::ZERO };
    let dc = (sk - straight).abs();
    ek + (ak - a).abs().max(ak * dc.x.max(dc.y.max(dc.z)))
}

/// A streamed store's batch for `brick_pyramid`: brick_list, the push's range of it (its `splats`
/// not 0: each brick into its own header's slot, a resident pyramid), and per header its slot
/// (written).
pub struct PyramidBatch<'a> {
    pub list: &'a [[u32; 4]],
    pub push: BrickPush,
    pub slots: &'a mut [u32],
}

/// Mirror of `brick_pyramid.comp`: every non-empty brick's pyramid cells and summary, or with
/// `batch` (a streamed store) the batch range's bricks' into their entries' slots.
pub fn brick_pyramid(
    inputs: &BrickInputs<'_>,
    batch: Option<PyramidBatch<'_>>,
    pyramid: &mut [u32],
    summary: &mut [u32],
) {
    let store = inputs.store;
    let shaded = inputs.bf.light[3] > 0.5;
    let mut fine = vec![Sums::default(); (BRICK * BRICK * BRICK) as usize];
    // (header, slot) of the bricks to build.
    let (bricks, mut slots): (Vec<(usize, usize)>, _) = match batch {
        Some(PyramidBatch { list, push, slots }) => {
            let range = push.first as usize..(push.first + push.count) as usize;
            let by_header = push.splats != 0;
            (
                range.map(|e| (list[e][0] as usize, if by_header { list[e][0] as usize } else { e })).collect(),
                Some(slots),
            )
        }
        None => ((0..store.headers.len()).map(|h| (h, h)).collect(), None),
    };
    for (h, slot) in bricks {
        let hd = &store.headers[h];
        let b = hd.coords();
        fine.fill(Sums::default());
        for (rank, &rec) in store.brick_records(hd).iter().enumerate() {
            if !inputs.emits(rec >> 16) {
                continue;
            }
            let l = rec & 511;
            let lc = local_cell(l);
            let v = [0, 1, 2].map(|a| (b[a] * BRICK + lc[a]) as i64);
            let c = inputs.classify_voxel(v, rec >> 16, false);
            let t = optical_depth(c[3]);
            let grad = if shaded { inputs.voxel_gradient(v, h as u32, rank as u32) * t } else { Vec3::ZERO };
            let a = 1.0 - (-t).exp();
            fine[l as usize] = Sums { tau: t, col: Vec3::new(c[0], c[1], c[2]) * t, grad, err: 0.0, axes: [a; 3] };
        }
        let mut cells = [Sums::default(); LOD_CELLS];
        let mut stored = [0f32; LOD_CELLS];
        for l in 1..=LOD_LEVELS {
            let n = BRICK >> l;
            let voxels = (1u32 << (3 * l)) as f32;
            for c in 0..n * n * n {
                let cc = [c % n, (c / n) % n, c / (n * n)];
                let children: [Sums; 8] = std::array::from_fn(|d| {
                    let d = d as u32;
                    let k = [0, 1, 2].map(|a| 2 * cc[a] + (d >> a & 1));
                    let m = 2 * n;
                    let i = (k[0] + m * (k[1] + m * k[2])) as usize;
                    if l == 1 {
                        fine[i]
                    } else {
                        cells[level_offset(l - 1) as usize + i]
                    }
                });
                let (mut t, mut col, mut g) = (0.0f32, Vec3::ZERO, Vec3::ZERO);
                for k in &children {
                    (t, col, g) = (t + k.tau, col + k.col, g + aligned(k.grad, g));
                }
                let a = 1.0 - (-t / voxels).exp();
                let straight = if t > 0.0 { col / t } else { Vec3::ZERO };
                let mut err = 0.0f32;
                for k in &children {
                    err = err.max(child_error(a, straight, k.tau, k.col, k.err, voxels / 8.0));
                }
                let axes = [0, 1, 2].map(|x| axis_opacity(children.map(|k| k.axes[x]), x));
                let i = level_offset(l) as usize + c as usize;
                cells[i] = Sums { tau: t, col, grad: g, err, axes };
                // Mirror of `put_cell`.
                let codes = axes.map(|a| tau_code(-(1.0 - a.min(0.999_999_9)).ln()));
                stored[i] = tau_decode(codes[0]);
                let words = [
                    codes[0] | codes[1] << 16,
                    codes[2] | pack_normal(g) << 16,
                    unorm10(straight.x) | unorm10(straight.y) << 10 | unorm10(straight.z) << 20,
                ];
                // Level 1 into the pyramid's slot, levels 2 and 3 into the brick's summary.
                let at = if i < SLOT_CELLS {
                    &mut pyramid[(slot * SLOT_CELLS + i) * CELL_WORDS..][..CELL_WORDS]
                } else {
                    &mut summary[h * SUMMARY_WORDS + 4 + (i - SLOT_CELLS) * CELL_WORDS..][..CELL_WORDS]
                };
                at.copy_from_slice(&words);
                if i == LOD_CELLS - 1 {
                    summary[h * SUMMARY_WORDS + SUMMARY_WORDS - 1] = t.to_bits();
                }
            }
        }
        let mut s = [fine.iter().filter(|f| f.tau > 0.0).count() as u32 * (1 << 16), 0, 0, 0];
        for l in 1..=LOD_LEVELS {
            let n = BRICK >> l;
            let range = level_offset(l) as usize..(level_offset(l) + n * n * n) as usize;
            let drawn = stored[range.clone()].iter().filter(|&&t| t > 0.0).count() as u32;
            let most = cells[range].iter().map(|c| c.err).fold(0.0f32, f32::max);
            s[0] |= drawn << [0, 8, 12][l as usize - 1];
            s[l as usize] = most.to_bits();
        }
        summary[h * SUMMARY_WORDS..][..4].copy_from_slice(&s);
        if let Some(slots) = slots.as_deref_mut() {
            slots[h] = slot as u32;
        }
    }
}

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

/// Mirror of `brick_lod_params.comp`: the parameters of the coarse splats at positions
/// `lod_splats` (`push.splats` of them) from their pyramid cells.
pub fn brick_lod_params(
    inputs: &BrickInputs<'_>,
    lod_splats: &[u32],
    push: &BrickPush,
    voxels: &[[u32; 2]],
    params: &mut [SplatParams],
) {
    let (shaded, dims) = (inputs.bf.light[3] > 0.5, inputs.frame.dims);
    let (f, grid) = (inputs.frame, super::splat_params::frame_grid(inputs.frame));
    for &s in &lod_splats[..push.splats as usize] {
        let v = voxels[s as usize];
        let (ijk, level) = (voxel_ijk(v), voxel_level(v));
        let at = Vec3::from_array(
            [0, 1, 2].map(|a| ijk[a] as f32 + 0.5 * ((1u32 << level).min(dims[a] - ijk[a]) as f32 - 1.0)),
        );
        let grow = if v[1] & VOXEL_MORPHS != 0 { inputs.splat_growth(at, level) } else { 1.0 };
        let view = if f.eye[3] > 0.5 {
            grid.point(at) - Vec3::new(f.eye[0], f.eye[1], f.eye[2])
        } else {
            Vec3::new(f.forward[0], f.forward[1], f.forward[2])
        };
        let view = grid.index_dir(view.as_dvec3()).as_vec3();
        let (mut c, normal) = if level > LOD_LEVELS {
            inputs.node_color(level - LOD_LEVELS, ijk.map(|c| c >> level), view)
        } else {
            inputs.cell_color(inputs.store.header_of(ijk), v[1] >> 16, view)
        };
        if shaded {
            inputs.shade(&mut c, normal);
        }
        params[s as usize] = params_at(inputs.frame, at, (1u32 << level) as f32, grow, [c[0], c[1], c[2]], c[3]);
    }
}

pub(crate) fn brick_lod_params_stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let mut params = b.take(Res::Params);
    brick_lod_params(
        &inputs_for(b, v)?,
        b.get(Res::LodSplats),
        &args.push_as(),
        b.get(Res::BrickVoxels),
        bytemuck::cast_slice_mut(&mut params),
    );
    b.put(Res::Params, params);
    Ok(())
}

pub(crate) fn brick_cells_stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
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

pub(crate) fn brick_pyramid_stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let (mut pyramid, mut summary) = (b.take(Res::Pyramid), b.take(Res::LodSummary));
    if streamed(v) {
        let mut slots = b.take(Res::PyramidSlot);
        let batch = Some(PyramidBatch { list: b.get(Res::BrickList), push: args.push_as(), slots: &mut slots });
        brick_pyramid(&inputs(b)?, batch, &mut pyramid, &mut summary);
        b.put(Res::PyramidSlot, slots);
    } else {
        brick_pyramid(&super::brick::inputs_for(b, v)?, None, &mut pyramid, &mut summary);
    }
    b.put(Res::Pyramid, pyramid);
    b.put(Res::LodSummary, summary);
    Ok(())
}
