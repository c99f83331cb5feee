//! THE stage table.
//!
//! Every GPU stage is declared once in [`STAGES`]: its name (the name of its GLSL file in `glsl/`
//! and of its CPU mirror in `src/cpu/`), its builds, what binding i of its descriptor set holds,
//! what it writes, its workgroup, the timing it is reported under, and the mirror's entry point.
//! `crate::recording::record_frame` writes a frame once, as a sequence of stage dispatches built
//! from the options, and runs it on an [`Engine`]: the Vulkan one (`crate::gpu`), the CPU mirrors
//! (`crate::cpu_engine`), or a split of the two (`crate::bisect`). Adding a stage is its shader,
//! its mirror, its row here and its line in the recording. The types they share are in
//! `crate::dispatch`, below both this table and the mirrors it names.
use crate::builds::{self, Build, Table};
use crate::constants::{BRICK_LANES, COMPOSITE_TILE, RASTER_TILE_H, RASTER_TILE_W, TILE_BIN_WORKGROUP, WORKGROUP_SIZE};
use crate::cpu::bindings::Bindings;
use crate::error::{Error, Result};
use crate::gpu_types::{
    BrickPush, CompositePush, DepthPush, FootprintPush, IsoPush, PresentPush, ProjectPush, SlabPush,
};

pub use crate::dispatch::{Args, Feature, Kind, Limits, List, Pass, Res, Variant, Workgroup};
use crate::gpu_types::Frame;
use crate::kernel::Kernel;
use crate::options::StageTime;

/// The CPU mirror's entry point: runs one dispatch on the CPU engine's bindings.
pub type Mirror = fn(&mut Bindings<'_>, &Args, &Variant) -> Result<()>;

/// One row of the stage table.
pub struct StageDesc {
    /// The stage's name: `glsl/<name>.comp` (draws: `.vert` + `.frag`) and `cpu::<name>`.
    pub name: &'static str,
    /// Compute or draw.
    pub kind: Kind,
    /// Binding i of the stage's descriptor set holds `bindings[i]`.
    pub bindings: &'static [Res],
    /// What it writes (the bisect switch hands these over).
    pub writes: &'static [Res],
    /// Push-constant bytes.
    pub push: u32,
    /// How invocation counts become workgroups.
    pub workgroup: Workgroup,
    /// The name its time is reported under (`StageTime::stage`).
    pub timing: &'static str,
    /// A build chosen by a device capability, when the device has it.
    pub device_build: Option<(Feature, &'static str)>,
    /// Its builds: a dispatch names one by value (`crate::builds`).
    pub builds: &'static Table,
    /// The CPU mirror's entry point.
    pub mirror: Mirror,
    /// Its shaders' builds (`glsl/<name>.*`).
    pub shaders: crate::shaders::Shaders,
}

mod bindings;
use bindings::*;

const ISO_PUSH: u32 = std::mem::size_of::<IsoPush>() as u32;
const FOOTPRINT_PUSH: u32 = std::mem::size_of::<FootprintPush>() as u32;
const SLAB_PUSH: u32 = std::mem::size_of::<SlabPush>() as u32;

/// Every stage, declared once: `name => Id { fields }` makes its id (`StageId::Id`), its row of
/// [`STAGES`] with `name`, its CPU mirror `cpu::<name>::stage` and its shaders' handle
/// `shaders::<name>::SHADERS` (`glsl/<name>.comp`, or `.vert` + `.frag`), so that a stage without
/// its mirror file or its shader fails to compile. Rows are in id
/// order; `Id` must be `name` in UpperCamelCase (checked below).
macro_rules! stages {
    ($($name:ident => $id:ident { $($field:ident: $value:expr),* $(,)? }),* $(,)?) => {
        /// A stage: its row of [`STAGES`] ([`StageId::desc`]).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[allow(missing_docs)]
        pub enum StageId {
            $($id),*
        }

        impl StageId {
            /// Every stage, in table order.
            pub const ALL: &'static [StageId] = &[$(StageId::$id),*];
            const NAMES: &'static [&'static str] = &[$(stringify!($id)),*];
        }

        /// The stages, indexed by [`StageId`].
        pub const STAGES: &[StageDesc] = &[$(StageDesc {
            name: stringify!($name),
            $($field: $value,)*
            mirror: crate::cpu::$name::stage,
            shaders: crate::shaders::$name::SHADERS,
        }),*];
    };
}

stages! {
    order_count => OrderCount {
        kind: Kind::Compute,
        bindings: ORDER,
        writes: &[Res::RowSplit, Res::Segments],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "order",
        device_build: None,
        builds: &builds::ONLY,
    },
    order_scan => OrderScan {
        kind: Kind::Compute,
        bindings: ORDER,
        writes: &[Res::Segments],
        push: 0,
        workgroup: Workgroup::Single(crate::constants::SCAN_WORKGROUP_SIZE),
        timing: "order",
        device_build: None,
        builds: &builds::ONLY,
    },
    order_scatter => OrderScatter {
        kind: Kind::Compute,
        bindings: ORDER,
        writes: &[Res::Order],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "order",
        device_build: None,
        builds: &builds::ONLY,
    },
    splat_params => SplatParams {
        kind: Kind::Compute,
        bindings: PARAMS,
        writes: &[Res::Params],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "splat_params",
        device_build: None,
        builds: &builds::ONLY,
    },
    brick_pyramid => BrickPyramid {
        kind: Kind::Compute,
        bindings: BRICK_GRADIENTS,
        writes: &[Res::Pyramid, Res::LodSummary, Res::PyramidSlot],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::PerItem(BRICK_LANES),
        timing: "lod",
        device_build: None,
        builds: &builds::RECORDS_OR_GRADIENTS,
    },
    brick_nodes => BrickNodes {
        kind: Kind::Compute,
        bindings: BRICK,
        writes: &[Res::LodSummary],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "lod",
        device_build: None,
        builds: &builds::ONLY,
    },
    brick_node_cut => BrickNodeCut {
        kind: Kind::Compute,
        bindings: BRICK,
        writes: &[Res::LodSummary],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "bricks",
        device_build: None,
        builds: &builds::ONLY,
    },
    brick_cull => BrickCull {
        kind: Kind::Compute,
        bindings: BRICK,
        // With levels of detail it also writes each brick's morph (a bisect split moves it).
        writes: &[Res::BrickSlots, Res::BrickMorph],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "bricks",
        device_build: None,
        builds: &builds::RECORDS,
    },
    brick_order => BrickOrder {
        kind: Kind::Compute,
        bindings: BRICK,
        writes: &[Res::BrickVoxels, Res::Order],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::PerItem(BRICK_LANES),
        timing: "order",
        device_build: None,
        builds: &builds::RECORDS,
    },
    brick_cells => BrickCells {
        kind: Kind::Compute,
        bindings: BRICK,
        writes: &[Res::BrickVoxels, Res::Order],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "order",
        device_build: None,
        builds: &builds::PYRAMIDS,
    },
    project_texels => ProjectTexels {
        kind: Kind::Compute,
        bindings: BRICK_TEXELS,
        writes: &[Res::BrickVoxels, Res::Order, Res::ProjectTexels, Res::VoxelTexels],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::PerItem(BRICK_LANES),
        timing: "texels",
        device_build: None,
        builds: &builds::RECORDS,
    },
    project_winners => ProjectWinners {
        kind: Kind::Compute,
        bindings: BRICK_TEXELS,
        writes: &[Res::ProjectTexels, Res::ProjectVoxels],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "winners",
        device_build: None,
        builds: &builds::ONLY,
    },
    brick_params => BrickParams {
        kind: Kind::Compute,
        bindings: BRICK_PARAMS,
        writes: &[Res::Params],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "splat_params",
        device_build: None,
        builds: &builds::PARAMS,
    },
    brick_quads => BrickQuads {
        kind: Kind::Compute,
        bindings: BRICK_QUADS,
        writes: &[Res::Quads],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "splat_params",
        device_build: None,
        builds: &builds::RECORDS_OR_GRADIENTS,
    },
    brick_lod_quads => BrickLodQuads {
        kind: Kind::Compute,
        bindings: BRICK_LOD_QUADS,
        writes: &[Res::Quads],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "splat_params",
        device_build: None,
        builds: &builds::RECORDS,
    },
    brick_lod_params => BrickLodParams {
        kind: Kind::Compute,
        bindings: BRICK,
        writes: &[Res::Params],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "splat_params",
        device_build: None,
        builds: &builds::RECORDS,
    },
    tile_occlusion => TileOcclusion {
        kind: Kind::Compute,
        bindings: &[Res::Frame, Res::Accum, Res::Occlusion],
        writes: &[Res::Occlusion],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "bricks",
        device_build: None,
        builds: &builds::ONLY,
    },
    brick_hidden => BrickHidden {
        kind: Kind::Compute,
        bindings: BRICK,
        writes: &[Res::BrickHidden],
        push: std::mem::size_of::<BrickPush>() as u32,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "bricks",
        device_build: None,
        builds: &builds::ONLY,
    },
    slab_count => SlabCount {
        kind: Kind::Compute,
        bindings: SLAB,
        writes: &[Res::SlabCounts],
        push: SLAB_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "slab_bins",
        device_build: None,
        builds: &builds::SLAB_BINS,
    },
    slab_scan => SlabScan {
        kind: Kind::Compute,
        bindings: SLAB,
        writes: &[Res::SlabCounts, Res::SlabStart],
        push: SLAB_PUSH,
        workgroup: Workgroup::Single(crate::constants::SCAN_WORKGROUP_SIZE),
        timing: "slab_bins",
        device_build: None,
        builds: &builds::ONLY,
    },
    slab_scatter => SlabScatter {
        kind: Kind::Compute,
        bindings: SLAB,
        writes: &[Res::SlabCounts, Res::SlabPairs],
        push: SLAB_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "slab_bins",
        device_build: None,
        builds: &builds::SLAB_BINS,
    },
    screen_quads => ScreenQuads {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::Quads],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "tile_bins",
        device_build: None,
        builds: &builds::PAGES,
    },
    tile_count => TileCount {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileCounts, Res::Status],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(TILE_BIN_WORKGROUP),
        timing: "tile_bins",
        device_build: None,
        builds: &builds::PAGES,
    },
    tile_scan => TileScan {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileCounts, Res::TileStart],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "tile_bins",
        device_build: None,
        builds: &builds::ONLY,
    },
    tile_offsets => TileOffsets {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileStart],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Single(crate::constants::SCAN_WORKGROUP_SIZE),
        timing: "tile_bins",
        device_build: None,
        builds: &builds::ONLY,
    },
    tile_scatter => TileScatter {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileCounts, Res::TileEntries],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(TILE_BIN_WORKGROUP),
        timing: "tile_bins",
        device_build: None,
        builds: &builds::PAGES,
    },
    tile_composite => TileComposite {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::Accum],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Tile(RASTER_TILE_W, RASTER_TILE_H),
        timing: "footprint",
        device_build: Some((Feature::SubgroupShuffle, "SHUFFLE")),
        builds: &builds::TILE_COMPOSITE,
    },
    sheet_tiles => SheetTiles {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::SheetTiles],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "sheet_tiles",
        device_build: None,
        builds: &builds::SHEET_TILES,
    },
    footprint => Footprint {
        kind: Kind::Draw,
        bindings: FOOTPRINT,
        writes: &[Res::Color, Res::Sums],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Instances,
        timing: "footprint",
        device_build: None,
        builds: &builds::FOOTPRINT,
    },
    footprint_sum => FootprintSum {
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::Fixed, Res::Status],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "footprint",
        device_build: Some((Feature::Int64Atomics, "SUM64")),
        builds: &builds::SHEET_MODES,
    },
    composite => Composite {
        kind: Kind::Compute,
        bindings: COMPOSITE,
        writes: &[Res::Accum, Res::Occlusion],
        push: std::mem::size_of::<CompositePush>() as u32,
        workgroup: Workgroup::Tile(COMPOSITE_TILE, COMPOSITE_TILE),
        timing: "composite",
        device_build: None,
        builds: &builds::COMPOSITE_LAYERS,
    },
    raycast => Raycast {
        kind: Kind::Compute,
        bindings: &[Res::RaycastParams, Res::Field, Res::Accum, Res::Bricks],
        writes: &[Res::Accum],
        push: 0,
        workgroup: Workgroup::Tile(COMPOSITE_TILE, COMPOSITE_TILE),
        timing: "raycast",
        device_build: None,
        builds: &builds::ONLY,
    },
    present => Present {
        kind: Kind::Compute,
        bindings: &[Res::Accum, Res::Color, Res::HostColor],
        writes: &[Res::Accum],
        push: std::mem::size_of::<PresentPush>() as u32,
        workgroup: Workgroup::Tile(COMPOSITE_TILE, COMPOSITE_TILE),
        timing: "present",
        device_build: None,
        builds: &builds::ONLY,
    },
    host_depth => HostDepth {
        kind: Kind::Compute,
        bindings: &[Res::HostDepthRaw, Res::HostDepth],
        writes: &[Res::HostDepth],
        push: std::mem::size_of::<DepthPush>() as u32,
        workgroup: Workgroup::Tile(COMPOSITE_TILE, COMPOSITE_TILE),
        timing: "host_depth",
        device_build: None,
        builds: &builds::ONLY,
    },
    iso_count => IsoCount {
        kind: Kind::Compute,
        bindings: ISO,
        writes: &[Res::IsoCounts],
        push: ISO_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "iso",
        device_build: None,
        builds: &builds::ONLY,
    },
    iso_scan => IsoScan {
        kind: Kind::Compute,
        bindings: ISO,
        writes: &[Res::IsoCounts],
        push: ISO_PUSH,
        workgroup: Workgroup::Single(crate::constants::SCAN_WORKGROUP_SIZE),
        timing: "iso",
        device_build: None,
        builds: &builds::ONLY,
    },
    iso_cells => IsoCells {
        kind: Kind::Compute,
        bindings: ISO,
        writes: &[Res::IsoCells],
        push: ISO_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "iso",
        device_build: None,
        builds: &builds::ONLY,
    },
    iso_splats => IsoSplats {
        kind: Kind::Compute,
        bindings: ISO,
        writes: &[Res::Params, Res::Order],
        push: ISO_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "splat_params",
        device_build: None,
        builds: &builds::ONLY,
    },
    project => Project {
        kind: Kind::Compute,
        bindings: &[Res::Accum, Res::Color, Res::ColorMap],
        writes: &[Res::Accum],
        push: std::mem::size_of::<ProjectPush>() as u32,
        workgroup: Workgroup::Tile(COMPOSITE_TILE, COMPOSITE_TILE),
        timing: "project",
        device_build: None,
        builds: &builds::ONLY,
    },
}

const _: () = assert!(StageId::ALL.len() == STAGES.len());
const _: () = {
    // Row i of the table is the stage the macro's i-th id names (`OrderCount` is `order_count`).
    let mut i = 0;
    while i < STAGES.len() {
        assert!(camel_is_snake(StageId::NAMES[i].as_bytes(), STAGES[i].name.as_bytes()));
        i += 1;
    }
};

/// Whether `camel` (`TileCount`) is `snake` (`tile_count`) in UpperCamelCase.
const fn camel_is_snake(camel: &[u8], snake: &[u8]) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < camel.len() {
        let c = camel[i];
        if c.is_ascii_uppercase() {
            if i > 0 {
                if j >= snake.len() || snake[j] != b'_' {
                    return false;
                }
                j += 1;
            }
            if j >= snake.len() || snake[j] != c.to_ascii_lowercase() {
                return false;
            }
        } else if j >= snake.len() || snake[j] != c {
            return false;
        }
        i += 1;
        j += 1;
    }
    j == snake.len()
}

impl StageId {
    /// Its row of the table.
    pub fn desc(self) -> &'static StageDesc {
        &STAGES[self as usize]
    }

    /// The stage of this name.
    pub fn named(name: &str) -> Result<StageId> {
        StageId::ALL.iter().copied().find(|s| s.desc().name == name).ok_or_else(|| {
            let names: Vec<_> = STAGES.iter().map(|s| s.name).collect();
            Error::InvalidArgument(format!("unknown stage '{name}' (stages: {})", names.join(", ")))
        })
    }
}

/// One stage invocation of a recording.
#[derive(Clone, Debug)]
pub struct Dispatch {
    /// The stage.
    pub stage: StageId,
    /// The build (in a recording's Debug log).
    #[allow(dead_code)]
    pub build: Build,
    /// Where `build` sits in the stage's table (its pipeline, its mirror's variant).
    pub variant: usize,
    /// Workgroups, draw list and push constants.
    pub args: Args,
}

impl Dispatch {
    /// A dispatch of `stage`'s `build` (push: the stage's push-constant struct's bytes). Refused
    /// when the stage has no such build or its push constants are of another size.
    pub fn new(stage: StageId, build: impl Into<Build>, groups: [u32; 3], list: List, push: &[u8]) -> Result<Self> {
        let (desc, build) = (stage.desc(), build.into());
        let variant = desc.builds.index(build).ok_or_else(|| {
            Error::Unsupported(format!("{}: no build {build:?} (its builds: {:?})", desc.name, desc.builds.builds))
        })?;
        if push.len() as u32 != desc.push {
            return Err(Error::InvalidArgument(format!(
                "{}: {} bytes of push constants, not {}",
                desc.name,
                push.len(),
                desc.push
            )));
        }
        Ok(Self { stage, build, variant, args: Args { groups, list, push: push.to_vec() } })
    }

    /// What the stage's mirror and pipeline are made of for this build.
    pub fn variant(&self) -> &'static Variant {
        &self.stage.desc().builds.variants[self.variant]
    }
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
    /// Write `words` words of `data` from word `src` into `res` at word `dst`, for each region
    /// `[src, dst, words]`, keeping the rest of `res` (which already holds them: `ensure`).
    fn upload_regions(&mut self, res: Res, data: &[u32], regions: &[[u64; 3]]) -> Result<()>;
    /// Run (or queue) one stage dispatch.
    fn run(&mut self, dispatch: &Dispatch) -> Result<()>;
    /// How far a long one-off build (the levels of detail) has got: `done` of `of` bricks, once
    /// the work so far has run. Only an engine given the host's hook does anything.
    fn progress(&mut self, _done: u64, _of: u64) -> Result<()> {
        Ok(())
    }
    /// Finish the work so far and read the first `words` 32-bit words of each resource.
    fn read(&mut self, what: &[(Res, usize)]) -> Result<Vec<Vec<u32>>>;
    /// Words `res` holds now (0 when it does not exist).
    fn words(&self, res: Res) -> usize;
    /// What `res` holds across frames (0: nothing known): a tag the recording sets after writing
    /// a cache (`set_tag`), forgotten when the buffer is replaced.
    fn tag(&self, res: Res) -> u64;
    /// Say that `res` holds `tag`.
    fn set_tag(&mut self, res: Res, tag: u64);
    /// Work done on the host, reported as a stage.
    fn host_time(&mut self, stage: &'static str, ms: f64);
    /// Finish the frame: the stage times.
    fn finish(&mut self) -> Result<Vec<StageTime>>;
    /// When the frame goes into a host's image (`Renderer::render_to`): whether that image wants
    /// linear values (it encodes sRGB itself, or stores floats). `None`: the frame is read back.
    fn target_linear(&self) -> Option<bool> {
        None
    }
    /// Copy the presented frame (the accumulation image) into the host's image, ordered by the
    /// host's semaphores: only an engine with a target can.
    fn deliver(&mut self) -> Result<()> {
        Err(Error::Unsupported("only the Vulkan engine writes into a host's image".into()))
    }
    /// When the frame is composited over the host's image (`vk::HostTarget::over`): its format.
    fn target_over(&self) -> Option<crate::image::TargetFormat> {
        None
    }
    /// Copy the host's image as the frame finds it into `res` (its texels as stored): only an
    /// engine with a target drawn over can.
    fn copy_target_color(&mut self, _res: Res) -> Result<()> {
        Err(Error::Unsupported("only the Vulkan engine reads a host's image".into()))
    }
    /// Copy the target's depth image into `res` (a word per pixel): only an engine with a
    /// target can.
    fn copy_target_depth(&mut self, _res: Res) -> Result<()> {
        Err(Error::Unsupported("only the Vulkan engine reads a host's depth image".into()))
    }
    /// The frame resources written so far (what a split hands over).
    fn live(&self) -> Vec<Res>;
    /// What the frame's plan must respect on this engine.
    fn limits(&self) -> Limits;
    /// Make the scene's dense field for `mode` (`Prepared::field_for`) and its occupancy of
    /// `brick`-voxel bricks resident (the ray caster's `Res::Field`, `Res::Bricks`; brick 0: no
    /// skipping).
    fn prepare_field(&mut self, brick: u32, mode: crate::options::Mode) -> Result<()>;
    /// Whether this is a device (host orders are then reported as `order_cpu`).
    fn is_device(&self) -> bool;
}
