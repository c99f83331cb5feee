//! What a recording is made of, below both the stage table and the engines: resources by name
//! ([`Res`], [`List`]), a stage invocation ([`Dispatch`]) and the builds a stage has
//! ([`Variant`]), and the [`Engine`] interface that the Vulkan engine, the CPU engine and the bisect
//! switch implement. The table itself (`crate::stages`) names the CPU mirrors, which read these.
use crate::error::Result;
use crate::gpu_types::Frame;
use crate::kernel::Kernel;
use crate::options::StageTime;

/// How a fragment combines with the attachment (premultiplied colour).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Back to front: src + (1 - src.a) dst.
    Over,
    /// Front to back: (1 - dst.a) src + dst.
    Under,
    /// Sheet summation: src + dst.
    Add,
}

/// A resource of a frame, named alike on both engines: stage bindings, probes and the bisect
/// switch's transfers name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Res {
    /// The per-frame uniforms (`Frame`).
    Frame,
    /// The kernel's radial footprint table and its kernel-slice table (a texture).
    Radial,
    /// The kernel-slice table of the image-aligned sheets (a texture).
    SliceTable,
    /// The scene: splats, PBTF rows, sheet ranks.
    Splats,
    /// Each PBTF row's first splat.
    RowStart,
    /// Each slice's rank among the non-empty slices, per axis (sheet batches index them).
    Ranks,
    /// PBTF order working buffers and the draw order it writes.
    RowSplit,
    /// Per-row octant segment counts, then their offsets.
    Segments,
    /// The draw order (PBTF, or an order computed on the host).
    Order,
    /// `SplatParams` per splat; `ParamsHi` binds its second page (`SPLAT_PAGE` records on).
    Params,
    /// The second page of `Params`.
    ParamsHi,
    /// The dispatch's draw list: the order, a slice-grouped list or the slab pairs ([`List`]).
    DrawList,
    /// Largest transmittance left per composite tile (early termination).
    Occlusion,
    /// Fixed-point sheet sums of the compute raster.
    Fixed,
    /// The tile x chunk count matrix of the tile binning.
    TileCounts,
    /// Each screen tile's first entry, then the total.
    TileStart,
    /// The tiles' lists of splat indices, each in draw order.
    TileEntries,
    /// `ScreenQuad` per splat; `QuadsHi` binds its second page.
    Quads,
    /// The second page of `Quads`.
    QuadsHi,
    /// Per composite tile, the lowest sheet reaching it, then the highest + 1.
    SheetTiles,
    /// The loop-budget status word (`LOOP_BUDGET_*`).
    Status,
    /// The slab x chunk count matrix of the slab binning.
    SlabCounts,
    /// Each slab's first pair, then the total.
    SlabStart,
    /// The (splat, slab) pairs in visiting order.
    SlabPairs,
    /// Images: the compute passes' accumulation image, the summation layers, the raster target.
    Accum,
    /// The summation layers.
    Sums,
    /// The raster target of per-splat compositing.
    Color,
}

impl Res {
    /// Made before any frame (renderer or scene) and never changed by a stage.
    pub fn is_constant(self) -> bool {
        matches!(self, Res::Frame | Res::Radial | Res::SliceTable | Res::Splats | Res::RowStart | Res::Ranks)
    }

    /// An image rather than a buffer.
    pub fn is_image(self) -> bool {
        matches!(self, Res::Accum | Res::Sums | Res::Color)
    }
}

/// Which list a dispatch binds as [`Res::DrawList`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum List {
    /// The visibility order (`Res::Order`).
    Order,
    /// The splats grouped by slice along axis 0, 1 or 2 (sheet mode).
    Slices(u8),
    /// The (splat, slab) pairs (slab mode).
    SlabPairs,
}

/// How a stage runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A compute dispatch.
    Compute,
    /// Instanced quads or point sprites through the raster pipeline, into the raster target
    /// (per-splat compositing) or the summation layers.
    Draw,
}

/// A device capability that selects a stage's build (`<stage>.<DEFINE>` in build.rs' naming).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    /// Subgroup shuffle and arithmetic in subgroups of at least `RASTER_LANES` lanes.
    SubgroupShuffle,
    /// 64-bit buffer atomics.
    Int64Atomics,
}

/// Where a draw goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// The single raster target (`Res::Color`).
    Target,
    /// The summation layers (`Res::Sums`).
    Sheet,
}

/// A draw variant's fixed-function state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawState {
    /// How fragments combine with the attachment.
    pub blend: Blend,
    /// Point sprites rather than instanced quads.
    pub points: bool,
    /// The attachment drawn into.
    pub pass: Pass,
}

/// One build of a stage: macros defined (`+`-joined, as in the `// variants:` line of the shader),
/// specialization constants 0.., and for draws the fixed-function state.
#[derive(Clone, Copy, Debug)]
pub struct Variant {
    /// Macros defined, `+`-joined (the shader's `// variants:` names).
    pub defines: &'static str,
    /// Specialization constants 0, 1, ...
    pub spec: &'static [u32],
    /// A draw's fixed-function state (`None` for compute).
    pub draw: Option<DrawState>,
}

/// A stage's workgroup shape: how invocation counts become workgroup counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Workgroup {
    /// `n` invocations in groups of this many (spilling into y, `plan::groups_1d`).
    Linear(u32),
    /// One workgroup per tile of this many pixels across and down.
    Tile(u32, u32),
    /// One workgroup of this many invocations.
    Single(u32),
    /// A draw: one instance per entry.
    Instances,
}

/// A stage: its row of `crate::stages::STAGES` (`StageId::desc`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StageId {
    /// `order_count`.
    OrderCount,
    /// `order_scan`.
    OrderScan,
    /// `order_scatter`.
    OrderScatter,
    /// `splat_params`.
    SplatParams,
    /// `slab_count`.
    SlabCount,
    /// `slab_scan`.
    SlabScan,
    /// `slab_scatter`.
    SlabScatter,
    /// `tile_count`.
    TileCount,
    /// `tile_scan`.
    TileScan,
    /// `tile_offsets`.
    TileOffsets,
    /// `tile_scatter`.
    TileScatter,
    /// `tile_composite`.
    TileComposite,
    /// `sheet_tiles`.
    SheetTiles,
    /// `footprint`.
    Footprint,
    /// `footprint_sum`.
    FootprintSum,
    /// `composite`.
    Composite,
}

/// One stage invocation of a recording.
#[derive(Clone, Debug)]
pub struct Dispatch {
    /// The stage.
    pub stage: StageId,
    /// Index into the stage's `variants`.
    pub variant: usize,
    /// Compute: workgroups. Draws: `[first instance, instances, 0]`.
    pub groups: [u32; 3],
    /// What `Res::DrawList` binds.
    pub list: List,
    /// The push constants' bytes.
    pub push: Vec<u8>,
}

impl Dispatch {
    /// A dispatch of `stage`'s build `variant` (push: the stage's push-constant struct's bytes).
    pub fn new(stage: StageId, variant: usize, groups: [u32; 3], list: List, push: &[u8]) -> Self {
        debug_assert_eq!(push.len() as u32, stage.desc().push, "{}: push size", stage.desc().name);
        Self { stage, variant, groups, list, push: push.to_vec() }
    }

    /// The push constants as the stage's struct.
    pub fn push_as<T: bytemuck::Pod>(&self) -> T {
        bytemuck::pod_read_unaligned(&self.push)
    }
}

/// What an engine can hold, which the frame's plan must respect.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Most layers of the summation image.
    pub max_layers: u32,
    /// Largest storage binding in bytes (the fixed-point layers are one).
    pub max_storage_range: u64,
}

/// Runs a recording: the Vulkan device, the CPU mirrors, or a split of the two.
pub trait Engine {
    /// A frame of `width` x `height` begins: its uniforms and kernel tables.
    fn begin(&mut self, frame: &Frame, kernel: Kernel, width: u32, height: u32) -> Result<()>;
    /// The summation image holds `layers` layers this frame.
    fn layers(&mut self, layers: u32) -> Result<()>;
    /// `res` holds at least `bytes`.
    fn ensure(&mut self, res: Res, bytes: u64) -> Result<()>;
    /// Set 32-bit words of `res` (all, or `count` from `first`) to `value`.
    fn fill(&mut self, res: Res, range: Option<(u64, u64)>, value: u32) -> Result<()>;
    /// Write host data into `res` from its start.
    fn upload(&mut self, res: Res, data: &[u32]) -> Result<()>;
    /// Run (or queue) one stage dispatch.
    fn run(&mut self, dispatch: &Dispatch) -> Result<()>;
    /// Finish the work so far and read the first `words` 32-bit words of each resource.
    fn read(&mut self, what: &[(Res, usize)]) -> Result<Vec<Vec<u32>>>;
    /// Words `res` holds now (0 when it does not exist).
    fn words(&self, res: Res) -> usize;
    /// Work done on the host, reported as a stage.
    fn host_time(&mut self, stage: &'static str, ms: f64);
    /// Finish the frame: the stage times.
    fn finish(&mut self) -> Result<Vec<StageTime>>;
    /// The frame resources written so far (what a split hands over).
    fn live(&self) -> Vec<Res>;
    /// What the frame's plan must respect on this engine.
    fn limits(&self) -> Limits;
    /// Whether this is a device (host orders are then reported as `order_cpu`).
    fn is_device(&self) -> bool;
}
