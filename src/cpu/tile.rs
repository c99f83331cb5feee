//! Mirrors of the compute per-splat compositing stages: `tile_count.comp`, `tile_scan.comp`,
//! `tile_offsets.comp`, `tile_scatter.comp` (a stable counting sort of the draw list into screen tiles, so every tile's
//! list keeps the PBTF order) and `tile_composite.comp` (each tile composites its list per pixel,
//! front to back with early termination or back to front).
use super::footprint::{footprint_value, screen_quad, FootprintInputs, Sweep};
use super::ImageF32;
use crate::constants::{RASTER_TILE_H, RASTER_TILE_W, TILE_SEGMENT};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{FootprintPush, Frame, ScreenQuad, SplatParams};
use glam::{IVec4, Mat3, Vec2, Vec3};
use rayon::prelude::*;

use super::bindings::Bindings;
// Decided by the plan (plan/layout.rs), read here too; kept here for the paths callers already use.
pub use crate::plan::tile_grid;

/// Mirror of `screen_record` in `glsl/shared/tiles.glsl`.
pub fn screen_record(frame: &Frame, p: &SplatParams) -> ScreenQuad {
    let (inv, bx) = screen_quad(frame, p).unwrap_or((Mat3::IDENTITY, IVec4::new(0, 0, -1, -1)));
    let row = |r: usize, w: f32| [inv.x_axis[r], inv.y_axis[r], inv.z_axis[r], w];
    ScreenQuad {
        inv: [row(0, p.axis_v[3]), row(1, p.screen[1]), row(2, 0.0)],
        bx: bx.to_array(),
        emit: [p.emit[0], p.emit[1], p.emit[2], p.emit[3] * p.axis_u[3]],
    }
}

/// Inclusive tile range (x0, y0, x1, y1) of a footprint box; `None` when the box is empty.
pub fn tile_range(bx: [i32; 4]) -> Option<[u32; 4]> {
    let tile = [RASTER_TILE_W, RASTER_TILE_H, RASTER_TILE_W, RASTER_TILE_H];
    (bx[0] <= bx[2] && bx[1] <= bx[3]).then(|| [0, 1, 2, 3].map(|i| bx[i].max(0) as u32 / tile[i]))
}

fn chunk_entries(push: &FootprintPush, chunk: u32) -> std::ops::Range<usize> {
    let size = push.count.div_ceil(push.chunks.max(1));
    (chunk * size).min(push.count) as usize..((chunk + 1) * size).min(push.count) as usize
}

/// Calls `f(tile)` for every tile the footprint box overlaps, row by row.
fn each_tile(frame: &Frame, bx: [i32; 4], mut f: impl FnMut(usize)) {
    let tiles_x = tile_grid(frame).0;
    if let Some([x0, y0, x1, y1]) = tile_range(bx) {
        for ty in y0..=y1 {
            for tx in x0..=x1 {
                f((ty * tiles_x + tx) as usize);
            }
        }
    }
}

/// The count matrix arrives zeroed (the GPU fills it first).
pub fn tile_count(inputs: &FootprintInputs<'_>, push: &FootprintPush, counts: &mut [u32], quads: &mut [ScreenQuad]) {
    let chunks = push.chunks as usize;
    for chunk in 0..push.chunks {
        for e in chunk_entries(push, chunk) {
            let splat = inputs.draw_list[e] as usize;
            let q = screen_record(inputs.frame, &inputs.params[splat]);
            quads[splat] = q;
            each_tile(inputs.frame, q.bx, |t| counts[t * chunks + chunk as usize] += 1);
        }
    }
}

/// Each tile's row of the count matrix becomes offsets within the tile; `tile_start[t]` its total.
pub fn tile_scan(inputs: &FootprintInputs<'_>, push: &FootprintPush, counts: &mut [u32], tile_start: &mut [u32]) {
    let (tx, ty) = tile_grid(inputs.frame);
    let chunks = push.chunks as usize;
    for t in 0..(tx * ty) as usize {
        let mut carry = 0u32;
        for c in &mut counts[t * chunks..(t + 1) * chunks] {
            let v = *c;
            *c = carry;
            carry += v;
        }
        tile_start[t] = carry;
    }
}

/// Exclusive prefix sum of the tiles' totals; `tile_start[tiles]` gets the total.
pub fn tile_offsets(inputs: &FootprintInputs<'_>, tile_start: &mut [u32]) {
    let (tx, ty) = tile_grid(inputs.frame);
    let tiles = (tx * ty) as usize;
    let mut carry = 0u32;
    for v in &mut tile_start[..tiles] {
        let c = *v;
        *v = carry;
        carry += c;
    }
    tile_start[tiles] = carry;
}

pub fn tile_scatter(
    inputs: &FootprintInputs<'_>,
    push: &FootprintPush,
    quads: &[ScreenQuad],
    tile_start: &[u32],
    counts: &mut [u32],
    entries: &mut [u32],
) {
    let chunks = push.chunks as usize;
    for chunk in 0..push.chunks {
        for e in chunk_entries(push, chunk) {
            let splat = inputs.draw_list[e];
            each_tile(inputs.frame, quads[splat as usize].bx, |t| {
                let cell = t * chunks + chunk as usize;
                entries[(tile_start[t] + counts[cell]) as usize] = splat;
                counts[cell] += 1;
            });
        }
    }
}

/// Composite segment `push.first` of every tile's list into `image` (segment 0 overwrites it
/// unless `push.carry` marks a later batch, later ones carry on from it), pixel by pixel: every pixel takes its tile's entries in list
/// order, whichever GPU lane composites it.
pub fn tile_composite(
    inputs: &FootprintInputs<'_>,
    push: &FootprintPush,
    quads: &[ScreenQuad],
    tile_start: &[u32],
    entries: &[u32],
    image: &mut ImageF32,
) {
    let tiles_x = tile_grid(inputs.frame).0;
    let btf = push.back_to_front != 0;
    let terminate = !btf && push.occluded > 0.0;
    let width = image.width;
    image.pixels.par_iter_mut().enumerate().for_each(|(i, px)| {
        let (x, y) = ((i as u32 % width) as i32, (i as u32 / width) as i32);
        let tile = ((y as u32 / RASTER_TILE_H) * tiles_x + x as u32 / RASTER_TILE_W) as usize;
        // Segment `push.first`: TILE_SEGMENT entries of the list, carrying the pixel across segments.
        let list_end = tile_start[tile + 1] as usize;
        let begin = tile_start[tile] as usize + (push.first * TILE_SEGMENT) as usize;
        let carry = push.first > 0 || push.carry != 0;
        if carry && begin >= list_end {
            return;
        }
        let end = list_end.min(begin + TILE_SEGMENT as usize);
        let mut acc = if carry { *px } else { [0.0f32; 4] };
        for &splat in &entries[begin..end] {
            if terminate && 1.0 - acc[3] <= push.occluded {
                break;
            }
            let q = &quads[splat as usize];
            if x < q.bx[0] || x > q.bx[2] || y < q.bx[1] || y > q.bx[3] {
                continue;
            }
            let p = Vec3::new(x as f32 + 0.5, y as f32 + 0.5, 1.0);
            let row = |r: usize| Vec3::new(q.inv[r][0], q.inv[r][1], q.inv[r][2]).dot(p);
            let uv = Vec2::new(row(0), row(1)) / row(2);
            if uv.x.abs() > 1.0 || uv.y.abs() > 1.0 {
                continue;
            }
            let sweep = Sweep { stretch: q.inv[0][3], bend: q.inv[1][3], profile: inputs.frame.sweep[1] };
            let a = footprint_value(inputs.table, uv, sweep, q.emit[3], true);
            if a <= 0.0 {
                continue;
            }
            let src = [q.emit[0] * a, q.emit[1] * a, q.emit[2] * a, a];
            if btf {
                acc = [0, 1, 2, 3].map(|c| src[c] + (1.0 - a) * acc[c]);
            } else {
                let r = 1.0 - acc[3];
                acc = [0, 1, 2, 3].map(|c| acc[c] + r * src[c]);
            }
        }
        *px = acc;
    });
}

pub(crate) fn tile_count_stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut quads) = (b.take(Res::TileCounts), b.take(Res::Quads));
    tile_count(&b.inputs(d.list), &d.push_as(), &mut counts, bytemuck::cast_slice_mut(&mut quads));
    b.put(Res::TileCounts, counts);
    b.put(Res::Quads, quads);
    Ok(())
}

pub(crate) fn tile_scan_stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut start) = (b.take(Res::TileCounts), b.take(Res::TileStart));
    tile_scan(&b.inputs(d.list), &d.push_as(), &mut counts, &mut start);
    b.put(Res::TileCounts, counts);
    b.put(Res::TileStart, start);
    Ok(())
}

pub(crate) fn tile_offsets_stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut start = b.take(Res::TileStart);
    tile_offsets(&b.inputs(d.list), &mut start);
    b.put(Res::TileStart, start);
    Ok(())
}

pub(crate) fn tile_scatter_stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut entries) = (b.take(Res::TileCounts), b.take(Res::TileEntries));
    let (inputs, push) = (b.inputs(d.list), d.push_as());
    tile_scatter(&inputs, &push, b.get(Res::Quads), b.get(Res::TileStart), &mut counts, &mut entries);
    b.put(Res::TileCounts, counts);
    b.put(Res::TileEntries, entries);
    Ok(())
}

pub(crate) fn tile_composite_stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut image = std::mem::replace(&mut b.accum, ImageF32::new(0, 0));
    let (inputs, push) = (b.inputs(d.list), d.push_as());
    tile_composite(&inputs, &push, b.get(Res::Quads), b.get(Res::TileStart), b.get(Res::TileEntries), &mut image);
    b.accum = image;
    Ok(())
}
