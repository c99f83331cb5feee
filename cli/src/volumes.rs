//! Large test volumes, made rather than committed: a volume upsampled by an integer
//! factor (the 512³ bonsai from the 256³ one) and a procedural field of any side (1024³: a billion
//! voxels). Written as attached raw 8-bit NRRD, slice by slice: the output is never held in memory.
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;
use voxsplat::volume::ScalarVolume;
use voxsplat::{Error, Result};

/// Most voxels along a side of a made volume.
pub const MAX_SIDE: u32 = 4096;

/// How a made volume's header places it: spacing alone, or in patient space (RAS, axis-aligned,
/// centred on the world origin).
#[derive(Clone, Copy)]
enum Frame {
    Spacing,
    Ras,
    /// Index -> world (RAS+) affine: columns i, j, k and the origin.
    Affine(glam::DMat4),
}

fn create(path: &Path, dims: [u32; 3], spacing: [f32; 3], frame: Frame) -> Result<std::io::BufWriter<std::fs::File>> {
    let io = |e| Error::Io { path: path.display().to_string(), source: e };
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    let [sx, sy, sz] = spacing;
    let place = match frame {
        Frame::Spacing => format!("spacings: {sx} {sy} {sz}"),
        Frame::Ras => {
            let o = [0, 1, 2].map(|a| -0.5 * (dims[a] - 1) as f32 * spacing[a]);
            format!(
                "space: right-anterior-superior\nspace directions: ({sx},0,0) (0,{sy},0) (0,0,{sz})\n\
                 space origin: ({},{},{})",
                o[0], o[1], o[2]
            )
        }
        Frame::Affine(a) => {
            let v = |c: glam::DVec4| format!("({},{},{})", c.x, c.y, c.z);
            format!(
                "space: right-anterior-superior\nspace directions: {} {} {}\nspace origin: {}",
                v(a.x_axis),
                v(a.y_axis),
                v(a.z_axis),
                v(a.w_axis)
            )
        }
    };
    write!(
        out,
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: {} {} {}\n{place}\nencoding: raw\n\n",
        dims[0], dims[1], dims[2]
    )
    .map_err(io)?;
    Ok(out)
}

/// Write slices `0..dims[2]` of `slice(z, buffer)` to `path`, slices computed in parallel a few
/// at a time; `progress(done)` after each batch.
fn write_slices(
    path: &Path,
    dims: [u32; 3],
    spacing: [f32; 3],
    frame: Frame,
    slice: impl Fn(u32, &mut [u8]) + Sync,
    mut progress: impl FnMut(u32),
) -> Result<()> {
    if dims.iter().any(|&d| d == 0 || d > MAX_SIDE) {
        return Err(Error::InvalidArgument(format!("volume sides must be in 1..={MAX_SIDE}, not {dims:?}")));
    }
    let io = |e| Error::Io { path: path.display().to_string(), source: e };
    let mut out = create(path, dims, spacing, frame)?;
    let area = dims[0] as usize * dims[1] as usize;
    let batch = 8u32;
    let mut buf = vec![0u8; area * batch as usize];
    for z0 in (0..dims[2]).step_by(batch as usize) {
        let n = batch.min(dims[2] - z0) as usize;
        buf[..n * area].par_chunks_mut(area).enumerate().for_each(|(s, b)| slice(z0 + s as u32, b));
        out.write_all(&buf[..n * area]).map_err(io)?;
        progress(z0 + n as u32);
    }
    out.flush().map_err(io)
}

/// `vol` upsampled `factor` times along each axis by trilinear interpolation (sample centres
/// aligned), its values mapped from [min, max] to 0..=255. `placement`: the source file's, which
/// the output keeps (the same object in the same place, so the same view frames both).
pub fn upsample(
    vol: &ScalarVolume,
    factor: u32,
    placement: Option<&voxsplat::orient::Orientation>,
    path: &Path,
    progress: impl FnMut(u32),
) -> Result<[u32; 3]> {
    if !(1..=8).contains(&factor) {
        return Err(Error::InvalidArgument(format!("upsampling factor {factor} must be in 1..=8")));
    }
    let [nx, ny, nz] = vol.dims;
    let dims = vol.dims.map(|d| d.saturating_mul(factor));
    let (lo, hi) = voxsplat::volume::value_span(&vol.values);
    let span = if hi > lo { hi - lo } else { 1.0 };
    let at = |i: usize, j: usize, k: usize| {
        let v = vol.values[i + nx as usize * (j + ny as usize * k)];
        if v.is_finite() {
            (v - lo) / span
        } else {
            0.0
        }
    };
    // Source coordinate of output sample o: its lower neighbour and the weight of the upper.
    let src = |o: u32, n: u32| {
        let t = ((o as f32 + 0.5) / factor as f32 - 0.5).clamp(0.0, (n - 1) as f32);
        let i0 = (t as usize).min(n as usize - 1);
        (i0, (i0 + 1).min(n as usize - 1), t - i0 as f32)
    };
    let spacing = vol.spacing.map(|s| s / factor as f32);
    let frame = match placement {
        None => Frame::Spacing,
        Some(o) => {
            // The affine of the stored grid (a left-handed file is stored with x reversed), then
            // of the output's: its sample o sits at source index (o + 0.5) / factor - 0.5.
            let mut a = o.affine();
            if o.flip_x() {
                a.w_axis += a.x_axis * (nx as f64 - 1.0);
                a.x_axis = -a.x_axis;
            }
            let f = factor as f64;
            let first = 0.5 / f - 0.5;
            let origin = a.w_axis + (a.x_axis + a.y_axis + a.z_axis) * first;
            Frame::Affine(glam::DMat4::from_cols(a.x_axis / f, a.y_axis / f, a.z_axis / f, origin))
        }
    };
    write_slices(
        path,
        dims,
        spacing,
        frame,
        |z, buf| {
            let (k0, k1, wk) = src(z, nz);
            for y in 0..dims[1] {
                let (j0, j1, wj) = src(y, ny);
                for x in 0..dims[0] {
                    let (i0, i1, wi) = src(x, nx);
                    let lerp = |a: f32, b: f32, w: f32| a + (b - a) * w;
                    let plane =
                        |k| lerp(lerp(at(i0, j0, k), at(i1, j0, k), wi), lerp(at(i0, j1, k), at(i1, j1, k), wi), wj);
                    let v = lerp(plane(k0), plane(k1), wk);
                    buf[(y * dims[0] + x) as usize] = (v * 255.0).round().clamp(0.0, 255.0) as u8;
                }
            }
        },
        progress,
    )?;
    Ok(dims)
}

/// The procedural field of side `n`: a gyroid's thin shell inside a ball, fading outward, and empty
/// space around it (at 256³, 11 % of the voxels above the ramp preset's threshold), values 0..=255.
pub fn procedural(n: u32, path: &Path, progress: impl FnMut(u32)) -> Result<[u32; 3]> {
    let dims = [n; 3];
    let f = 6.0 * std::f32::consts::PI / n as f32;
    write_slices(
        path,
        dims,
        [1.0; 3],
        Frame::Spacing,
        |z, buf| {
            let c = n as f32 * 0.5;
            for y in 0..n {
                for x in 0..n {
                    let p = [x as f32 + 0.5 - c, y as f32 + 0.5 - c, z as f32 + 0.5 - c];
                    let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() / c;
                    let g = (f * p[0]).sin() * (f * p[1]).cos()
                        + (f * p[1]).sin() * (f * p[2]).cos()
                        + (f * p[2]).sin() * (f * p[0]).cos();
                    let shell = (1.0 - g.abs() / 0.45).max(0.0);
                    let v = if r < 0.95 { shell * (1.0 - 0.5 * r) } else { 0.0 };
                    buf[(y * n + x) as usize] = (v * 255.0).round() as u8;
                }
            }
        },
        progress,
    )?;
    Ok(dims)
}

/// T1-weighted intensities of the head phantom's tissues (of 255 = 1.0).
const T1_WHITE: f32 = 0.72;
const T1_GREY: f32 = 0.45;
const T1_SKIN: f32 = 0.30;
const T1_CSF: f32 = 0.12;
const T1_BONE: f32 = 0.08;

/// A T1-weighted MRI head phantom of side `n` (220 mm across, RAS+: i toward the patient's right,
/// j anterior, k superior): scalp, a dark skull, cerebrospinal fluid, a folded grey-matter cortex
/// over white matter, two ventricles and the fissure between the hemispheres, the eyes, and the
/// neck; a little deterministic noise. Not a real scan (../shared/data has none): a stand-in to
/// tune and check the `mri` preset on, whose tissue values are in T1's order (white matter
/// brightest, then grey matter, scalp, fluid and bone darkest). Scalp fat, as bright as white
/// matter in a real T1 scan, is left out: a one-dimensional transfer function cannot tell them
/// apart.
pub fn head_phantom(n: u32, path: &Path, progress: impl FnMut(u32)) -> Result<[u32; 3]> {
    let dims = [n; 3];
    let spacing = 220.0 / n as f32;
    write_slices(
        path,
        dims,
        [spacing; 3],
        Frame::Ras,
        |z, buf| {
            for y in 0..n {
                for x in 0..n {
                    let p = [x, y, z].map(|v| (v as f32 + 0.5) / n as f32 * 2.0 - 1.0);
                    let v = (t1_head(p) + 0.015 * noise(x, y, z)).clamp(0.0, 1.0);
                    buf[(y * n + x) as usize] = (v * 255.0).round() as u8;
                }
            }
        },
        progress,
    )?;
    Ok(dims)
}

/// The ellipsoidal radius of `p` about `c` with radii `r` (1 on the surface).
fn ellipsoid(p: [f32; 3], c: [f32; 3], r: [f32; 3]) -> f32 {
    (0..3).map(|a| ((p[a] - c[a]) / r[a]).powi(2)).sum::<f32>().sqrt()
}

/// The phantom's T1 intensity at `p` (each axis -1..1: right, anterior, superior).
fn t1_head(p: [f32; 3]) -> f32 {
    let [x, y, z] = p;
    let head = ellipsoid(p, [0.0, 0.0, 0.05], [0.68, 0.84, 0.82]);
    let eye = ellipsoid([x.abs(), y, z], [0.3, 0.72, -0.12], [0.11, 0.1, 0.1]);
    let neck = ((x / 0.4).powi(2) + ((y + 0.08) / 0.45).powi(2)).sqrt();
    if eye < 1.0 {
        return T1_CSF; // the vitreous: fluid
    }
    if head > 1.0 {
        return if z < -0.55 && neck < 1.0 { T1_SKIN } else { 0.0 };
    }
    if head > 0.95 {
        return T1_SKIN;
    }
    if head > 0.89 {
        return T1_BONE;
    }
    // Below the brain: the skull base and the soft tissue of the face and neck.
    if z < -0.38 + 0.25 * y.max(0.0) {
        return if head > 0.8 { T1_BONE } else { T1_SKIN };
    }
    if head > 0.85 {
        return T1_CSF;
    }
    let ventricle = ellipsoid([x.abs(), y, z], [0.1, 0.0, 0.12], [0.06, 0.3, 0.1]);
    let fissure = x.abs() < 0.012 && z > -0.1;
    if ventricle < 1.0 || fissure {
        return T1_CSF;
    }
    // A cortex 4-8 % of the head's radius thick, folded into gyri.
    let fold = (23.0 * x).sin() * (19.0 * y).sin() * (21.0 * z).sin();
    if head > 0.76 + 0.04 * fold {
        return T1_GREY;
    }
    T1_WHITE
}

/// Deterministic noise in -1..1 (a hash of the voxel).
fn noise(x: u32, y: u32, z: u32) -> f32 {
    let mut h = (x as u64) << 42 ^ (y as u64) << 21 ^ z as u64;
    h = (h ^ (h >> 33)).wrapping_mul(0xff51_afd7_ed55_8ccd);
    h = (h ^ (h >> 33)).wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    ((h >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
}
