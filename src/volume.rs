//! Volume rasters and their sparse extraction into splat rows (section 1.2.5): only non-empty
//! voxels are stored, each keeping its grid index.
//!
//! ```
//! use voxsplat::{Grid, SplatSet};
//! // A splat set made voxel by voxel: premultiplied RGBA, `None` where nothing is drawn.
//! let grid = Grid::centered([4, 4, 4], [1.0, 1.0, 2.0])?;
//! let set = SplatSet::from_fn(grid, |i, _, _| (i % 2 == 0).then_some([0.5, 0.5, 0.5, 0.5]))?;
//! assert_eq!(set.len(), 32);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
use crate::gpu_types::Splat;
use glam::{DVec3, Vec3};

/// Most splats a scene may hold (32 bytes each on the GPU, plus order and parameters).
pub const MAX_SPLATS: usize = 1 << 26;
/// Most rows (ny * nz) of the row table.
pub const MAX_ROWS: u64 = 1 << 26;
/// Largest extent of one axis.
pub const MAX_DIM: u32 = 1 << 16;

/// A regular grid: dimensions, the cell matrix (voxel spacing, and a sheared grid's shear), and
/// the world position of voxel (0, 0, 0). Voxel (i, j, k) lies at `origin + U (i, j, k)` with
/// U = [[sx, hxy, hxz], [0, sy, hyz], [0, 0, sz]]: upper triangular, so any index-to-world affine
/// is a rotation of one (`Orientation::grid`), and an axis-aligned grid has a diagonal U.
///
/// ```
/// use voxsplat::Grid;
/// // 256 x 256 x 128 voxels, 0.5 mm apart in-plane and 1 mm between slices, centred on the origin.
/// let grid = Grid::centered([256, 256, 128], [0.5, 0.5, 1.0])?;
/// assert_eq!(grid.dims, [256, 256, 128]);
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// U's diagonal: the voxel spacing along x, y, z in world units (a sheared grid's distances
    /// between its index planes).
    pub spacing: [f32; 3],
    /// World position of voxel (0, 0, 0).
    pub origin: [f32; 3],
    /// U above its diagonal: how far x moves per step in j and in k, and y per step in k (zero
    /// for an axis-aligned grid).
    pub shear: [f32; 3],
}

impl Grid {
    /// A grid centred on the world origin.
    pub fn centered(dims: [u32; 3], spacing: [f32; 3]) -> Result<Self> {
        Self::centered_sheared(dims, spacing, [0.0; 3])
    }

    /// A sheared grid (`shear`: U above its diagonal) centred on the world origin.
    pub fn centered_sheared(dims: [u32; 3], spacing: [f32; 3], shear: [f32; 3]) -> Result<Self> {
        if shear.iter().any(|h| !h.is_finite()) {
            return Err(Error::InvalidArgument(format!("grid shear {shear:?} must be finite")));
        }
        let mut g = Self { dims, spacing, origin: [0.0; 3], shear };
        let mid = Vec3::from(dims.map(|d| (d.max(1) - 1) as f32)) * 0.5;
        g.origin = (-g.offset(mid)).to_array();
        g.validate()?;
        Ok(g)
    }

    /// U `at`: the world offset of grid point `at` (index units) from voxel (0, 0, 0).
    fn offset(&self, at: Vec3) -> Vec3 {
        let (s, h) = (self.spacing, self.shear);
        Vec3::new(at.x * s[0] + at.y * h[0] + at.z * h[1], at.y * s[1] + at.z * h[2], at.z * s[2])
    }

    /// World position of grid point `at` (index units; mirror of `grid_point` in
    /// glsl/shared/params.glsl).
    pub fn point(&self, at: Vec3) -> Vec3 {
        Vec3::from(self.origin) + self.offset(at)
    }

    /// The world box holding every grid point of the index box `lo..=hi`.
    pub fn world_box(&self, lo: Vec3, hi: Vec3) -> [Vec3; 2] {
        let corners =
            (0..8).map(|c| self.offset(Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo)));
        let (l, h) = corners.fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(p), h.max(p)));
        [Vec3::from(self.origin) + l, Vec3::from(self.origin) + h]
    }

    /// The index coordinates of world point `p` (U's inverse, by back substitution).
    pub fn index_point(&self, p: DVec3) -> DVec3 {
        self.index_dir(p - DVec3::from(self.origin.map(f64::from)))
    }

    /// A world direction (or offset) in index units.
    pub fn index_dir(&self, d: DVec3) -> DVec3 {
        let (s, h) = (DVec3::from(self.spacing.map(f64::from)), self.shear.map(f64::from));
        let z = d.z / s.z;
        let y = (d.y - h[2] * z) / s.y;
        DVec3::new((d.x - h[0] * y - h[1] * z) / s.x, y, z)
    }

    /// The world gradient of a field whose central differences (value at index + 1 minus value
    /// at index - 1) along i, j, k are `diff`: solves U^T g = diff / 2 (mirror of `gradient_at`
    /// in glsl/shared/brick.glsl).
    pub fn gradient(&self, diff: [f32; 3]) -> [f32; 3] {
        let (s, h) = (self.spacing, self.shear);
        let gx = diff[0] / (2.0 * s[0]);
        let gy = (diff[1] - 2.0 * h[0] * gx) / (2.0 * s[1]);
        let gz = (diff[2] - 2.0 * (h[1] * gx + h[2] * gy)) / (2.0 * s[2]);
        [gx, gy, gz]
    }

    /// The cell matrix U (columns: the world steps along i, j, k).
    pub fn cell_matrix(&self) -> glam::DMat3 {
        let (s, h) = (self.spacing.map(f64::from), self.shear.map(f64::from));
        glam::DMat3::from_cols(DVec3::new(s[0], 0.0, 0.0), DVec3::new(h[0], s[1], 0.0), DVec3::new(h[1], h[2], s[2]))
    }

    /// The grid is sheared (U not diagonal).
    pub fn is_sheared(&self) -> bool {
        self.shear != [0.0; 3]
    }

    /// Reject empty, overflowing or degenerate grids.
    pub fn validate(&self) -> Result<()> {
        if self.dims.iter().any(|&d| d == 0 || d > MAX_DIM) {
            return Err(Error::InvalidArgument(format!("grid dimensions {:?} must be in 1..={MAX_DIM}", self.dims)));
        }
        if self.spacing.iter().any(|s| !s.is_finite() || *s <= 0.0) {
            return Err(Error::InvalidArgument(format!(
                "voxel spacing {:?} must be finite and positive",
                self.spacing
            )));
        }
        if self.origin.iter().chain(&self.shear).any(|o| !o.is_finite()) {
            return Err(Error::InvalidArgument("grid origin and shear must be finite".into()));
        }
        let rows = self.dims[1] as u64 * self.dims[2] as u64;
        if rows > MAX_ROWS {
            return Err(Error::TooLarge(format!("{rows} rows exceed the limit of {MAX_ROWS}")));
        }
        Ok(())
    }

    /// World position of voxel `ijk`.
    pub fn position(&self, ijk: [u32; 3]) -> Vec3 {
        self.point(Vec3::new(ijk[0] as f32, ijk[1] as f32, ijk[2] as f32))
    }

    /// World centre of the grid.
    pub fn center(&self) -> Vec3 {
        self.position([0, 0, 0]).lerp(self.position([self.dims[0] - 1, self.dims[1] - 1, self.dims[2] - 1]), 0.5)
    }

    /// Length of the grid's diagonal (corner voxel centres).
    pub fn diagonal(&self) -> f32 {
        (self.position([self.dims[0] - 1, self.dims[1] - 1, self.dims[2] - 1]) - self.position([0, 0, 0])).length()
    }

    /// The spacing the footprint kernel is scaled by (the largest, so anisotropic grids have no
    /// holes). A sheared grid's too: every point lies within half a diagonal entry per axis of a
    /// voxel (the nearest-plane bound), as on the axis-aligned grid of the same spacing, so its
    /// kernels and their energy are that grid's and only their centres move.
    pub fn kernel_spacing(&self) -> f32 {
        self.spacing.iter().cloned().fold(0.0, f32::max)
    }
}

/// The smallest and largest finite values of `values` ((inf, -inf) when none is finite). Eight
/// lanes of compares and selects, which vectorise: a 1024^3 store's range pass took seconds one
/// value at a time.
pub fn value_span(values: &[f32]) -> (f32, f32) {
    let (mut l8, mut h8) = ([f32::INFINITY; 8], [f32::NEG_INFINITY; 8]);
    let mut lanes = values.chunks_exact(8);
    for c in &mut lanes {
        for i in 0..8 {
            let (v, f) = (c[i], c[i].is_finite());
            l8[i] = if f && v < l8[i] { v } else { l8[i] };
            h8[i] = if f && v > h8[i] { v } else { h8[i] };
        }
    }
    let finite = lanes.remainder().iter().chain(&l8).chain(&h8).filter(|v| v.is_finite());
    finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)))
}

/// The extracted voxels of a grid as rows along i: row (j, k) holds its voxels sorted by i.
///
/// ```
/// use voxsplat::{Grid, SplatSet};
/// // Keep every voxel of the lower half, translucent blue.
/// let set = SplatSet::from_fn(Grid::centered([8; 3], [1.0; 3])?, |_, _, k| (k < 4).then_some([0.2, 0.4, 1.0, 0.5]))?;
/// assert_eq!(set.len(), 8 * 8 * 4);
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct SplatSet {
    grid: Grid,
    row_start: Vec<u32>,
    splats: Vec<Splat>,
    /// Per-axis voxel positions of a rectilinear grid (`with_coordinates`).
    coords: Option<std::sync::Arc<[Vec<f32>; 3]>>,
    /// A label volume's voxels whose label its table lacks (`labels::classify_labels`).
    unlabelled: u64,
}

impl SplatSet {
    /// Visit every cell in (k, j, i) order and keep those for which `voxel` returns a colour
    /// (straight RGB, opacity). Memory is proportional to the kept voxels plus one entry per row.
    /// Each splat's value (what the projection modes take, `Mode`) is its opacity.
    pub fn from_fn(grid: Grid, mut voxel: impl FnMut(u32, u32, u32) -> Option<[f32; 4]>) -> Result<Self> {
        Self::from_fn_valued(grid, |i, j, k| voxel(i, j, k).map(|c| (c, c[3].clamp(0.0, 1.0))))
    }

    /// As `from_fn`, `voxel` giving each kept voxel's colour and its value in [0, 1] (a classified
    /// volume's normalised density; what the projection modes take). A value outside [0, 1] or
    /// not finite is refused.
    pub fn from_fn_valued(grid: Grid, mut voxel: impl FnMut(u32, u32, u32) -> Option<([f32; 4], f32)>) -> Result<Self> {
        grid.validate()?;
        let [nx, ny, nz] = grid.dims;
        let mut row_start = Vec::with_capacity((ny as usize) * (nz as usize) + 1);
        let mut splats = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                row_start.push(splats.len() as u32);
                for i in 0..nx {
                    if let Some((c, value)) = voxel(i, j, k) {
                        if c.iter().any(|v| !v.is_finite()) {
                            return Err(Error::InvalidArgument(format!("voxel ({i},{j},{k}) has a non-finite colour")));
                        }
                        if !(0.0..=1.0).contains(&value) {
                            return Err(Error::InvalidArgument(format!(
                                "voxel ({i},{j},{k}) has the value {value}: values lie in [0, 1]"
                            )));
                        }
                        if c[3] <= 0.0 {
                            continue;
                        }
                        if splats.len() >= MAX_SPLATS {
                            return Err(Error::TooLarge(format!("more than {MAX_SPLATS} non-empty voxels")));
                        }
                        splats.push(Splat { ijk: [i, j, k, value.to_bits()], color: c });
                    }
                }
            }
        }
        row_start.push(splats.len() as u32);
        Ok(Self { grid, row_start, splats, coords: None, unlabelled: 0 })
    }

    /// No splats on `grid` (a bricked volume's stand-in: its splats are made per frame).
    pub fn empty(grid: Grid) -> Result<Self> {
        grid.validate()?;
        let rows = grid.dims[1] as usize * grid.dims[2] as usize + 1;
        Ok(Self { grid, row_start: vec![0; rows], splats: Vec::new(), coords: None, unlabelled: 0 })
    }

    /// A label volume's voxels whose label the table lacks, hidden (`Rendered::stats` reports them).
    pub fn unlabelled(&self) -> u64 {
        self.unlabelled
    }

    /// The same splats, recording `n` voxels hidden for a label the table lacks.
    pub fn with_unlabelled(mut self, n: u64) -> Self {
        self.unlabelled = n;
        self
    }

    /// The grid the splats sit on.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The same splats on a rectilinear grid whose spacing varies along each axis (chapter 2's
    /// vectors U, V, W; e.g. CT slices at irregular positions): `coords[a][i]` is the world
    /// coordinate of index `i` along axis `a`, one per voxel, finite and strictly increasing.
    /// PBTF needs only the eye's cell, so the orders and validators of `crate::order` run on
    /// such grids through [`SplatSet::index_of`]; the per-splat stage places each splat at its
    /// coordinates, as wide as its own cell and weighted by its cell's volume (docs/MODEL.md,
    /// "PBTF on rectilinear grids"). The grid's origin
    /// and spacing become the coordinates' first values and mean gaps. The ray casters and the
    /// truths, which sample a uniform grid, refuse such sets.
    pub fn with_coordinates(mut self, coords: [Vec<f32>; 3]) -> Result<Self> {
        if self.grid.is_sheared() {
            return Err(Error::Unsupported("per-axis coordinates on a sheared grid".into()));
        }
        for (a, c) in coords.iter().enumerate() {
            let axis = ["x", "y", "z"][a];
            if c.len() != self.grid.dims[a] as usize {
                return Err(Error::InvalidArgument(format!(
                    "{} {axis} coordinates for {} voxels along {axis}",
                    c.len(),
                    self.grid.dims[a]
                )));
            }
            if let Some(bad) = c.iter().position(|v| !v.is_finite()) {
                return Err(Error::InvalidArgument(format!("{axis} coordinate {bad} is not finite")));
            }
            if let Some(w) = c.windows(2).position(|w| w[1] <= w[0]) {
                return Err(Error::InvalidArgument(format!(
                    "{axis} coordinates must increase strictly: {} then {} at index {w}",
                    c[w],
                    c[w + 1]
                )));
            }
        }
        // The grid spans the same box: its corners (framing, culling, slab ranges) are the
        // coordinates' ends, its spacing the mean gap.
        for (a, c) in coords.iter().enumerate() {
            self.grid.origin[a] = c[0];
            if c.len() > 1 {
                self.grid.spacing[a] = (c[c.len() - 1] - c[0]) / (c.len() - 1) as f32;
            }
        }
        self.grid.validate()?;
        self.coords = Some(std::sync::Arc::new(coords));
        Ok(self)
    }

    /// The smallest and largest grid index of its splats (`None`: no splats): what a camera frames.
    pub fn bounds(&self) -> Option<[[u32; 3]; 2]> {
        let first = self.splats.first()?.ijk;
        let start = [[first[0], first[1], first[2]]; 2];
        Some(self.splats.iter().fold(start, |[lo, hi], s| {
            [[0, 1, 2].map(|a| lo[a].min(s.ijk[a])), [0, 1, 2].map(|a| hi[a].max(s.ijk[a]))]
        }))
    }

    /// The per-axis coordinates of a rectilinear grid, if set.
    pub fn coordinates(&self) -> Option<&[Vec<f32>; 3]> {
        self.coords.as_deref()
    }

    /// World position of voxel `ijk`: the per-axis coordinates where set, else the grid's.
    pub fn position(&self, ijk: [u32; 3]) -> Vec3 {
        match &self.coords {
            Some(c) => Vec3::new(c[0][ijk[0] as usize], c[1][ijk[1] as usize], c[2][ijk[2] as usize]),
            None => self.grid.position(ijk),
        }
    }

    /// The spacing footprints are scaled by: the grid's, or a rectilinear grid's widest gap (which
    /// bounds its splats; each is as wide as its own cell).
    pub fn kernel_spacing(&self) -> f32 {
        match &self.coords {
            Some(c) => {
                let widest = c.iter().flat_map(|v| v.windows(2).map(|w| w[1] - w[0])).fold(0.0, f32::max);
                if widest > 0.0 {
                    widest
                } else {
                    self.grid.kernel_spacing()
                }
            }
            None => self.grid.kernel_spacing(),
        }
    }

    /// The length a splat's opacity is per: the kernel spacing, or on a rectilinear grid the widest
    /// gap that is not an outlier (at most ten times its axis's median gap). One far slice or
    /// position leaves the rest of the volume as opaque as it would be alone.
    pub fn opacity_length(&self) -> f32 {
        let Some(c) = &self.coords else { return self.grid.kernel_spacing() };
        let widest = c
            .iter()
            .filter_map(|v| {
                let mut gaps: Vec<f32> = v.windows(2).map(|w| w[1] - w[0]).collect();
                gaps.sort_by(f32::total_cmp);
                let median = *gaps.get(gaps.len() / 2)?;
                gaps.into_iter().filter(|&g| g <= 10.0 * median).reduce(f32::max)
            })
            .fold(0.0, f32::max);
        if widest > 0.0 {
            widest
        } else {
            self.kernel_spacing()
        }
    }

    /// The index coordinates of world point `p` (`index_of` per axis on a rectilinear grid; a
    /// sheared grid's inverse cell matrix).
    pub fn index_point(&self, p: DVec3) -> DVec3 {
        match self.coords {
            Some(_) => DVec3::new(self.index_of(0, p.x), self.index_of(1, p.y), self.index_of(2, p.z)),
            None => self.grid.index_point(p),
        }
    }

    /// The index-space coordinate of world coordinate `x` along `axis`: linear between the voxel
    /// positions (so the midpoint between two voxels maps to the half index between them, the grid
    /// plane PBTF splits at) and beyond the ends with the end spacing.
    pub fn index_of(&self, axis: usize, x: f64) -> f64 {
        let Some(c) = &self.coords else {
            return (x - self.grid.origin[axis] as f64) / self.grid.spacing[axis] as f64;
        };
        let c = &c[axis];
        if c.len() == 1 {
            return (x - c[0] as f64) / self.grid.spacing[axis] as f64;
        }
        // The segment [c[i], c[i + 1]] holding x (the first or last one beyond the ends).
        let i = c.partition_point(|&v| (v as f64) <= x).clamp(1, c.len() - 1) - 1;
        let (a, b) = (c[i] as f64, c[i + 1] as f64);
        i as f64 + (x - a) / (b - a)
    }
    /// The splats, row by row (PBTF rows along x).
    pub fn splats(&self) -> &[Splat] {
        &self.splats
    }
    /// Each row's first splat, then the count.
    pub fn row_start(&self) -> &[u32] {
        &self.row_start
    }
    /// The number of splats.
    pub fn len(&self) -> usize {
        self.splats.len()
    }
    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.splats.is_empty()
    }

    /// The row of (j, k).
    pub fn row_index(&self, j: u32, k: u32) -> usize {
        (j + self.grid.dims[1] * k) as usize
    }

    /// Index of the splat at (i, j, k), if that voxel was extracted.
    pub fn find(&self, i: u32, j: u32, k: u32) -> Option<usize> {
        let [nx, ny, nz] = self.grid.dims;
        if i >= nx || j >= ny || k >= nz {
            return None;
        }
        let r = self.row_index(j, k);
        let (s, e) = (self.row_start[r] as usize, self.row_start[r + 1] as usize);
        self.splats[s..e].binary_search_by_key(&i, |sp| sp.ijk[0]).ok().map(|x| s + x)
    }

    /// Splat indices grouped by slice along `axis` (a counting sort): `(offsets, list)` where
    /// slice `s` holds `list[offsets[s]..offsets[s + 1]]`.
    pub fn slices(&self, axis: usize) -> (Vec<u32>, Vec<u32>) {
        let n = self.grid.dims[axis] as usize;
        let mut offsets = vec![0u32; n + 1];
        for sp in &self.splats {
            offsets[sp.ijk[axis] as usize + 1] += 1;
        }
        for s in 0..n {
            offsets[s + 1] += offsets[s];
        }
        let mut fill = offsets.clone();
        let mut list = vec![0u32; self.splats.len()];
        for (idx, sp) in self.splats.iter().enumerate() {
            let s = sp.ijk[axis] as usize;
            list[fill[s] as usize] = idx as u32;
            fill[s] += 1;
        }
        (offsets, list)
    }

    /// Rank of each slice along `axis` among the non-empty slices (empty slices get the rank of
    /// the next non-empty one; they are never drawn).
    pub fn sheet_ranks(offsets: &[u32]) -> Vec<u32> {
        let mut rank = 0;
        let mut out = Vec::with_capacity(offsets.len().saturating_sub(1));
        for w in offsets.windows(2) {
            out.push(rank);
            if w[1] > w[0] {
                rank += 1;
            }
        }
        out
    }
}

/// A dense volume raster: density and RGBA per voxel. Loaders produce these; rendering uses the
/// sparse [`SplatSet`] extracted from it.
///
/// ```
/// use voxsplat::{Grid, Volume};
/// let grid = Grid::centered([2, 2, 2], [1.0; 3])?;
/// let volume = Volume::new(grid, vec![1.0; 8], vec![[0.5, 0.5, 0.5, 0.5]; 8])?;
/// # let _ = volume;
/// assert!(Volume::new(grid, vec![1.0; 7], vec![[0.0; 4]; 8]).is_err(), "one density per voxel");
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Volume {
    /// The grid.
    pub grid: Grid,
    /// Density per voxel (x fastest).
    pub density: Vec<f32>,
    /// Straight RGBA per voxel.
    pub rgba: Vec<[f32; 4]>,
}

impl Volume {
    /// A volume, checked: both arrays hold one value per voxel.
    pub fn new(grid: Grid, density: Vec<f32>, rgba: Vec<[f32; 4]>) -> Result<Self> {
        grid.validate()?;
        let n = grid.dims.iter().map(|&d| d as u64).product::<u64>();
        if density.len() as u64 != n || rgba.len() as u64 != n {
            return Err(Error::InvalidArgument(format!(
                "volume of {n} voxels given {} densities and {} colours",
                density.len(),
                rgba.len()
            )));
        }
        Ok(Self { grid, density, rgba })
    }

    /// Keep the voxels whose density exceeds `threshold`.
    pub fn extract(&self, threshold: f32) -> Result<SplatSet> {
        let [nx, ny, _] = self.grid.dims;
        SplatSet::from_fn(self.grid, |i, j, k| {
            let idx = i as usize + nx as usize * (j as usize + ny as usize * k as usize);
            (self.density[idx] > threshold).then_some(self.rgba[idx])
        })
    }
}

/// A dense scalar volume as loaded: x fastest, then y, then z.
///
/// ```
/// use voxsplat::volume::ScalarVolume;
/// // 2 x 2 x 2 samples, 0.5 apart along z: sample (i, j, k) is values[i + 2 * (j + 2 * k)].
/// let v = ScalarVolume { dims: [2, 2, 2], spacing: [1.0, 1.0, 0.5], values: (0..8).map(|i| i as f32).collect() };
/// assert_eq!(v.values[1 + 2 * (0 + 2 * 1)], 5.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarVolume {
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing along x, y, z.
    pub spacing: [f32; 3],
    /// The samples, x fastest.
    pub values: Vec<f32>,
}

/// A height grid: `width` × `rows` heights, row 0 first (north for the DEMs here); a NaN height
/// is a cell without one (a GeoTIFF no-data cell), drawn as a hole.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightGrid {
    /// Heights across.
    pub width: u32,
    /// Rows of heights.
    pub rows: u32,
    /// The heights, row by row.
    pub heights: Vec<f32>,
}

/// Largest dense field the references build (RGBA32F per voxel).
pub const MAX_DENSE_BYTES: u64 = 4 << 30;

/// The voxels as a dense grid of (colour * tau, tau): what the ray caster's 3D texture holds.
#[derive(Clone, Debug)]
pub struct DenseField {
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// (colour * tau, tau) per voxel, x fastest.
    pub values: Vec<[f32; 4]>,
}

impl DenseField {
    /// Which bricks of `brick`³ voxels hold a voxel with optical depth, looking one voxel beyond each
    /// face (the trilinear support of every sample inside the brick): (bricks per axis, flags). The
    /// ray caster's empty-space skipping reads them (`raycast`, both engines).
    pub fn brick_occupancy(&self, brick: u32) -> ([u32; 3], Vec<u32>) {
        let field = self;
        let b = brick.max(1) as i64;
        let nb = field.dims.map(|d| (d as i64 + b - 1) / b);
        let mut occ = vec![0u32; (nb[0] * nb[1] * nb[2]) as usize];
        for k in 0..field.dims[2] as i64 {
            for j in 0..field.dims[1] as i64 {
                for i in 0..field.dims[0] as i64 {
                    if field.at(i, j, k)[3] <= 0.0 {
                        continue;
                    }
                    // Mark every brick whose widened range [bB - 1, (b+1)B + 1] holds (i, j, k).
                    let range = |c: i64, n: i64| ((c - 1).div_euclid(b).max(0), ((c + 1).div_euclid(b)).min(n - 1));
                    let (rx, ry, rz) = (range(i, nb[0]), range(j, nb[1]), range(k, nb[2]));
                    for bz in rz.0..=rz.1 {
                        for by in ry.0..=ry.1 {
                            for bx in rx.0..=rx.1 {
                                occ[((bz * nb[1] + by) * nb[0] + bx) as usize] = 1;
                            }
                        }
                    }
                }
            }
        }
        (nb.map(|n| n as u32), occ)
    }

    /// The non-empty voxels of `set` on their grid (refused past `MAX_DENSE_BYTES`).
    pub fn new(set: &SplatSet) -> Result<Self> {
        let [nx, ny, nz] = set.grid().dims;
        let n = nx as u64 * ny as u64 * nz as u64;
        if n * 16 > MAX_DENSE_BYTES {
            return Err(Error::TooLarge(format!("a dense field of {n} voxels exceeds {MAX_DENSE_BYTES} bytes")));
        }
        let mut values = vec![[0.0f32; 4]; n as usize];
        for sp in set.splats() {
            let tau = optical_depth(sp.color[3]);
            let idx = sp.ijk[0] as usize + nx as usize * (sp.ijk[1] as usize + ny as usize * sp.ijk[2] as usize);
            values[idx] = [sp.color[0] * tau, sp.color[1] * tau, sp.color[2] * tau, tau];
        }
        Ok(Self { dims: [nx, ny, nz], values })
    }

    /// The projection modes' field of `set`: (value, 1, 0, tau) at each non-empty voxel, zero
    /// elsewhere, so a trilinear sample holds the reconstructed value, the voxels' coverage and
    /// the optical depth (refused past `MAX_DENSE_BYTES`).
    pub fn projection(set: &SplatSet) -> Result<Self> {
        let mut field = Self::new(set)?;
        let nx = field.dims[0] as usize;
        let ny = field.dims[1] as usize;
        for sp in set.splats() {
            let idx = sp.ijk[0] as usize + nx * (sp.ijk[1] as usize + ny * sp.ijk[2] as usize);
            let tau = field.values[idx][3];
            field.values[idx] = [f32::from_bits(sp.ijk[3]), 1.0, 0.0, tau];
        }
        Ok(field)
    }

    /// The voxel at (i, j, k); empty outside the grid.
    pub fn at(&self, i: i64, j: i64, k: i64) -> [f32; 4] {
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        if i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz {
            return [0.0; 4];
        }
        self.values[(i + nx * (j + ny * k)) as usize]
    }

    /// For each voxel, whether any non-empty voxel lies within `reach` cells (Chebyshev): lets the
    /// references skip empty space without changing the result.
    #[cfg(feature = "lab")] // the truth's empty-space skipping reads it
    pub(crate) fn occupancy(&self, reach: i64) -> Vec<bool> {
        let [nx, ny, nz] = self.dims.map(|d| d as usize);
        let mut occ: Vec<bool> = self.values.iter().map(|v| v[3] > 0.0).collect();
        let strides = [1usize, nx, nx * ny];
        for (axis, &len) in [nx, ny, nz].iter().enumerate() {
            let stride = strides[axis];
            let src = occ.clone();
            for (idx, o) in occ.iter_mut().enumerate() {
                let c = (idx / stride % len) as i64;
                let lo = (c - reach).max(0);
                let hi = (c + reach).min(len as i64 - 1);
                let base = idx - c as usize * stride;
                *o = (lo..=hi).any(|q| src[base + q as usize * stride]);
            }
        }
        occ
    }
}

/// The largest opacity of one voxel-length of material (tau stays finite).
pub const MAX_OPACITY: f32 = 0.999;

/// tau = -ln(1 - alpha) of one voxel-length of material, alpha clamped to `MAX_OPACITY`.
pub fn optical_depth(opacity: f32) -> f32 {
    -(1.0 - opacity.clamp(0.0, MAX_OPACITY)).ln()
}

/// GPU memory a scene costs per splat: the splat (32 B), its parameters (80 B), its order entry and
/// its three slice-list entries (16 B), plus the per-row tables spread over the splats.
pub fn gpu_bytes_per_splat(set: &SplatSet) -> f64 {
    let n = set.len().max(1) as f64;
    let rows = (set.row_start().len() - 1) as f64;
    let dims = set.grid().dims;
    let per_splat = (std::mem::size_of::<crate::gpu_types::Splat>()
        + std::mem::size_of::<crate::gpu_types::SplatParams>()
        + 16) as f64;
    per_splat + (rows * (4.0 + 4.0 + 8.0) + (dims[0] + dims[1] + dims[2]) as f64 * 4.0) / n
}

#[cfg(test)]
mod tests {
    /// The eight-lane span equals a plain fold over the finite values, whatever the length and
    /// wherever NaN and infinities fall.
    #[test]
    fn value_span_is_the_finite_values_span() {
        let mut seed = 7u64;
        for n in 0..70usize {
            let values: Vec<f32> = (0..n)
                .map(|_| {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    match seed >> 60 {
                        0 => f32::NAN,
                        1 => f32::INFINITY,
                        2 => f32::NEG_INFINITY,
                        _ => (seed >> 32) as u32 as f32 / 1e6 - 2000.0,
                    }
                })
                .collect();
            let plain = values
                .iter()
                .filter(|v| v.is_finite())
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
            assert_eq!(super::value_span(&values), plain, "{values:?}");
        }
    }
}
