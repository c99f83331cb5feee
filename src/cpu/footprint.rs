//! Mirror of `footprint.vert` + `footprint.frag` and the fixed-function blend: rasterise each
//! splat's eye-facing quad by intersecting every covered pixel's ray with the quad's plane (what
//! perspective-correct interpolation computes on the GPU), weight by the footprint table, blend.
use super::ImageF32;
use crate::constants::FOOTPRINT_TABLE_SIZE;
use crate::gpu_types::{FootprintPush, Frame, Splat, SplatParams, SHEET_MODE_AXIS, SHEET_MODE_SLAB};
use glam::{DMat4, DVec3, DVec4, Mat4, Vec4};

/// How a fragment combines with the attachment (premultiplied colour).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    Over,
    Under,
    Add,
}

/// Mirror of `sample_table` in `glsl/shared/footprint_table.glsl`.
pub fn sample_table(table: &[f32], u: f32, v: f32) -> f32 {
    let n = FOOTPRINT_TABLE_SIZE as i32;
    let tx = (u * 0.5 + 0.5) * n as f32 - 0.5;
    let ty = (v * 0.5 + 0.5) * n as f32 - 0.5;
    let (fx, fy) = (tx.floor(), ty.floor());
    let (wx, wy) = (tx - fx, ty - fy);
    let c = |i: i32| i.clamp(0, n - 1) as usize;
    let (x0, x1, y0, y1) = (c(fx as i32), c(fx as i32 + 1), c(fy as i32), c(fy as i32 + 1));
    let at = |x: usize, y: usize| table[y * n as usize + x];
    let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * wx;
    let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * wx;
    top + (bottom - top) * wy
}

/// Mirror of `sample_slice_table` in `glsl/shared/footprint_table.glsl`.
pub fn sample_slice_table(table: &[f32], r: f32, z: f32) -> f32 {
    let n = FOOTPRINT_TABLE_SIZE as usize;
    let m = (n - 1) as f32;
    let (tx, ty) = (r.clamp(0.0, 1.0) * m, (z.clamp(-1.0, 1.0) * 0.5 + 0.5) * m);
    let (x0, y0) = ((tx.floor() as usize).min(n - 2), (ty.floor() as usize).min(n - 2));
    let (wx, wy) = (tx - x0 as f32, ty - y0 as f32);
    let at = |x: usize, y: usize| table[y * n + x];
    let top = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * wx;
    let bottom = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * wx;
    top + (bottom - top) * wy
}

/// The draw call's inputs, as bound on the GPU.
pub struct FootprintInputs<'a> {
    pub frame: &'a Frame,
    pub params: &'a [SplatParams],
    pub draw_list: &'a [u32],
    pub splats: &'a [Splat],
    pub sheet_rank: &'a [u32],
    pub table: &'a [f32],
    /// The kernel-slice table (slab mode).
    pub slice_table: &'a [f32],
    /// Largest transmittance left per composite tile (early termination; empty when off).
    pub occlusion: &'a [f32],
}

/// Draw `instances` quads starting at `first_instance` of the draw list into `layers`.
pub fn footprint(
    inputs: &FootprintInputs<'_>,
    push: &FootprintPush,
    blend: Blend,
    first_instance: u32,
    instances: u32,
    layers: &mut [ImageF32],
) {
    let vp = Mat4::from_cols_array_2d(&inputs.frame.view_proj);
    let inv = vp.as_dmat4().inverse();
    for inst in first_instance..first_instance + instances {
        let slab_mode = push.sheet_mode == SHEET_MODE_SLAB;
        let splat =
            if slab_mode { inputs.draw_list[2 * inst as usize] } else { inputs.draw_list[inst as usize] } as usize;
        let p = &inputs.params[splat];
        if p.center[3] == 0.0 || (push.occluded > 0.0 && occluded(inputs, p, push.occluded)) {
            continue;
        }
        let mut weight = Weight::Footprint(inputs.table);
        let layer = if slab_mode {
            let slab = inputs.draw_list[2 * inst as usize + 1];
            let radius = glam::Vec3::new(p.axis_v[0], p.axis_v[1], p.axis_v[2]).length();
            let near_face = push.slab_z0 + slab as f32 * push.slab_dz - p.screen[0];
            let faces = [near_face / radius, (near_face + push.slab_dz) / radius];
            weight = Weight::Slice(inputs.slice_table, faces);
            if push.rank_dir > 0 {
                slab.wrapping_sub(push.rank_base)
            } else {
                push.rank_base.wrapping_sub(slab)
            }
        } else if push.sheet_mode == SHEET_MODE_AXIS {
            let rank = inputs.sheet_rank[(push.rank_offset + inputs.splats[splat].ijk[push.axis as usize]) as usize];
            if push.rank_dir > 0 {
                rank.wrapping_sub(push.rank_base)
            } else {
                push.rank_base.wrapping_sub(rank)
            }
        } else {
            0
        } as usize;
        let Some(target) = layers.get_mut(layer) else { continue };
        raster_quad(p, push.sheet_mode != 0, blend, vp, &inv, weight, target);
    }
}

/// Mirror of `occluded` in `footprint.vert`: the quad lies wholly over tiles with at most
/// `threshold` transmittance left (footprints over more than 16 tiles are always drawn).
pub fn occluded(inputs: &FootprintInputs<'_>, p: &SplatParams, threshold: f32) -> bool {
    let vp = Mat4::from_cols_array_2d(&inputs.frame.view_proj);
    let size = glam::Vec2::new(inputs.frame.blur[2], inputs.frame.blur[3]);
    let (mut lo, mut hi) = (glam::Vec2::splat(1e30), glam::Vec2::splat(-1e30));
    let v3 = |v: [f32; 4]| glam::Vec3::new(v[0], v[1], v[2]);
    for (cx, cy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let q = v3(p.center) + cx * v3(p.axis_u) + cy * v3(p.axis_v);
        let c = vp * q.extend(1.0);
        if c.w <= 0.0 {
            return false;
        }
        let s = (glam::Vec2::new(c.x, c.y) / c.w * 0.5 + 0.5) * size;
        lo = lo.min(s);
        hi = hi.max(s);
    }
    let tile = crate::constants::COMPOSITE_TILE as f32;
    let tiles_x = (size.x / tile).ceil() as i64;
    let t = |v: glam::Vec2| (v.clamp(glam::Vec2::ZERO, size - 1.0) / tile).floor();
    let (t0, t1) = (t(lo), t(hi));
    if (t1.x - t0.x + 1.0) * (t1.y - t0.y + 1.0) > 16.0 {
        return false;
    }
    for y in t0.y as i64..=t1.y as i64 {
        for x in t0.x as i64..=t1.x as i64 {
            if inputs.occlusion.get((y * tiles_x + x) as usize).is_none_or(|&o| o > threshold) {
                return false;
            }
        }
    }
    true
}

/// What a fragment weighs: the whole pre-integrated footprint, or the slice between two slab
/// faces (radius units, relative to the splat's centre).
#[derive(Clone, Copy)]
enum Weight<'a> {
    Footprint(&'a [f32]),
    Slice(&'a [f32], [f32; 2]),
}

fn raster_quad(
    p: &SplatParams,
    sheet: bool,
    blend: Blend,
    vp: Mat4,
    inv: &DMat4,
    weight: Weight<'_>,
    target: &mut ImageF32,
) {
    let v3 = |v: [f32; 4]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
    let (c, au, av) = (v3(p.center), v3(p.axis_u), v3(p.axis_v));
    let (w, h) = (target.width as f64, target.height as f64);
    let (mut minx, mut maxx, mut miny, mut maxy) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (cx, cy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let q = c + cx * au + cy * av;
        let clip = vp * Vec4::new(q.x as f32, q.y as f32, q.z as f32, 1.0);
        if clip.w <= 0.0 {
            return;
        }
        let (sx, sy) = ((clip.x / clip.w * 0.5 + 0.5) as f64 * w, (clip.y / clip.w * 0.5 + 0.5) as f64 * h);
        minx = minx.min(sx);
        maxx = maxx.max(sx);
        miny = miny.min(sy);
        maxy = maxy.max(sy);
    }
    let x0 = (minx - 0.5).ceil().max(0.0) as i64;
    let x1 = (maxx - 0.5).floor().min(w - 1.0) as i64;
    let y0 = (miny - 0.5).ceil().max(0.0) as i64;
    let y1 = (maxy - 0.5).floor().min(h - 1.0) as i64;
    let n = au.cross(av);
    let (uu, vv) = (au.length_squared(), av.length_squared());
    let energy = p.axis_u[3];
    for y in y0..=y1 {
        for x in x0..=x1 {
            let ndc = DVec4::new((x as f64 + 0.5) / w * 2.0 - 1.0, (y as f64 + 0.5) / h * 2.0 - 1.0, 0.0, 1.0);
            let a = *inv * ndc;
            let b = *inv * DVec4::new(ndc.x, ndc.y, 1.0, 1.0);
            let (a, b) = (a.truncate() / a.w, b.truncate() / b.w);
            let dir = b - a;
            let denom = dir.dot(n);
            if denom.abs() < 1e-30 {
                continue;
            }
            let hit = a + dir * ((c - a).dot(n) / denom);
            let d = hit - c;
            let (u, v) = (d.dot(au) / uu, d.dot(av) / vv);
            if u.abs() > 1.0 || v.abs() > 1.0 {
                continue;
            }
            let stretch = p.axis_v[3];
            let along = ((u.abs() as f32) * (1.0 + stretch) - stretch).max(0.0);
            let w = match weight {
                Weight::Footprint(table) => sample_table(table, along, v as f32),
                Weight::Slice(table, [za, zb]) => {
                    let r = (along * along + (v * v) as f32).sqrt();
                    sample_slice_table(table, r, zb) - sample_slice_table(table, r, za)
                }
            };
            let tau = p.emit[3] * energy * w;
            if tau <= 0.0 {
                continue;
            }
            let src = if sheet {
                [p.emit[0] * tau, p.emit[1] * tau, p.emit[2] * tau, tau]
            } else {
                let a = 1.0 - (-tau).exp();
                [p.emit[0] * a, p.emit[1] * a, p.emit[2] * a, a]
            };
            let dst = &mut target.pixels[(y as u32 * target.width + x as u32) as usize];
            match blend {
                Blend::Over => {
                    let k = 1.0 - src[3];
                    *dst = [0, 1, 2, 3].map(|i| src[i] + k * dst[i]);
                }
                Blend::Under => {
                    let k = 1.0 - dst[3];
                    *dst = [0, 1, 2, 3].map(|i| k * src[i] + dst[i]);
                }
                Blend::Add => *dst = [0, 1, 2, 3].map(|i| src[i] + dst[i]),
            }
        }
    }
}
