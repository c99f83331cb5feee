//! Mirror of `raycast.comp`, in the shader's f32 arithmetic, with an optional per-pixel jitter of
//! the first sample (CPU only) for supersampled references.
use super::ImageF32;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::RaycastParams;

use super::bindings::Bindings;
use crate::volume::DenseField;
use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

/// Mirror of `to_index` in `raycast.comp`: world offset `d` in index units.
fn to_index(rc: &RaycastParams, d: Vec3) -> Vec3 {
    let (s, h) = (rc.inv_spacing, rc.inv_shear);
    Vec3::new(d.x * s[0] + d.y * h[0] + d.z * h[1], d.y * s[1] + d.z * h[2], d.z * s[2])
}

/// A pixel's ray as `raycast.comp` casts it: from `a` (on the near plane) along unit `dir`, cut
/// to [t0, t1] by the sampled box and the clipping planes.
pub(crate) struct Ray {
    pub a: Vec3,
    pub dir: Vec3,
    pub t0: f32,
    pub t1: f32,
    /// `a` and `dir` in index units.
    pub ia: Vec3,
    pub idir: Vec3,
    origin: Vec3,
    rc: RaycastParams,
}

impl Ray {
    /// The index-space point at `t`.
    pub fn index(&self, t: f32) -> Vec3 {
        to_index(&self.rc, self.a + self.dir * t - self.origin)
    }
}

/// The ray through pixel position (`x`, `y`) (pixels from the top left; a centre at + 0.5), or
/// `None` where the box and the planes leave none of it.
pub(crate) fn ray_index(rc: &RaycastParams, x: f32, y: f32) -> Option<Ray> {
    let (w, h) = (rc.image[0], rc.image[1]);
    let inv = Mat4::from_cols_array_2d(&rc.inv_view_proj);
    let (lo, hi) = (Vec3::from_slice(&rc.box_min[..3]), Vec3::from_slice(&rc.box_max[..3]));
    let origin = Vec3::from_slice(&rc.origin[..3]);
    let ndc = Vec3::new(x / w as f32 * 2.0 - 1.0, y / h as f32 * 2.0 - 1.0, 0.0);
    let a4 = inv * Vec4::new(ndc.x, ndc.y, 0.0, 1.0);
    let b4 = inv * Vec4::new(ndc.x, ndc.y, 1.0, 1.0);
    let a = a4.truncate() / a4.w;
    let d = b4.truncate() / b4.w - a;
    let len = d.length();
    let dir = d / len;
    let (ia, idir) = (to_index(rc, a - origin), to_index(rc, dir));
    let (mut t0, mut t1) = (0.0f32, len);
    for ax in 0..3 {
        if idir[ax].abs() < 1e-30 {
            if ia[ax] < lo[ax] || ia[ax] > hi[ax] {
                t1 = -1.0;
            }
            continue;
        }
        let p = (lo[ax] - ia[ax]) / idir[ax];
        let q = (hi[ax] - ia[ax]) / idir[ax];
        t0 = t0.max(p.min(q));
        t1 = t1.min(p.max(q));
    }
    // Mirror of the clipping in raycast.comp.
    for c in &rc.clip[..rc.image[3] as usize] {
        let n = Vec3::new(c[0], c[1], c[2]);
        let (na, nd) = (n.dot(a) + c[3], n.dot(dir));
        if nd.abs() < 1e-30 {
            if na < 0.0 {
                t1 = -1.0;
            }
        } else if nd > 0.0 {
            t0 = t0.max(-na / nd);
        } else {
            t1 = t1.min(-na / nd);
        }
    }
    (t1 > t0).then_some(Ray { a, dir, t0, t1, ia, idir, origin, rc: *rc })
}

/// Mirror of `skip_brick` in `raycast.comp`.
#[allow(clippy::too_many_arguments)]
fn skip_brick(rc: &RaycastParams, b: [i32; 3], nb: [i32; 3], a: Vec3, dir: Vec3, t0: f32, offset: f32, s: u32) -> u32 {
    let bs = rc.image[2] as f32;
    let lo = Vec3::new(b[0] as f32, b[1] as f32, b[2] as f32) * bs;
    let hi = lo + bs;
    let mut t_exit = 3.4e38f32;
    for ax in 0..3 {
        if dir[ax] > 0.0 && b[ax] < nb[ax] - 1 {
            t_exit = t_exit.min((hi[ax] - a[ax]) / dir[ax]);
        }
        if dir[ax] < 0.0 && b[ax] > 0 {
            t_exit = t_exit.min((lo[ax] - a[ax]) / dir[ax]);
        }
    }
    let step = rc.box_min[3];
    let next = ((t_exit - 1e-3 * step - t0) / step - offset).ceil();
    if next > (s + 1) as f32 {
        if next < 4.0e9 {
            next as u32
        } else {
            u32::MAX
        }
    } else {
        s + 1
    }
}

/// Mirror of `trilinear` in `glsl/shared/trilinear.glsl`.
pub fn trilinear(field: &DenseField, u: Vec3) -> [f32; 4] {
    trilinear_by(&|i, j, k| field.at(i, j, k), u)
}

/// `trilinear` over any voxel lookup (picking reads a bricked store through one).
pub(crate) fn trilinear_by(voxel: &impl Fn(i64, i64, i64) -> [f32; 4], u: Vec3) -> [f32; 4] {
    let b = u.floor();
    let f = u - b;
    let (i, j, k) = (b.x as i64, b.y as i64, b.z as i64);
    let lerp = |p: [f32; 4], q: [f32; 4], t: f32| [0, 1, 2, 3].map(|c| p[c] + (q[c] - p[c]) * t);
    let x00 = lerp(voxel(i, j, k), voxel(i + 1, j, k), f.x);
    let x10 = lerp(voxel(i, j + 1, k), voxel(i + 1, j + 1, k), f.x);
    let x01 = lerp(voxel(i, j, k + 1), voxel(i + 1, j, k + 1), f.x);
    let x11 = lerp(voxel(i, j + 1, k + 1), voxel(i + 1, j + 1, k + 1), f.x);
    lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z)
}

/// `jitter`: `Some(seed)` offsets each pixel's samples by a hashed fraction of a step.
/// `bricks`: `field.brick_occupancy(rc.image[2])` when skipping is on.
pub fn raycast(rc: &RaycastParams, field: &DenseField, bricks: &[u32], jitter: Option<u64>) -> ImageF32 {
    let (w, h) = (rc.image[0], rc.image[1]);
    let mut pixels = vec![[0.0f32; 4]; (w * h) as usize];
    pixels.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let (mut col, mut trans) = ([0.0f32; 3], 1.0f32);
            // A projection mode's (key, weight) (raycast.comp).
            let mode = rc.inv_spacing[3] as u32;
            let mut acc = [0.0f32; 2];
            // The isosurface's last sample below it (t, value), and whether it crossed (1), is
            // below (0) or started inside (-1).
            let (mut prev, mut hit) = ((0.0f32, 0.0f32), 0.0f32);
            if let Some(Ray { a, dir, t0, t1, ia, idir, origin, .. }) = ray_index(rc, x as f32 + 0.5, y as f32 + 0.5) {
                let step = rc.box_min[3];
                let n = (((t1 - t0) / step).ceil() as u32).min(rc.dims[3]);
                let offset = match jitter {
                    Some(seed) => hash01(seed, x as u64, y as u64),
                    None => 0.5,
                };
                let bs = rc.image[2];
                let nb = [0, 1, 2].map(|ax| (rc.dims[ax] as i32 + bs as i32 - 1) / (bs as i32).max(1));
                let mut s = 0u32;
                while s < n {
                    // The last sample covers only what is left of the ray (a clip plane or a
                    // crop's face cuts it there; a cast of tiles would count the rest twice).
                    let seg = if jitter.is_none() { step.min(t1 - t0 - s as f32 * step).max(0.0) } else { step };
                    let u = to_index(rc, a + dir * (t0 + s as f32 * step + offset * seg) - origin);
                    if bs > 0 {
                        let b = [0, 1, 2].map(|ax| ((u[ax] / bs as f32).floor() as i32).clamp(0, nb[ax] - 1));
                        if bricks[((b[2] * nb[1] + b[1]) * nb[0] + b[0]) as usize] == 0 {
                            s = skip_brick(rc, b, nb, ia, idir, t0, offset, s);
                            continue;
                        }
                    }
                    s += 1;
                    let v = trilinear(field, u);
                    if mode == crate::options::Mode::Iso.code() {
                        let iso = rc.inv_shear[3];
                        let t = t0 + (s - 1) as f32 * step + offset * seg;
                        if v[0] < iso || hit < 0.0 {
                            hit = if v[0] < iso { 0.0 } else { -1.0 };
                            prev = (t, v[0]);
                            continue;
                        }
                        if s == 1 {
                            hit = -1.0;
                            continue;
                        }
                        let th = prev.0 + (iso - prev.1) / (v[0] - prev.1) * (t - prev.0);
                        let h = to_index(rc, a + dir * th - origin);
                        let cell = h.floor();
                        let (ci, cj, ck) = (cell.x as i64, cell.y as i64, cell.z as i64);
                        let corner: [f32; 8] = std::array::from_fn(|c| {
                            field.at(ci + (c & 1) as i64, cj + (c >> 1 & 1) as i64, ck + (c >> 2 & 1) as i64)[0]
                        });
                        let g = super::iso_splats::cell_gradient(&corner, h - cell);
                        let (is, ih) = (rc.inv_spacing, rc.inv_shear);
                        let gw =
                            Vec3::new(is[0] * g.x, ih[0] * g.x + is[1] * g.y, ih[1] * g.x + ih[2] * g.y + is[2] * g.z);
                        let gl = gw.length();
                        acc = super::iso_splats::surface_light(if gl > 0.0 { gw / gl } else { -dir }, dir);
                        hit = 1.0;
                        break;
                    }
                    if v[3] <= 0.0 {
                        continue;
                    }
                    let length = rc.origin[3] * seg;
                    match mode {
                        1 => acc = [acc[0].max(v[0]), acc[1].max(v[1])],
                        2 => acc = [acc[0].max(v[1] - v[0]), acc[1].max(v[1])],
                        3 => acc = [acc[0] + v[0] * length, acc[1] + v[1] * length],
                        4 => acc[0] += v[3] * length,
                        _ => {}
                    }
                    if mode != 0 {
                        continue;
                    }
                    let alpha = 1.0 - (-v[3] * length).exp();
                    for c in 0..3 {
                        col[c] += trans * alpha * (v[c] / v[3]);
                    }
                    trans *= 1.0 - alpha;
                    if trans < rc.box_max[3] {
                        break;
                    }
                }
            }
            *px = if mode != 0 { [acc[0], acc[1], hit.max(0.0), 0.0] } else { [col[0], col[1], col[2], 1.0 - trans] };
        }
    });
    ImageF32 { width: w, height: h, pixels }
}

fn hash01(seed: u64, x: u64, y: u64) -> f32 {
    let mut z = seed ^ x.wrapping_mul(0x9E3779B97F4A7C15) ^ y.wrapping_mul(0xC2B2AE3D27D4EB4F);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

pub(crate) fn stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let rc: RaycastParams = bytemuck::pod_read_unaligned(bytemuck::cast_slice(b.get::<u32>(Res::RaycastParams)));
    let mode = crate::options::Mode::ALL.into_iter().find(|m| m.code() == rc.inv_spacing[3] as u32).unwrap_or_default();
    let field = b.prep.field_for(mode)?;
    b.accum = raycast(&rc, field, &b.bricks, None);
    Ok(())
}
