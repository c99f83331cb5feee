//! Helpers the tile compositor's mirrors share (`tile_count.rs`, `tile_scan.rs`, `tile_offsets.rs`,
//! `tile_scatter.rs`, `tile_composite.rs`): screen records and tile ranges.
use super::footprint::screen_quad;
use crate::constants::{RASTER_TILE_H, RASTER_TILE_W};
use crate::gpu_types::{FootprintPush, Frame, ScreenQuad, SplatParams};
use crate::plan::tile_grid;
use glam::{IVec4, Mat3};

/// Mirror of `screen_record` in `glsl/shared/tiles.glsl`.
pub fn screen_record(frame: &Frame, p: &SplatParams) -> ScreenQuad {
    let (inv, bx) = screen_quad(frame, p).unwrap_or((Mat3::IDENTITY, IVec4::new(0, 0, -1, -1)));
    let row = |r: usize, w: f32| [inv.x_axis[r], inv.y_axis[r], inv.z_axis[r], w];
    ScreenQuad {
        inv: [row(0, p.axis_v[3]), row(1, p.screen[1]), row(2, p.screen[0])],
        bx: bx.to_array(),
        emit: [p.emit[0], p.emit[1], p.emit[2], p.emit[3] * p.axis_u[3]],
    }
}

/// Inclusive tile range (x0, y0, x1, y1) of a footprint box; `None` when the box is empty.
pub fn tile_range(bx: [i32; 4]) -> Option<[u32; 4]> {
    let tile = [RASTER_TILE_W, RASTER_TILE_H, RASTER_TILE_W, RASTER_TILE_H];
    (bx[0] <= bx[2] && bx[1] <= bx[3]).then(|| [0, 1, 2, 3].map(|i| bx[i].max(0) as u32 / tile[i]))
}

pub(crate) fn chunk_entries(push: &FootprintPush, chunk: u32) -> std::ops::Range<usize> {
    let size = push.count.div_ceil(push.chunks.max(1));
    (chunk * size).min(push.count) as usize..((chunk + 1) * size).min(push.count) as usize
}

/// Calls `f(tile)` for every tile the footprint box overlaps, row by row.
pub(crate) fn each_tile(frame: &Frame, bx: [i32; 4], mut f: impl FnMut(usize)) {
    let tiles_x = tile_grid(frame).0;
    if let Some([x0, y0, x1, y1]) = tile_range(bx) {
        for ty in y0..=y1 {
            for tx in x0..=x1 {
                f((ty * tiles_x + tx) as usize);
            }
        }
    }
}
