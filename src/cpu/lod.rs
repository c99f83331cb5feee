//! Helpers of the levels-of-detail mirrors (`brick_pyramid.rs`, `brick_cells.rs`,
//! `brick_lod_params.rs`, `brick_nodes.rs`): `glsl/shared/brick.glsl`'s pyramid helpers
//! (`level_split`, `brick_level`, `cell_color`; the word codecs the brick mirrors share are in
//! brick_words.rs).
use super::brick::BrickInputs;
pub use super::brick_words::{tau_code, tau_decode};
use crate::bricks::BRICK;
use crate::gpu_types::BrickPush;
use crate::plan::NO_NORMAL;
use crate::plan::SUMMARY_WORDS;
use crate::plan::{CELL_WORDS, LOD_LEVELS, SLOT_CELLS};
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
pub(crate) fn snorm8(v: f32) -> u32 {
    ((v.clamp(-1.0, 1.0) * 127.0).round() as i32 as u32) & 0xff
}

/// Mirror of `unorm10` (brick_pyramid.comp).
pub(crate) fn unorm10(v: f32) -> u32 {
    (v.clamp(0.0, 1.0) * 1023.0 + 0.5).floor() as u32
}

/// Mirror of `sign_not_zero` (one component).
pub(crate) fn sign_not_zero(v: f32) -> f32 {
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
/// `size` pixels (below a pixel, times the share of the pixel's area it covers).
pub fn seen_error(err: f32, size: f32) -> f32 {
    let s = size.min(1.0);
    err * s * s
}

/// Mirror of `COHERENT_DRIFT`: the share of a cell a ray may drift across and stay in one column
/// of its children.
pub const COHERENT_DRIFT: f32 = 0.5;
/// Mirror of `MAX_COHERENCE`: the most cells' departures `view_coherence` counts along a ray.
pub const MAX_COHERENCE: f32 = 4.0;

/// Mirror of `view_coherence`: how many cells' departures a ray seen along `view` (index space)
/// adds up, 1 for an oblique view up to `MAX_COHERENCE` along a grid axis.
pub fn view_coherence(view: Vec3) -> f32 {
    let g = view.abs();
    let m = g.max_element();
    let across = (g.dot(g) - m * m).max(0.0).sqrt();
    (COHERENT_DRIFT * m / across.max(1e-30)).clamp(1.0, MAX_COHERENCE)
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
    pub(crate) fn level_octaves(&self, depth: f32, l: u32) -> f32 {
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

    /// Mirror of `seen_along`: the direction the world box `lo`..`hi` is seen along, in index
    /// space (`grid_direction` is the frame's grid's `index_dir`).
    pub(crate) fn seen_along(&self, lo: Vec3, hi: Vec3) -> Vec3 {
        let f = self.frame;
        let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
        let d = if f.eye[3] > 0.5 { 0.5 * (lo + hi) - v3(f.eye) } else { v3(f.forward) };
        super::splat_params::frame_grid(f).index_dir(d.as_dvec3()).as_vec3()
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
        let coh = view_coherence(self.seen_along(lo, hi));
        let mut level = 0;
        for l in 1..=LOD_LEVELS {
            let size = px * (1u32 << l) as f32;
            if size > bf.grad[1] || seen_error(f32::from_bits(s[l as usize]) * coh, size) > bf.grad[2] {
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
            && seen_error(f32::from_bits(s[level as usize + 1]) * coh, px * (2u32 << level) as f32) <= bf.grad[2]
            && octaves > 1.0 - bf.grad[3];
        (level, if morph { 1.0 } else { 0.0 })
    }
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
pub(crate) fn child_error(a: f32, straight: Vec3, tk: f32, ck: Vec3, ek: f32, voxels: f32, len: f32) -> f32 {
    let ak = 1.0 - (-tk / voxels * len).exp();
    let sk = if tk > 0.0 { ck / tk } else { Vec3::ZERO };
    let dc = (sk - straight).abs();
    ek + (ak - a).abs().max(ak * dc.x.max(dc.y.max(dc.z)))
}

/// A streamed store's batch for `brick_pyramid`: brick_list, the push's range of it (its `splats`
/// not 0: each brick into its own header's slot, a resident pyramid), and per header its slot
/// (written).
pub struct PyramidBatch<'a> {
    /// The batch's brick list.
    pub list: &'a [[u32; 4]],
    /// The range of it built.
    pub push: BrickPush,
    /// Per header its slot (written).
    pub slots: &'a mut [u32],
}
