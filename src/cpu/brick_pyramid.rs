//! Mirror of `glsl/brick_pyramid.comp` (the `brick_pyramid` stage); shared helpers in `lod.rs`.
use super::bindings::Bindings;
use super::brick::{inputs, streamed, BrickInputs};
use super::lod::*;
use super::splat_params::optical_depth;
use crate::bricks::{local_cell, BRICK};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::plan::SUMMARY_WORDS;
use crate::plan::{CELL_WORDS, LOD_CELLS, LOD_LEVELS, SLOT_CELLS};
use glam::Vec3;

/// Per-level sums of a brick's cells: optical depth, tau-weighted colour and gradient
/// (sign-aligned), error, its opacity along x, y and z (a voxel's: its opacity), and its
/// tau-weighted sum of value codes.
#[derive(Clone, Copy, Default)]
struct Sums {
    tau: f32,
    col: Vec3,
    grad: Vec3,
    err: f32,
    axes: [f32; 3],
    code: f32,
}

/// Mirror of `brick_pyramid.comp`: the non-empty bricks' pyramid cells and summaries of the
/// push's range of bricks, or with `batch` (a streamed store) the batch range's bricks' into
/// their entries' slots.
pub fn brick_pyramid(
    inputs: &BrickInputs<'_>,
    push: &crate::gpu_types::BrickPush,
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
        None => {
            let end = (push.first as usize + push.count as usize).min(store.headers.len());
            ((push.first as usize..end).map(|h| (h, h)).collect(), None)
        }
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
            let code = t * (rec >> 16) as f32;
            fine[l as usize] =
                Sums { tau: t, col: Vec3::new(c[0], c[1], c[2]) * t, grad, err: 0.0, axes: [a; 3], code };
        }
        let (empty_out, range_out) = outside_layer(inputs, b);
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
                let (mut t, mut col, mut g, mut code) = (0.0f32, Vec3::ZERO, Vec3::ZERO, 0.0f32);
                for k in &children {
                    (t, col, g, code) = (t + k.tau, col + k.col, g + aligned(k.grad, g), code + k.code);
                }
                let len = BRICK as f32;
                let a = 1.0 - (-t / voxels * len).exp();
                let straight = if t > 0.0 { col / t } else { Vec3::ZERO };
                let mut err = 0.0f32;
                for k in &children {
                    err = err.max(child_error(a, straight, k.tau, k.col, k.err, voxels / 8.0, len));
                }
                let axes = [0, 1, 2].map(|x| axis_opacity(children.map(|k| k.axes[x]), x));
                let i = level_offset(l) as usize + c as usize;
                cells[i] = Sums { tau: t, col, grad: g, err, axes, code };
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
            edge_errors(inputs, &mut cells, &empty_out, &range_out, l);
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

/// Mirror of the outside layer `brick_pyramid.comp` fills (`empty_out`, `range_out`): per face (2
/// axis + high side) of brick `b`, 8 x 8 voxels just past it, true where nothing is drawn there;
/// and the value range of the brick past each face (`neighbour_range`; 0 for none).
fn outside_layer(inputs: &BrickInputs<'_>, b: [u32; 3]) -> ([bool; 6 * 64], [u32; 6]) {
    let store = inputs.store;
    let voxel = |i: usize| {
        let f = i / 64;
        let ax = f / 2;
        let mut v = b.map(|c| (c * BRICK) as i64);
        v[ax] += if f & 1 != 0 { BRICK as i64 } else { -1 };
        v[(ax + 1) % 3] += (i % 8) as i64;
        v[(ax + 2) % 3] += (i / 8 % 8) as i64;
        let inside = (0..3).all(|a| v[a] >= 0 && v[a] < store.dims[a] as i64);
        inside.then(|| v.map(|x| x as u32))
    };
    let empty = std::array::from_fn(|i| {
        // Mirror of `empty_voxel`: outside the grid, an empty brick, or one the TF leaves empty,
        // or a voxel not stored (the mask).
        let Some(v) = voxel(i) else { return true };
        let Some((h, _)) = store.stored(v) else { return true };
        let range = store.headers[h as usize].range;
        inputs.tf_empty(range & 0xffff, range >> 16)
    });
    let ranges = std::array::from_fn(|f| {
        let Some(v) = voxel(f * 64) else { return 0 };
        let h = store.header_of(v);
        if h == u32::MAX {
            0
        } else {
            store.headers[h as usize].range
        }
    });
    (empty, ranges)
}

/// Mirror of `edge_errors`: level `l`'s cells' errors raised to their face neighbours' departure
/// from what the coarse level predicts there (the cell carried on linearly from the opposite
/// neighbour, or the cell's own where that one is outside the brick; a neighbour inside whose
/// opposite is outside is skipped; past the faces, the outside layer's drawn fraction of the
/// prediction, and where the predicted value lies outside the value range of the brick past the
/// face, that range's nearest end, classified).
fn edge_errors(
    inputs: &BrickInputs<'_>,
    cells: &mut [Sums; LOD_CELLS],
    empty_out: &[bool; 6 * 64],
    range_out: &[u32; 6],
    l: u32,
) {
    let n = BRICK >> l;
    let side = 1u32 << l;
    let voxels = (1u32 << (3 * l)) as f32;
    let len = BRICK as f32;
    let at = |c: [u32; 3]| level_offset(l) as usize + (c[0] + n * (c[1] + n * c[2])) as usize;
    // Gradient-weighted opacity: the neighbour's value range does not bound it.
    let weighted = inputs.bf.tf[3] > 0.0;
    let errs: Vec<f32> = (0..n * n * n)
        .map(|c| {
            let cc = [c % n, (c / n) % n, c / (n * n)];
            let me = cells[at(cc)];
            let mut err = me.err;
            // The cell's value (its voxels' codes, tau-weighted).
            let q = if me.tau > 0.0 { me.code / me.tau } else { 0.0 };
            for f in 0..6 {
                let (ax, high) = (f / 2, f & 1 != 0);
                let inside = if high { cc[ax] + 1 < n } else { cc[ax] > 0 };
                let opposite = if high { cc[ax] > 0 } else { cc[ax] + 1 < n };
                // No slope is known here: left to the neighbour's own comparisons.
                if inside && !opposite {
                    continue;
                }
                let (mut pt, mut pc) = (me.tau, me.col);
                // The cell's value, carried on likewise.
                let mut pq = q;
                if opposite {
                    let mut oc = cc;
                    oc[ax] = if high { cc[ax] - 1 } else { cc[ax] + 1 };
                    let o = cells[at(oc)];
                    pt = (2.0 * me.tau - o.tau).max(0.0);
                    pc = (2.0 * me.col - o.col).max(Vec3::ZERO);
                    if o.tau > 0.0 {
                        pq = 2.0 * q - o.code / o.tau;
                    }
                }
                let a = 1.0 - (-pt / voxels * len).exp();
                let straight = if pt > 0.0 { pc / pt } else { Vec3::ZERO };
                if inside {
                    let mut nc = cc;
                    nc[ax] = if high { cc[ax] + 1 } else { cc[ax] - 1 };
                    let k = cells[at(nc)];
                    err = err.max(child_error(a, straight, k.tau, k.col, 0.0, voxels, len));
                } else {
                    let (u0, w0) = (cc[(ax + 1) % 3] * side, cc[(ax + 2) % 3] * side);
                    let mut empty = 0u32;
                    for w in w0..w0 + side {
                        for u in u0..u0 + side {
                            empty += u32::from(empty_out[f * 64 + (u + 8 * w) as usize]);
                        }
                    }
                    let kept = 1.0 - empty as f32 / (side * side) as f32;
                    err = err.max(child_error(a, straight, pt * kept, pc * kept, 0.0, voxels, len));
                    // The predicted value against the range of the brick past the face.
                    let r = range_out[f];
                    let (lo, hi) = ((r & 0xffff) as f32, (r >> 16) as f32);
                    if kept > 0.0 && me.tau > 0.0 && !weighted && (pq < lo - 0.5 || pq > hi + 0.5) {
                        let c = inputs.tf_color(if pq < lo { r & 0xffff } else { r >> 16 });
                        let to = optical_depth(c[3]) * voxels * kept;
                        let col = Vec3::new(c[0], c[1], c[2]) * to;
                        err = err.max(child_error(a, straight, to, col, 0.0, voxels, len));
                    }
                }
            }
            err
        })
        .collect();
    for (c, e) in errs.into_iter().enumerate() {
        cells[level_offset(l) as usize + c].err = e;
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let (mut pyramid, mut summary) = (b.take(Res::Pyramid), b.take(Res::LodSummary));
    if streamed(v) {
        let mut slots = b.take(Res::PyramidSlot);
        let batch = Some(PyramidBatch { list: b.get(Res::BrickList), push: args.push_as(), slots: &mut slots });
        brick_pyramid(&inputs(b)?, &args.push_as(), batch, &mut pyramid, &mut summary);
        b.put(Res::PyramidSlot, slots);
    } else {
        brick_pyramid(&super::brick::inputs_for(b, v)?, &args.push_as(), None, &mut pyramid, &mut summary);
    }
    b.put(Res::Pyramid, pyramid);
    b.put(Res::LodSummary, summary);
    Ok(())
}
