//! THE frame's plan: every per-frame decision that needs nothing from the device, made once by
//! [`frame`] from (scene, camera, options, the engine's limits). The recording
//! (`crate::recording`) reads only the plan and the counts the device reads back, so a plan can be
//! printed (`voxsplat render --plan`), tested and diffed without a device.
use super::bricked::BrickedPlan;
use super::pass::{sheet_pass, SheetPass, TileRule};
use super::{slab, Prepared};
use crate::builds::{Footprint, Pages, TileComposite, TileOrder};
use crate::camera::Camera;
use crate::dispatch::{Blend, Limits, List};
use crate::error::{Error, Result};
use crate::gpu_types::{Frame, SlabPush};
use crate::kernel::Kernel;
use crate::options::Raster;
use crate::options::{Composite, Mode, RenderOptions};
use crate::order::{Direction, OrderKind};
use std::fmt;

/// A frame's decisions.
#[derive(Clone, Debug)]
pub struct FramePlan {
    /// The uniforms every stage reads.
    pub frame: Frame,
    /// The camera (a host-computed order reads it).
    pub camera: Camera,
    /// The footprint kernel (its tables are uploaded when the frame begins).
    pub kernel: Kernel,
    /// The image's size.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// Visiting order.
    pub direction: Direction,
    /// The straight-alpha background the frame is presented over, if any.
    pub background: Option<[f32; 4]>,
    /// The host's depth, turned into eye-space depth (`host_depth`) when the frame begins
    /// (`frame.rect[3]` is then 1).
    pub depth: Option<DepthSource>,
    /// What the frame draws and how.
    pub draw: Draw,
}

/// How the frame draws.
#[derive(Clone, Debug)]
pub enum Draw {
    /// Per-splat compositing of a dense splat set.
    Splats {
        /// Splats in the scene.
        splats: u32,
        /// PBTF rows (the order stages' invocations).
        rows: u32,
        /// Where the draw order comes from.
        order: OrderSource,
        /// How the footprints reach the image.
        raster: SplatRaster,
    },
    /// Axis-aligned sheets: batches known before the frame.
    Sheets {
        /// Splats in the scene.
        splats: u32,
        /// The sheets' normal axis.
        axis: usize,
        /// The batches and how they are summed.
        pass: SheetPass,
    },
    /// Image-aligned slabs: the batches are cut once the binning's counts are read back.
    Slabs {
        /// Splats in the scene.
        splats: u32,
        /// Where the slabs lie (the binning's push constants).
        geometry: SlabPush,
        /// How the batches are summed (`batches` empty until the counts are back).
        pass: SheetPass,
    },
    /// A bricked volume: its splats made per frame, batch by batch through the budget.
    Bricked(Box<BrickedPlan>),
    /// The isosurface (`Mode::Iso`) of the scene's values (a dense set's or a bricked volume's):
    /// its surface splats made on the device each frame from the scene's field
    /// (`iso::IsoField`, uploaded once), blended by depth in the tile compositor, then lit.
    Surface {
        /// The isosurface stages' push constants: the value, its threshold, the rows of cells
        /// and the depth band.
        push: crate::gpu_types::IsoPush,
        /// The surface's colour (`Projection::mode` is `Mode::Iso`).
        projection: Projection,
    },
    /// An order-independent projection (`Mode`) of a dense splat set: no order stages, the
    /// footprints blended by maximum or sum in storage order, then mapped through the colour map.
    Projection {
        /// Splats in the scene.
        splats: u32,
        /// How the footprints reach the image (a tile rule whose walk is `Maximum` or `Sum`, or
        /// a `Footprint::Project` draw).
        raster: SplatRaster,
        /// The mode and its colours.
        projection: Projection,
    },
}

/// Where a frame's host depth comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum DepthSource {
    /// `RenderOptions::depth`: texels uploaded with the frame.
    Buffer(std::sync::Arc<crate::options::DepthBuffer>),
    /// The render target's depth image (`vk::HostTarget::with_depth`), copied on the device.
    Target(crate::options::DepthFormat, glam::Mat4),
}

/// A projection mode's last step (`project`): how the blended (key, weight) become colours.
#[derive(Clone, Debug, PartialEq)]
pub struct Projection {
    /// The mode.
    pub mode: Mode,
    /// The colour map, `COLOR_MAP_SIZE` straight RGBA entries.
    pub color_map: Vec<[f32; 4]>,
    /// The radial table's value at a footprint's centre (the average's unit weight).
    pub centre: f32,
    /// The isosurface's value (its colour's place in the map; 0 for the projections).
    pub iso: f32,
}

/// The isosurface's depth band, in voxel lengths: the discs within it of a pixel's visible depth
/// blend. Where two surfaces meet at a crease their discs' planes part by more than a voxel near
/// it (one voxel left holes along the creases of a cut ball; two close them, and cost the bonsai
/// 0.06 dB against the ray caster: 28.27 against 28.33 dB at 512², iso 60).
pub const ISO_BAND_VOXELS: f32 = 2.0;

/// The isosurface's colour where no colour map is given: bone.
pub const ISO_COLOR: [f32; 4] = [0.93, 0.87, 0.78, 1.0];

impl Projection {
    /// The projection `opts` asks for (`None`: compositing).
    pub fn of(opts: &RenderOptions) -> Option<Projection> {
        opts.mode.is_projection().then(|| Projection {
            mode: opts.mode,
            color_map: mode_color_map(opts.colormap.as_ref(), opts.mode),
            centre: opts.kernel.radial_table()[0],
            iso: opts.iso.unwrap_or(0.0),
        })
    }

    /// Its tile compositor walk and footprint draw build.
    pub fn builds(&self, points: bool) -> (TileOrder, Footprint) {
        let max = self.mode.takes_max();
        let blend = if max { Blend::Max } else { Blend::Add };
        (TileOrder::projection(max), Footprint::Project { blend, points })
    }
}

/// Where the per-splat draw order comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrderSource {
    /// The PBTF order stages on the engine.
    Pbtf,
    /// Computed on the host (the other orders) and uploaded.
    Host(OrderKind),
}

/// How per-splat footprints reach the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SplatRaster {
    /// The compute tile compositor.
    Tiles(TileRule),
    /// The footprint draw.
    Draw(Footprint),
}

/// THE plan of a frame: `prep` drawn from `camera` with `opts` (whose raster is already chosen)
/// on an engine with `limits`.
pub fn frame(prep: &Prepared, camera: &Camera, opts: &RenderOptions, limits: &Limits) -> Result<FramePlan> {
    camera.validate()?;
    let (width, height) = (camera.width, camera.height);
    let direction = opts.direction();
    let slotted = opts.slotted();
    // The host's depth: from the options (texels) or the engine's target (its depth image).
    let depth = match (&opts.depth, limits.target_depth) {
        (Some(_), Some(_)) => {
            return Err(Error::InvalidArgument(
                "a depth buffer in the options and a depth image on the target: give one".into(),
            ))
        }
        (Some(d), None) => {
            d.check(width, height)?;
            Some(DepthSource::Buffer(d.clone()))
        }
        (None, Some((format, projection))) => Some(DepthSource::Target(format, projection)),
        (None, None) => None,
    };
    if depth.is_some() {
        if opts.composite != Composite::Splat {
            return Err(Error::InvalidArgument(
                "the host's depth hides splats per pixel as they are composited: use --accumulate splat".into(),
            ));
        }
        if opts.motion.is_some() && opts.raster == Raster::Compute {
            return Err(Error::Unsupported(
                "the tile compositor draws still frames over the host's depth: use --raster graphics for motion blur"
                    .into(),
            ));
        }
    }
    let with_depth =
        |rule: TileRule| TileRule { composite: TileComposite { depth: depth.is_some(), ..rule.composite }, ..rule };
    let plan = |mut frame: Frame, draw| {
        frame.rect[3] = depth.is_some() as u32;
        FramePlan {
            frame,
            camera: *camera,
            kernel: opts.kernel,
            width,
            height,
            direction,
            background: opts.background,
            depth: depth.clone(),
            draw,
        }
    };
    if opts.mode == Mode::Iso {
        return surface(prep, camera, opts).map(|(frame, draw)| plan(frame, draw));
    }
    if let Some(scene) = &prep.bricks {
        if slotted {
            return Err(Error::Unsupported(
                "the slotted blur draws dense splat sets; a bricked volume takes splat:tapered".into(),
            ));
        }
        let (frame, mut bricked) = super::bricked::plan(prep, scene, camera, opts, limits)?;
        bricked.depth = depth.is_some();
        return Ok(plan(frame, Draw::Bricked(Box::new(bricked))));
    }
    let set = &prep.set;
    let mut frame = super::frame_for(set, camera, opts);
    let splats = set.len() as u32;
    if let Some(projection) = Projection::of(opts) {
        frame.rect[2] = opts.mode.code();
        let (walk, draw) = projection.builds(opts.raster == Raster::Points);
        let raster = if opts.raster == Raster::Compute {
            let mut rule = TileRule::plan(splats, width, height, Direction::FrontToBack, 0.0, false);
            rule.composite.order = walk;
            SplatRaster::Tiles(with_depth(rule))
        } else {
            SplatRaster::Draw(draw)
        };
        return Ok(plan(frame, Draw::Projection { splats, raster, projection }));
    }
    let draw = match opts.composite {
        Composite::Splat => {
            let order = if opts.order == OrderKind::Pbtf { OrderSource::Pbtf } else { OrderSource::Host(opts.order) };
            let raster = if opts.raster == Raster::Compute {
                let blur = opts.motion.is_some();
                let rule = TileRule::plan(splats, width, height, direction, opts.early_termination, blur);
                SplatRaster::Tiles(with_depth(rule))
            } else {
                let blend = if direction == Direction::BackToFront { Blend::Over } else { Blend::Under };
                let points = opts.raster == Raster::Points;
                SplatRaster::Draw(if slotted { Footprint::Slots(blend) } else { Footprint::Ordered { blend, points } })
            };
            Draw::Splats { splats, rows: (set.row_start().len() - 1) as u32, order, raster }
        }
        Composite::Sheet => {
            let mut pass = sheet_pass(opts, limits, List::Order, width, height);
            let (axis, batches) = super::sheet_plan(prep, camera, direction, pass.layers);
            pass.list = List::Slices(axis as u8);
            pass.batches = pass.terminated(batches);
            Draw::Sheets { splats, axis, pass }
        }
        Composite::Slab => {
            let geometry = slab::slab_geometry(&frame, set.grid(), set.len(), opts.slab_thickness, direction)?;
            Draw::Slabs { splats, geometry, pass: sheet_pass(opts, limits, List::SlabPairs, width, height) }
        }
    };
    Ok(plan(frame, draw))
}

/// The isosurface's frame and draw: its push constants from the iso value and the grid.
fn surface(prep: &Prepared, camera: &Camera, opts: &RenderOptions) -> Result<(Frame, Draw)> {
    let set = &prep.set;
    if set.coordinates().is_some() {
        return Err(Error::Unsupported(
            "--mode iso: isosurfaces are extracted on a uniform grid, not a rectilinear one".into(),
        ));
    }
    let iso = opts.iso.ok_or_else(|| Error::InvalidArgument("--mode iso needs an iso value (--iso VALUE)".into()))?;
    let mut frame = super::frame_for(set, camera, opts);
    frame.rect[2] = Mode::Iso.code();
    let dims = set.grid().dims;
    let push = crate::gpu_types::IsoPush {
        iso,
        threshold: crate::iso::threshold(iso),
        rows: (dims[1] + 1) * (dims[2] + 1),
        // One voxel length: the footprint's world radius over its radius in voxels.
        band: ISO_BAND_VOXELS * frame.spacing[3] / frame.origin[3],
        ..Default::default()
    };
    let projection = Projection::of(opts).ok_or_else(|| Error::InvalidArgument("--mode iso: no surface".into()))?;
    Ok((frame, Draw::Surface { push, projection }))
}

/// Mode `mode`'s colour map: `color_map`, or for the isosurface without one, bone.
pub fn mode_color_map(tf: Option<&crate::classify::TransferFunction>, mode: Mode) -> Vec<[f32; 4]> {
    match (tf, mode) {
        (None, Mode::Iso) => vec![ISO_COLOR; crate::constants::COLOR_MAP_SIZE as usize],
        (tf, _) => color_map(tf),
    }
}

/// A projection's colour map: `tf`'s colours at `COLOR_MAP_SIZE` values from 0 to 1 (opacity
/// unused), or a grey ramp.
pub fn color_map(tf: Option<&crate::classify::TransferFunction>) -> Vec<[f32; 4]> {
    let n = crate::constants::COLOR_MAP_SIZE;
    (0..n)
        .map(|i| {
            let v = i as f32 / (n - 1) as f32;
            match tf {
                Some(tf) => {
                    let c = tf.eval(v);
                    [c[0], c[1], c[2], 1.0]
                }
                None => [v, v, v, 1.0],
            }
        })
        .collect()
}

impl fmt::Display for FramePlan {
    /// A few lines: the draw, the order, the raster or sums, batches and layers; for a bricked
    /// volume its records, levels of detail and budget split.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "image      {}x{}, kernel {:?}, {:?}", self.width, self.height, self.kernel, self.direction)?;
        match &self.draw {
            Draw::Surface { push, .. } => {
                writeln!(
                    f,
                    "draw       the isosurface at {}: a disc per cell it crosses, made on the device each frame",
                    push.iso
                )?;
                writeln!(f, "order      none (the nearest disc per pixel, and those within {} of it)", push.band)?;
                writeln!(f, "raster     compute tiles, by depth")?;
            }
            Draw::Projection { splats, raster, projection } => {
                let mode = projection.mode;
                let blend = if mode.takes_max() { "the largest" } else { "summed" };
                writeln!(f, "draw       {splats} splats, {mode} projection: footprints {blend}, in any order")?;
                writeln!(f, "order      none (order-independent)")?;
                write_raster(f, raster)?;
            }
            Draw::Splats { splats, order, raster, .. } => {
                writeln!(f, "draw       {splats} splats, composited per splat")?;
                match order {
                    OrderSource::Pbtf => writeln!(f, "order      PBTF on the engine")?,
                    OrderSource::Host(k) => writeln!(f, "order      {k:?}, on the host")?,
                }
                write_raster(f, raster)?;
            }
            Draw::Sheets { splats, axis, pass } => {
                writeln!(f, "draw       {splats} splats in axis-aligned sheets along axis {axis}")?;
                write_pass(f, pass)?;
            }
            Draw::Slabs { splats, geometry, pass } => {
                writeln!(f, "draw       {splats} splats in {} image-aligned slabs", geometry.slabs)?;
                write_pass(f, pass)?;
            }
            Draw::Bricked(b) => write!(f, "{b}")?,
        }
        Ok(())
    }
}

fn write_raster(f: &mut fmt::Formatter<'_>, raster: &SplatRaster) -> fmt::Result {
    match raster {
        SplatRaster::Tiles(t) => {
            let walk = match t.composite.order {
                TileOrder::BackToFront => "back to front",
                TileOrder::FrontToBack => "front to back",
                TileOrder::Terminating => "front to back, ending opaque tiles",
                TileOrder::Maximum => "keeping the maximum",
                TileOrder::Sum => "summing",
                TileOrder::Surface | TileOrder::SurfaceDepth => "the visible surface's discs, in two passes",
            };
            let pages = if t.pages == Pages::One { "one page" } else { "two pages" };
            writeln!(
                f,
                "raster     compute tiles, {walk}; binned in {} chunks (at most {}); {pages} of splat records",
                t.push.chunks, t.most_chunks
            )
        }
        SplatRaster::Draw(b) => writeln!(f, "raster     footprint draw {b:?}"),
    }
}

fn write_pass(f: &mut fmt::Formatter<'_>, pass: &SheetPass) -> fmt::Result {
    let sums = if pass.compute {
        "compute fixed-point sums"
    } else if pass.points {
        "point-sprite sums"
    } else {
        "quad sums"
    };
    let batches = if pass.batches.is_empty() && pass.list == List::SlabPairs {
        "cut after the binning".to_string()
    } else {
        pass.batches.len().to_string()
    };
    writeln!(f, "sums       {sums}; up to {} layers a batch; batches {batches}", pass.layers)?;
    if pass.early_termination > 0.0 {
        writeln!(f, "terminate  tiles below {} transmittance", pass.early_termination)?;
    }
    Ok(())
}
