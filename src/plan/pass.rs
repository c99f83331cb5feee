//! The passes a frame's plan names: the compute tile compositor's rule and the sheet modes'
//! summation pass, shared by dense and bricked frames.
use super::Batch;
use crate::builds::{Footprint, Pages, SheetMode, TileComposite, TileOrder};
use crate::constants::{RASTER_TILE_H, RASTER_TILE_W, TILE_CHUNK};
use crate::dispatch::{Limits, List};
use crate::error::{Error, Result};
use crate::gpu_types::FootprintPush;
use crate::options::Raster;
use crate::options::RenderOptions;
use crate::order::Direction;

/// The compute tile compositor's decisions for a draw list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileRule {
    /// The binning's and compositing's push constants (`chunks`: the first try).
    pub push: FootprintPush,
    /// The most chunks the binning may grow to when an invocation runs out of loop budget.
    pub most_chunks: u32,
    /// The splat records the binning reads.
    pub pages: Pages,
    /// The compositor's build.
    pub composite: TileComposite,
}

impl TileRule {
    /// The rule for a draw list of `n` entries on a `width` x `height` image, in `direction`,
    /// terminating at `early_termination` front to back; `blur`: motion-blurred footprints.
    /// (`composite.depth` is the frame's: `plan::frame` sets it.)
    pub fn plan(n: u32, width: u32, height: u32, direction: Direction, early_termination: f32, blur: bool) -> Self {
        let btf = direction == Direction::BackToFront;
        let tiles = (width.div_ceil(RASTER_TILE_W) as u64 * height.div_ceil(RASTER_TILE_H) as u64).max(1);
        let most = (super::MAX_TILE_CELLS / tiles).max(1);
        let push = FootprintPush {
            count: n,
            chunks: (n.div_ceil(TILE_CHUNK) as u64).clamp(1, most) as u32,
            back_to_front: btf as u32,
            occluded: if btf { 0.0 } else { early_termination },
            ..Default::default()
        };
        let order = if btf {
            TileOrder::BackToFront
        } else if push.occluded > 0.0 {
            TileOrder::Terminating
        } else {
            TileOrder::FrontToBack
        };
        let pages = Pages::of(n);
        // The original bound, without `most`'s floor: a frame past the cell limit is refused.
        let most_chunks = (super::MAX_TILE_CELLS / tiles).min(push.count.max(1) as u64) as u32;
        TileRule { push, most_chunks, pages, composite: TileComposite { pages, order, blur, depth: false } }
    }
}

/// How sheet batches are summed and composited.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetPass {
    /// The list the sums walk.
    pub list: List,
    /// The batches in visiting order, early termination set.
    pub batches: Vec<Batch>,
    /// Most summation layers a batch may take (budget and engine limits).
    pub layers: u32,
    /// Compute fixed-point sums, else footprint draws (`points`: point sprites).
    pub compute: bool,
    /// Point sprites rather than quads (the draws).
    pub points: bool,
    /// Front to back with this threshold ends tiles early (0: never).
    pub early_termination: f32,
    /// Back to front.
    pub back_to_front: bool,
}

impl SheetPass {
    /// Batches as the pass draws them: the early-termination threshold in their push constants.
    pub fn terminated(&self, mut batches: Vec<Batch>) -> Vec<Batch> {
        for b in &mut batches {
            b.push.occluded = if self.back_to_front { 0.0 } else { self.early_termination };
        }
        batches
    }

    /// The sheet mode a batch's push constants name.
    pub fn mode(b: &Batch) -> Result<SheetMode> {
        SheetMode::from_word(b.push.sheet_mode)
            .ok_or_else(|| Error::InvalidArgument(format!("sheet mode {} is no sheet mode", b.push.sheet_mode)))
    }

    /// The footprint build that sums batch `b`.
    pub fn footprint(&self, b: &Batch) -> Result<Footprint> {
        Ok(Footprint::Sheet { mode: Self::mode(b)?, points: self.points })
    }
}

/// Summation layers a sheet batch may use at `w` x `h`: the options' memory budget, the engine's
/// layer limit and, for the fixed-point layers (one storage binding), its range.
pub fn sheet_layers(opts: &RenderOptions, limits: &Limits, w: u32, h: u32) -> u32 {
    let layers = opts.batch_layers(w, h).min(limits.max_layers.max(1));
    let layer_bytes = w as u64 * h as u64 * 16;
    if opts.raster == Raster::Compute {
        layers.min((limits.max_storage_range / layer_bytes.max(1)).clamp(1, u32::MAX as u64) as u32)
    } else {
        layers
    }
}

/// The sheet pass of a frame drawn with `opts` (its batches still to be planned).
pub fn sheet_pass(opts: &RenderOptions, limits: &Limits, list: List, w: u32, h: u32) -> SheetPass {
    let direction = opts.direction();
    SheetPass {
        list,
        batches: Vec::new(),
        layers: sheet_layers(opts, limits, w, h),
        compute: opts.raster == Raster::Compute,
        points: opts.raster == Raster::Points,
        early_termination: if direction == Direction::FrontToBack { opts.early_termination.max(0.0) } else { 0.0 },
        back_to_front: direction == Direction::BackToFront,
    }
}
