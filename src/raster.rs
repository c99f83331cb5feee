//! How the footprint stage turns splats into pixels, and the `auto` rule that picks one.
//!
//! | variant    | per-splat compositing (`Composite::Splat`)      | sheet modes (`Sheet`, `Slab`)          |
//! |------------|-------------------------------------------------|----------------------------------------|
//! | `graphics` | instanced eye-facing quads, over/under blending | quads, additive blending into layers   |
//! | `points`   | one point sprite per splat (circular footprint) | point sprites, additive                |
//! | `compute`  | tile binning + per-tile compositing (`tile_*`)  | fixed-point atomic sums (`footprint_sum`) |
//!
//! The graphics pass is the design and what a hardware rasteriser is built for. A CPU device
//! (lavapipe) pays per primitive, not per pixel (../shared/peers/README.md), so there small
//! footprints are cheaper in compute. `auto`: graphics on a hardware device; on a CPU device
//! compute for small footprints (the tile compositor per splat, the fixed-point sums for sheets),
//! else point sprites where they fit (no motion blur, footprints from `AUTO_POINTS_MIN_PX` to the
//! device's point size), else graphics. Point sprites draw a screen-aligned square of the
//! footprint's radius at its centre: exact in orthographic views; for perspective splats they
//! ignore the eye-facing quad's off-axis elongation, which measured no worse against the truth than
//! the quads (docs/MODEL.md); they cannot stretch along a motion path.
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::options::{Composite, RenderOptions};
use crate::volume::SplatSet;

pub use crate::options::{Raster, RasterChoice};

/// What the device offers the choice.
#[derive(Clone, Copy, Debug)]
pub struct Device {
    /// A CPU implementation (lavapipe) or the CPU mirrors: primitive-bound rasteriser.
    pub cpu: bool,
    /// Widest point sprite in pixels.
    pub point_size_max: f32,
    /// The graphics pipeline can draw footprints (RGBA32F targets blend): else compute only.
    pub graphics: bool,
}

impl Device {
    /// What `Raster::Auto` weighs of a device's choices.
    pub fn of(choices: &crate::device::DeviceChoices) -> Self {
        Device { cpu: choices.cpu, point_size_max: choices.point_size_max, graphics: choices.graphics_raster }
    }
}

/// Footprint diameters in pixels, estimated from the grid's bounds (O(1), no pass over splats).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootprintSize {
    /// At the depth of the grid's centre.
    pub typical_px: f32,
    /// At the nearest grid corner's depth (the largest footprint).
    pub max_px: f32,
    /// At the farthest grid corner's depth (the smallest footprint).
    pub min_px: f32,
}

/// Footprint diameter estimate for `set` seen from `camera` with `opts` (anti-aliasing widens far
/// splats, which only matters for the typical size).
pub fn footprint_size(set: &SplatSet, camera: &Camera, opts: &RenderOptions) -> FootprintSize {
    let frame = crate::plan::frame_for(set, camera, opts);
    let g = set.grid();
    let eye = camera.eye;
    let forward = camera.forward();
    let (mut near, mut far, mut sum) = (f32::INFINITY, f32::NEG_INFINITY, 0.0);
    for c in 0..8u32 {
        let ijk = [0, 1, 2].map(|a| if c >> a & 1 == 1 { g.dims[a].saturating_sub(1) } else { 0 });
        let d = (set.position(ijk) - eye).dot(forward);
        near = near.min(d);
        far = far.max(d);
        sum += d;
    }
    let centre = sum / 8.0;
    // A rectilinear grid's splats are as wide as their own cells: the widest gap bounds them, and
    // the widest gap that is not an outlier is their typical size (one far position must not
    // turn a frame of small footprints into one of huge ones).
    let widest = frame.spacing[3];
    let typical = widest * (set.opacity_length() / set.kernel_spacing()).min(1.0);
    let diameter = |depth: f32, radius: f32| {
        let depth = depth.max(camera.near);
        let radius = radius * crate::plan::footprint_scale(&frame, depth);
        let ppu = frame.up[3];
        2.0 * if camera.is_perspective() { radius * ppu / depth } else { radius * ppu }
    };
    FootprintSize {
        typical_px: diameter(centre, typical),
        max_px: diameter(near, widest),
        min_px: diameter(far, typical),
    }
}

/// Typical footprint diameters (px) up to which `auto` uses compute on a CPU device: the tile
/// compositor for per-splat compositing, the fixed-point sums for sheet modes. Measured on lavapipe
/// (`voxsplat-lab rates`, docs/RESULTS.md, two full runs) since the compositor deals each box's pixels
/// to its lanes: 5.4-6.3x, 3.8-4.2x, 2.7x the quads at 3, 5, 7 px and 2.1-2.4x, 1.7-1.9x at 11 and
/// 15 px, ahead of the point sprites at every size (2.1-2.7x, 2.2-2.3x, 1.8-2.0x, 1.6-1.7x, 1.5x),
/// and level with them on the peers' 128^3 scene (~14 px in perspective: 306 and 228 ms against
/// 274 and 244 ms); the sums (an earlier run) 7.4x, 3.7x, 3.4x at 3-7 px, 1.6-1.7x at 11-15 px,
/// ahead of or level with the sprites up to 11 px.
pub const AUTO_COMPUTE_TILES_MAX_PX: f32 = 15.0;
/// Largest footprint, in pixels, for which `auto` picks the compute sheet sums on a CPU device.
pub const AUTO_COMPUTE_SUM_MAX_PX: f32 = 10.0;
/// Narrowest footprint (px) for which `auto` draws point sprites. Below about a pixel the device
/// clamps a sprite to its minimum point size and evaluates the footprint at the sprite's centre, so
/// a sub-pixel splat lands on a whole pixel at its peak weight where a quad covers no pixel centre
/// (bonsai at 96x72: 3.5/255 mean, 220/255 largest difference). Quads and compute sample the same
/// pixel centres.
pub const AUTO_POINTS_MIN_PX: f32 = 2.0;

/// Whether the frame blurs with chapter 4's future work (an arc path or a tapered or teardrop
/// profile), which only the graphics pipeline draws.
fn swept(opts: &RenderOptions) -> bool {
    opts.motion.is_some_and(|m| m.middle.is_some() || m.profile != crate::BlurProfile::Uniform)
}

/// Resolve `opts.raster` for this frame; `Auto` becomes a concrete variant. Explicit choices are
/// checked: points cannot stretch along a motion path nor exceed the device's point size.
pub fn choose(set: &SplatSet, camera: &Camera, opts: &RenderOptions, device: Device) -> Result<RasterChoice> {
    if opts.mode == crate::options::Mode::Iso {
        // RenderOptions::validate refuses the graphics rasters here.
        return Ok(RasterChoice {
            raster: Raster::Compute,
            reason: "iso: surface splats blend by depth in the tile compositor".into(),
        });
    }
    let size = footprint_size(set, camera, opts);
    if !device.graphics {
        let needs_quads = swept(opts) || (opts.motion.is_some() && opts.depth.is_some());
        match opts.raster {
            Raster::Graphics | Raster::Points => {
                return Err(Error::Unsupported(format!(
                    "--raster {} needs RGBA32F targets that blend, which this device lacks: use --raster compute",
                    opts.raster.name()
                )))
            }
            Raster::Auto if needs_quads => {
                return Err(Error::Unsupported(
                    "a bent or tapered motion blur, or one over the host's depth, needs the graphics pipeline, \
                     whose RGBA32F targets this device cannot blend"
                        .into(),
                ))
            }
            Raster::Auto => {
                return Ok(RasterChoice {
                    raster: Raster::Compute,
                    reason: "auto: the device's RGBA32F targets do not blend".into(),
                })
            }
            Raster::Compute => {}
        }
    }
    match opts.raster {
        Raster::Points => {
            if opts.motion.is_some() {
                return Err(Error::InvalidArgument(
                    "point sprites cannot stretch along a motion path: use --raster graphics or compute".into(),
                ));
            }
            if size.max_px > device.point_size_max {
                return Err(Error::InvalidArgument(format!(
                    "footprints up to {:.0} px exceed the device's widest point sprite ({:.0} px): use --raster \
                     graphics or compute",
                    size.max_px, device.point_size_max
                )));
            }
            Ok(RasterChoice { raster: Raster::Points, reason: "requested".into() })
        }
        Raster::Compute if swept(opts) => Err(Error::InvalidArgument(
            "the compute rasters draw the seed's straight, uniform blur only (a bent or tapered footprint's \
             per-pixel loops would pass llvmpipe's loop budget): use --raster graphics"
                .into(),
        )),
        Raster::Graphics | Raster::Compute => Ok(RasterChoice { raster: opts.raster, reason: "requested".into() }),
        Raster::Auto if swept(opts) => Ok(RasterChoice {
            raster: Raster::Graphics,
            reason: "auto: a bent or tapered motion blur (graphics quads only)".into(),
        }),
        Raster::Auto if opts.motion.is_some() && opts.depth.is_some() => Ok(RasterChoice {
            raster: Raster::Graphics,
            reason: "auto: motion blur over the host's depth (graphics quads only)".into(),
        }),
        Raster::Auto => {
            let limit = match opts.composite {
                Composite::Splat => AUTO_COMPUTE_TILES_MAX_PX,
                Composite::Sheet | Composite::Slab => AUTO_COMPUTE_SUM_MAX_PX,
            };
            let px = size.typical_px;
            let points_fit =
                opts.motion.is_none() && size.max_px <= device.point_size_max && size.min_px >= AUTO_POINTS_MIN_PX;
            let sheets = opts.composite != Composite::Splat;
            // Point sprites: exact in orthographic views; in perspective as close to the truth as
            // the eye-facing quads (docs/MODEL.md, "Raster variants"), and the fastest per-splat
            // variant measured at every footprint size.
            let view = if camera.is_perspective() { "perspective" } else { "orthographic" };
            let (raster, why) = if !device.cpu {
                (Raster::Graphics, "hardware rasteriser".to_string())
            } else if px <= limit {
                let how = if sheets { "fixed-point sums" } else { "tile compositor" };
                (Raster::Compute, format!("CPU device, footprints ~{px:.1} px <= {limit:.0} px: {how}"))
            } else if points_fit {
                (
                    Raster::Points,
                    format!("CPU device, {view} view, footprints up to {:.0} px: point sprites", size.max_px),
                )
            } else {
                (Raster::Graphics, format!("CPU device, footprints ~{px:.1} px > {limit:.0} px"))
            };
            Ok(RasterChoice { raster, reason: format!("auto: {why}") })
        }
    }
}

pub use crate::plan::MAX_TILE_CELLS;
/// Most (tile, splat) entries in one frame (4 bytes each: 128 MiB, the one storage binding every
/// device allows, 2^27 bytes).
pub const MAX_TILE_ENTRIES: u64 = 1 << 25;

/// The count matrix's cells, checked before it is allocated.
pub fn check_tile_cells(tiles: u64, chunks: u32) -> Result<u64> {
    let cells = tiles * chunks as u64;
    if cells > MAX_TILE_CELLS {
        return Err(Error::TooLarge(format!(
            "{tiles} screen tiles x {chunks} splat chunks exceed {MAX_TILE_CELLS} binning cells: use a smaller \
             image or --raster graphics"
        )));
    }
    Ok(cells)
}

/// The tile lists' total length, checked before the list is allocated.
pub fn check_tile_entries(total: u64) -> Result<()> {
    if total > MAX_TILE_ENTRIES {
        return Err(Error::TooLarge(format!(
            "{total} (tile, splat) entries exceed {MAX_TILE_ENTRIES}: use a smaller image or --raster graphics"
        )));
    }
    Ok(())
}
