//! What the stage table and the CPU mirrors share, below both: resources by name ([`Res`],
//! [`List`]), a stage's builds ([`Variant`]) and a dispatch's arguments ([`Args`]). The table
//! (`crate::stages`) names the mirrors, so the mirrors cannot name the table.

/// How a fragment combines with the attachment (premultiplied colour).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Back to front: src + (1 - src.a) dst.
    Over,
    /// Front to back: (1 - dst.a) src + dst.
    Under,
    /// Sheet summation and the summing projections: src + dst.
    Add,
    /// The maximum projections: max(src, dst) per channel.
    Max,
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
    /// A rectilinear grid's voxel coordinates (`SplatSet::with_coordinates`).
    Coords,
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
    /// The ray caster's uniforms (`RaycastParams`).
    RaycastParams,
    /// A projection mode's colour map (`COLOR_MAP_SIZE` straight RGBA entries).
    ColorMap,
    /// The isosurface's field (`iso::IsoField::words`): the scene's values, 16 bits each, uploaded
    /// once per scene (`Engine::tag`).
    IsoField,
    /// Its voxel rows' ranges (`iso::IsoField::rows`), with it.
    IsoRows,
    /// Per row of cells its surface splats, then (scanned) its first one, then the total.
    IsoCounts,
    /// Per surface splat its cell and inside corners (`iso_cells`).
    IsoCells,
    /// The host's depth buffer as it stores it (`DepthBuffer::texels`, row 0 at the top).
    HostDepthRaw,
    /// The host's depth as eye-space depth per pixel (`host_depth`), which hides the splats behind it.
    HostDepth,
    /// The host's image as the frame finds it, texels as stored (`vk::HostTarget::over`): what
    /// `present` composites the frame over.
    HostColor,
    /// The ray caster's dense (colour * tau, tau) field, a 3D texture: a per-scene cache built on
    /// first use (`Engine::prepare_field`).
    Field,
    /// Its brick occupancy (1: a brick holds a non-empty voxel), cached with it.
    Bricks,
    /// A bricked volume's store (`crate::bricks`): 16-byte brick headers, resident per scene.
    BrickHeaders,
    /// Its 64-byte occupancy masks.
    BrickMasks,
    /// Its 4-byte voxel records (page 0 of `RECORD_PAGES`; the next are `BrickRecords1`..).
    BrickRecords,
    /// Pages 1-7 of the records (page 0 again where the store is shorter).
    BrickRecords1,
    #[allow(missing_docs)]
    BrickRecords2,
    #[allow(missing_docs)]
    BrickRecords3,
    #[allow(missing_docs)]
    BrickRecords4,
    #[allow(missing_docs)]
    BrickRecords5,
    #[allow(missing_docs)]
    BrickRecords6,
    #[allow(missing_docs)]
    BrickRecords7,
    /// Brick id -> header (`u32::MAX`: empty).
    BrickIndex,
    /// The brick stages' uniforms (`BrickFrame`).
    BrickFrame,
    /// The transfer function's points (a TF change rewrites only this).
    Tf,
    /// Per brick-grid position in draw order: header << 10 | voxels drawn, 0 when culled.
    BrickSlots,
    /// The visible bricks in draw order: (header, first position in its batch).
    BrickList,
    /// A batch's voxels in draw order: (i | j << 16, k | stored value << 16).
    BrickVoxels,
    /// Per entry of the next wave, 1 when hidden (front to back, early termination).
    BrickHidden,
    /// Per stored voxel the first word of its packed central differences
    /// (`BrickStore::gradient_words`): what a shaded or gradient-weighted frame's `brick_params`
    /// reads (its `GRADIENTS` build).
    BrickGradients,
    /// The second words of `BrickGradients`.
    BrickGradientsHi,
    /// A streamed store's records for one batch (the store stays on the host).
    BatchRecords,
    /// A streamed store's drawn voxels per brick under the current TF (counted on the host).
    BrickCounts,
    /// Levels of detail: per brick the cells of levels 1-3 (`brick_pyramid`), kept while the
    /// classification lasts (`Engine::tag`).
    Pyramid,
    /// Per brick its levels' drawn cells and errors.
    LodSummary,
    /// Per brick, this frame, how far its splats morph toward the next level (`brick_cull`).
    BrickMorph,
    /// A streamed store's pyramid holds one batch's bricks: per brick, its slot there.
    PyramidSlot,
    /// Pages 1-3 of `Pyramid` (`PYRAMID_PAGE` words each; `Pyramid` binds page 0).
    Pyramid1,
    /// Page 2 of `Pyramid`.
    Pyramid2,
    /// Page 3 of `Pyramid`.
    Pyramid3,
    /// Levels of detail: a batch's coarse splats' positions (`brick_lod_params`' lanes).
    LodSplats,
    /// A projection's texels (MIP, MinIP): a batch's drawn voxels (`project_winners`' count), then
    /// per texel the claim of the brightest voxel whose centre falls in it (`project_texels`), the
    /// only one of them that draws.
    ProjectTexels,
    /// A projection's voxels that draw, packed (`project_winners`): `brick_params`' input then.
    ProjectVoxels,
    /// A projection's texels: per voxel of a batch the word of the texel it claims
    /// (`project_texels`, for `project_winners`).
    VoxelTexels,
    /// Images: the compute passes' accumulation image, the summation layers, the raster target.
    Accum,
    /// The summation layers.
    Sums,
    /// The raster target of per-splat compositing.
    Color,
}

impl Res {
    /// `list` with `from` replaced by `to`: a stage's bindings that differ from its family's in
    /// one place.
    pub const fn replaced<const N: usize>(list: [Res; N], from: Res, to: Res) -> [Res; N] {
        let mut out = list;
        let mut i = 0;
        while i < N {
            if list[i] as u32 == from as u32 {
                out[i] = to;
            }
            i += 1;
        }
        out
    }

    /// Made before any frame (renderer or scene) and never changed by a stage.
    pub fn is_constant(self) -> bool {
        matches!(
            self,
            Res::Frame
                | Res::Radial
                | Res::SliceTable
                | Res::Splats
                | Res::Coords
                | Res::RowStart
                | Res::Ranks
                | Res::Field
                | Res::Bricks
                | Res::BrickHeaders
                | Res::BrickMasks
                | Res::BrickIndex
        ) || self.record_page().is_some()
    }

    /// Which page of the store's records this binding holds (`BrickRecords` is page 0).
    pub fn record_page(self) -> Option<u64> {
        Some(match self {
            Res::BrickRecords => 0,
            Res::BrickRecords1 => 1,
            Res::BrickRecords2 => 2,
            Res::BrickRecords3 => 3,
            Res::BrickRecords4 => 4,
            Res::BrickRecords5 => 5,
            Res::BrickRecords6 => 6,
            Res::BrickRecords7 => 7,
            _ => return None,
        })
    }

    /// Which page of the pyramid this binding holds (`Pyramid` is page 0).
    pub fn pyramid_page(self) -> Option<u64> {
        Some(match self {
            Res::Pyramid => 0,
            Res::Pyramid1 => 1,
            Res::Pyramid2 => 2,
            Res::Pyramid3 => 3,
            _ => return None,
        })
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
    /// Two time slots of a motion-blurred frame composited apart, each fragment writing both: the
    /// raster target (`Res::Color`, the first half of the shutter) and the accumulation image
    /// (`Res::Accum`, the second).
    Slots,
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
    /// One workgroup of this many invocations per item (spilling into y, `plan::groups_per_item`).
    PerItem(u32),
    /// A draw: one instance per entry.
    Instances,
}

/// A dispatch's arguments, what its stage's mirror reads besides the bindings.
#[derive(Clone, Debug)]
pub struct Args {
    /// Compute: workgroups. Draws: `[first instance, instances, 0]`.
    pub groups: [u32; 3],
    /// What `Res::DrawList` binds.
    pub list: List,
    /// The push constants' bytes.
    pub push: Vec<u8>,
}

impl Args {
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
    /// Device memory a frame may hold (`RendererOptions::gpu_budget_bytes`): a bricked volume's
    /// splats stream through it in batches. The CPU engine keeps the same budget, so it cuts the
    /// same batches.
    pub budget_bytes: u64,
    /// The host's depth image of the frame's target (`vk::HostTarget::with_depth`): its format
    /// and projection; `None` for a frame read back.
    pub target_depth: Option<(crate::options::DepthFormat, glam::Mat4)>,
}
