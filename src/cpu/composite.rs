//! Mirror of `composite.comp`.
use super::ImageF32;
use crate::constants::COMPOSITE_TILE;
use crate::gpu_types::CompositePush;
use rayon::prelude::*;

/// Composite the batch into `accum`, then write each tile's largest remaining transmittance into
/// `occlusion` (row-major tiles of `COMPOSITE_TILE`² pixels).
pub fn composite(push: &CompositePush, sums: &[ImageF32], accum: &mut ImageF32, occlusion: &mut [f32]) {
    let width = push.width as usize;
    accum.pixels.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let mut acc = *px;
            for s in sums.iter().take(push.layers as usize) {
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
    let (tile, tiles_x) = (COMPOSITE_TILE as usize, push.width.div_ceil(COMPOSITE_TILE) as usize);
    occlusion.iter_mut().for_each(|o| *o = 0.0);
    for (i, p) in accum.pixels.iter().enumerate() {
        let (x, y) = (i % width, i / width);
        let o = &mut occlusion[(y / tile) * tiles_x + x / tile];
        *o = o.max(1.0 - p[3]);
    }
}
