//! Mirror of `composite.comp`.
use super::ImageF32;
use crate::constants::COMPOSITE_TILE;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::CompositePush;
use rayon::prelude::*;

use super::bindings::Bindings;

/// Mirror of `layer_range` in `composite.comp`: the batch's layers that footprints reach on tile
/// `tile`, from the per-tile sheet ranges of `sheet_tiles`.
pub fn layer_range(push: &CompositePush, sheet_tiles: &[u32], tile: usize) -> std::ops::Range<usize> {
    let (lo, hi) = (sheet_tiles[tile], sheet_tiles[push.tiles as usize + tile]);
    if hi == 0 {
        return 0..0;
    }
    let (a, b) = (lo as i64 - push.rank_base as i64, hi as i64 - 1 - push.rank_base as i64);
    let (first, last) = if push.rank_dir > 0 { (a, b) } else { (-b, -a) };
    let (first, last) = (first.max(0), last.min(push.layers as i64 - 1));
    if first > last {
        0..0
    } else {
        first as usize..last as usize + 1
    }
}

/// Composite the batch into `accum` (at each tile only the layers `sheet_tiles` says footprints
/// reach), then write each tile's largest remaining transmittance into `occlusion` (row-major
/// tiles of `COMPOSITE_TILE`² pixels).
pub fn composite(
    push: &CompositePush,
    sums: &[ImageF32],
    sheet_tiles: &[u32],
    accum: &mut ImageF32,
    occlusion: &mut [f32],
) {
    let width = push.width as usize;
    let (tile, tiles_x) = (COMPOSITE_TILE as usize, push.width.div_ceil(COMPOSITE_TILE) as usize);
    accum.pixels.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let mut acc = *px;
            let range = layer_range(push, sheet_tiles, (y / tile) * tiles_x + x / tile);
            for s in sums.iter().take(push.layers as usize).skip(range.start).take(range.len()) {
                let v = s.pixels[y * width + x];
                let t = v[3];
                if t <= 0.0 {
                    continue;
                }
                let a = 1.0 - (-t).exp();
                let k = a / t;
                let rgb = [v[0] * k, v[1] * k, v[2] * k];
                if push.back_to_front != 0 {
                    acc = [
                        rgb[0] + (1.0 - a) * acc[0],
                        rgb[1] + (1.0 - a) * acc[1],
                        rgb[2] + (1.0 - a) * acc[2],
                        a + (1.0 - a) * acc[3],
                    ];
                } else {
                    let r = 1.0 - acc[3];
                    acc = [acc[0] + r * rgb[0], acc[1] + r * rgb[1], acc[2] + r * rgb[2], acc[3] + r * a];
                }
            }
            *px = acc;
        }
    });
    occlusion.iter_mut().for_each(|o| *o = 0.0);
    for (i, p) in accum.pixels.iter().enumerate() {
        let (x, y) = (i % width, i / width);
        let o = &mut occlusion[(y / tile) * tiles_x + x / tile];
        *o = o.max(1.0 - p[3]);
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let push: CompositePush = d.push_as();
    let mut occlusion = b.take(Res::Occlusion);
    let mut accum = std::mem::replace(&mut b.accum, ImageF32::new(0, 0));
    let fixed: Vec<ImageF32>;
    let layers = if v.spec.first() == Some(&1) {
        let sums = b.get::<u32>(Res::Fixed);
        fixed = (0..push.layers as usize).map(|l| super::footprint::fixed_layer(sums, l, b.width, b.height)).collect();
        &fixed
    } else {
        &b.sums
    };
    composite(&push, layers, b.get(Res::SheetTiles), &mut accum, bytemuck::cast_slice_mut(&mut occlusion));
    b.accum = accum;
    b.put(Res::Occlusion, occlusion);
    Ok(())
}
