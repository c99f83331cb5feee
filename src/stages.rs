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
use crate::constants::{COMPOSITE_TILE, RASTER_TILE_H, RASTER_TILE_W, TILE_BIN_WORKGROUP, WORKGROUP_SIZE};
use crate::cpu::bindings::Bindings;
use crate::error::{Error, Result};
use crate::gpu_types::{CompositePush, FootprintPush, SlabPush, SHEET_MODE_AXIS, SHEET_MODE_SLAB, SHEET_MODE_SPLAT};

pub use crate::dispatch::{
    Blend, Dispatch, DrawState, Engine, Feature, Kind, Limits, List, Pass, Res, StageId, Variant, Workgroup,
};

/// The CPU mirror's entry point: runs one dispatch on the CPU engine's bindings.
pub type Mirror = fn(&mut Bindings<'_>, &Dispatch, &Variant) -> Result<()>;

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
    /// Its builds; a dispatch names one by index.
    pub variants: &'static [Variant],
    /// The CPU mirror's entry point.
    pub mirror: Mirror,
}

const fn v(defines: &'static str, spec: &'static [u32]) -> Variant {
    Variant { defines, spec, draw: None }
}

const fn d(blend: Blend, points: bool, pass: Pass, spec: &'static [u32]) -> Variant {
    Variant { defines: "", spec, draw: Some(DrawState { blend, points, pass }) }
}

const ORDER: &[Res] = &[Res::Frame, Res::Splats, Res::RowStart, Res::RowSplit, Res::Segments, Res::Order];
const PARAMS: &[Res] = &[Res::Frame, Res::Splats, Res::Params, Res::ParamsHi];
const SLAB: &[Res] = &[Res::Params, Res::SlabCounts, Res::SlabPairs, Res::SlabStart, Res::ParamsHi];
const COMPOSITE: &[Res] = &[Res::Sums, Res::Accum, Res::Occlusion, Res::Fixed, Res::SheetTiles];
/// glsl/shared/footprint.glsl's bindings, shared by every footprint-reading stage.
const FOOTPRINT: &[Res] = &[
    Res::Frame,
    Res::Params,
    Res::DrawList,
    Res::Splats,
    Res::Ranks,
    Res::Radial,
    Res::SliceTable,
    Res::Occlusion,
    Res::Fixed,
    Res::TileCounts,
    Res::TileStart,
    Res::TileEntries,
    Res::Accum,
    Res::Quads,
    Res::SheetTiles,
    Res::ParamsHi,
    Res::QuadsHi,
    Res::Status,
];
const ONE: &[Variant] = &[v("", &[])];
/// Two pages of splat records, and one (`ONE_PAGE`, types.glsl): see [`one_page`].
const PAGED: &[Variant] = &[v("", &[]), v("ONE_PAGE", &[])];
const FOOTPRINT_PUSH: u32 = std::mem::size_of::<FootprintPush>() as u32;
const SLAB_PUSH: u32 = std::mem::size_of::<SlabPush>() as u32;

/// The stages, indexed by [`StageId`].
pub static STAGES: [StageDesc; 16] = [
    StageDesc {
        name: "order_count",
        kind: Kind::Compute,
        bindings: ORDER,
        writes: &[Res::RowSplit, Res::Segments],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "order",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::order::order_count_stage,
    },
    StageDesc {
        name: "order_scan",
        kind: Kind::Compute,
        bindings: ORDER,
        writes: &[Res::Segments],
        push: 0,
        workgroup: Workgroup::Single(crate::constants::SCAN_WORKGROUP_SIZE),
        timing: "order",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::order::order_scan_stage,
    },
    StageDesc {
        name: "order_scatter",
        kind: Kind::Compute,
        bindings: ORDER,
        writes: &[Res::Order],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "order",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::order::order_scatter_stage,
    },
    StageDesc {
        name: "splat_params",
        kind: Kind::Compute,
        bindings: PARAMS,
        writes: &[Res::Params],
        push: 0,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "splat_params",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::splat_params::splat_params_stage,
    },
    StageDesc {
        name: "slab_count",
        kind: Kind::Compute,
        bindings: SLAB,
        writes: &[Res::SlabCounts],
        push: SLAB_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "slab_bins",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::slab::slab_count_stage,
    },
    StageDesc {
        name: "slab_scan",
        kind: Kind::Compute,
        bindings: SLAB,
        writes: &[Res::SlabCounts, Res::SlabStart],
        push: SLAB_PUSH,
        workgroup: Workgroup::Single(crate::constants::SCAN_WORKGROUP_SIZE),
        timing: "slab_bins",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::slab::slab_scan_stage,
    },
    StageDesc {
        name: "slab_scatter",
        kind: Kind::Compute,
        bindings: SLAB,
        writes: &[Res::SlabCounts, Res::SlabPairs],
        push: SLAB_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "slab_bins",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::slab::slab_scatter_stage,
    },
    StageDesc {
        name: "tile_count",
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileCounts, Res::Quads, Res::Status],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(TILE_BIN_WORKGROUP),
        timing: "tile_bins",
        device_build: None,
        variants: PAGED,
        mirror: crate::cpu::tile::tile_count_stage,
    },
    StageDesc {
        name: "tile_scan",
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileCounts, Res::TileStart],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "tile_bins",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::tile::tile_scan_stage,
    },
    StageDesc {
        name: "tile_offsets",
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileStart],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Single(crate::constants::SCAN_WORKGROUP_SIZE),
        timing: "tile_bins",
        device_build: None,
        variants: ONE,
        mirror: crate::cpu::tile::tile_offsets_stage,
    },
    StageDesc {
        name: "tile_scatter",
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::TileCounts, Res::TileEntries],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(TILE_BIN_WORKGROUP),
        timing: "tile_bins",
        device_build: None,
        variants: PAGED,
        mirror: crate::cpu::tile::tile_scatter_stage,
    },
    StageDesc {
        name: "tile_composite",
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::Accum],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Tile(RASTER_TILE_W, RASTER_TILE_H),
        timing: "footprint",
        device_build: Some((Feature::SubgroupShuffle, "SHUFFLE")),
        // [paged, one page] x [back to front, front to back, front to back terminating] x
        // [still, motion-blurred]: see `tile_composite_variant`.
        variants: &[
            v("", &[SHEET_MODE_SPLAT, 1, 0, 0]),
            v("", &[SHEET_MODE_SPLAT, 1, 0, 1]),
            v("", &[SHEET_MODE_SPLAT, 0, 0, 0]),
            v("", &[SHEET_MODE_SPLAT, 0, 0, 1]),
            v("", &[SHEET_MODE_SPLAT, 0, 1, 0]),
            v("", &[SHEET_MODE_SPLAT, 0, 1, 1]),
            v("ONE_PAGE", &[SHEET_MODE_SPLAT, 1, 0, 0]),
            v("ONE_PAGE", &[SHEET_MODE_SPLAT, 1, 0, 1]),
            v("ONE_PAGE", &[SHEET_MODE_SPLAT, 0, 0, 0]),
            v("ONE_PAGE", &[SHEET_MODE_SPLAT, 0, 0, 1]),
            v("ONE_PAGE", &[SHEET_MODE_SPLAT, 0, 1, 0]),
            v("ONE_PAGE", &[SHEET_MODE_SPLAT, 0, 1, 1]),
        ],
        mirror: crate::cpu::tile::tile_composite_stage,
    },
    StageDesc {
        name: "sheet_tiles",
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::SheetTiles],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "sheet_tiles",
        device_build: None,
        // [axis quads, axis points, slab quads, slab points].
        variants: &[
            v("", &[SHEET_MODE_AXIS, 0]),
            v("", &[SHEET_MODE_AXIS, 1]),
            v("", &[SHEET_MODE_SLAB, 0]),
            v("", &[SHEET_MODE_SLAB, 1]),
        ],
        mirror: crate::cpu::sheet_tiles::sheet_tiles_stage,
    },
    StageDesc {
        name: "footprint",
        kind: Kind::Draw,
        bindings: FOOTPRINT,
        writes: &[Res::Color, Res::Sums],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Instances,
        timing: "footprint",
        device_build: None,
        // See `footprint_variant`.
        variants: &[
            d(Blend::Over, false, Pass::Target, &[SHEET_MODE_SPLAT, 0]),
            d(Blend::Under, false, Pass::Target, &[SHEET_MODE_SPLAT, 0]),
            d(Blend::Add, false, Pass::Sheet, &[SHEET_MODE_AXIS, 0]),
            d(Blend::Add, false, Pass::Sheet, &[SHEET_MODE_SLAB, 0]),
            d(Blend::Over, true, Pass::Target, &[SHEET_MODE_SPLAT, 1]),
            d(Blend::Under, true, Pass::Target, &[SHEET_MODE_SPLAT, 1]),
            d(Blend::Add, true, Pass::Sheet, &[SHEET_MODE_AXIS, 1]),
            d(Blend::Add, true, Pass::Sheet, &[SHEET_MODE_SLAB, 1]),
        ],
        mirror: crate::cpu::footprint::footprint_stage,
    },
    StageDesc {
        name: "footprint_sum",
        kind: Kind::Compute,
        bindings: FOOTPRINT,
        writes: &[Res::Fixed, Res::Status],
        push: FOOTPRINT_PUSH,
        workgroup: Workgroup::Linear(WORKGROUP_SIZE),
        timing: "footprint",
        device_build: Some((Feature::Int64Atomics, "SUM64")),
        variants: &[v("", &[SHEET_MODE_AXIS]), v("", &[SHEET_MODE_SLAB])],
        mirror: crate::cpu::footprint::footprint_sum_stage,
    },
    StageDesc {
        name: "composite",
        kind: Kind::Compute,
        bindings: COMPOSITE,
        writes: &[Res::Accum, Res::Occlusion],
        push: std::mem::size_of::<CompositePush>() as u32,
        workgroup: Workgroup::Tile(COMPOSITE_TILE, COMPOSITE_TILE),
        timing: "composite",
        device_build: None,
        // Float layers (the summation image), fixed-point layers (`Res::Fixed`).
        variants: &[v("", &[]), v("", &[1])],
        mirror: crate::cpu::composite::composite_stage,
    },
];

impl StageId {
    /// Its row of the table.
    pub fn desc(self) -> &'static StageDesc {
        &STAGES[self as usize]
    }

    /// The stage of this name.
    pub fn named(name: &str) -> Result<StageId> {
        const ALL: [StageId; 16] = [
            StageId::OrderCount,
            StageId::OrderScan,
            StageId::OrderScatter,
            StageId::SplatParams,
            StageId::SlabCount,
            StageId::SlabScan,
            StageId::SlabScatter,
            StageId::TileCount,
            StageId::TileScan,
            StageId::TileOffsets,
            StageId::TileScatter,
            StageId::TileComposite,
            StageId::SheetTiles,
            StageId::Footprint,
            StageId::FootprintSum,
            StageId::Composite,
        ];
        ALL.into_iter().find(|s| s.desc().name == name).ok_or_else(|| {
            let names: Vec<_> = STAGES.iter().map(|s| s.name).collect();
            Error::InvalidArgument(format!("unknown stage '{name}' (stages: {})", names.join(", ")))
        })
    }
}

const _: () = assert!(StageId::Composite as usize + 1 == STAGES.len());
