//! Mirror of `tile_occlusion.comp` and of `glsl/shared/occlusion.glsl`: the occlusion map a bricked
//! frame drawn front to back builds after each wave, and the test of a pixel box against it that
//! `brick_hidden` makes for each brick (or node) of the next wave.
use super::bindings::Bindings;
use crate::constants::COMPOSITE_TILE;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{BrickPush, Frame};
use crate::image::ImageF32;
use crate::plan::tile_counts;
use glam::IVec4;

// A tile's open pixels are one bit each in two words.
const _: () = assert!(COMPOSITE_TILE * COMPOSITE_TILE == 64);

/// Most composite tiles a box may span and still be tested (larger ones are always drawn).
const MAX_BOX_TILES: i32 = 256;

/// Per composite tile the largest transmittance left in `accum`, then per tile the mask of its
/// pixels with more than `occluded` left (bit (y % 8) * 8 + x % 8; rows 0-3 in the first word).
pub fn tile_occlusion(accum: &ImageF32, occluded: f32, occlusion: &mut [u32]) {
    let (w, h) = (accum.width, accum.height);
    let (tiles_x, tiles) = tile_counts(w, h);
    for t in 0..tiles {
        let (x0, y0) = ((t % tiles_x) * COMPOSITE_TILE, (t / tiles_x) * COMPOSITE_TILE);
        let mut most = 0.0f32;
        let mut open = [0u32; 2];
        for y in y0..(y0 + COMPOSITE_TILE).min(h) {
            for x in x0..(x0 + COMPOSITE_TILE).min(w) {
                let left = 1.0 - accum.pixels[(y * w + x) as usize][3];
                most = most.max(left);
                let bit = (y - y0) * COMPOSITE_TILE + x - x0;
                if left > occluded {
                    open[bit as usize / 32] |= 1 << (bit % 32);
                }
            }
        }
        occlusion[t as usize] = most.to_bits();
        occlusion[(tiles + 2 * t) as usize] = open[0];
        occlusion[(tiles + 2 * t + 1) as usize] = open[1];
    }
}

/// Whether no pixel of the inclusive pixel `bx` (clamped to the frame) is open in `occlusion`.
pub fn box_hidden(frame: &Frame, occlusion: &[u32], bx: IVec4) -> bool {
    let (w, h) = (frame.blur[2] as u32, frame.blur[3] as u32);
    let (tiles_x, tiles) = tile_counts(w, h);
    let side = COMPOSITE_TILE as i32;
    let bx = bx.clamp(IVec4::ZERO, IVec4::new(w as i32 - 1, h as i32 - 1, w as i32 - 1, h as i32 - 1));
    let (t0x, t0y, t1x, t1y) = (bx.x / side, bx.y / side, bx.z / side, bx.w / side);
    if (t1x - t0x + 1) * (t1y - t0y + 1) > MAX_BOX_TILES {
        return false;
    }
    for ty in t0y..=t1y {
        for tx in t0x..=t1x {
            let t = (ty as u32 * tiles_x + tx as u32) as usize;
            let open = [occlusion[tiles as usize + 2 * t], occlusion[tiles as usize + 2 * t + 1]];
            if open == [0, 0] {
                continue;
            }
            // The box's part of the tile, as a mask of the same layout.
            let (ax, ay) = (bx.x.max(tx * side) - tx * side, bx.y.max(ty * side) - ty * side);
            let (zx, zy) = (bx.z.min(tx * side + side - 1) - tx * side, bx.w.min(ty * side + side - 1) - ty * side);
            let row = ((1u32 << (zx - ax + 1)) - 1) << ax;
            let mut part = [0u32; 2];
            for y in ay..=zy {
                part[y as usize / 4] |= row << (8 * (y % 4));
            }
            if open[0] & part[0] != 0 || open[1] & part[1] != 0 {
                return false;
            }
        }
    }
    true
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, _: &Variant) -> Result<()> {
    let mut occlusion = b.take(Res::Occlusion);
    let push: BrickPush = args.push_as();
    tile_occlusion(&b.accum, push.occluded, &mut occlusion);
    b.put(Res::Occlusion, occlusion);
    Ok(())
}
