//! Large test volumes, made rather than committed (issue 23): a volume upsampled by an integer
//! factor (the 512³ bonsai from the 256³ one) and a procedural field of any side (1024³: a billion
//! voxels). Written as attached raw 8-bit NRRD, slice by slice: the output is never held in memory.
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;
use voxsplat::volume::ScalarVolume;
use voxsplat::{Error, Result};

/// Most voxels along a side of a made volume.
pub const MAX_SIDE: u32 = 4096;

fn create(path: &Path, dims: [u32; 3], spacing: [f32; 3]) -> Result<std::io::BufWriter<std::fs::File>> {
    let io = |e| Error::Io { path: path.display().to_string(), source: e };
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    write!(
        out,
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: {} {} {}\nspacings: {} {} {}\nencoding: raw\n\n",
        dims[0], dims[1], dims[2], spacing[0], spacing[1], spacing[2]
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
    slice: impl Fn(u32, &mut [u8]) + Sync,
    mut progress: impl FnMut(u32),
) -> Result<()> {
    if dims.iter().any(|&d| d == 0 || d > MAX_SIDE) {
        return Err(Error::InvalidArgument(format!("volume sides must be in 1..={MAX_SIDE}, not {dims:?}")));
    }
    let io = |e| Error::Io { path: path.display().to_string(), source: e };
    let mut out = create(path, dims, spacing)?;
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
/// aligned), its values mapped from [min, max] to 0..=255.
pub fn upsample(vol: &ScalarVolume, factor: u32, path: &Path, progress: impl FnMut(u32)) -> Result<[u32; 3]> {
    if !(1..=8).contains(&factor) {
        return Err(Error::InvalidArgument(format!("upsampling factor {factor} must be in 1..=8")));
    }
    let [nx, ny, nz] = vol.dims;
    let dims = vol.dims.map(|d| d.saturating_mul(factor));
    let (lo, hi) = vol
        .values
        .iter()
        .filter(|v| v.is_finite())
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
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
    write_slices(
        path,
        dims,
        spacing,
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
