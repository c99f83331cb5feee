//! Helpers both the engine's tests and the CLI's share: renderers, random scenes and cameras, file
//! writers, image checks. Public API only (`vs` is the crate for the one, `voxsplat` for the other).
#![allow(dead_code)]
use super::vs;
use glam::Vec3;
use vs::camera::Projection;
use vs::{Backend, Camera, Grid, RenderOptions, Renderer, RendererOptions, SplatSet};

/// A GPU renderer with validation on (every GPU test asks for it).
pub fn gpu() -> Renderer {
    let mut o = RendererOptions::default();
    o.backend = Backend::Gpu;
    o.validation = true;
    Renderer::new(&o).expect("a Vulkan device with the validation layer (run scripts/setup.sh)")
}

pub fn cpu() -> Renderer {
    let mut o = RendererOptions::default();
    o.backend = Backend::Cpu;
    Renderer::new(&o).expect("cpu renderer")
}

/// Two renderers (two builds of a stage) draw `cam` bit for bit alike, and draw something.
pub fn assert_same_frame(a: &mut Renderer, b: &mut Renderer, cam: &Camera, o: &RenderOptions, what: &str) {
    let (a, b) = (a.render(cam, o).unwrap().image, b.render(cam, o).unwrap().image);
    assert!(a.pixels.iter().any(|p| p[3] > 0.0), "{what}: something drawn");
    let differ = a.pixels.iter().zip(&b.pixels).filter(|(p, q)| p != q).count();
    assert_eq!(differ, 0, "{what}: pixels where the two builds disagree");
}

/// Fails the test on any validation message, printing them.
pub fn assert_clean(r: &Renderer) {
    let n = r.validation_count();
    if n > 0 {
        for m in r.validation_messages() {
            eprintln!("{m}");
        }
    }
    assert_eq!(n, 0, "validation messages");
}

/// splitmix64: seeded, dependency-free randomness.
pub struct Rng(pub u64);
impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^ (z >> 31)
    }
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    pub fn dir(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            if v.length() > 0.1 && v.length() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

/// A random sparse volume with holes in its rows, to exercise the row logic.
pub fn random_sparse(seed: u64, dims: [u32; 3], fill: f32) -> SplatSet {
    let mut rng = Rng(seed);
    let grid = Grid::centered(dims, [1.0, 1.5, 0.75]).unwrap();
    SplatSet::from_fn(grid, |i, j, k| {
        (rng.f32() < fill).then(|| [(i % 3) as f32 / 2.0, (j % 2) as f32, (k % 5) as f32 / 4.0, 0.8])
    })
    .unwrap()
}

/// Which kind of viewpoint a random camera is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewKind {
    Outside,
    Inside,
    OnGridPlane,
    Orthographic,
}

/// A random camera of `kind` around `grid`.
pub fn random_camera(rng: &mut Rng, grid: &Grid, kind: ViewKind) -> Camera {
    let c = grid.center();
    let r = 0.5 * grid.diagonal().max(1.0);
    let lo = Vec3::from(grid.origin);
    let hi = grid.position([grid.dims[0] - 1, grid.dims[1] - 1, grid.dims[2] - 1]);
    let sp = Vec3::from(grid.spacing);
    let eye = match kind {
        ViewKind::Outside | ViewKind::Orthographic => c + rng.dir() * r * rng.range(1.05, 3.0),
        ViewKind::Inside => Vec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z)),
        ViewKind::OnGridPlane => {
            // Snap some coordinates to a voxel plane or to a midplane between voxels, inside or
            // just outside the grid.
            let mut e = c + rng.dir() * r * rng.range(0.0, 2.0);
            for a in 0..3 {
                if rng.f32() < 0.7 {
                    let idx = ((e[a] - lo[a]) / sp[a]).round();
                    let half = if rng.f32() < 0.5 { 0.0 } else { 0.5 };
                    e[a] = lo[a] + (idx + half) * sp[a];
                }
            }
            e
        }
    };
    let mut target = c + rng.dir() * r * 0.3;
    if (target - eye).length() < 1e-3 {
        target = eye + Vec3::X;
    }
    let fwd = (target - eye).normalize();
    let up = if fwd.cross(Vec3::Y).length() > 0.1 { Vec3::Y } else { Vec3::Z };
    let projection = match kind {
        ViewKind::Orthographic => Projection::Orthographic { height: 2.0 * r },
        _ => Projection::Perspective { fov_y_deg: rng.range(20.0, 90.0) },
    };
    let d = (c - eye).length();
    Camera {
        eye,
        target,
        up,
        projection,
        near: if matches!(kind, ViewKind::Orthographic) { -4.0 * r } else { 0.05 },
        far: d + 4.0 * r,
        width: 64,
        height: 64,
        window: None,
    }
}

/// An .npy file (format 1.0, C order) of `shape` holding `data` as `descr` (e.g. `|u1`, `<f4`).
pub fn npy(shape: &[u64], descr: &str, data: &[u8]) -> Vec<u8> {
    let shape_s = shape.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", ");
    let mut header = format!(
        "{{'descr': '{descr}', 'fortran_order': False, 'shape': ({shape_s}{}), }}",
        if shape.len() == 1 { "," } else { "" }
    );
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(header.len() as u16).to_le_bytes());
    b.extend_from_slice(header.as_bytes());
    b.extend_from_slice(data);
    b
}

/// A lumpy blob with empty space around it and a hollow, on a grid whose sides are not multiples
/// of the brick side.
pub fn blob(dims: [u32; 3]) -> vs::volume::ScalarVolume {
    let c = dims.map(|d| d as f32 / 2.0);
    let mut values = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = [i, j, k].map(|v| v as f32);
                let r = ((0..3).map(|a| ((p[a] - c[a]) / c[a]).powi(2)).sum::<f32>()).sqrt();
                let wobble = 0.15 * ((p[0] * 0.7).sin() * (p[1] * 0.5).cos() + (p[2] * 0.9).sin());
                values.push(if r < 0.9 { (1.0 - r + wobble).max(0.0) * 100.0 } else { 0.0 });
            }
        }
    }
    vs::volume::ScalarVolume { dims, spacing: [1.0, 1.2, 0.9], values }
}

/// A volume with flat regions: empty space (its minimum), a block at one value, and noise.
pub fn flat_blocks(dims: [u32; 3]) -> vs::volume::ScalarVolume {
    let mut rng = Rng(44);
    let mut values = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let inside = |lo: u32, hi: u32, v: u32| (lo..hi).contains(&v);
                values.push(
                    if inside(3, dims[0] - 2, i) && inside(2, dims[1] - 3, j) && inside(1, 2 * dims[2] / 3, k) {
                        50.0 // a flat block: its full bricks are uniform
                    } else if k >= 2 * dims[2] / 3 + 2 && i > 4 {
                        10.0 + 80.0 * rng.f32()
                    } else {
                        0.0
                    },
                );
            }
        }
    }
    vs::volume::ScalarVolume { dims, spacing: [1.0, 1.2, 0.9], values }
}

/// The bricked tests' transfer function for `blob`.
pub fn blob_tf() -> vs::classify::TransferFunction {
    vs::classify::TransferFunction {
        points: vec![(0.1, [0.0, 0.0, 0.0, 0.0]), (0.3, [0.9, 0.4, 0.2, 0.3]), (1.0, [0.9, 0.9, 1.0, 0.8])],
        gradient_weight: 0.0,
        range: None,
        threshold: 0.0,
    }
}

/// Largest and mean absolute channel difference.
pub fn diff(a: &vs::image::ImageF32, b: &vs::image::ImageF32) -> (f32, f32) {
    let d: Vec<f32> =
        a.pixels.iter().zip(&b.pixels).flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs())).collect();
    (d.iter().copied().fold(0.0, f32::max), d.iter().sum::<f32>() / d.len() as f32)
}

/// Pixels with any opacity.
pub fn covered(img: &vs::image::ImageF32) -> usize {
    img.pixels.iter().filter(|p| p[3] > 0.0).count()
}

/// A GPU frame against its CPU mirror's: the largest channel difference at most 2e-3 (measured
/// at most 2e-5, 7e-4 with point sprites), the mean of each covered pixel's largest difference at
/// most 2e-4, and something covered (a mean over every byte, background included, let a bug
/// confined to a few pixels pass). Returns (max, mean) for the log.
pub fn assert_mirrors(g: &vs::image::ImageF32, c: &vs::image::ImageF32, tag: &str) -> (f32, f64) {
    assert_eq!((g.width, g.height), (c.width, c.height), "{tag}: sizes");
    let (mut max, mut sum, mut n) = (0.0f32, 0.0f64, 0usize);
    for (p, q) in g.pixels.iter().zip(&c.pixels) {
        let d = (0..4).map(|k| (p[k] - q[k]).abs()).fold(0.0f32, |m, x| {
            if x.is_nan() || m.is_nan() {
                f32::NAN
            } else {
                m.max(x)
            }
        });
        assert!(!d.is_nan(), "{tag}: a NaN pixel");
        max = max.max(d);
        if p[3] > 0.0 || q[3] > 0.0 {
            (sum, n) = (sum + d as f64, n + 1);
        }
    }
    assert!(n > 0, "{tag}: nothing drawn");
    let mean = sum / n as f64;
    assert!(max <= 2e-3 && mean <= 2e-4, "{tag}: GPU against mirror: max {max}, mean over {n} covered px {mean}");
    (max, mean)
}

/// Placement tests (issue 29): a small object with no symmetry, and NIfTI files that place it.
pub const DIMS: [u32; 3] = [12, 10, 16];

/// An object with no symmetry: a ball low in k, a bar along i high in k, a stub toward high j.
pub fn object(i: i64, j: i64, k: i64) -> u8 {
    let p = glam::DVec3::new(i as f64, j as f64, k as f64);
    let ball = (p - glam::DVec3::new(5.0, 4.5, 4.0)).length() < 3.2;
    let bar = (2..=10).contains(&i) && (3..=5).contains(&j) && (11..=13).contains(&k);
    let stub = (4..=6).contains(&i) && (5..=8).contains(&j) && (7..=9).contains(&k);
    if ball || bar {
        200
    } else if stub {
        120
    } else {
        0
    }
}

/// The file voxels of `dims` whose index `b` holds the object's voxel `map(b)`.
pub fn samples(dims: [u32; 3], map: impl Fn([i64; 3]) -> [i64; 3]) -> Vec<u8> {
    let mut v = Vec::new();
    for k in 0..dims[2] as i64 {
        for j in 0..dims[1] as i64 {
            for i in 0..dims[0] as i64 {
                let [a, b, c] = map([i, j, k]);
                v.push(object(a, b, c));
            }
        }
    }
    v
}

/// A NIfTI-1 file of u8 samples with an sform (code 1) or, without one, a qform (code 1:
/// quaternion b, c, d, offset, qfac).
pub fn nifti(
    dims: [u32; 3],
    v: &[u8],
    sform: Option<glam::DMat4>,
    qform: Option<(glam::DQuat, glam::DVec3, f32)>,
) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    let put_f32 = |h: &mut Vec<u8>, at: usize, x: f32| h[at..at + 4].copy_from_slice(&x.to_le_bytes());
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dim: [i16; 8] = [3, dims[0] as i16, dims[1] as i16, dims[2] as i16, 1, 1, 1, 1];
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&2i16.to_le_bytes()); // uint8
    h[72..74].copy_from_slice(&8i16.to_le_bytes());
    let qfac = qform.map(|q| q.2).unwrap_or(1.0);
    for (i, p) in [qfac, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0].iter().enumerate() {
        put_f32(&mut h, 76 + 4 * i, *p);
    }
    put_f32(&mut h, 108, 352.0);
    if let Some((q, offset, _)) = qform {
        h[252..254].copy_from_slice(&1i16.to_le_bytes());
        let q = if q.w < 0.0 { -q } else { q };
        for (n, x) in [q.x, q.y, q.z, offset.x, offset.y, offset.z].iter().enumerate() {
            put_f32(&mut h, 256 + 4 * n, *x as f32);
        }
    }
    if let Some(m) = sform {
        h[254..256].copy_from_slice(&1i16.to_le_bytes());
        for r in 0..3 {
            for c in 0..4 {
                put_f32(&mut h, 280 + 16 * r + 4 * c, m.col(c)[r] as f32);
            }
        }
    }
    h[344..348].copy_from_slice(b"n+1\0");
    h.extend_from_slice(v);
    h
}
