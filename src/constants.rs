// Shared by the library and build.rs (which injects each one into every GLSL stage as a macro),
// so the workgroup sizes and table sizes have a single source of truth.

/// Invocations per workgroup for the 1D compute stages (order, splat_params).
pub const WORKGROUP_SIZE: u32 = 256;
/// Invocations of the single-workgroup prefix sum in `order_scan`.
pub const SCAN_WORKGROUP_SIZE: u32 = 256;
/// Side of the square composite tile (`composite.comp` runs TILE×TILE invocations).
pub const COMPOSITE_TILE: u32 = 8;
/// Texels per side of the pre-integrated footprint table.
pub const FOOTPRINT_TABLE_SIZE: u32 = 64;
/// Intervals of the radial footprint table (in r², radius units) the footprint stage samples.
pub const RADIAL_TABLE_SIZE: u32 = 256;
/// Splats per invocation of the slab binning stages (one column of the slab x chunk count matrix).
pub const SLAB_CHUNK: u32 = 1024;
/// Screen tile of the compute per-splat compositor (`tile_composite.comp`): RASTER_TILE_H rows of
/// RASTER_TILE_W pixels, run by one SIMD group of RASTER_LANES lanes that deal each footprint box's
/// pixels in the tile among themselves.
pub const RASTER_TILE_W: u32 = 16;
/// Pixels down a tile of the compute tile compositor.
pub const RASTER_TILE_H: u32 = 16;
/// Lanes of a compositor workgroup (llvmpipe's SIMD width on AVX2).
pub const RASTER_LANES: u32 = 8;
const _: () =
    assert!((RASTER_TILE_W * RASTER_TILE_H).is_multiple_of(RASTER_LANES) && RASTER_TILE_W * RASTER_TILE_H <= 256);
const _: () = assert!((RASTER_TILE_W * RASTER_TILE_H).is_power_of_two());
/// Draw-list entries per invocation of the tile binning stages.
pub const TILE_CHUNK: u32 = 1024;
/// Invocations per workgroup of the tile binning stages: few chunks still fill several workgroups
/// (llvmpipe runs one workgroup per thread).
pub const TILE_BIN_WORKGROUP: u32 = 8;
/// Fixed-point scale of the compute sheet summation (`footprint_sum.comp`): 2^20 per unit of
/// optical depth, so a pixel's sum within one sheet may reach 4096 before the u32 wraps and each
/// contribution is rounded to within 5e-7.
pub const SUM_FIXED_SCALE: u32 = 1 << 20;
/// Records of a page of the per-splat arrays of 80-byte records (`SplatParams`, `ScreenQuad`): each
/// array is bound as two pages of one buffer, because one storage binding may not exceed the device's
/// `maxStorageBufferRange`, which is only guaranteed to reach 2^27 bytes (lavapipe's limit; 1.68 M such
/// records). 1.6 M records = 128 000 000 bytes, a multiple of every allowed offset alignment.
pub const SPLAT_PAGE: u32 = 1_600_000;
/// Splats the GPU path takes (two pages); larger scenes get a typed error (the CPU backend has no such limit).
pub const MAX_GPU_SPLATS: u32 = 2 * SPLAT_PAGE;
/// Entries of each tile's list one dispatch of `tile_composite` takes (longer lists take several
/// dispatches, the accumulators carried in the image between them): llvmpipe ends every loop of a
/// shader invocation once it has made 65535 loop iterations in all (`LP_MAX_TGSI_LOOP_ITERATIONS`),
/// silently, and an entry costs the compositor at most one per RASTER_LANES pixels of the tile
/// (plus one per batch, and the tile's pixels once each to load and store).
pub const TILE_SEGMENT: u32 = 1536;
const TILE_STEPS: u64 = (RASTER_TILE_W * RASTER_TILE_H / RASTER_LANES) as u64;
const _: () = assert!(TILE_SEGMENT as u64 * (2 + TILE_STEPS) + 2 * TILE_STEPS < 65535);
/// Loop iterations a binning or footprint-sum invocation may plan for: llvmpipe ends every loop of
/// an invocation once it has made 65535 in all, so those stages count theirs ahead and flag work
/// that would pass this (recording.rs: re-binned in shorter chunks, or a typed error).
pub const LOOP_BUDGET: u32 = 60_000;
/// Samples the GPU ray caster takes per ray at most (a typed error past it): its sample loop shares
/// llvmpipe's 65535 loop iterations per invocation with the brick skips.
pub const MAX_GPU_RAY_STEPS: u32 = 60_000;
/// Workgroups per dispatch row: larger 1D dispatches spill into y so they stay under the 65535 limit.
pub const MAX_GROUPS_X: u32 = 32768;

/// Voxels along each side of a brick of the bricked store (`crate::bricks`; chosen by measurement
/// there).
pub const BRICK_SIDE: u32 = 8;
/// Lanes of the brick stages' workgroups: one workgroup per brick, each lane a record in eight.
pub const BRICK_LANES: u32 = 64;
/// Records of a bricked store per storage binding (128 MiB, the binding every device allows);
/// a store binds up to `RECORD_PAGES` of them.
pub const RECORD_PAGE: u32 = 1 << 25;
/// Most pages of store records (1 GiB, the default device budget).
pub const RECORD_PAGES: u32 = 8;
/// Words of one storage binding of the levels-of-detail pyramid (2^27 bytes, lavapipe's binding
/// limit); it binds up to `PYRAMID_PAGES` of them (`Res::Pyramid`, `Res::Pyramid1`..).
pub const PYRAMID_PAGE: u32 = 1 << 25;
/// See `PYRAMID_PAGE`.
pub const PYRAMID_PAGES: u32 = 4;
/// Entries of the brick stages' transfer-function table: one per 16-bit stored value.
pub const TF_ENTRIES: u32 = 1 << 16;

/// Most clipping planes a frame takes besides its box crop.
pub const MAX_CLIP_PLANES: usize = 6;
/// Planes a frame holds: the clipping planes and the crop box's six faces.
pub const CLIP_SLOTS: usize = MAX_CLIP_PLANES + 6;

/// Voxels along x of a segment of the isosurface's row maxima (`iso::IsoField::rows`), and cells
/// of a block its walks skip whole (glsl/shared/iso.glsl).
pub const ISO_SEGMENT: u32 = 32;

/// Entries of a projection mode's colour map (`Res::ColorMap`, glsl/project.comp).
pub const COLOR_MAP_SIZE: u32 = 256;

/// Macros injected into GLSL (name, value).
#[allow(dead_code)] // build.rs reads it (the shaders' macros), the library does not
pub const GLSL_DEFINES: &[(&str, u32)] = &[
    ("WORKGROUP_SIZE", WORKGROUP_SIZE),
    ("SCAN_WORKGROUP_SIZE", SCAN_WORKGROUP_SIZE),
    ("COMPOSITE_TILE", COMPOSITE_TILE),
    ("FOOTPRINT_TABLE_SIZE", FOOTPRINT_TABLE_SIZE),
    ("RADIAL_TABLE_SIZE", RADIAL_TABLE_SIZE),
    ("SLAB_CHUNK", SLAB_CHUNK),
    ("RASTER_TILE_W", RASTER_TILE_W),
    ("RASTER_TILE_H", RASTER_TILE_H),
    ("RASTER_LANES", RASTER_LANES),
    ("TILE_CHUNK", TILE_CHUNK),
    ("TILE_BIN_WORKGROUP", TILE_BIN_WORKGROUP),
    ("SUM_FIXED_SCALE", SUM_FIXED_SCALE),
    ("SPLAT_PAGE", SPLAT_PAGE),
    ("TILE_SEGMENT", TILE_SEGMENT),
    ("LOOP_BUDGET", LOOP_BUDGET),
    ("BRICK_SIDE", BRICK_SIDE),
    ("BRICK_LANES", BRICK_LANES),
    ("TF_ENTRIES", TF_ENTRIES),
    ("RECORD_PAGE", RECORD_PAGE),
    ("PYRAMID_PAGE", PYRAMID_PAGE),
    ("CLIP_SLOTS", CLIP_SLOTS as u32),
    ("COLOR_MAP_SIZE", COLOR_MAP_SIZE),
    ("ISO_SEGMENT", ISO_SEGMENT),
];

/// Splats closer than this many radii to the near or far plane are culled (the quad's corners
/// must stay in front of the eye; 1.5 > sqrt 2); the framing view keeps the nearest voxels clear.
pub const CULL_RADII: f32 = 1.5;

/// The default device-memory budget of a frame: 1 GiB, as on a mid-range GPU (lavapipe too).
pub const DEFAULT_GPU_BUDGET: u64 = 1 << 30;
