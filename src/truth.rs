//! The reference images every method is scored against (see docs/MODEL.md).
//!
//! [`volumetric_summation`] is the volumetric summation buffer of section 1.2.2.2, which Westover
//! proposed and never built: the whole volume is reconstructed as the sum of the voxels' 3D kernels
//! (optical depth and emission both), and every pixel's column is integrated front to back with
//! the emission–absorption model at a depth step of at most a quarter voxel, in f64. It does not
//! store the m×m×n buffer: each column is integrated as it is reconstructed.
//!
//! ```
//! use voxsplat::{scene, truth::{volumetric_summation, TruthOptions}, Camera};
//! // The volumetric-summation truth the splatted frames are measured against (chapter 4).
//! let set = scene::build("cube40")?;
//! let camera = Camera::framing(set.grid(), 16, 16);
//! let truth = volumetric_summation(&set, &camera, &TruthOptions::default())?;
//! assert!(truth.pixels.iter().any(|p| p[3] > 0.0));
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::image::{Downsample, ImageF32};
use crate::kernel::Kernel;
use crate::volume::SplatSet;
pub use crate::volume::{DenseField, MAX_DENSE_BYTES};
use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};
use rayon::prelude::*;

/// How the continuous volume is rebuilt from the voxels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reconstruction {
    /// The splatting kernel (radially symmetric, radius in voxel spacings).
    Kernel(Kernel),
    /// Trilinear interpolation: a separable tent kernel, what the ray casters sample.
    Trilinear,
}

impl Reconstruction {
    /// The reconstruction's support radius in voxel spacings.
    pub fn radius(self) -> f64 {
        match self {
            Reconstruction::Kernel(k) => k.radius() as f64,
            Reconstruction::Trilinear => 1.0,
        }
    }
}

/// Options of the reference integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthOptions {
    /// How the samples between voxels are reconstructed.
    pub reconstruction: Reconstruction,
    /// Samples per voxel spacing along each ray (at least 4).
    pub oversampling: u32,
    /// Rays stop once their transmittance falls below this.
    pub min_transmittance: f64,
}

impl Default for TruthOptions {
    fn default() -> Self {
        Self { reconstruction: Reconstruction::Kernel(Kernel::Gaussian), oversampling: 4, min_transmittance: 1e-7 }
    }
}

/// The truth rendered at `factor`× the camera's size and box-filtered down: a supersampled
/// reference for anti-aliasing (chapter 3).
pub fn supersampled(set: &SplatSet, camera: &Camera, factor: u32, opts: &TruthOptions) -> Result<ImageF32> {
    supersampled_with(set, camera, factor, Downsample::Box, opts)
}

/// The truth rendered at `factor`× the camera's size and brought down by `filter`.
pub fn supersampled_with(
    set: &SplatSet,
    camera: &Camera,
    factor: u32,
    filter: Downsample,
    opts: &TruthOptions,
) -> Result<ImageF32> {
    if factor == 0 || factor > 16 {
        return Err(Error::InvalidArgument("supersampling factor must be in 1..=16".into()));
    }
    let big = camera.supersampled(factor);
    let img = volumetric_summation(set, &big, opts)?;
    Ok(crate::image::downsample(&img, factor as usize, filter))
}

/// The ray through pixel (x, y)'s centre: origin on the near plane, unit direction, length to far.
pub fn pixel_ray(inv: &DMat4, x: u32, y: u32, width: u32, height: u32) -> (DVec3, DVec3, f64) {
    let nx = (x as f64 + 0.5) / width as f64 * 2.0 - 1.0;
    let ny = (y as f64 + 0.5) / height as f64 * 2.0 - 1.0;
    let a = *inv * DVec4::new(nx, ny, 0.0, 1.0);
    let b = *inv * DVec4::new(nx, ny, 1.0, 1.0);
    let (a, b) = (a.truncate() / a.w, b.truncate() / b.w);
    let d = b - a;
    let len = d.length();
    (a, d / len, len)
}

/// Entry and exit distances of a ray through an axis-aligned box, if it hits.
pub fn slab(origin: DVec3, dir: DVec3, lo: DVec3, hi: DVec3, t_max: f64) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, t_max);
    for a in 0..3 {
        if dir[a].abs() < 1e-300 {
            if origin[a] < lo[a] || origin[a] > hi[a] {
                return None;
            }
            continue;
        }
        let (p, q) = ((lo[a] - origin[a]) / dir[a], (hi[a] - origin[a]) / dir[a]);
        t0 = t0.max(p.min(q));
        t1 = t1.min(p.max(q));
    }
    (t1 > t0).then_some((t0, t1))
}

/// The volumetric summation buffer image: premultiplied RGBA.
pub fn volumetric_summation(set: &SplatSet, camera: &Camera, opts: &TruthOptions) -> Result<ImageF32> {
    camera.validate()?;
    if set.coordinates().is_some() {
        return Err(Error::Unsupported("the truth samples a uniform grid, not a rectilinear one".into()));
    }
    if opts.oversampling < 4 {
        return Err(Error::InvalidArgument("the truth needs at least 4 samples per voxel".into()));
    }
    let field = DenseField::new(set)?;
    let g = *set.grid();
    let radius = opts.reconstruction.radius();
    let occ = field.occupancy(radius.ceil() as i64 + 1);
    let spacing = DVec3::from(g.spacing.map(f64::from));
    let cell = g.cell_matrix();
    let ks = g.kernel_spacing() as f64;
    let last = DVec3::from(g.dims.map(|d| d as f64 - 1.0));
    // The kernel's reach in index units per axis (a world ball's extent through the inverse cell
    // matrix: its rows' lengths), and the world box sampled.
    let (r, [lo, hi]) = match opts.reconstruction {
        Reconstruction::Kernel(_) => {
            let (reach, inv_rows) = (radius * ks, cell.inverse().transpose());
            let [lo, hi] = g.world_box(Vec3::ZERO, last.as_vec3());
            let r = DVec3::new(inv_rows.x_axis.length(), inv_rows.y_axis.length(), inv_rows.z_axis.length()) * reach;
            (r, [lo.as_dvec3() - reach, hi.as_dvec3() + reach])
        }
        Reconstruction::Trilinear => {
            let [lo, hi] = g.world_box(Vec3::splat(-1.0), last.as_vec3() + 1.0);
            (DVec3::ONE, [lo.as_dvec3(), hi.as_dvec3()])
        }
    };
    let step = spacing.min_element() / opts.oversampling as f64;
    let inv = Mat4::from_cols_array_2d(&camera.view_proj().to_cols_array_2d()).as_dmat4().inverse();
    let norm = match opts.reconstruction {
        Reconstruction::Kernel(k) => 1.0 / k.volume_integral(),
        Reconstruction::Trilinear => 1.0,
    };
    let (w, h) = (camera.width, camera.height);
    let dims = g.dims.map(|d| d as i64);

    // (sum c tau h, sum tau h) at a world point.
    let sample = |x: DVec3| -> [f64; 4] {
        let u = g.index_point(x);
        let c = [0, 1, 2].map(|a| u[a].round().clamp(0.0, (dims[a] - 1) as f64) as i64);
        if !occ[(c[0] + dims[0] * (c[1] + dims[1] * c[2])) as usize] {
            return [0.0; 4];
        }
        let range =
            |a: usize| ((u[a] - r[a]).ceil().max(0.0) as i64, (u[a] + r[a]).floor().min((dims[a] - 1) as f64) as i64);
        let ((i0, i1), (j0, j1), (k0, k1)) = (range(0), range(1), range(2));
        let mut acc = [0.0f64; 4];
        for k in k0..=k1 {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let v = field.at(i, j, k);
                    if v[3] <= 0.0 {
                        continue;
                    }
                    let d = DVec3::new(i as f64, j as f64, k as f64) - u;
                    let wgt = match opts.reconstruction {
                        Reconstruction::Kernel(kern) => {
                            let r = (cell * d).length() / ks;
                            kern.profile(r) * norm
                        }
                        Reconstruction::Trilinear => {
                            (1.0 - d.x.abs()).max(0.0) * (1.0 - d.y.abs()).max(0.0) * (1.0 - d.z.abs()).max(0.0)
                        }
                    };
                    for ch in 0..4 {
                        acc[ch] += wgt * v[ch] as f64;
                    }
                }
            }
        }
        acc
    };

    let mut pixels = vec![[0.0f32; 4]; (w * h) as usize];
    pixels.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let (o, dir, len) = pixel_ray(&inv, x as u32, y as u32, w, h);
            let Some((t0, t1)) = slab(o, dir, lo, hi, len) else { continue };
            let n = ((t1 - t0) / step).ceil().max(1.0) as usize;
            let dt = (t1 - t0) / n as f64;
            let (mut t_rem, mut col) = (1.0f64, [0.0f64; 3]);
            for s in 0..n {
                let v = sample(o + dir * (t0 + (s as f64 + 0.5) * dt));
                if v[3] <= 0.0 {
                    continue;
                }
                let sigma = v[3] / ks;
                let a = 1.0 - (-sigma * dt).exp();
                for ch in 0..3 {
                    col[ch] += t_rem * a * v[ch] / v[3];
                }
                t_rem *= 1.0 - a;
                if t_rem < opts.min_transmittance {
                    break;
                }
            }
            *px = [col[0] as f32, col[1] as f32, col[2] as f32, (1.0 - t_rem) as f32];
        }
    });
    Ok(ImageF32 { width: w, height: h, pixels })
}

/// Ray integration that interpolates the *scalar* and classifies every sample, as VTK's ray
/// casters do (docs/MODEL.md "One truth for the peers"). `volume` sits on voxsplat's
/// centred grid; samples every `step` voxel spacings between the entry and exit of the box of voxel
/// centres; per sample the transfer function's opacity, given per unit length, becomes
/// `1 - (1 - a)^step` and colour is composited front to back. Premultiplied RGBA, in f64.
pub fn ray_integrate_scalars(
    volume: &crate::volume::ScalarVolume,
    tf: &crate::classify::TransferFunction,
    camera: &Camera,
    step: f64,
) -> Result<ImageF32> {
    camera.validate()?;
    tf.validate()?;
    if !(step.is_finite() && step > 0.0) {
        return Err(Error::InvalidArgument("the integration step must be positive".into()));
    }
    let [nx, ny, nz] = volume.dims.map(|d| d as usize);
    if nx * ny * nz != volume.values.len() || nx == 0 || ny == 0 || nz == 0 {
        return Err(Error::InvalidArgument("volume dims do not match its values".into()));
    }
    let spacing = DVec3::from(volume.spacing.map(f64::from));
    let origin = DVec3::new(
        -((nx - 1) as f64) * 0.5 * spacing.x,
        -((ny - 1) as f64) * 0.5 * spacing.y,
        -((nz - 1) as f64) * 0.5 * spacing.z,
    );
    let hi = origin + DVec3::new((nx - 1) as f64, (ny - 1) as f64, (nz - 1) as f64) * spacing;
    let (lo_v, hi_v) = tf.range.unwrap_or_else(|| {
        volume.values.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)))
    });
    let span = if hi_v > lo_v { hi_v as f64 - lo_v as f64 } else { 1.0 };
    let dt = step * spacing.min_element();
    let at = |i: usize, j: usize, k: usize| volume.values[i + nx * (j + ny * k)] as f64;
    let sample = |p: DVec3| -> f64 {
        let u =
            ((p - origin) / spacing).clamp(DVec3::ZERO, DVec3::new((nx - 1) as f64, (ny - 1) as f64, (nz - 1) as f64));
        let i0 = [u.x.floor() as usize, u.y.floor() as usize, u.z.floor() as usize];
        let i1 = [(i0[0] + 1).min(nx - 1), (i0[1] + 1).min(ny - 1), (i0[2] + 1).min(nz - 1)];
        let f = u - DVec3::new(i0[0] as f64, i0[1] as f64, i0[2] as f64);
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let x00 = lerp(at(i0[0], i0[1], i0[2]), at(i1[0], i0[1], i0[2]), f.x);
        let x10 = lerp(at(i0[0], i1[1], i0[2]), at(i1[0], i1[1], i0[2]), f.x);
        let x01 = lerp(at(i0[0], i0[1], i1[2]), at(i1[0], i0[1], i1[2]), f.x);
        let x11 = lerp(at(i0[0], i1[1], i1[2]), at(i1[0], i1[1], i1[2]), f.x);
        lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z)
    };
    let inv = camera.view_proj().as_dmat4().inverse();
    let (w, h) = (camera.width, camera.height);
    let mut image = ImageF32::new(w, h);
    image.pixels.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let (o, d, len) = pixel_ray(&inv, x as u32, y as u32, w, h);
            let Some((t0, t1)) = slab(o, d, origin, hi, len) else { continue };
            let (mut c, mut trans) = (DVec3::ZERO, 1.0f64);
            let mut t = t0 + 0.5 * dt;
            while t < t1 && trans > 1e-7 {
                let v = (sample(o + d * t) - lo_v as f64) / span;
                let e = tf.eval(v as f32);
                let a = 1.0 - (1.0 - (e[3] as f64).clamp(0.0, 1.0)).powf(dt);
                c += trans * a * DVec3::new(e[0] as f64, e[1] as f64, e[2] as f64);
                trans *= 1.0 - a;
                t += dt;
            }
            *px = [c.x as f32, c.y as f32, c.z as f32, (1.0 - trans) as f32];
        }
    });
    Ok(image)
}
