//! Reconstruction kernels (section 1.2.3), pre-integrated along the view direction into the 2D
//! footprint table that `footprint.frag` reads as a texture.
//!
//! Units: distances are in voxel spacings. The table covers uv in [-1, 1]^2 = [-R, R]^2 and holds
//! the footprint f(rho) = integral of h(sqrt(rho^2 + z^2)) dz, normalised so that the table's own
//! discrete integral is exactly 1 voxel^2. A sheet of unit-spaced splats therefore sums to ~1, and
//! a voxel of optical depth tau contributes tau * f to the pixels its footprint covers.
//!
//! ```
//! use voxsplat::{kernel::Kernel, RenderOptions};
//! // The reconstruction kernel each splat's footprint integrates; Gaussian by default.
//! let mut options = RenderOptions::default();
//! options.kernel = "cubic".parse::<Kernel>()?;
//! assert!(options.kernel.radius() > 1.0);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::constants::FOOTPRINT_TABLE_SIZE;
use crate::error::{Error, Result};
use std::sync::OnceLock;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
/// The reconstruction kernel, pre-integrated along the ray into a footprint.
pub enum Kernel {
    /// Westover's Gaussian, sigma = 0.6 voxel, truncated at radius 2.
    Gaussian,
    /// The Hermite cubic with Crawfis and Max's support, radius 1.6 voxel: h(r) = 1 - 3x^2 + 2x^3
    /// with x = r / 1.6 (zero value and slope at the edge); their fitted kernel is `CrawfisMax`.
    Cubic,
    /// A narrower Gaussian, sigma = 0.5 voxel truncated at radius 1.5 (3 sigma): 56% of the
    /// default's footprint area, so fewer fragments, and closer to renderers that interpolate the
    /// scalar trilinearly (whose tent filter has sigma 0.41; the peers' scene, docs/RESULTS.md). The
    /// price is ripple: a flat sheet of voxels seen head-on is no longer uniform
    /// (`Kernel::sheet_ripple`: 7.6% peak to peak, against 0.4% for the default and 3.0% for the
    /// cubic).
    Narrow,
    /// Crawfis and Max's criterion with their support (radius 1.6): the piecewise cubic
    /// (`CRAWFIS_MAX`, two C1 Hermite pieces) whose footprints sum over a unit lattice with the
    /// smallest variance, fitted here (`fit_crawfis_max`) since their coefficients are not at hand.
    /// The default: against the supersampled ray-cast reference it errs less than the Gaussian
    /// on every gallery file (42 against 38 dB on the bonsai and the stent: the Gaussian blurs
    /// more than trilinear interpolation does), its footprints are 64 % of the Gaussian's area,
    /// and a flat sheet of its voxels ripples least (0.37 %; docs/RESULTS.md).
    #[default]
    CrawfisMax,
}

/// Standard deviation of the Gaussian kernel, in voxel spacings.
pub const GAUSSIAN_SIGMA: f64 = 0.6;
/// Sigma of `Kernel::Narrow` (voxels).
pub const NARROW_SIGMA: f64 = 0.5;

/// Every kernel, in cache-slot order.
pub const KERNELS: [Kernel; 4] = [Kernel::Gaussian, Kernel::Cubic, Kernel::Narrow, Kernel::CrawfisMax];

type KernelTables = [OnceLock<Vec<f32>>; 4];

/// Simpson's rule over [a, b] with `n` (even) intervals.
fn simpson(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / n as f64;
    let mut sum = f(a) + f(b);
    for i in 1..n {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
    }
    sum * h / 3.0
}

impl std::str::FromStr for Kernel {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        KERNELS.into_iter().find(|k| k.name() == s).ok_or_else(|| {
            let names: Vec<&str> = KERNELS.iter().map(|k| k.name()).collect();
            Error::InvalidArgument(format!("unknown kernel '{s}' ({})", names.join(", ")))
        })
    }
}

impl Kernel {
    /// The name `--kernel` takes.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Gaussian => "gaussian",
            Kernel::Cubic => "cubic",
            Kernel::Narrow => "narrow",
            Kernel::CrawfisMax => "crawfis-max",
        }
    }

    /// Support radius in voxel spacings.
    pub fn radius(self) -> f32 {
        match self {
            Kernel::Gaussian => 2.0,
            Kernel::Cubic => 1.6,
            Kernel::Narrow => 1.5,
            Kernel::CrawfisMax => CRAWFIS_MAX_RADIUS as f32,
        }
    }

    /// The 3D radial profile (unnormalised).
    pub fn profile(self, r: f64) -> f64 {
        let rr = self.radius() as f64;
        if r >= rr {
            return 0.0;
        }
        match self {
            Kernel::Gaussian => (-(r * r) / (2.0 * GAUSSIAN_SIGMA * GAUSSIAN_SIGMA)).exp(),
            Kernel::Narrow => (-(r * r) / (2.0 * NARROW_SIGMA * NARROW_SIGMA)).exp(),
            Kernel::Cubic => {
                let x = r / rr;
                1.0 - 3.0 * x * x + 2.0 * x * x * x
            }
            Kernel::CrawfisMax => CRAWFIS_MAX.eval(r / rr),
        }
    }

    /// The profile integrated along the view ray at distance `rho` from the centre.
    pub fn integrated(self, rho: f64) -> f64 {
        let rr = self.radius() as f64;
        if rho >= rr {
            return 0.0;
        }
        let half = (rr * rr - rho * rho).sqrt();
        simpson(-half, half, 256, |z| self.profile((rho * rho + z * z).sqrt()))
    }

    /// The 3D kernel normalised so that its integral over space is 1 voxel^3.
    pub fn normalized(self, r: f64) -> f64 {
        self.profile(r) / self.volume_integral()
    }

    /// Integral of the 3D profile over its ball (Simpson, 1024 intervals in r).
    pub fn volume_integral(self) -> f64 {
        let rr = self.radius() as f64;
        simpson(0.0, rr, 1024, |r| self.profile(r) * 4.0 * std::f64::consts::PI * r * r)
    }

    /// Standard deviation (voxels) of the 2D footprint along one screen axis; the EWA low-pass adds
    /// its variance to this one.
    pub fn footprint_sigma(self) -> f64 {
        match self {
            Kernel::Gaussian => GAUSSIAN_SIGMA,
            Kernel::Cubic | Kernel::Narrow | Kernel::CrawfisMax => {
                let rr = self.radius() as f64;
                let n = 400;
                let (mut m0, mut m2) = (0.0, 0.0);
                for i in 0..n {
                    let rho = (i as f64 + 0.5) / n as f64 * rr;
                    let f = self.integrated(rho) * rho;
                    m0 += f;
                    m2 += f * rho * rho;
                }
                // For a radial density, E[x^2] = E[rho^2] / 2.
                (m2 / m0 / 2.0).sqrt()
            }
        }
    }

    /// G of the motion-blurred footprint: its integral along a line across the centre over its
    /// integral over the whole disc, in units of the radius. A footprint stretched by a length l
    /// (radius units) gains l·G of its energy, so Eq. 4.2's A1 / (A1 + l·w), with A1 and w the
    /// footprint's effective area and width (integral over peak), is 1 / (1 + l·G).
    pub fn motion_g(self) -> f64 {
        let rr = self.radius() as f64;
        let line = simpson(-rr, rr, 512, |b| self.integrated(b.abs()));
        let area = simpson(0.0, rr, 512, |r| self.integrated(r) * 2.0 * std::f64::consts::PI * r);
        line / area * rr
    }

    /// The footprint table, row-major, `FOOTPRINT_TABLE_SIZE`^2 texels, in voxel^-2. Computed once
    /// per kernel (a million profile evaluations) and shared.
    pub fn footprint_table(self) -> Vec<f32> {
        static TABLES: KernelTables = [const { OnceLock::new() }; 4];
        self.cached(&TABLES, Kernel::compute_footprint_table)
    }

    /// The footprint as a function of s = r² in radius units (`RADIAL_TABLE_SIZE` + 1 samples at
    /// s = i / N, linear in between, 0 from s = 1), in voxel^-2 with `footprint_table`'s normaliser.
    /// A radially symmetric kernel's footprint depends on r alone, so the footprint stage samples
    /// this (one pair load, no sampler; `radial_pairs`) rather than the 2D table (four texel fetches).
    pub fn radial_table(self) -> Vec<f32> {
        static TABLES: KernelTables = [const { OnceLock::new() }; 4];
        self.cached(&TABLES, Kernel::compute_radial_table)
    }

    /// `radial_table` as (value, step to the next value) per interval, the layout the GPU reads:
    /// one 8-byte load per pixel instead of two lane-by-lane loads on llvmpipe (~10 % of the tile
    /// compositor's time). The step is the same f32 difference the mirror takes, so both agree.
    pub fn radial_pairs(self) -> Vec<[f32; 2]> {
        self.radial_table().windows(2).map(|w| [w[0], w[1] - w[0]]).collect()
    }

    fn compute_radial_table(self) -> Vec<f32> {
        let n = crate::constants::RADIAL_TABLE_SIZE as usize;
        let rr = self.radius() as f64;
        let (_, total) = self.raw_footprint_table();
        (0..=n).map(|i| (self.integrated((i as f64 / n as f64).sqrt() * rr) / total) as f32).collect()
    }

    /// One table per kernel, computed on first use.
    fn cached(self, tables: &'static KernelTables, compute: fn(Kernel) -> Vec<f32>) -> Vec<f32> {
        let slot = KERNELS.iter().position(|&k| k == self).expect("every kernel is listed");
        tables[slot].get_or_init(|| compute(self)).clone()
    }

    /// How far the footprints of a flat, uniform sheet of unit-spaced voxels seen head-on are from
    /// summing to a constant: (max - min) / mean of their sum over the cell, from the radial table.
    /// A kernel narrower than the voxel spacing shows the grid.
    pub fn sheet_ripple(self) -> f64 {
        let table = self.radial_table();
        let rr = self.radius() as f64;
        let n = 32;
        let (mut lo, mut hi, mut sum) = (f64::INFINITY, 0.0f64, 0.0);
        for a in 0..n {
            for b in 0..n {
                let v = lattice_sum(rr, a as f64 / n as f64, b as f64 / n as f64, |dx, dy| {
                    let (u, v) = (dx / rr, dy / rr);
                    sample_radial(&table, (u * u + v * v) as f32) as f64
                });
                lo = lo.min(v);
                hi = hi.max(v);
                sum += v;
            }
        }
        (hi - lo) / (sum / (n * n) as f64)
    }

    fn compute_footprint_table(self) -> Vec<f32> {
        let (t, total) = self.raw_footprint_table();
        t.iter().map(|v| (v / total) as f32).collect()
    }

    /// Unnormalised footprint texels and their discrete integral (the normaliser both tables share).
    fn raw_footprint_table(self) -> (Vec<f64>, f64) {
        let n = FOOTPRINT_TABLE_SIZE as usize;
        let rr = self.radius() as f64;
        let mut t = vec![0.0f64; n * n];
        for y in 0..n {
            for x in 0..n {
                let u = ((x as f64 + 0.5) / n as f64 * 2.0 - 1.0) * rr;
                let v = ((y as f64 + 0.5) / n as f64 * 2.0 - 1.0) * rr;
                t[y * n + x] = self.integrated((u * u + v * v).sqrt());
            }
        }
        let texel_area = (2.0 * rr / n as f64).powi(2);
        let total = t.iter().sum::<f64>() * texel_area;
        (t, total)
    }

    /// The pre-integrated kernel-slice table of the image-aligned sheet buffer (Mueller & Crawfis
    /// 1998): texel (x, y) holds the kernel integrated along the view axis from -R up to z at
    /// in-plane distance r, with r = x / (N-1) and z = 2y / (N-1) - 1 in radius units, so the first
    /// row is exactly 0 and the last equals the footprint. A slab [za, zb] of a splat then weighs
    /// S(r, zb) - S(r, za), and the slabs of one splat sum to its footprint. Same normaliser as
    /// `footprint_table`; computed once per kernel.
    pub fn slice_table(self) -> Vec<f32> {
        static TABLES: KernelTables = [const { OnceLock::new() }; 4];
        self.cached(&TABLES, Kernel::compute_slice_table)
    }

    fn compute_slice_table(self) -> Vec<f32> {
        let n = FOOTPRINT_TABLE_SIZE as usize;
        let rr = self.radius() as f64;
        let (_, total) = self.raw_footprint_table();
        let mut t = vec![0.0f32; n * n];
        // Cumulative Simpson along z, 16 intervals per table row.
        const SUB: usize = 16;
        for x in 0..n {
            let rho = x as f64 / (n - 1) as f64 * rr;
            let mut acc = 0.0;
            for y in 1..n {
                let z0 = (2.0 * (y - 1) as f64 / (n - 1) as f64 - 1.0) * rr;
                let z1 = (2.0 * y as f64 / (n - 1) as f64 - 1.0) * rr;
                acc += simpson(z0, z1, SUB, |z| self.profile((rho * rho + z * z).sqrt()));
                t[y * n + x] = (acc / total) as f32;
            }
        }
        t
    }
}

/// The radial table lookup, as `sample_radial` in `glsl/shared/footprint_table.glsl`: the radial footprint table at
/// s = r² (radius units).
pub fn sample_radial(table: &[f32], s: f32) -> f32 {
    let n = crate::constants::RADIAL_TABLE_SIZE;
    let t = s.clamp(0.0, 1.0) * n as f32;
    let i = (t as u32).min(n - 1);
    let a = table[i as usize];
    a + (table[i as usize + 1] - a) * (t - i as f32)
}

/// A radial profile in x = r / R of two cubic Hermite pieces: from 1 with zero slope at the centre
/// to `value` with `slope` at `knot`, and on to 0 with zero slope at x = 1 (C1 throughout).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialSpline {
    /// Where the pieces meet, in (0, 1).
    pub knot: f64,
    /// The profile there.
    pub value: f64,
    /// Its slope there (per unit x).
    pub slope: f64,
}

impl RadialSpline {
    /// The profile at x (0 from x = 1 on).
    pub fn eval(&self, x: f64) -> f64 {
        let hermite = |x0: f64, x1: f64, p0: f64, m0: f64, p1: f64, m1: f64| {
            let d = x1 - x0;
            let t = (x - x0) / d;
            let (t2, t3) = (t * t, t * t * t);
            (2.0 * t3 - 3.0 * t2 + 1.0) * p0
                + (t3 - 2.0 * t2 + t) * d * m0
                + (3.0 * t2 - 2.0 * t3) * p1
                + (t3 - t2) * d * m1
        };
        match x {
            x if x >= 1.0 => 0.0,
            x if x <= self.knot => hermite(0.0, self.knot, 1.0, 0.0, self.value, self.slope),
            _ => hermite(self.knot, 1.0, self.value, self.slope, 0.0, 0.0),
        }
    }
}

/// Support of `Kernel::CrawfisMax` in voxel spacings (Crawfis and Max's).
pub const CRAWFIS_MAX_RADIUS: f64 = 1.6;

/// `fit_crawfis_max`'s result, baked in (tests/units.rs fits it again and compares).
pub const CRAWFIS_MAX: RadialSpline =
    RadialSpline { knot: 0.18708572534168427, value: 0.8426488031131327, slope: -1.3164634908267445 };

/// The footprints of a unit lattice of kernels of support `radius` summed at (x, y) in the cell:
/// `footprint(dx, dy)` at each lattice point's offset (voxels) within reach.
fn lattice_sum(radius: f64, x: f64, y: f64, footprint: impl Fn(f64, f64) -> f64) -> f64 {
    let reach = radius.ceil() as i32 + 1;
    let mut v = 0.0;
    for i in -reach..=reach {
        for j in -reach..=reach {
            v += footprint(x - i as f64, y - j as f64);
        }
    }
    v
}

/// How far the footprints of a uniform unit lattice of radial kernels `h(r)` (r in voxels, support
/// `radius`) seen along an axis are from summing to a constant: the RMS of their sum over the
/// lattice cell, relative to its mean. Crawfis and Max chose their kernel to make this smallest.
pub fn lattice_rms(h: impl Fn(f64) -> f64, radius: f64) -> f64 {
    // The footprint f(rho) = integral of h along the ray, tabulated, linear in between.
    const M: usize = 160;
    let f: Vec<f64> = (0..=M)
        .map(|k| {
            let rho = k as f64 / M as f64 * radius;
            let half = (radius * radius - rho * rho).max(0.0).sqrt();
            simpson(-half, half, 64, |z| h((rho * rho + z * z).sqrt()))
        })
        .collect();
    let at = |rho: f64| {
        let t = rho / radius * M as f64;
        let i = t as usize;
        if i >= M {
            return 0.0;
        }
        f[i] + (f[i + 1] - f[i]) * (t - i as f64)
    };
    // The lattice's symmetry: a quarter of the cell, sampled at cell centres.
    const N: usize = 16;
    let mut sums = Vec::with_capacity(N * N);
    for a in 0..N {
        for b in 0..N {
            let (x, y) = ((a as f64 + 0.5) / N as f64 * 0.5, (b as f64 + 0.5) / N as f64 * 0.5);
            sums.push(lattice_sum(radius, x, y, |dx, dy| at((dx * dx + dy * dy).sqrt())));
        }
    }
    let mean = sums.iter().sum::<f64>() / sums.len() as f64;
    (sums.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / sums.len() as f64).sqrt() / mean
}

/// Crawfis and Max's kernel by their criterion: the `RadialSpline` of support 1.6 whose lattice
/// of footprints sums with the smallest `lattice_rms`, non-negative everywhere (a negative lobe
/// would be negative optical depth). Nelder-Mead over (knot, value, slope) from three starts, the
/// Hermite cubic first (the variance has several local minima: starts nearer the edge end higher).
pub fn fit_crawfis_max() -> RadialSpline {
    let spline = |p: &[f64; 3]| RadialSpline { knot: p[0], value: p[1], slope: p[2] };
    let cost = |p: &[f64; 3]| {
        let s = spline(p);
        let valid = (0.05..=0.95).contains(&s.knot) && (0..=200).all(|i| s.eval(i as f64 / 200.0) >= 0.0);
        if !valid {
            return f64::INFINITY;
        }
        lattice_rms(|r| s.eval(r / CRAWFIS_MAX_RADIUS), CRAWFIS_MAX_RADIUS)
    };
    // The Hermite cubic 1 - 3x^2 + 2x^3 at x = 0.5 (value 0.5, slope -1.5), and two others.
    let fits = [[0.5, 0.5, -1.5], [0.35, 0.7, -1.5], [0.7, 0.15, -0.6]].map(|start| nelder_mead(start, &cost));
    let best = fits.iter().min_by(|a, b| a.1.total_cmp(&b.1)).expect("three fits");
    spline(&best.0)
}

/// Nelder-Mead's simplex search for the smallest `cost` from `start`: 400 steps, the best point
/// and its cost.
fn nelder_mead(start: [f64; 3], cost: &impl Fn(&[f64; 3]) -> f64) -> ([f64; 3], f64) {
    let mut simplex: Vec<([f64; 3], f64)> = (0..4)
        .map(|i| {
            let mut p = start;
            if i > 0 {
                p[i - 1] += [0.1, 0.1, 0.3][i - 1];
            }
            (p, cost(&p))
        })
        .collect();
    for _ in 0..400 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let centroid: [f64; 3] = std::array::from_fn(|k| simplex[..3].iter().map(|s| s.0[k]).sum::<f64>() / 3.0);
        let toward =
            |t: f64| -> [f64; 3] { std::array::from_fn(|k| centroid[k] + t * (simplex[3].0[k] - centroid[k])) };
        let r = toward(-1.0);
        let fr = cost(&r);
        if fr < simplex[0].1 {
            let e = toward(-2.0);
            let fe = cost(&e);
            simplex[3] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < simplex[2].1 {
            simplex[3] = (r, fr);
        } else {
            let c = toward(0.5);
            let fc = cost(&c);
            if fc < simplex[3].1 {
                simplex[3] = (c, fc);
            } else {
                let best = simplex[0].0;
                for s in &mut simplex[1..] {
                    s.0 = std::array::from_fn(|k| best[k] + 0.5 * (s.0[k] - best[k]));
                    s.1 = cost(&s.0);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex[0]
}
