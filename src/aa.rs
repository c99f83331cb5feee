//! Chapter 3 helpers: where k falls on a single-sheet scene, and the k line overlay.
//!
//! ```
//! use voxsplat::{aa::k_regions, scene, Camera};
//! // Where a frame crosses k, the distance beyond which a voxel is smaller than a pixel (§3.4).
//! let set = scene::build("cube40")?;
//! let camera = Camera::framing(set.grid(), 32, 32);
//! let regions = k_regions(&set, &camera);
//! assert_eq!(regions.len(), 32 * 32);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::camera::Camera;
use crate::image::ImageF32;
use crate::truth::pixel_ray;
use crate::volume::SplatSet;
use glam::Mat4;

/// Per pixel: 0 where the ray meets no splat, 1 where the first it meets lies before k, 2 beyond
/// k. For orthographic views every hit pixel is 1 or 2 by the pixels-per-voxel ratio. A grid one
/// voxel thick in z (the checkerboard plane) is met exactly at its plane; any other grid (a
/// terrain's columns, a volume) at its first non-empty voxel, marched in steps of half the
/// smallest spacing.
pub fn k_regions(set: &SplatSet, camera: &Camera) -> Vec<u8> {
    let g = set.grid();
    // One axis-aligned sheet is a plane of known z and box; others are marched.
    if g.dims[2] != 1 || g.is_sheared() {
        return k_regions_marched(set, camera);
    }
    let (w, h) = (camera.width, camera.height);
    let mut out = vec![0u8; (w * h) as usize];
    let s = g.kernel_spacing();
    let inv = Mat4::from_cols_array_2d(&camera.view_proj().to_cols_array_2d()).as_dmat4().inverse();
    let z = g.origin[2] as f64;
    let lo = g.position([0, 0, 0]).as_dvec3();
    let hi = g.position([g.dims[0] - 1, g.dims[1] - 1, 0]).as_dvec3();
    let eye = camera.eye.as_dvec3();
    let fwd = camera.forward().as_dvec3();
    let ortho_beyond = s * camera.pixels_per_unit() < 1.0;
    for y in 0..h {
        for x in 0..w {
            let (o, d, len) = pixel_ray(&inv, x, y, w, h);
            if d.z.abs() < 1e-12 {
                continue;
            }
            let t = (z - o.z) / d.z;
            if t < 0.0 || t > len {
                continue;
            }
            let p = o + d * t;
            if p.x < lo.x - 0.5 || p.x > hi.x + 0.5 || p.y < lo.y - 0.5 || p.y > hi.y + 0.5 {
                continue;
            }
            let beyond = match camera.k(s) {
                Some(k) => (p - eye).dot(fwd) > k as f64,
                None => ortho_beyond,
            };
            out[(y * w + x) as usize] = if beyond { 2 } else { 1 };
        }
    }
    out
}

/// `k_regions` for grids more than one voxel thick: each pixel's ray marched to its first
/// non-empty voxel. Grids of more than 2^30 cells give all zeros (the occupancy takes a bit a cell).
fn k_regions_marched(set: &SplatSet, camera: &Camera) -> Vec<u8> {
    let g = set.grid();
    let (w, h) = (camera.width, camera.height);
    let mut out = vec![0u8; (w * h) as usize];
    let [nx, ny, nz] = g.dims.map(|d| d as usize);
    let cells = nx * ny * nz;
    if cells as u64 > 1 << 30 {
        return out;
    }
    let mut occupied = vec![0u64; cells.div_ceil(64)];
    for s in set.splats() {
        let c = (s.ijk[2] as usize * ny + s.ijk[1] as usize) * nx + s.ijk[0] as usize;
        occupied[c / 64] |= 1 << (c % 64);
    }
    let spacing = glam::DVec3::from(g.spacing.map(f64::from));
    let [lo, hi] = g.world_box(glam::Vec3::splat(-0.5), glam::Vec3::from(g.dims.map(|d| d as f32 - 0.5)));
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    // Half the smallest gap (a rectilinear grid's may be below its mean spacing).
    let smallest = set.coordinates().map_or(f64::MAX, |c| {
        c.iter().flat_map(|v| v.windows(2).map(|w| (w[1] - w[0]) as f64)).fold(f64::MAX, f64::min)
    });
    let step = 0.5 * spacing.min_element().min(smallest);
    let inv = camera.view_proj().as_dmat4().inverse();
    let (eye, fwd) = (camera.eye.as_dvec3(), camera.forward().as_dvec3());
    let k = camera.k(g.kernel_spacing()).map(f64::from);
    let ortho_beyond = g.kernel_spacing() * camera.pixels_per_unit() < 1.0;
    for y in 0..h {
        for x in 0..w {
            let (o, d, len) = pixel_ray(&inv, x, y, w, h);
            let Some((t0, t1)) = crate::truth::slab(o, d, lo, hi, len) else { continue };
            let mut t = t0;
            while t <= t1 {
                let p = o + d * t;
                // Index space (through a rectilinear grid's coordinates where it has them).
                let ijk = set.index_point(p).round();
                let inside = (0..3).all(|a| ijk[a] >= 0.0 && ijk[a] < g.dims[a] as f64);
                if inside {
                    let c = (ijk.z as usize * ny + ijk.y as usize) * nx + ijk.x as usize;
                    if occupied[c / 64] >> (c % 64) & 1 == 1 {
                        let beyond = k.map_or(ortho_beyond, |k| (p - eye).dot(fwd) > k);
                        out[(y * w + x) as usize] = if beyond { 2 } else { 1 };
                        break;
                    }
                }
                t += step;
            }
        }
    }
    out
}

/// Paint the boundary between the before-k and beyond-k regions in opaque yellow.
pub fn draw_k_line(img: &mut ImageF32, regions: &[u8]) {
    let (w, h) = (img.width as usize, img.height as usize);
    for y in 0..h {
        for x in 0..w {
            let r = regions[y * w + x];
            let right = if x + 1 < w { regions[y * w + x + 1] } else { r };
            let down = if y + 1 < h { regions[(y + 1) * w + x] } else { r };
            let edge = |q: u8| r != 0 && q != 0 && q != r;
            if edge(right) || edge(down) {
                img.pixels[y * w + x] = [1.0, 0.85, 0.0, 1.0];
            }
        }
    }
}
