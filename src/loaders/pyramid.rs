//! Which level of an OME-Zarr pyramid to read, and which part of it: the finest the host budget
//! holds (whole, or the part a crop box needs), or the one a view needs (`--level auto`).
use super::zarr::OmeZarr;
use super::zarr_chunks::may_see_voxels;

/// The largest size, in pixels, at the nearest point of the view, of a voxel of the level
/// `OmeZarr::level_for` picks: the levels-of-detail cut draws cells of `DEFAULT_LOD_PIXELS` (1.5 px),
/// two voxels a side, from what it is given, so a level whose voxels project to at most half that
/// holds every cell the cut would draw from the finest level's voxels.
pub const LEVEL_PIXELS: f32 = crate::options::DEFAULT_LOD_PIXELS * 0.5;

/// Pixels past the image's edges a view's read reaches (`VolumeHints::view`): a coarse
/// level-of-detail splat centred outside the image spills about 2.4 px into it (a brick's one
/// cell, radius 1.6 cells).
pub const VIEW_MARGIN_PX: f32 = 4.0;

impl OmeZarr {
    /// The level read when none is asked for: the finest whose bricked store fits the host budget
    /// (`host_budget`) even with every voxel stored, else the coarsest. The file's levels average
    /// the raw samples, and a transfer function that shows a narrow band of values loses thin
    /// structures in them (on the bonsai, level 1 against level 0: 20-21 dB at 32² to 64²), so a
    /// coarser level is read only when the finest cannot be held.
    pub fn default_level(&self) -> u32 {
        self.default_level_within(None, None).unwrap_or(0)
    }

    /// `default_level` for the part of the image inside `crop` (`region`), and of it what `view`
    /// may see (`VolumeHints::view`): the finest level whose part's store fits. `None` when the
    /// box misses the image.
    pub fn default_level_within(&self, crop: Option<[[f32; 3]; 2]>, view: Option<&crate::Camera>) -> Option<u32> {
        let fits = |level: usize| {
            let l = &self.levels[level];
            let [lo, hi] = match crop {
                Some(c) => self.region(level as u32, c)?,
                None => [[0; 3], l.dims],
            };
            let b = crate::constants::BRICK_SIDE;
            let voxels = match view {
                Some(camera) => self.seen_voxels(level, [lo, hi], camera),
                None => (0..3).fold(1u64, |a, i| a.saturating_mul((hi[i] - lo[i]) as u64)),
            };
            let bricks = l.dims.iter().fold(1u64, |a, &d| a.saturating_mul(d.div_ceil(b) as u64));
            let part = (0..3).fold(1u64, |a, i| a.saturating_mul((hi[i].div_ceil(b) - lo[i] / b) as u64));
            // Records, the part's headers and masks, the whole grid's index (`BrickStore::from_region`'s
            // worst case).
            let worst =
                voxels.saturating_mul(4).saturating_add(part.saturating_mul(16 + 64)).saturating_add(bricks * 4);
            Some(crate::error::host_budget().is_none_or(|b| worst <= b))
        };
        let mut last = None;
        for level in 0..self.levels.len() {
            last = Some(level as u32);
            if fits(level)? {
                return last;
            }
        }
        last
    }

    /// The voxels of `region` of level `level` in the chunks `camera` may see (as
    /// `ZarrReader::only_in_view` reads them).
    fn seen_voxels(&self, level: usize, [lo, hi]: [[u32; 3]; 2], camera: &crate::Camera) -> u64 {
        let l = &self.levels[level];
        let Ok(grid) = crate::Grid::centered(l.dims, l.spacing) else { return u64::MAX };
        let n = l.chunk.len();
        // The chunk along x, y, z (array order is z, y, x last).
        let chunk = [0, 1, 2].map(|a| l.chunk[n - 1 - a].max(1));
        let first = [0, 1, 2].map(|a| lo[a] as u64 / chunk[a]);
        let last = [0, 1, 2].map(|a| (hi[a] as u64 - 1) / chunk[a]);
        let mut voxels = 0u64;
        for cz in first[2]..=last[2] {
            for cy in first[1]..=last[1] {
                for cx in first[0]..=last[0] {
                    let c = [cx, cy, cz];
                    let start = [0, 1, 2].map(|a| c[a] * chunk[a]);
                    let end = [0, 1, 2].map(|a| ((c[a] + 1) * chunk[a]).min(l.dims[a] as u64));
                    if may_see_voxels(camera, VIEW_MARGIN_PX, &grid, start, end) {
                        let s = [0, 1, 2].map(|a| start[a].max(lo[a] as u64));
                        let e = [0, 1, 2].map(|a| end[a].min(hi[a] as u64));
                        voxels = voxels.saturating_add((0..3).map(|a| e[a] - s[a]).product());
                    }
                }
            }
        }
        voxels
    }

    /// The voxels of level `level` a store needs to draw what lies inside `crop` (a box in the
    /// level's grid frame, centred on the origin as its grid is placed; `--crop`'s box for an
    /// image without an anatomical frame): the bricks the box touches and one brick around them,
    /// so that each of those bricks' gradients and levels of detail are what the whole level gives.
    /// `None` when the box holds no voxel centre of the level.
    pub fn region(&self, level: u32, crop: [[f32; 3]; 2]) -> Option<[[u32; 3]; 2]> {
        let l = self.levels.get(level as usize)?;
        let b = crate::constants::BRICK_SIDE as i64;
        let mut out = [[0u32; 3]; 2];
        for a in 0..3 {
            // Voxel i's centre lies at (i - (n - 1) / 2) spacing.
            let (n, s) = (l.dims[a] as f64, l.spacing[a] as f64);
            let first = (crop[0][a] as f64 / s + (n - 1.0) * 0.5).ceil().max(0.0);
            let last = (crop[1][a] as f64 / s + (n - 1.0) * 0.5).floor().min(n - 1.0);
            if first > last || first.is_nan() || last.is_nan() {
                return None;
            }
            out[0][a] = ((first as i64 / b - 1) * b).max(0) as u32;
            out[1][a] = ((last as i64 / b + 2) * b).min(n as i64) as u32;
        }
        Some(out)
    }

    /// The coarsest level whose voxels project to at most `pixels` pixels in `camera`'s view
    /// (`voxel_pixels`); level 0 when none is fine enough. A frame drawn from it reads the chunks
    /// of that level only.
    pub fn level_for(&self, camera: &crate::Camera, pixels: f32) -> u32 {
        (0..self.levels.len() as u32).rev().find(|&l| self.voxel_pixels(camera, l) <= pixels).unwrap_or(0)
    }

    /// The pixels a voxel of `level` (its widest spacing) spans at the point of the image nearest
    /// the eye of `camera` (the image centred on the origin, as its grids are; the near plane when
    /// the eye is inside it).
    pub fn voxel_pixels(&self, camera: &crate::Camera, level: u32) -> f32 {
        let first = &self.levels[0];
        let half = glam::Vec3::from(first.dims.map(|d| d as f32)) * glam::Vec3::from(first.spacing) * 0.5;
        let forward = camera.forward();
        // The box's nearest depth along the view: one of its corners.
        let mut depth = f32::INFINITY;
        for i in 0..8 {
            let sign = |bit: i32| if i & bit == 0 { -1.0 } else { 1.0 };
            let corner = half * glam::Vec3::new(sign(1), sign(2), sign(4));
            depth = depth.min((corner - camera.eye).dot(forward));
        }
        let inside = (camera.eye.abs() - half).max_element() <= 0.0;
        let per_unit = match camera.projection {
            crate::Projection::Perspective { .. } if inside => camera.pixels_per_unit() / camera.near,
            crate::Projection::Perspective { .. } => camera.pixels_per_unit() / depth.max(camera.near),
            crate::Projection::Orthographic { .. } => camera.pixels_per_unit(),
        };
        let widest =
            self.levels.get(level as usize).map_or(f32::INFINITY, |l| l.spacing.into_iter().fold(0f32, f32::max));
        widest * per_unit
    }
}
