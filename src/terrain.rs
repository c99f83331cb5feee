//! Terrain as voxel columns (chapter 5): one splat at each height cell's surface, plus splats
//! filling the vertical gap down to the lowest 4-neighbour so the surface has no holes from a
//! grazing view.
//!
//! ```
//! use voxsplat::{loaders::HeightGrid, terrain::{terrain_splats, TerrainOptions}};
//! // A height field as voxel columns (chapter 5): each cell a column of splats up to its height.
//! let heights = HeightGrid { width: 4, rows: 4, heights: vec![2.0; 16] };
//! let set = terrain_splats(&heights, &TerrainOptions::default())?;
//! assert!(set.len() >= 16);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
use crate::volume::HeightGrid;
use crate::volume::{Grid, SplatSet, MAX_SPLATS};

/// Host bytes a splat set takes per splat: the splat (32 bytes), doubled as its vector grows.
const SPLAT_HOST_BYTES: u64 = 2 * std::mem::size_of::<crate::gpu_types::Splat>() as u64;

/// Most height levels a terrain may span.
pub const MAX_LEVELS: u32 = 4096;
/// The level of a cell without a height (a hole: no column).
const HOLE: u32 = u32::MAX;

#[derive(Clone, Debug)]
/// How a height grid becomes voxel columns.
pub struct TerrainOptions {
    /// Horizontal size of one height cell, in height units (e.g. 233 for a 233 m DEM in metres);
    /// 0 picks one that makes the relief a sixth of the grid's width (before `vscale`).
    pub cell: f32,
    /// Vertical exaggeration.
    pub vscale: f32,
    /// Colour image covering the same extent (row 0 = the grid's row 0); `None`: hypsometric ramp.
    pub color: Option<image::RgbaImage>,
    /// Opacity of one voxel-length of ground.
    pub opacity: f32,
    /// Fill each column down to its lowest neighbour (on by default; off only to show the holes).
    pub fill_gaps: bool,
}

impl Default for TerrainOptions {
    fn default() -> Self {
        Self { cell: 1.0, vscale: 1.0, color: None, opacity: 0.98, fill_gaps: true }
    }
}

/// Green lowlands through brown to white peaks.
fn hypsometric(t: f32) -> [f32; 3] {
    let stops: [(f32, [f32; 3]); 5] = [
        (0.0, [0.20, 0.45, 0.20]),
        (0.35, [0.45, 0.55, 0.25]),
        (0.6, [0.55, 0.42, 0.28]),
        (0.85, [0.6, 0.55, 0.5]),
        (1.0, [0.95, 0.95, 0.97]),
    ];
    for w in stops.windows(2) {
        if t <= w[1].0 {
            let s = ((t - w[0].0) / (w[1].0 - w[0].0)).clamp(0.0, 1.0);
            return [0, 1, 2].map(|c| w[0].1[c] + (w[1].1[c] - w[0].1[c]) * s);
        }
    }
    stops[4].1
}

/// Build the splat columns. Grid x = column, y = row counted from the last row (so +y points to
/// row 0, north for the DEMs here), z = height level.
pub fn terrain_splats(h: &HeightGrid, opts: &TerrainOptions) -> Result<SplatSet> {
    let (w, rows) = (h.width, h.rows);
    if w < 2 || rows < 2 || h.heights.len() as u64 != w as u64 * rows as u64 {
        return Err(Error::InvalidArgument("a height grid needs at least 2x2 cells".into()));
    }
    if !(opts.cell.is_finite() && opts.cell >= 0.0 && opts.vscale.is_finite() && opts.vscale > 0.0) {
        return Err(Error::InvalidArgument("cell size and vertical scale must be positive".into()));
    }
    let finite: Vec<f32> = h.heights.iter().cloned().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return Err(Error::InvalidArgument("no finite height".into()));
    }
    let (hmin, hmax) = finite.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let cell = if opts.cell > 0.0 { opts.cell } else { ((hmax - hmin) / (w.max(rows) as f32 / 6.0)).max(1e-6) };
    // The top level in f64 before any cast: a huge --vscale would saturate the u32 and wrap the
    // grid's height to 0.
    let top = ((hmax as f64 - hmin as f64) / cell as f64 * opts.vscale as f64).round();
    if top.is_nan() || top >= MAX_LEVELS as f64 {
        return Err(Error::TooLarge(format!(
            "{top:e} height levels (relief {} at cell {cell} and vscale {}) exceed {MAX_LEVELS}: lower --vscale",
            hmax - hmin,
            opts.vscale
        )));
    }
    // A cell without a height (NaN: a GeoTIFF's no-data value) is a hole: no column.
    let level_of = |v: f32| -> u32 {
        if v.is_finite() {
            ((v - hmin) / cell * opts.vscale).round().max(0.0) as u32
        } else {
            HOLE
        }
    };
    let levels: Vec<u32> = h.heights.iter().map(|&v| level_of(v)).collect();
    let nz = levels.iter().filter(|&&l| l != HOLE).max().copied().unwrap_or(0) + 1;
    if nz > MAX_LEVELS {
        return Err(Error::TooLarge(format!("{nz} height levels exceed {MAX_LEVELS}: lower --vscale")));
    }
    let at = |x: i64, r: i64| -> u32 {
        let (x, r) = (x.clamp(0, w as i64 - 1), r.clamp(0, rows as i64 - 1));
        levels[(r * w as i64 + x) as usize]
    };
    // Column (x, r)'s lowest and highest level: its top, down to one above its lowest neighbour
    // when gaps are filled.
    // A hole's column is empty (bottom above top); a hole beside a column does not lower it.
    let column = |x: i64, r: i64| -> (u32, u32) {
        let top = at(x, r);
        if top == HOLE {
            return (1, 0);
        }
        let lowest = [at(x - 1, r), at(x + 1, r), at(x, r - 1), at(x, r + 1)]
            .into_iter()
            .filter(|&l| l != HOLE)
            .min()
            .unwrap_or(top);
        (if opts.fill_gaps { top.min(lowest + 1) } else { top }, top)
    };
    let height = |x: i64, r: i64| -> f32 {
        let (x, r) = (x.clamp(0, w as i64 - 1), r.clamp(0, rows as i64 - 1));
        let v = h.heights[(r * w as i64 + x) as usize];
        if v.is_finite() {
            v
        } else {
            hmin
        }
    };
    // The columns' voxels counted before any is made: a 4096² terrain took 2.3 GB and 13 s to be
    // refused for passing MAX_SPLATS.
    let voxels: u64 = (0..rows as i64)
        .flat_map(|r| (0..w as i64).map(move |x| (x, r)))
        .map(|(x, r)| {
            let (bottom, top) = column(x, r);
            (top + 1).saturating_sub(bottom) as u64
        })
        .sum();
    if voxels > MAX_SPLATS as u64 {
        return Err(Error::TooLarge(format!(
            "a {w}x{rows} terrain of {voxels} column voxels: more than {MAX_SPLATS} (lower --vscale or the resolution)"
        )));
    }
    crate::error::check_host_memory(voxels * SPLAT_HOST_BYTES, &format!("a {w}x{rows} terrain's {voxels} splats"))?;
    let grid = Grid::centered([w, rows, nz], [1.0; 3])?;
    let span = (hmax - hmin).max(1e-6);
    let color = opts.color.as_ref();
    SplatSet::from_fn(grid, |i, j, k| {
        let r = (rows - 1 - j) as i64;
        let x = i as i64;
        let (bottom, top) = column(x, r);
        if k > top || k < bottom {
            return None;
        }
        let base = match color {
            Some(img) => {
                let (iw, ih) = img.dimensions();
                let px = ((x as f32 + 0.5) / w as f32 * iw as f32) as u32;
                let py = ((r as f32 + 0.5) / rows as f32 * ih as f32) as u32;
                let p = img.get_pixel(px.min(iw - 1), py.min(ih - 1));
                [p[0] as f32 / 255.0, p[1] as f32 / 255.0, p[2] as f32 / 255.0]
            }
            None => {
                // Hillshade from the north-west, 45 degrees up.
                let dzdx = (height(x + 1, r) - height(x - 1, r)) * opts.vscale / (2.0 * cell);
                let dzdy = (height(x, r - 1) - height(x, r + 1)) * opts.vscale / (2.0 * cell);
                let n = glam::Vec3::new(-dzdx, -dzdy, 1.0).normalize();
                let l = glam::Vec3::new(-1.0, 1.0, 1.4).normalize();
                let shade = 0.45 + 0.55 * n.dot(l).max(0.0);
                hypsometric((height(x, r) - hmin) / span).map(|c| c * shade)
            }
        };
        // Gap-filling splats below the surface are a little darker (cliff faces).
        let dim = if k < top { 0.75 } else { 1.0 };
        Some([base[0] * dim, base[1] * dim, base[2] * dim, opts.opacity])
    })
}
