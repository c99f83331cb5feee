//! Chapter 3 helpers: where k falls on a single-sheet scene, and the k line overlay.
use crate::camera::Camera;
use crate::image::ImageF32;
use crate::truth::pixel_ray;
use crate::volume::SplatSet;
use glam::Mat4;

/// Per pixel: 0 where the ray misses the sheet, 1 where it meets the sheet before k, 2 beyond k.
/// For orthographic views every hit pixel is 1 or 2 by the pixels-per-voxel ratio. Only for grids
/// one voxel thick in z (the checkerboard plane); other grids give all zeros.
pub fn k_regions(set: &SplatSet, camera: &Camera) -> Vec<u8> {
    let g = set.grid();
    let (w, h) = (camera.width, camera.height);
    let mut out = vec![0u8; (w * h) as usize];
    if g.dims[2] != 1 {
        return out;
    }
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
