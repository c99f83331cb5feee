//! Mirrors of the compute per-splat compositing stages: `tile_count.comp`, `tile_scan.comp`,
//! `tile_scatter.comp` (a stable counting sort of the draw list into screen tiles, so every tile's
//! list keeps the PBTF order) and `tile_composite.comp` (each tile composites its list per pixel,
//! front to back with early termination or back to front).
use super::footprint::{quad_uv, screen_quad, FootprintInputs};
use super::ImageF32;
use crate::constants::{RASTER_TILE, TILE_CHUNK};
use crate::error::Result;
use crate::gpu_types::{FootprintPush, Frame, SplatParams};

/// Tiles across and down an image of the frame's size.
pub fn tile_grid(frame: &Frame) -> (u32, u32) {
    ((frame.blur[2] as u32).div_ceil(RASTER_TILE), (frame.blur[3] as u32).div_ceil(RASTER_TILE))
}

/// Inclusive tile range (x0, y0, x1, y1) of a splat's footprint box; `None` when it covers no pixel.
pub fn tile_range(frame: &Frame, p: &SplatParams) -> Option<[u32; 4]> {
    let (_, b) = screen_quad(frame, p)?;
    Some([b.x, b.y, b.z, b.w].map(|v| v as u32 / RASTER_TILE))
}

fn chunk_entries(push: &FootprintPush, chunk: u32) -> std::ops::Range<usize> {
    (chunk * TILE_CHUNK) as usize..((chunk + 1) * TILE_CHUNK).min(push.count) as usize
}

/// Calls `f(tile)` for every tile the entry's footprint overlaps, row by row.
fn each_tile(frame: &Frame, p: &SplatParams, mut f: impl FnMut(usize)) {
    let tiles_x = tile_grid(frame).0;
    if let Some([x0, y0, x1, y1]) = tile_range(frame, p) {
        for ty in y0..=y1 {
            for tx in x0..=x1 {
                f((ty * tiles_x + tx) as usize);
            }
        }
    }
}

pub fn tile_count(inputs: &FootprintInputs<'_>, push: &FootprintPush, counts: &mut [u32]) {
    let (tx, ty) = tile_grid(inputs.frame);
    let chunks = push.chunks as usize;
    for chunk in 0..push.chunks {
        for t in 0..(tx * ty) as usize {
            counts[t * chunks + chunk as usize] = 0;
        }
        for e in chunk_entries(push, chunk) {
            let p = &inputs.params[inputs.draw_list[e] as usize];
            each_tile(inputs.frame, p, |t| counts[t * chunks + chunk as usize] += 1);
        }
    }
}

/// Exclusive prefix sum of the count matrix; `tile_start` gets each tile's first entry and the total.
pub fn tile_scan(inputs: &FootprintInputs<'_>, push: &FootprintPush, counts: &mut [u32], tile_start: &mut [u32]) {
    let (tx, ty) = tile_grid(inputs.frame);
    let tiles = (tx * ty) as usize;
    let mut carry = 0u32;
    for c in counts.iter_mut().take(tiles * push.chunks as usize) {
        let v = *c;
        *c = carry;
        carry += v;
    }
    for t in 0..tiles {
        tile_start[t] = counts[t * push.chunks as usize];
    }
    tile_start[tiles] = carry;
}

pub fn tile_scatter(inputs: &FootprintInputs<'_>, push: &FootprintPush, counts: &mut [u32], entries: &mut [u32]) {
    let chunks = push.chunks as usize;
    for chunk in 0..push.chunks {
        for e in chunk_entries(push, chunk) {
            let splat = inputs.draw_list[e];
            each_tile(inputs.frame, &inputs.params[splat as usize], |t| {
                let cell = t * chunks + chunk as usize;
                entries[counts[cell] as usize] = splat;
                counts[cell] += 1;
            });
        }
    }
}

/// Composite every tile's list into `image` (which it overwrites).
pub fn tile_composite(
    inputs: &FootprintInputs<'_>,
    push: &FootprintPush,
    tile_start: &[u32],
    entries: &[u32],
    image: &mut ImageF32,
) {
    let frame = inputs.frame;
    let tiles_x = tile_grid(frame).0;
    let btf = push.back_to_front != 0;
    let terminate = !btf && push.occluded > 0.0;
    let quads: Vec<_> = entries.iter().map(|&s| screen_quad(frame, &inputs.params[s as usize])).collect();
    let width = image.width;
    for (i, px) in image.pixels.iter_mut().enumerate() {
        let (x, y) = (i as u32 % width, i as u32 / width);
        let tile = ((y / RASTER_TILE) * tiles_x + x / RASTER_TILE) as usize;
        let mut acc = [0.0f32; 4];
        for k in tile_start[tile] as usize..tile_start[tile + 1] as usize {
            if terminate && 1.0 - acc[3] <= push.occluded {
                break;
            }
            let Some((inv, b)) = quads[k] else { continue };
            let (xi, yi) = (x as i32, y as i32);
            if xi < b.x || xi > b.z || yi < b.y || yi > b.w {
                continue;
            }
            let uv = quad_uv(&inv, xi, yi);
            if uv.x.abs() > 1.0 || uv.y.abs() > 1.0 {
                continue;
            }
            let p = &inputs.params[entries[k] as usize];
            let tau = p.emit[3] * p.axis_u[3] * super::footprint::footprint_weight(inputs.table, uv, p.axis_v[3]);
            if tau <= 0.0 {
                continue;
            }
            let a = 1.0 - (-tau).exp();
            let src = [p.emit[0] * a, p.emit[1] * a, p.emit[2] * a, a];
            if btf {
                acc = [0, 1, 2, 3].map(|c| src[c] + (1.0 - a) * acc[c]);
            } else {
                let r = 1.0 - acc[3];
                acc = [0, 1, 2, 3].map(|c| acc[c] + r * src[c]);
            }
        }
        *px = acc;
    }
}

/// The whole binning on the CPU mirrors, sizes checked against the limits before allocating:
/// (tile_start, entries).
pub fn tile_bins_cpu(inputs: &FootprintInputs<'_>, push: &FootprintPush) -> Result<(Vec<u32>, Vec<u32>)> {
    let (tx, ty) = tile_grid(inputs.frame);
    let tiles = (tx * ty) as usize;
    let cells = crate::raster::check_tile_cells(tiles as u64, push.chunks)?;
    let mut counts = vec![0u32; cells as usize];
    let mut start = vec![0u32; tiles + 1];
    tile_count(inputs, push, &mut counts);
    tile_scan(inputs, push, &mut counts, &mut start);
    crate::raster::check_tile_entries(start[tiles] as u64)?;
    let mut entries = vec![0u32; start[tiles] as usize];
    tile_scatter(inputs, push, &mut counts, &mut entries);
    Ok((start, entries))
}
