//! The research switches of `voxsplat-lab render` (`Research`), which `voxsplat render` takes at
//! their defaults.
use crate::open::parse_finite;
use clap::Args;

/// The switches of `voxsplat-lab render` that measure the renderer rather than set up a picture: the
/// reference and the k line, the engine's paths and budgets kept apart from the defaults.
#[derive(Args, Clone, Debug)]
#[command(next_help_heading = "Research")]
pub struct Research {
    /// Bricked volumes: also draw the bricks that nearer ones already hide (slower; pixels move by
    /// at most --early-termination; for measuring what dropping them saves).
    #[arg(long)]
    pub keep_hidden_bricks: bool,
    /// --mode mip or minip: draw every voxel, where by default each third of a pixel draws only
    /// the brightest voxel there (slower; the others add next to nothing).
    #[arg(long)]
    pub every_voxel: bool,
    /// Slab thickness in voxel spacings for `--accumulate slab` (at least 0.25) [default: 1].
    #[arg(long, value_parser = parse_finite)]
    pub slab_thickness: Option<f32>,
    /// Octaves of projected size (0 to 1) over which a brick's splats morph toward its next level
    /// before it takes over (0: abrupt level changes) [default: 0.75].
    #[arg(long, value_parser = parse_finite)]
    pub lod_band: Option<f32>,
    /// Levels of detail above the brick too: a block of bricks seen within a pixel drawn as one
    /// prefiltered splat (fewer splats for a large volume seen small; off by default: on this
    /// machine kind it pays only at thumbnail sizes).
    #[arg(long)]
    pub lod_nodes: bool,
    /// Draw the line where the first splat each pixel meets lies at eye distance k (Figs 3.6, 3.7).
    #[arg(long, conflicts_with = "plan")]
    pub k_line: bool,
    /// Order of drawing: front to back (the default, which lets early termination stop), or back to
    /// front (the default where per-splat footprints go through the graphics or point pipelines).
    #[arg(long, value_parser = ["ftb", "btf"])]
    pub direction: Option<String>,
    /// Memory budget for one batch of sheet summation layers (--accumulate sheet or slab), in MiB
    /// [default: 256].
    #[arg(long)]
    pub sheet_budget_mib: Option<u64>,
    /// Render the volumetric-summation truth (CPU, f64) with --kernel's reconstruction.
    // (The conflicts are declared here: `voxsplat render` has none of these flags for its own to
    // name; clap checks that every name exists.)
    #[arg(long, conflicts_with_all = ["raycast", "repeat", "plan"])]
    pub truth: bool,
    /// How footprints accumulate: composited per splat (the default), summed into Westover's
    /// axis-aligned sheet buffer, or into image-aligned sheets (slabs parallel to the image plane,
    /// Mueller & Crawfis 1998). (`--mode composite` is what a pixel shows; this is how.)
    #[arg(long, default_value = "splat", value_parser = ["splat", "sheet", "slab"], conflicts_with = "session")]
    pub accumulate: String,
    /// Front to back, stop drawing where what is drawn already lets at most this much light
    /// through (0 = off; the default, a quarter of an 8-bit step, changes a value by at most one
    /// step). No pixel changes by more than this.
    #[arg(long, value_parser = parse_finite, default_value_t = voxsplat::options::DEFAULT_EARLY_TERMINATION)]
    pub early_termination: f32,
    /// How footprints become pixels: instanced quads (graphics), point sprites (points), compute
    /// shaders (tile compositing / fixed-point sheet sums), or auto (on a CPU device: compute for
    /// small footprints, else point sprites where they fit, else graphics; graphics on hardware; it
    /// prints what it picked).
    #[arg(long, default_value = "auto", value_parser = ["graphics", "points", "compute", "auto"], conflicts_with = "session")]
    pub raster: String,
    /// Largest projected cell spacing of a coarse level, in pixels (above 0, at most 64).
    #[arg(long, value_parser = parse_finite, default_value_t = voxsplat::options::DEFAULT_LOD_PIXELS)]
    pub lod_pixels: f32,
    /// Largest error of a coarse level, 0 to 3: how far a cell's children depart from it, or its
    /// neighbours from its linear continuation, in the opacity a ray crossing a brick (8 voxels) sees
    /// (summed down the levels), times the share of a pixel a cell smaller than one covers, and up to
    /// 4 times more where the view runs along a grid axis. On translucent volumes about the largest
    /// change of a pixel (0.04: about 10 steps of 8 bits). 3: no bound; 0: only cells equal to their
    /// children coarsen.
    #[arg(long, value_parser = parse_finite, default_value_t = voxsplat::options::DEFAULT_LOD_ERROR)]
    pub lod_error: f32,
    /// Reconstruction kernel: the piecewise cubic fitted by Crawfis and Max's criterion (the
    /// default: radius 1.6, flat sheets stay flat to 0.37 %, closest to the ray-cast picture but for
    /// narrow), Westover's Gaussian (sigma 0.6, radius 2: softer), the Hermite cubic of Crawfis and
    /// Max's support (radius 1.6), or a narrow Gaussian (sigma 0.5, radius 1.5: sharpest and
    /// fewest fragments, but flat sheets ripple by 7.6 %).
    #[arg(long, default_value = "crawfis-max", value_parser = ["gaussian", "cubic", "narrow", "crawfis-max"], conflicts_with = "session")]
    pub kernel: String,
    /// With --raycast: cast K x K rays per pixel and average them (the converged reference that
    /// levels of detail and anti-aliasing are scored against; 4 with --raycast 0.25 is the one
    /// docs/MODEL.md checks).
    #[arg(long, default_value_t = 1, requires = "raycast")]
    pub supersample: u32,
    /// With --raycast: transmittance below which a ray stops.
    #[arg(long, value_parser = parse_finite, requires = "raycast")]
    pub raycast_stop: Option<f32>,
    /// Render the frame this many times and report each stage's median (the first frames pay
    /// one-off costs: allocation, shader compilation on some drivers).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..),
        conflicts_with_all = ["raycast", "plan"])]
    pub repeat: u32,
}

impl Default for Research {
    /// What `voxsplat render` draws with: each switch's default.
    fn default() -> Self {
        Self {
            keep_hidden_bricks: false,
            every_voxel: false,
            slab_thickness: None,
            lod_band: None,
            lod_nodes: false,
            k_line: false,
            direction: None,
            sheet_budget_mib: None,
            truth: false,
            accumulate: "splat".into(),
            early_termination: voxsplat::options::DEFAULT_EARLY_TERMINATION,
            raster: "auto".into(),
            lod_pixels: voxsplat::options::DEFAULT_LOD_PIXELS,
            lod_error: voxsplat::options::DEFAULT_LOD_ERROR,
            kernel: "crawfis-max".into(),
            supersample: 1,
            raycast_stop: None,
            repeat: 1,
        }
    }
}
