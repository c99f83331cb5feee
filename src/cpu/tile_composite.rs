//! Mirror of `glsl/tile_composite.comp` (the `tile_composite` stage); shared helpers in `tile.rs`.
use super::bindings::Bindings;
use super::footprint::{footprint_value, FootprintInputs, Sweep};
use super::ImageF32;
use crate::constants::{RASTER_TILE_H, RASTER_TILE_W, TILE_SEGMENT};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{
    FootprintPush, ScreenQuad, BLEND_COMPOSITE, BLEND_MAX, BLEND_SUM, BLEND_SURFACE, BLEND_SURFACE_DEPTH,
};
use crate::plan::tile_grid;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

pub use super::footprint::PROJECT_FULL;

/// Mirror of `SURFACE_VISIBLE`: the least weight, over a footprint's centre's, of a surface disc
/// that makes a pixel's visible depth.
pub const SURFACE_VISIBLE: f32 = 0.1;

/// Mirror of `NO_SURFACE`: the first pass's depth where no disc is visible.
pub const NO_SURFACE: f32 = 3.0e38;

/// Composite segment `push.first` of every tile's list into `image` (segment 0 overwrites it
/// unless `push.carry` marks a later batch, later ones carry on from it), pixel by pixel: every pixel takes its tile's entries in list
/// order, whichever GPU lane composites it. `project`: a projection's blend (`BLEND_*`, the
/// shader's PROJECT), by maximum or sum in place of compositing; `depth_test`: the host's depth
/// hides what lies behind it (HOST_DEPTH).
#[allow(clippy::too_many_arguments)]
pub fn tile_composite(
    inputs: &FootprintInputs<'_>,
    push: &FootprintPush,
    project: u32,
    depth_test: bool,
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
        let empty = if project == BLEND_SURFACE_DEPTH { [0.0, 0.0, 0.0, NO_SURFACE] } else { [0.0f32; 4] };
        let mut acc = if carry { *px } else { empty };
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
            if depth_test && q.inv[2][3] > inputs.host_depth[i] {
                continue;
            }
            if project == BLEND_SURFACE || project == BLEND_SURFACE_DEPTH {
                // At the disc plane's depth here (inv[0][3], inv[1][3]: the depth's steps along u
                // and v): the first pass keeps the nearest visible disc's, the second sums the
                // discs within the band (emit[3]) of it.
                let still = Sweep { stretch: 0.0, bend: 0.0, profile: inputs.frame.sweep[1] };
                let w = footprint_value(inputs.table, uv, still, 1.0, false);
                let z = q.inv[2][3] + uv.x * q.inv[0][3] + uv.y * q.inv[1][3];
                if project == BLEND_SURFACE_DEPTH {
                    if w >= SURFACE_VISIBLE * inputs.table[0] {
                        acc[3] = acc[3].min(z);
                    }
                } else if w > 0.0 && (z - acc[3]).abs() <= q.emit[3] {
                    acc = [acc[0] + q.emit[0] * w, acc[1] + q.emit[1] * w, acc[2] + w, acc[3]];
                }
                continue;
            }
            let sweep = Sweep { stretch: q.inv[0][3], bend: q.inv[1][3], profile: inputs.frame.sweep[1] };
            if project == BLEND_MAX {
                let w =
                    (footprint_value(inputs.table, uv, sweep, 1.0, false) / (PROJECT_FULL * inputs.table[0])).min(1.0);
                if w > 0.0 {
                    acc = [acc[0].max(q.emit[0] * w), acc[1].max(w), acc[2], acc[3]];
                }
                continue;
            }
            if project == BLEND_SUM {
                let d = footprint_value(inputs.table, uv, sweep, q.emit[3], false);
                acc = [acc[0] + q.emit[0] * d, acc[1] + d, acc[2], acc[3]];
                continue;
            }
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

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let mut image = std::mem::replace(&mut b.accum, ImageF32::new(0, 0));
    let (inputs, push) = (b.inputs(d.list), d.push_as());
    let project = v.spec.get(4).copied().unwrap_or(BLEND_COMPOSITE);
    let depth_test = v.spec.get(5).is_some_and(|&d| d != 0);
    tile_composite(
        &inputs,
        &push,
        project,
        depth_test,
        b.get(Res::Quads),
        b.get(Res::TileStart),
        b.get(Res::TileEntries),
        &mut image,
    );
    b.accum = image;
    Ok(())
}
