//! Every stage's builds, by name. A stage's row in `crate::stages` names one [`Table`]; its
//! values, in order, are the builds the engines make (the Vulkan engine one pipeline each, the
//! CPU engine the mirror's [`Variant`]). A dispatch names a [`Build`] value, never an index:
//! `Dispatch::new` finds the value in the stage's table and refuses one the stage lacks.
use crate::dispatch::{Blend, DrawState, Pass, Variant};
use crate::gpu_types::{
    BLEND_MAX, BLEND_SUM, BLEND_SURFACE, BLEND_SURFACE_DEPTH, SHEET_MODE_AXIS, SHEET_MODE_BINNED, SHEET_MODE_SLAB,
    SHEET_MODE_SPLAT,
};

/// A stage's builds: the values a dispatch may name and, in the same order, what each is made of.
#[derive(Debug)]
pub struct Table {
    /// The builds, in pipeline order.
    pub builds: &'static [Build],
    /// Each build's defines, specialization constants and draw state.
    pub variants: &'static [Variant],
}

impl Table {
    /// Where `build` sits in the table, if the stage has it.
    pub fn index(&self, build: Build) -> Option<usize> {
        self.builds.iter().position(|&b| b == build)
    }
}

/// One build of some stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Build {
    /// The stage's one build.
    Only,
    /// A brick stage's reading of the store's records.
    Records(Records),
    /// `brick_cells`: a resident pyramid or a streamed batch's.
    Pyramids(Pyramids),
    /// The slab binning stages' grouping.
    SlabBins(SlabBins),
    /// The tile binning stages' pages of splat records.
    Pages(Pages),
    /// The compute tile compositor.
    TileComposite(TileComposite),
    /// `sheet_tiles`.
    SheetTiles(SheetTiles),
    /// The footprint draw.
    Footprint(Footprint),
    /// `footprint_sum`: the sheets it sums.
    SheetMode(SheetMode),
    /// `composite`: the layers it reads.
    CompositeLayers(CompositeLayers),
}

/// The stage's only build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Only;

/// How a brick stage reads the store's records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Records {
    /// One page of records (`RECORD_PAGE`).
    OnePage,
    /// Up to `RECORD_PAGES` pages (`PAGED_RECORDS`).
    Paged,
    /// A streamed store: the batch's records only (`STREAMED_STORE`).
    Streamed,
    /// One page, with the voxels' differences read from `Res::BrickGradients` (`GRADIENTS`):
    /// `brick_params` and `brick_pyramid` only.
    Gradients,
    /// A projection's voxels that draw, packed by `project_winners` (`PROJECT_VOXELS`):
    /// `brick_params` only.
    Winners,
}

impl Records {
    /// The reading of a store of `records` words, or of a streamed one.
    pub fn of(streamed: bool, records: usize) -> Records {
        if streamed {
            Records::Streamed
        } else if records > crate::constants::RECORD_PAGE as usize {
            Records::Paged
        } else {
            Records::OnePage
        }
    }
}

/// `brick_cells`' pyramid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pyramids {
    /// The store's resident pyramid.
    Resident,
    /// A streamed store's batch of pyramids (`STREAMED_STORE`).
    Streamed,
}

/// What the slab binning stages group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlabBins {
    /// Slabs along the view.
    Slabs,
    /// A bricked batch's axis-aligned sheets, by voxel plane (`AXIS_SHEETS`).
    AxisSheets,
}

/// The pages of splat records a tile stage reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pages {
    /// Both pages (the paged reader).
    Two,
    /// Only the first (`ONE_PAGE`: llvmpipe runs both sides of the paged reader's branch).
    One,
}

impl Pages {
    /// The pages a scene of `n` splats needs.
    pub fn of(n: u32) -> Pages {
        if n <= crate::constants::SPLAT_PAGE {
            Pages::One
        } else {
            Pages::Two
        }
    }
}

/// The tile compositor's walk along each tile's list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TileOrder {
    /// Back to front.
    BackToFront,
    /// Front to back.
    FrontToBack,
    /// Front to back, ending a tile's walk once it is opaque.
    Terminating,
    /// A projection: in any order, keeping the maximum (MIP, MinIP).
    Maximum,
    /// A projection: in any order, summing (average, X-ray).
    Sum,
    /// The isosurface's discs, second pass: those within a band of each pixel's visible depth
    /// summed.
    Surface,
    /// The isosurface's discs, first pass: each pixel's visible depth.
    SurfaceDepth,
}

impl TileOrder {
    /// A projection's blend: by maximum or by sum.
    pub fn projection(max: bool) -> TileOrder {
        if max {
            TileOrder::Maximum
        } else {
            TileOrder::Sum
        }
    }
}

/// A build of the compute tile compositor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileComposite {
    /// The splat records it reads.
    pub pages: Pages,
    /// Its walk.
    pub order: TileOrder,
    /// Motion-blurred footprints.
    pub blur: bool,
    /// The host's depth hides what lies behind it (`HOST_DEPTH`; not with motion blur).
    pub depth: bool,
}

/// The sheets a sheet stage works on (`SHEET_MODE_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SheetMode {
    /// Axis-aligned voxel slices.
    Axis,
    /// Slabs along the view.
    Slab,
    /// A bricked batch's binned slices.
    Binned,
}

impl SheetMode {
    /// The mode a `FootprintPush::sheet_mode` word names (`None`: per-splat, or no mode).
    pub fn from_word(word: u32) -> Option<SheetMode> {
        match word {
            SHEET_MODE_AXIS => Some(SheetMode::Axis),
            SHEET_MODE_SLAB => Some(SheetMode::Slab),
            SHEET_MODE_BINNED => Some(SheetMode::Binned),
            _ => None,
        }
    }
}

/// A build of `sheet_tiles`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SheetTiles {
    /// The sheets.
    pub mode: SheetMode,
    /// Point sprites' footprints (else quads', or the compute sums').
    pub points: bool,
}

/// A build of the footprint draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Footprint {
    /// Per-splat compositing into the raster target, `Over` or `Under`.
    Ordered {
        /// Back to front (`Over`) or front to back (`Under`).
        blend: Blend,
        /// Point sprites rather than quads.
        points: bool,
    },
    /// Summed into the sheet layers.
    Sheet {
        /// The sheets.
        mode: SheetMode,
        /// Point sprites rather than quads.
        points: bool,
    },
    /// A motion-blurred frame's two time slots (`SLOTS`), `Over` or `Under`.
    Slots(Blend),
    /// A projection mode's footprints into the raster target, blended by maximum (`Max`) or
    /// sum (`Add`) in any order.
    Project {
        /// `Max` or `Add`.
        blend: Blend,
        /// Point sprites rather than quads.
        points: bool,
    },
}

/// The layers `composite` reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompositeLayers {
    /// The float summation image.
    Float,
    /// The compute raster's fixed-point layers (`Res::Fixed`).
    Fixed,
}

macro_rules! into_build {
    ($($ty:ident),*) => {$(
        impl From<$ty> for Build {
            fn from(b: $ty) -> Build {
                Build::$ty(b)
            }
        }
    )*};
}
into_build!(Records, Pyramids, SlabBins, Pages, TileComposite, SheetTiles, Footprint, SheetMode, CompositeLayers);

impl From<Only> for Build {
    fn from(_: Only) -> Build {
        Build::Only
    }
}

const fn v(defines: &'static str, spec: &'static [u32]) -> Variant {
    Variant { defines, spec, draw: None }
}

const fn d(blend: Blend, points: bool, pass: Pass, spec: &'static [u32]) -> Variant {
    let defines = if matches!(pass, Pass::Slots) { "SLOTS" } else { "" };
    Variant { defines, spec, draw: Some(DrawState { blend, points, pass }) }
}

/// A table from `(build, variant)` pairs, so each build sits beside what it is made of.
macro_rules! table {
    ($($build:expr => $variant:expr),* $(,)?) => {
        Table { builds: &[$($build),*], variants: &[$($variant),*] }
    };
}

/// Stages with one build.
pub const ONLY: Table = table! { Build::Only => v("", &[]) };

/// The brick stages that read the store's records.
pub const RECORDS: Table = table! {
    Build::Records(Records::OnePage) => v("", &[]),
    Build::Records(Records::Paged) => v("PAGED_RECORDS", &[]),
    Build::Records(Records::Streamed) => v("STREAMED_STORE", &[]),
};

/// `brick_params` and `brick_pyramid`: [`RECORDS`], and one page with precomputed differences.
pub const RECORDS_OR_GRADIENTS: Table = table! {
    Build::Records(Records::OnePage) => v("", &[]),
    Build::Records(Records::Paged) => v("PAGED_RECORDS", &[]),
    Build::Records(Records::Streamed) => v("STREAMED_STORE", &[]),
    Build::Records(Records::Gradients) => v("GRADIENTS", &[]),
};

/// `brick_params`: `RECORDS_OR_GRADIENTS`, or a projection's packed voxels.
pub const PARAMS: Table = table! {
    Build::Records(Records::OnePage) => v("", &[]),
    Build::Records(Records::Paged) => v("PAGED_RECORDS", &[]),
    Build::Records(Records::Streamed) => v("STREAMED_STORE", &[]),
    Build::Records(Records::Gradients) => v("GRADIENTS", &[]),
    Build::Records(Records::Winners) => v("PROJECT_VOXELS", &[]),
};

/// `brick_cells`.
pub const PYRAMIDS: Table = table! {
    Build::Pyramids(Pyramids::Resident) => v("", &[]),
    Build::Pyramids(Pyramids::Streamed) => v("STREAMED_STORE", &[]),
};

/// `slab_count` and `slab_scatter`.
pub const SLAB_BINS: Table = table! {
    Build::SlabBins(SlabBins::Slabs) => v("", &[]),
    Build::SlabBins(SlabBins::AxisSheets) => v("AXIS_SHEETS", &[]),
};

/// `tile_count` and `tile_scatter`.
pub const PAGES: Table = table! {
    Build::Pages(Pages::Two) => v("", &[]),
    Build::Pages(Pages::One) => v("ONE_PAGE", &[]),
};

const fn tc(pages: Pages, order: TileOrder, blur: bool, depth: bool) -> Build {
    Build::TileComposite(TileComposite { pages, order, blur, depth })
}

const fn tc_variant(pages: Pages, order: TileOrder, blur: bool, depth: bool) -> Variant {
    let defines = if matches!(pages, Pages::One) { "ONE_PAGE" } else { "" };
    if depth {
        // Spec 5: the host's depth (still footprints only).
        let spec: &'static [u32] = match order {
            TileOrder::BackToFront => &[SHEET_MODE_SPLAT, 1, 0, 0, 0, 1],
            TileOrder::FrontToBack => &[SHEET_MODE_SPLAT, 0, 0, 0, 0, 1],
            TileOrder::Terminating => &[SHEET_MODE_SPLAT, 0, 1, 0, 0, 1],
            TileOrder::Maximum => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_MAX, 1],
            TileOrder::Sum => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_SUM, 1],
            TileOrder::Surface => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_SURFACE, 1],
            TileOrder::SurfaceDepth => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_SURFACE_DEPTH, 1],
        };
        return v(defines, spec);
    }
    // Spec: sheet mode, back to front, terminating, blurred.
    let spec: &'static [u32] = match (order, blur) {
        (TileOrder::BackToFront, false) => &[SHEET_MODE_SPLAT, 1, 0, 0],
        (TileOrder::BackToFront, true) => &[SHEET_MODE_SPLAT, 1, 0, 1],
        (TileOrder::FrontToBack, false) => &[SHEET_MODE_SPLAT, 0, 0, 0],
        (TileOrder::FrontToBack, true) => &[SHEET_MODE_SPLAT, 0, 0, 1],
        (TileOrder::Terminating, false) => &[SHEET_MODE_SPLAT, 0, 1, 0],
        (TileOrder::Terminating, true) => &[SHEET_MODE_SPLAT, 0, 1, 1],
        // Spec 4: the projection's blend (motion blur is refused there).
        (TileOrder::Maximum, _) => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_MAX],
        (TileOrder::Sum, _) => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_SUM],
        (TileOrder::Surface, _) => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_SURFACE],
        (TileOrder::SurfaceDepth, _) => &[SHEET_MODE_SPLAT, 0, 0, 0, BLEND_SURFACE_DEPTH],
    };
    v(defines, spec)
}

macro_rules! tile_composite {
    ($(($p:ident, $o:ident, $b:expr, $d:expr)),* $(,)?) => {
        table! { $(tc(Pages::$p, TileOrder::$o, $b, $d) => tc_variant(Pages::$p, TileOrder::$o, $b, $d)),* }
    };
}

/// The compute tile compositor: pages x walk x (blur, or the host's depth).
pub const TILE_COMPOSITE: Table = tile_composite![
    (Two, BackToFront, false, false),
    (Two, BackToFront, true, false),
    (Two, FrontToBack, false, false),
    (Two, FrontToBack, true, false),
    (Two, Terminating, false, false),
    (Two, Terminating, true, false),
    (One, BackToFront, false, false),
    (One, BackToFront, true, false),
    (One, FrontToBack, false, false),
    (One, FrontToBack, true, false),
    (One, Terminating, false, false),
    (One, Terminating, true, false),
    (Two, Maximum, false, false),
    (Two, Sum, false, false),
    (One, Maximum, false, false),
    (One, Sum, false, false),
    (Two, BackToFront, false, true),
    (Two, FrontToBack, false, true),
    (Two, Terminating, false, true),
    (Two, Maximum, false, true),
    (Two, Sum, false, true),
    (One, BackToFront, false, true),
    (One, FrontToBack, false, true),
    (One, Terminating, false, true),
    (One, Maximum, false, true),
    (One, Sum, false, true),
    (Two, Surface, false, false),
    (One, Surface, false, false),
    (Two, Surface, false, true),
    (One, Surface, false, true),
    (Two, SurfaceDepth, false, false),
    (One, SurfaceDepth, false, false),
    (Two, SurfaceDepth, false, true),
    (One, SurfaceDepth, false, true),
];

const fn st(mode: SheetMode, points: bool) -> Build {
    Build::SheetTiles(SheetTiles { mode, points })
}

/// `sheet_tiles`: sheets x (quads or compute sums, points).
pub const SHEET_TILES: Table = table! {
    st(SheetMode::Axis, false) => v("", &[SHEET_MODE_AXIS, 0]),
    st(SheetMode::Axis, true) => v("", &[SHEET_MODE_AXIS, 1]),
    st(SheetMode::Slab, false) => v("", &[SHEET_MODE_SLAB, 0]),
    st(SheetMode::Slab, true) => v("", &[SHEET_MODE_SLAB, 1]),
    st(SheetMode::Binned, false) => v("", &[SHEET_MODE_BINNED, 0]),
    st(SheetMode::Binned, true) => v("", &[SHEET_MODE_BINNED, 1]),
};

const fn ordered(blend: Blend, points: bool) -> Build {
    Build::Footprint(Footprint::Ordered { blend, points })
}

const fn sheet(mode: SheetMode, points: bool) -> Build {
    Build::Footprint(Footprint::Sheet { mode, points })
}

const fn project(blend: Blend, points: bool) -> Build {
    Build::Footprint(Footprint::Project { blend, points })
}

/// The footprint draw: ordered into the target, summed into sheets, or two time slots.
pub const FOOTPRINT: Table = table! {
    ordered(Blend::Over, false) => d(Blend::Over, false, Pass::Target, &[SHEET_MODE_SPLAT, 0]),
    ordered(Blend::Under, false) => d(Blend::Under, false, Pass::Target, &[SHEET_MODE_SPLAT, 0]),
    sheet(SheetMode::Axis, false) => d(Blend::Add, false, Pass::Sheet, &[SHEET_MODE_AXIS, 0]),
    sheet(SheetMode::Slab, false) => d(Blend::Add, false, Pass::Sheet, &[SHEET_MODE_SLAB, 0]),
    ordered(Blend::Over, true) => d(Blend::Over, true, Pass::Target, &[SHEET_MODE_SPLAT, 1]),
    ordered(Blend::Under, true) => d(Blend::Under, true, Pass::Target, &[SHEET_MODE_SPLAT, 1]),
    sheet(SheetMode::Axis, true) => d(Blend::Add, true, Pass::Sheet, &[SHEET_MODE_AXIS, 1]),
    sheet(SheetMode::Slab, true) => d(Blend::Add, true, Pass::Sheet, &[SHEET_MODE_SLAB, 1]),
    sheet(SheetMode::Binned, false) => d(Blend::Add, false, Pass::Sheet, &[SHEET_MODE_BINNED, 0]),
    sheet(SheetMode::Binned, true) => d(Blend::Add, true, Pass::Sheet, &[SHEET_MODE_BINNED, 1]),
    Build::Footprint(Footprint::Slots(Blend::Over)) => d(Blend::Over, false, Pass::Slots, &[SHEET_MODE_SPLAT, 0]),
    Build::Footprint(Footprint::Slots(Blend::Under)) => d(Blend::Under, false, Pass::Slots, &[SHEET_MODE_SPLAT, 0]),
    project(Blend::Max, false) => d(Blend::Max, false, Pass::Target, &[SHEET_MODE_SPLAT, 0, BLEND_MAX]),
    project(Blend::Max, true) => d(Blend::Max, true, Pass::Target, &[SHEET_MODE_SPLAT, 1, BLEND_MAX]),
    project(Blend::Add, false) => d(Blend::Add, false, Pass::Target, &[SHEET_MODE_SPLAT, 0, BLEND_SUM]),
    project(Blend::Add, true) => d(Blend::Add, true, Pass::Target, &[SHEET_MODE_SPLAT, 1, BLEND_SUM]),
};

/// `footprint_sum`: the sheets it sums.
pub const SHEET_MODES: Table = table! {
    Build::SheetMode(SheetMode::Axis) => v("", &[SHEET_MODE_AXIS]),
    Build::SheetMode(SheetMode::Slab) => v("", &[SHEET_MODE_SLAB]),
    Build::SheetMode(SheetMode::Binned) => v("", &[SHEET_MODE_BINNED]),
};

/// `composite`: float layers, or the compute raster's fixed-point ones.
pub const COMPOSITE_LAYERS: Table = table! {
    Build::CompositeLayers(CompositeLayers::Float) => v("", &[]),
    Build::CompositeLayers(CompositeLayers::Fixed) => v("", &[1]),
};

/// Every table, for the checks that each build is its own row.
pub const TABLES: &[&Table] = &[
    &ONLY,
    &RECORDS,
    &RECORDS_OR_GRADIENTS,
    &PARAMS,
    &PYRAMIDS,
    &SLAB_BINS,
    &PAGES,
    &TILE_COMPOSITE,
    &SHEET_TILES,
    &FOOTPRINT,
    &SHEET_MODES,
    &COMPOSITE_LAYERS,
];
