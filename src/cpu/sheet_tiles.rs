//! Mirror of `sheet_tiles.comp`.
use super::bindings::Bindings;
use super::footprint::{entry, screen_quad, FootprintInputs};
use crate::constants::COMPOSITE_TILE;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::FootprintPush;
use glam::{IVec2, Mat4, Vec2, Vec4};

/// For each composite tile, the lowest sheet whose footprints reach it (`u32::MAX`: none) in
/// `tiles[..n]` and the highest + 1 in `tiles[n..]`, over `push.count` entries from 0 (the push's
/// `rank_base` 0 and `rank_dir` +1 make entry layers global sheets). `points`: the raster draws
/// point sprites. Boxes grow by a pixel, as on the GPU.
pub fn sheet_tiles(inputs: &FootprintInputs<'_>, push: &FootprintPush, points: bool, tiles: &mut [u32]) {
    let size = Vec2::new(inputs.frame.blur[2], inputs.frame.blur[3]);
    let tiles_x = (size.x as u32).div_ceil(COMPOSITE_TILE);
    let n = (tiles_x * (size.y as u32).div_ceil(COMPOSITE_TILE)) as usize;
    let (lows, highs) = tiles.split_at_mut(n);
    lows.fill(u32::MAX);
    highs.fill(0);
    let vp = Mat4::from_cols_array_2d(&inputs.frame.view_proj);
    for e in 0..push.count {
        let Some((splat, sheet, _)) = entry(inputs, push, e) else { continue };
        let p = &inputs.params[splat];
        let bx = if points {
            let c = vp * Vec4::new(p.center[0], p.center[1], p.center[2], 1.0);
            if c.w <= 0.0 {
                continue;
            }
            let s = ((Vec2::new(c.x, c.y) / c.w * 0.5 + 0.5) * size).clamp(Vec2::splat(-1e6), Vec2::splat(1e6));
            let half = p.screen[2].max(0.5);
            let (a, b) = ((s - half).floor(), (s + half).floor());
            [a.x as i32, a.y as i32, b.x as i32, b.y as i32]
        } else {
            let Some((_, b)) = screen_quad(inputs.frame, p) else { continue };
            b.to_array()
        };
        let last = size.as_ivec2() - 1;
        if bx[0] > last.x + 1 || bx[1] > last.y + 1 || bx[2] < -1 || bx[3] < -1 {
            continue;
        }
        let lo = (IVec2::new(bx[0], bx[1]) - 1).clamp(IVec2::ZERO, last).as_uvec2() / COMPOSITE_TILE;
        let hi = (IVec2::new(bx[2], bx[3]) + 1).clamp(IVec2::ZERO, last).as_uvec2() / COMPOSITE_TILE;
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                let t = (y * tiles_x + x) as usize;
                lows[t] = lows[t].min(sheet as u32);
                highs[t] = highs[t].max(sheet as u32 + 1);
            }
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let mut tiles = b.take(Res::SheetTiles);
    sheet_tiles(&b.inputs(d.list), &d.push_as(), v.spec.get(1) == Some(&1), &mut tiles);
    b.put(Res::SheetTiles, tiles);
    Ok(())
}
