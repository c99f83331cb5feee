//! Per-frame choices (`RenderOptions` and its enums) and what a frame returns.
//!
//! ```
//! use voxsplat::options::{Antialias, Composite, Mode};
//! use voxsplat::RenderOptions;
//! // A frame's options: sheet compositing with EWA anti-aliasing.
//! let mut options = RenderOptions::default();
//! options.composite = Composite::Sheet;
//! options.antialias = Antialias::Ewa;
//! options.validate()?;
//! // What cannot apply is refused, never ignored: maximum intensity needs no sheets.
//! options.mode = Mode::Mip;
//! assert!(options.validate().is_err());
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
use crate::kernel::Kernel;
use crate::order::{Direction, OrderKind};

mod depth;
mod mode;
mod stats;
pub use depth::{DepthBuffer, DepthFormat};
pub use mode::Mode;
pub use stats::{add_time, FrameStats, Rendered, StageTime};

/// How splats become pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Composite {
    /// Every footprint is composited (over / under) in visibility order.
    #[default]
    Splat,
    /// Westover's sheet summation buffer: splats summed per sheet, sheets composited in order.
    Sheet,
    /// Image-aligned sheet buffer (Mueller & Crawfis 1998): slabs parallel to the image plane, each
    /// splat's kernel sliced into the slabs it overlaps (`crate::slab`).
    Slab,
}

impl std::str::FromStr for Composite {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "splat" => Ok(Self::Splat),
            "sheet" => Ok(Self::Sheet),
            "slab" => Ok(Self::Slab),
            _ => Err(Error::InvalidArgument(format!("unknown compositing '{s}' (splat, sheet, slab)"))),
        }
    }
}

/// Anti-aliasing of distant splats (chapter 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Antialias {
    /// Footprints keep their world size at every distance.
    #[default]
    None,
    /// Swan's method: beyond k = s·D/p a splat's radius grows by d/k and its energy by (k/d)².
    Swan,
    /// EWA-style screen-space low-pass (Zwicker et al. 2001): the footprint convolved with a
    /// Gaussian of `EWA_LOWPASS_PX` pixels standard deviation, energy preserved.
    Ewa,
}

/// Standard deviation, in pixels, of the EWA low-pass filter: variance ½ px² (full width at half
/// maximum 1.7 px), about one pixel wide; with less, a distant footprint is point-sampled too
/// coarsely to keep its energy (0.5 px loses 1.7 % at d = 4k).
pub const EWA_LOWPASS_PX: f32 = std::f32::consts::FRAC_1_SQRT_2;

impl Antialias {
    /// The mode code `splat_params` reads (`Frame::aa[0]`).
    pub fn code(self) -> f32 {
        match self {
            Antialias::None => 0.0,
            Antialias::Swan => 1.0,
            Antialias::Ewa => 2.0,
        }
    }
}

impl std::str::FromStr for Antialias {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "none" => Ok(Self::None),
            "swan" => Ok(Self::Swan),
            "ewa" => Ok(Self::Ewa),
            _ => Err(Error::InvalidArgument(format!("unknown anti-aliasing '{s}' (none, swan, ewa)"))),
        }
    }
}

pub use crate::constants::{CLIP_SLOTS, MAX_CLIP_PLANES};
pub use crate::error::{host_budget, set_host_budget};

/// Clipping in world space: up to `MAX_CLIP_PLANES` half-spaces `n · x + d >= 0` and a box crop.
/// Splats whose centres lie outside any are not drawn (every splat mode, dense and bricked); the
/// ray caster cuts each ray to the part inside all of them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Clip {
    planes: [glam::Vec4; CLIP_SLOTS],
    count: u32,
}

impl Clip {
    /// `planes` as (n, d) with `n` any non-zero length (normalised here), and an optional crop
    /// box (min, max corners). Refused: more than `MAX_CLIP_PLANES` planes, a zero or non-finite
    /// normal, a non-finite offset, a box not finite or empty along an axis.
    pub fn new(planes: &[glam::Vec4], crop: Option<[glam::Vec3; 2]>) -> Result<Self> {
        if planes.len() > MAX_CLIP_PLANES {
            return Err(Error::InvalidArgument(format!(
                "{} clipping planes: at most {MAX_CLIP_PLANES} (and a box crop)",
                planes.len()
            )));
        }
        let mut clip = Self::default();
        for (i, p) in planes.iter().enumerate() {
            // The length in f64: a normal of 1e30 is a direction, though its f32 length overflows.
            let len = p.truncate().as_dvec3().length();
            if !(p.is_finite() && len > 0.0 && len.is_finite()) {
                return Err(Error::InvalidArgument(format!(
                    "clipping plane {i} ({}, {}, {}, {}): its normal must be finite and non-zero, its offset finite",
                    p.x, p.y, p.z, p.w
                )));
            }
            clip.push((p.as_dvec4() / len).as_vec4());
        }
        if let Some([lo, hi]) = crop {
            if !(lo.is_finite() && hi.is_finite()) || (0..3).any(|a| lo[a] >= hi[a]) {
                return Err(Error::InvalidArgument(format!(
                    "crop box {lo} to {hi}: its corners must be finite, the first below the second on every axis"
                )));
            }
            for a in 0..3 {
                let mut n = glam::Vec3::ZERO;
                n[a] = 1.0;
                clip.push(n.extend(-lo[a]));
                clip.push((-n).extend(hi[a]));
            }
        }
        Ok(clip)
    }

    fn push(&mut self, p: glam::Vec4) {
        self.planes[self.count as usize] = p;
        self.count += 1;
    }

    /// The planes in use (normalised).
    pub fn planes(&self) -> &[glam::Vec4] {
        &self.planes[..self.count as usize]
    }

    /// Whether world point `p` lies inside every plane.
    pub fn keeps(&self, p: glam::Vec3) -> bool {
        self.planes().iter().all(|q| q.truncate().dot(p) + q.w >= 0.0)
    }

    /// The planes as the GPU reads them (`Frame::clip`, `RaycastParams::clip`) and their count.
    pub fn uniforms(&self) -> ([[f32; 4]; CLIP_SLOTS], u32) {
        (self.planes.map(|p| p.to_array()), self.count)
    }
}

/// Motion blur of one frame (chapter 4): where every grid point was at the previous time step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Maps a grid point (the scene's own coordinates, as drawn this frame) to its position at
    /// t_{i-1} relative to the eye at t_i: `(V_i M_i)^-1 V_{i-1} M_{i-1}` for object transforms M and
    /// view transforms V.
    pub previous: glam::Mat4,
    /// Where every grid point was halfway through the shutter, mapped as `previous`: `Some` bends
    /// each path through it (a parabola, the seed's future work: a turn's arc is no chord), `None`
    /// keeps the seed's straight segment.
    pub middle: Option<glam::Mat4>,
    /// Splats whose projected path is at most this many pixels are drawn unblurred (delta).
    pub delta_px: f32,
    /// How the footprint's weight spreads along its path.
    pub profile: BlurProfile,
}

impl Motion {
    /// The seed's blur: a straight path, uniform weight.
    pub fn straight(previous: glam::Mat4, delta_px: f32) -> Self {
        Self { previous, middle: None, delta_px, profile: BlurProfile::Uniform }
    }
}

/// How a motion-blurred footprint's weight spreads along its path (chapter 4's future work).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BlurProfile {
    /// The seed's: the footprint swept along the path at uniform weight, energy scaled by Eq. 4.2.
    #[default]
    Uniform,
    /// The footprint averaged over the shutter (brightest mid-path, tapering to each end); per
    /// splat its alpha is averaged, as the accumulation buffer averages a lone splat's frames.
    Tapered,
    /// As `Tapered` with the time weighted towards t_i (2t): a clear head trailing off, the
    /// teardrop the seed suggests for stills that show movement.
    Teardrop,
    /// `Tapered` in two time slots: each fragment writes the first and the second half of the
    /// shutter to two images composited apart and averaged, so splats that cover a pixel in turn
    /// are not mixed as if independent (one geometry pass; per-splat compositing through graphics
    /// quads, dense splat sets).
    Slotted,
}

impl BlurProfile {
    /// The code `params.glsl` and the footprint stages read (`Frame::sweep[1]`, `SWEEP_*`).
    pub fn code(self) -> f32 {
        match self {
            BlurProfile::Uniform => 0.0,
            BlurProfile::Tapered => 1.0,
            BlurProfile::Teardrop => 2.0,
            BlurProfile::Slotted => 3.0,
        }
    }
}

impl std::str::FromStr for BlurProfile {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "uniform" => Ok(Self::Uniform),
            "tapered" => Ok(Self::Tapered),
            "teardrop" => Ok(Self::Teardrop),
            "slotted" => Ok(Self::Slotted),
            _ => {
                Err(Error::InvalidArgument(format!("unknown blur profile '{s}' (uniform, tapered, teardrop, slotted)")))
            }
        }
    }
}

/// Per-frame choices. `Default` gives what `voxsplat render` draws with no flags: PBTF, per-splat
/// back-to-front compositing, the Crawfis-Max kernel, levels of detail on.
///
/// ```
/// use voxsplat::{options::Composite, kernel::Kernel, options::Lod, RenderOptions};
/// // Westover's sheet buffer with the Gaussian kernel, over a dark background, no levels of detail.
/// let mut options = RenderOptions::default();
/// options.composite = Composite::Sheet;
/// options.kernel = Kernel::Gaussian;
/// options.background = Some([0.1, 0.1, 0.1, 1.0]);
/// options.lod = Lod::Off;
/// options.validate()?;
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RenderOptions {
    /// What the frame shows: compositing (the default) or an order-independent projection.
    pub mode: Mode,
    /// The projection modes' colour map: the values 0 to 1 mapped to this transfer function's
    /// colours (its opacities are not used); `None`: a grey ramp. Compositing ignores it (its
    /// colours come from the classification).
    pub colormap: Option<crate::classify::TransferFunction>,
    /// `Mode::Iso`'s value, in the scene's normalised values [0, 1] (required there, refused
    /// with the other modes). A value the volume never crosses draws nothing
    /// (`Rendered::stats.splats` is 0).
    pub iso: Option<f32>,
    /// The host's depth buffer: splats behind its geometry add nothing to a pixel (`None`: no
    /// depth). `Renderer::render_to` can read the host's depth image on the device instead
    /// (`vk::HostTarget::with_depth`).
    pub depth: Option<std::sync::Arc<DepthBuffer>>,
    /// The visibility order.
    pub order: OrderKind,
    /// Per-splat compositing or sheet buffers.
    pub composite: Composite,
    /// The reconstruction kernel.
    pub kernel: Kernel,
    /// Anti-aliasing of distant splats.
    pub antialias: Antialias,
    /// Motion-blurred splats (chapter 4); `None` draws the frame still.
    pub motion: Option<Motion>,
    /// Clipping planes and a crop box (none by default).
    pub clip: Clip,
    /// `None`: back to front for per-splat compositing, front to back for sheets.
    pub direction: Option<Direction>,
    /// Memory allowed for one batch of sheet summation layers (RGBA32F each).
    pub sheet_budget_bytes: u64,
    /// Image-aligned slab thickness in voxel spacings (`Composite::Slab`): thinner is closer to the
    /// volume integral and costs more primitives (about 2R/Δ + 1 per splat).
    pub slab_thickness: f32,
    /// Front-to-back early termination (Mueller et al. 1999): the compute tile compositor
    /// (`Raster::Compute` with `Composite::Splat`) stops each pixel at this transmittance, a
    /// bricked volume drops the bricks that earlier batches already hide, and the sheet modes
    /// skip, after each batch, footprints lying wholly over composite tiles this transparent. No
    /// pixel changes by more than this much. Default `DEFAULT_EARLY_TERMINATION` (a quarter of an
    /// 8-bit step: a value changes by at most one step, in under 0.1 % of the bonsai's; docs/RESULTS.md);
    /// 0 turns it off; back to front ignores it.
    pub early_termination: f32,
    /// Bricked volumes, front to back with early termination on the tile compositor: cut the
    /// frame into several batches and drop, before each later batch, the bricks the image so far
    /// already hides (the same frame; on by default, off to measure what it saves).
    pub cull_hidden_bricks: bool,
    /// MIP and MinIP of a bricked volume: draw every voxel, where by default each third of a
    /// pixel draws only the brightest voxel whose centre falls in it (the rest, that close to a
    /// brighter one, add next to nothing: `FrameStats::splats_outshone` counts them). Slower;
    /// refused in the other modes.
    pub every_voxel: bool,
    /// How the footprint stage rasterises (`crate::raster`); `Auto` picks per device and footprint
    /// size, and `Rendered::raster` says what it picked.
    pub raster: Raster,
    /// Draw the frame on a grid this fraction of the camera's size and resample it bilinearly to
    /// full size (`crate::resample`; a ray caster's image sample distance is its inverse). Pays
    /// where voxels cover several pixels and the kernel already blurs finer than the grid; the
    /// error it adds is measured against the full-size truth. 1 (the default) draws full size.
    pub render_scale: f32,
    /// Levels of detail of a bricked volume drawn per splat: `Auto` (the default) draws each
    /// brick at the coarsest level of its prefiltered pyramid whose cells project to at most
    /// `lod_pixels` pixels and whose error is at most `lod_error` (docs/MODEL.md): full detail
    /// wherever voxels project to a pixel or more, fewer splats where they are smaller. Sheet and
    /// slab modes and classified splat sets draw full detail.
    pub lod: Lod,
    /// Largest projected cell spacing, in pixels, of a coarse level (at the brick's nearest point).
    pub lod_pixels: f32,
    /// Largest error of a coarse level: how far a cell's children depart from it, or its face
    /// neighbours from its linear continuation, in the opacity a ray through a brick (8 voxels) sees
    /// or colour weighted by it, down the levels, times the cell's share of a pixel and up to 4 near an axis.
    pub lod_error: f32,
    /// Levels of detail: over the last `lod_band` octaves (0 to 1) before a brick's next level
    /// takes over, its splats move and widen toward that level's cells (geomorphing), so a level
    /// change is continuous in time and across brick faces. 0: abrupt changes.
    pub lod_band: f32,
    /// Levels of detail above the brick (off by default): a node of 2^k bricks a side whose one
    /// prefiltered cell projects to at most a pixel is drawn as that one splat (docs/MODEL.md).
    /// Measured on lavapipe it halves the splats of a 1024³ volume at 32², but the cut over the
    /// nodes costs about what it saves from 64² up (docs/log/2026-11-28-thumbnails-and-nodes.md).
    pub lod_nodes: bool,
    /// Composite the frame over this straight RGBA colour on the device (`present.comp`) before it
    /// is read back or written into a host image; alpha 1 gives an opaque frame, as a window shows
    /// it. `None` (the default) leaves the premultiplied frame as drawn: transparent where empty.
    pub background: Option<[f32; 4]>,
}

/// Levels of detail (`RenderOptions::lod`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Lod {
    /// Every voxel is a splat.
    Off,
    /// Each brick of a bricked store drawn per splat at the coarsest level its projection and
    /// error allow (the default). A classified splat set, and the sheet and slab modes, have no
    /// levels: they draw every splat (the CLI refuses `--lod auto` there).
    #[default]
    Auto,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            mode: Mode::Composite,
            colormap: None,
            iso: None,
            depth: None,
            order: OrderKind::Pbtf,
            composite: Composite::Splat,
            // The kernel's own default (Crawfis-Max): two literals had drifted apart.
            kernel: Kernel::default(),
            antialias: Antialias::None,
            motion: None,
            clip: Clip::default(),
            direction: None,
            sheet_budget_bytes: 256 << 20,
            slab_thickness: 1.0,
            early_termination: DEFAULT_EARLY_TERMINATION,
            cull_hidden_bricks: true,
            every_voxel: false,
            raster: Raster::Auto,
            render_scale: 1.0,
            lod: Lod::Auto,
            lod_pixels: DEFAULT_LOD_PIXELS,
            lod_error: DEFAULT_LOD_ERROR,
            lod_band: 0.75,
            lod_nodes: false,
            background: None,
        }
    }
}

/// Default `RenderOptions::lod_pixels`: against the supersampled reference (docs/MODEL.md), at
/// 512² from the default view, the 512³ bonsai's frame cost 0.43x the 1-px cut's at 44.35 dB
/// (1 px: 44.56 dB; its level-1 cells project to 0.8-1.5 px, so at 1 px almost none coarsens), and
/// the 256³ gallery files stayed at or above 42.2 dB (2026-11-28, over the whole frame; over the
/// covered pixels the gallery's default frames score 33.5-43.4 dB: docs/RESULTS.md).
pub const DEFAULT_LOD_PIXELS: f32 = 1.5;

/// Default `RenderOptions::lod_error` (0 to `MAX_LOD_ERROR`): `scripts/family.py`'s family lies
/// within 1 dB of full detail at 0.04, the 1024³ field drawn in 0.64x its time (docs/RESULTS.md).
pub const DEFAULT_LOD_ERROR: f32 = 0.04;

/// Largest `RenderOptions::lod_pixels`: a wider coarse cell is a blur, not a level of detail.
pub const MAX_LOD_PIXELS: f32 = 64.0;

/// Largest `RenderOptions::lod_error`: no bound (an error sums a departure of at most 1 a level).
pub const MAX_LOD_ERROR: f32 = 3.0;

/// Default transmittance threshold of front-to-back early termination: a quarter of an 8-bit step.
pub const DEFAULT_EARLY_TERMINATION: f32 = 1.0 / 1024.0;

/// Most summation layers in one batch when front-to-back early termination is on.
pub const EARLY_TERMINATION_BATCH: u32 = 8;

/// Most summation layers in one batch, whatever the budget.
pub const MAX_BATCH_LAYERS: u32 = 256;

impl RenderOptions {
    /// The visiting direction: as set, else back to front for per-splat compositing through the
    /// graphics pipeline (the over operator needs no destination alpha) and front to back
    /// otherwise (sheets, and the compute tile compositor, which can then stop early).
    pub fn direction(&self) -> Direction {
        self.direction.unwrap_or(match (self.composite, self.raster) {
            (Composite::Splat, Raster::Compute) => Direction::FrontToBack,
            (Composite::Splat, _) => Direction::BackToFront,
            (Composite::Sheet | Composite::Slab, _) => Direction::FrontToBack,
        })
    }

    /// Whether the frame blurs with two time slots (`BlurProfile::Slotted`).
    pub(crate) fn slotted(&self) -> bool {
        self.motion.is_some_and(|m| m.profile == BlurProfile::Slotted)
    }

    /// Reject values no frame can use.
    pub fn validate(&self) -> Result<()> {
        if self.mode.is_projection() {
            let refuse = |what: &str| {
                Err(Error::InvalidArgument(format!(
                    "--mode {}: {what}; the projection modes are order-independent splats (--accumulate splat, \
                     no order, direction or motion blur)",
                    self.mode
                )))
            };
            if self.composite != Composite::Splat {
                return refuse("sheets and slabs composite in visibility order");
            }
            if self.order != OrderKind::Pbtf || self.direction.is_some() {
                return refuse("a projection draws no visibility order");
            }
            if self.motion.is_some() {
                return refuse("motion-blurred splats are composited in order");
            }
        }
        if self.every_voxel && !matches!(self.mode, Mode::Mip | Mode::Minip) {
            return Err(Error::InvalidArgument(format!(
                "--every-voxel: --mode {} draws every voxel already; only MIP and MinIP draw the brightest voxel of                  each texel",
                self.mode
            )));
        }
        check_iso(self.mode, self.iso)?;
        if self.mode == Mode::Iso && matches!(self.raster, Raster::Graphics | Raster::Points) {
            return Err(Error::InvalidArgument(
                "--mode iso: surface splats blend by depth in the compute tile compositor: use --raster compute or \
                 auto"
                    .into(),
            ));
        }
        if let Some(tf) = &self.colormap {
            tf.validate()?;
        }
        if self.depth.is_some() && self.render_scale != 1.0 {
            return Err(Error::InvalidArgument(
                "the host's depth buffer is read pixel for pixel: draw at render scale 1".into(),
            ));
        }
        if self.depth.is_some() && self.composite != Composite::Splat {
            return Err(Error::InvalidArgument(
                "the host's depth buffer hides splats per pixel as they are composited: use --accumulate splat".into(),
            ));
        }
        if self.slotted() && self.composite != Composite::Splat {
            return Err(Error::InvalidArgument(
                "the slotted blur composites each half of the shutter per splat: use --accumulate splat".into(),
            ));
        }
        if !(0.0..1.0).contains(&self.early_termination) {
            return Err(Error::InvalidArgument(format!(
                "early-termination transmittance {} must be in [0, 1)",
                self.early_termination
            )));
        }
        if !(self.lod_pixels > 0.0 && self.lod_pixels <= MAX_LOD_PIXELS) {
            return Err(Error::InvalidArgument(format!(
                "the level-of-detail pixel size {} must be above 0 and at most {MAX_LOD_PIXELS} (--lod off: full detail)",
                self.lod_pixels
            )));
        }
        if !(0.0..=MAX_LOD_ERROR).contains(&self.lod_error) {
            return Err(Error::InvalidArgument(format!(
                "the level-of-detail error {} must be in [0, {MAX_LOD_ERROR}] (0: exact cells only; 3: no bound)",
                self.lod_error
            )));
        }
        if !(0.0..=1.0).contains(&self.lod_band) {
            return Err(Error::InvalidArgument(format!(
                "the level-of-detail band {} must be in [0, 1]",
                self.lod_band
            )));
        }
        if self.lod_nodes && self.lod != Lod::Auto {
            return Err(Error::InvalidArgument(
                "levels of detail above the brick (lod_nodes) are part of the level-of-detail cut: it needs lod = Auto"
                    .into(),
            ));
        }
        if let Some(bg) = self.background {
            if !bg.iter().all(|c| (0.0..=1.0).contains(c)) {
                return Err(Error::InvalidArgument(format!("background {bg:?}: each channel must be in [0, 1]")));
            }
        }
        if self.sheet_budget_bytes == 0 {
            return Err(Error::InvalidArgument("the sheet budget must be positive".into()));
        }
        check_scale(self.render_scale)
    }

    /// Layers per batch for an image of this size. With early termination on, batches hold at most
    /// `EARLY_TERMINATION_BATCH` layers: the occlusion map only changes between batches.
    pub fn batch_layers(&self, width: u32, height: u32) -> u32 {
        let layer = width as u64 * height as u64 * 16;
        let most = if self.direction() == Direction::FrontToBack && self.early_termination > 0.0 {
            EARLY_TERMINATION_BATCH
        } else {
            MAX_BATCH_LAYERS
        };
        (self.sheet_budget_bytes / layer.max(1)).clamp(1, most as u64) as u32
    }
}

/// Ray caster settings.
#[derive(Clone, Debug, PartialEq)]
pub struct RaycastOptions {
    /// What the rays gather: compositing (the default) or a projection mode, over the trilinear
    /// reconstruction of the classified voxels' values (`Mode`): the splats' reference.
    pub mode: Mode,
    /// A projection's colour map, as `RenderOptions::colormap`.
    pub colormap: Option<crate::classify::TransferFunction>,
    /// `Mode::Iso`'s value, as `RenderOptions::iso`: the first crossing along each ray, refined
    /// between its two samples, shaded as the surface splats are.
    pub iso: Option<f32>,
    /// Step length in voxel spacings.
    pub step: f32,
    /// Transmittance below which a ray stops.
    pub min_transmittance: f32,
    /// Most samples per ray.
    pub max_steps: u32,
    /// Empty-space skipping over bricks of this many voxels per side (0: off). Exact: only samples
    /// that read nothing but empty voxels are skipped.
    pub brick: u32,
    /// Cast on a grid this fraction of the camera's size and resample (`crate::resample`; the
    /// inverse of an image sample distance). 1: full size.
    pub render_scale: f32,
    /// Clipping planes and crop box: each ray is cut to the part inside them.
    pub clip: crate::options::Clip,
    /// Rays per pixel along each axis (1 to `MAX_SUPERSAMPLE`): `k`×`k` rays on a regular grid
    /// inside each pixel, averaged (a box filter over the pixel's area). The converged reference
    /// that levels of detail and anti-aliasing are scored against (docs/MODEL.md, "The reference").
    pub supersample: u32,
}

/// `iso` is given exactly when `mode` is `Mode::Iso`, and is a finite value.
pub(crate) fn check_iso(mode: Mode, iso: Option<f32>) -> Result<()> {
    match (mode, iso) {
        (Mode::Iso, None) => Err(Error::InvalidArgument("--mode iso needs an iso value (--iso VALUE)".into())),
        (Mode::Iso, Some(v)) if !v.is_finite() => {
            Err(Error::InvalidArgument(format!("iso value {v}: not a finite number")))
        }
        (m, Some(_)) if m != Mode::Iso => {
            Err(Error::InvalidArgument(format!("an iso value applies to --mode iso only, not --mode {m}")))
        }
        _ => Ok(()),
    }
}

/// Most rays per pixel along each axis of a supersampled cast.
pub const MAX_SUPERSAMPLE: u32 = 16;

/// Default brick side of the empty-space skipping.
pub const DEFAULT_BRICK: u32 = 8;

impl Default for RaycastOptions {
    fn default() -> Self {
        Self {
            mode: Mode::Composite,
            colormap: None,
            iso: None,
            step: 0.5,
            min_transmittance: 1e-3,
            max_steps: 1 << 16,
            brick: DEFAULT_BRICK,
            render_scale: 1.0,
            clip: Default::default(),
            supersample: 1,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
/// How the footprint stage turns splats into pixels.
pub enum Raster {
    /// Instanced quads through the graphics pipeline.
    Graphics,
    /// Point sprites through the graphics pipeline (no motion blur).
    Points,
    /// Compute shaders: tile binning (per-splat) or fixed-point sums (sheets).
    Compute,
    /// Pick per device and footprint size (`choose`).
    #[default]
    Auto,
}

impl Raster {
    /// The name the CLI and the reports use.
    pub fn name(self) -> &'static str {
        match self {
            Raster::Graphics => "graphics",
            Raster::Points => "points",
            Raster::Compute => "compute",
            Raster::Auto => "auto",
        }
    }
}

impl std::str::FromStr for Lod {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "off" => Ok(Self::Off),
            "auto" => Ok(Self::Auto),
            _ => Err(Error::InvalidArgument(format!("unknown level-of-detail mode '{s}' (off, auto)"))),
        }
    }
}

impl std::str::FromStr for Raster {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "graphics" => Ok(Self::Graphics),
            "points" => Ok(Self::Points),
            "compute" => Ok(Self::Compute),
            "auto" => Ok(Self::Auto),
            _ => Err(Error::InvalidArgument(format!("unknown raster '{s}' (graphics, points, compute, auto)"))),
        }
    }
}

impl std::fmt::Display for Raster {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The variant a frame was drawn with and why.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterChoice {
    /// The variant drawn.
    pub raster: Raster,
    /// Why (`auto`'s rule, or "requested").
    pub reason: String,
}

/// Smallest render scale accepted: below it a 512-px view would have fewer than 32 rows.
pub const MIN_RENDER_SCALE: f32 = 1.0 / 16.0;

/// Check a render scale: finite, in [`MIN_RENDER_SCALE`], 1].
pub fn check_scale(scale: f32) -> Result<()> {
    if scale.is_finite() && (MIN_RENDER_SCALE..=1.0).contains(&scale) {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!("render scale {scale} must be in [{MIN_RENDER_SCALE}, 1]")))
    }
}

/// What a frame drawn into a host's image (`Renderer::render_to`) reports.
#[derive(Clone, Debug)]
pub struct Delivered {
    /// Per-stage times, as `Rendered::timings`.
    pub timings: Vec<StageTime>,
    /// What `Raster::Auto` picked.
    pub raster: RasterChoice,
    /// What a bricked volume's frame drew and culled, as `Rendered::stats`.
    pub stats: FrameStats,
}
