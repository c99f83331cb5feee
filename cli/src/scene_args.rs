//! The scene flags shared by the commands that draw (`render`, `pick`, `order`, `animate`'s series)
//! and the viewer example: what to open, the camera, the transfer function, and how to draw it.
use crate::parse::*;
use clap::Args;
use glam::Vec3;
use std::path::PathBuf;

#[derive(Args)]
pub struct SceneArgs {
    /// A saved session (`render --session`): its camera, transfer function and shading stand for
    /// the flags that would give them.
    #[arg(skip)]
    pub session: Option<crate::session::Session>,
    /// The research switches (`voxsplat-lab`); off under `voxsplat`.
    #[arg(skip)]
    pub research: SceneResearch,
    /// What `render` draws of the volume (lo, hi): --crop's box, or the part of an OME-Zarr image
    /// its one view sees; an OME-Zarr image reads only what it needs there.
    #[arg(skip)]
    pub crop: Option<[[f32; 3]; 2]>,
    /// `render`'s one view, when it sees only part of an OME-Zarr image: only the chunks it may
    /// see are read.
    #[arg(skip)]
    pub view_read: Option<voxsplat::Camera>,
    /// Told how far a volume file's read has got (the viewer's bar), besides the terminal's.
    #[arg(skip)]
    pub progress: Option<voxsplat::loaders::Progress>,
    /// Built-in scene name (see `voxsplat scenes`).
    #[arg(help_heading = "Scene and file", long, default_value = "cube60", conflicts_with_all = ["volume", "terrain", "labels"])]
    pub scene: String,
    /// Eye position (default: the --view's; patient RAS coordinates for a file with an anatomical
    /// frame, the grid's centred frame otherwise).
    #[arg(help_heading = "View", long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Look-at point (default: the centre of what the view frames; coordinates as --eye's).
    #[arg(help_heading = "View", long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Up vector (default: +y; superior for data with an anatomical frame).
    #[arg(help_heading = "View", long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees (perspective).
    #[arg(help_heading = "View", long, value_parser = parse_finite, conflicts_with = "ortho", allow_hyphen_values = true)]
    pub fov: Option<f32>,
    /// Orthographic projection with this view height (world units).
    #[arg(help_heading = "View", long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub ortho: Option<f32>,
    /// Near plane distance (default: fitted to the scene).
    #[arg(help_heading = "View", long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub near: Option<f32>,
    /// Far plane distance (default: fitted to the scene).
    #[arg(help_heading = "View", long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub far: Option<f32>,
    /// Image size.
    #[arg(help_heading = "View", long, value_parser = parse_size, default_value = "512x512")]
    pub size: (u32, u32),
    /// Preset view: auto (fly-over for terrain, VTK's camera for the peer scenes, the oblique
    /// anatomical view for data with an anatomical frame, framing otherwise), a three-quarter
    /// framing, a grazing view across a single-sheet scene (Fig. 3.6), a terrain fly-over
    /// (Figs 5.1-5.3), the peers' VTK camera, or an anatomical view of a volume whose file
    /// places it in patient space (NIfTI sform/qform, NRRD space), superior up: anterior,
    /// posterior, left, right, superior and inferior (anterior up), oblique (anterior, a little
    /// right and above). Volumes are framed on the voxels the transfer function shows.
    #[arg(help_heading = "View", long, default_value = "auto", value_parser = ["auto", "framing", "grazing", "flyover", "peer",
        "anterior", "posterior", "left", "right", "superior", "inferior", "oblique"])]
    pub view: String,
    /// Render a volume file (.nrrd/.nhdr, .nii/.nii.gz, .npy, a multipage .tif, a DICOM series (its
    /// folder or a file of it), an OME-Zarr image's folder, a folder of numbered PNG or TIFF slices,
    /// or raw with --dims and --dtype); a series of numbered files as a quoted pattern
    /// ('scan_*.nii.gz', one time point each).
    #[arg(help_heading = "Scene and file", long, conflicts_with = "terrain")]
    pub volume: Option<PathBuf>,
    /// Raw volume dimensions.
    #[arg(help_heading = "Scene and file", long, value_parser = parse_dims, requires = "volume")]
    pub dims: Option<[u32; 3]>,
    /// Raw sample type.
    #[arg(help_heading = "Scene and file", long, value_parser = ["u8", "i8", "u16", "i16", "u32", "i32", "f32", "f64"], requires = "volume")]
    pub dtype: Option<String>,
    /// Raw data is big-endian.
    #[arg(help_heading = "Scene and file", long, requires = "volume")]
    pub big_endian: bool,
    /// Voxel spacing (overrides the file's).
    #[arg(help_heading = "Scene and file", long, value_parser = parse_vec3, requires = "volume")]
    pub spacing: Option<Vec3>,
    /// A folder of several DICOM series: the one to read (its number in `voxsplat info DIR`'s
    /// list, or its Series Instance UID).
    #[arg(help_heading = "Scene and file", long)]
    pub series: Option<String>,
    /// An OME-Zarr image's pyramid level to draw (`voxsplat info` lists them), or `auto`: the
    /// coarsest whose voxels span at most 0.75 px in this view, which reads only that level's
    /// chunks but averages thin structures away (a preview). By default the finest the host's
    /// memory holds.
    #[arg(help_heading = "Scene and file", long, value_parser = parse_level, requires = "volume")]
    pub level: Option<String>,
    /// The time point of a series to draw: a 4-D NIfTI or NRRD, an OME-Zarr image, a DICOM series
    /// of several temporal positions, a pattern of numbered files (needed when it holds several;
    /// `voxsplat animate --volume` plays them all).
    #[arg(help_heading = "Scene and file", long, requires = "volume")]
    pub time: Option<u32>,
    /// A rectilinear grid's voxel positions: a TOML file whose x, y, z arrays give every voxel's
    /// world coordinate along that axis (e.g. irregular CT slices; an axis left out keeps the even
    /// spacing). Draws the volume as host splats.
    #[arg(help_heading = "Scene and file", long, requires = "volume")]
    pub positions: Option<PathBuf>,
    /// Transfer function for --volume: a preset (ramp, ct, bonsai, mri) or a TOML file [default:
    /// ramp].
    #[arg(help_heading = "Transfer function and mode", long)]
    pub tf: Option<String>,
    /// Phong shading with a headlight, applied to the voxels before splatting: `--shade` (or
    /// `--shade on`) lights the volume, `--shade off` leaves it unlit [default: on for the presets
    /// it measurably helps (bonsai), off otherwise].
    #[arg(help_heading = "Transfer function and mode", long, num_args = 0..=1, default_missing_value = "on",
        value_parser = ["on", "off"])]
    pub shade: Option<String>,
    /// A label volume (a segmentation: one whole number per voxel, u8, u16 or u32) coloured by
    /// --label-table, drawn alone or over the --volume on the same grid (the two added per voxel).
    /// Label 0 is the background; voxels whose label the table lacks are hidden and counted.
    #[arg(help_heading = "Scene and file", long, requires = "label_table", conflicts_with_all = ["terrain", "channels", "positions"])]
    pub labels: Option<PathBuf>,
    /// The label table, TOML: one [[label]] per label with value, color = [r, g, b], opacity and
    /// optionally visible = false (docs/guide/cli.md).
    #[arg(help_heading = "Scene and file", long, requires = "labels")]
    pub label_table: Option<PathBuf>,
    /// Another channel of the --volume (a scalar volume on its grid; up to 4 channels in all, a
    /// 4-D NIfTI --volume's own included), classified by its own --channel-tf and added per
    /// voxel: emission and extinction summed.
    #[arg(help_heading = "Scene and file", long = "channel", requires = "volume", conflicts_with = "positions")]
    pub channels: Vec<PathBuf>,
    /// The transfer function of each channel after the first (--tf's): a 4-D NIfTI --volume's
    /// further channels, then each --channel, in order (a preset or a TOML file).
    #[arg(help_heading = "Scene and file", long = "channel-tf", requires = "volume")]
    pub channel_tfs: Vec<String>,
    /// Render a height grid (16-bit PNG, GeoTIFF, or 2D .npy) as voxel columns.
    #[arg(help_heading = "Scene and file", long)]
    pub terrain: Option<PathBuf>,
    /// Colour image for --terrain (default: hypsometric ramp with hillshade).
    #[arg(help_heading = "Scene and file", long, requires = "terrain")]
    pub color: Option<PathBuf>,
    /// Vertical exaggeration for --terrain.
    #[arg(help_heading = "Scene and file", long, value_parser = parse_finite, default_value = "1")]
    pub vscale: f32,
    /// Horizontal cell size of --terrain, in height units (0: relief a sixth of the width).
    #[arg(help_heading = "Scene and file", long, value_parser = parse_finite, default_value = "0")]
    pub cell: f32,
    /// Render on the CPU instead of the Vulkan device: every GPU step has a CPU twin that computes
    /// the same picture to within rounding (slower; for a machine without Vulkan, or checking a
    /// device).
    #[arg(help_heading = "Quality and speed", long)]
    pub cpu: bool,
    /// Enable the Khronos validation layer and report its messages.
    #[arg(help_heading = "Output", long)]
    pub validation: bool,
    /// Device memory a frame may hold, in MiB: a bricked volume's splats stream through it in
    /// batches [default: 1024 on a CPU device such as lavapipe, half the GPU's memory on a GPU].
    #[arg(help_heading = "Quality and speed", long)]
    pub gpu_budget_mib: Option<u64>,
}

/// The scene switches of `voxsplat-lab render` and `order` that pick the engine's path rather than
/// the picture: the split between the device and the mirrors, the host's classification and the
/// visibility order.
#[derive(Args, Clone, Debug)]
#[command(next_help_heading = "Research")]
pub struct SceneResearch {
    /// Split each frame between Vulkan and the CPU mirrors at a stage, to find the stage that
    /// departs from its mirror: gpu-until:STAGE (the device runs the stages before STAGE, the
    /// mirrors the rest) or cpu-until:STAGE. Stages: see src/stages.rs.
    #[arg(long, conflicts_with = "cpu")]
    pub bisect: Option<voxsplat::low_level::Bisect>,
    /// Classify a --volume, or the peers' scene (--scene peer128, peer256), on the host into a
    /// splat set: needed by the other orders, --truth, --raycast and --k-line, which pick it
    /// themselves. Without it a volume is a bricked store classified on the device (levels of
    /// detail need it).
    #[arg(long)]
    pub dense: bool,
    /// Visibility order: PBTF (the default; the device orders a bricked volume), or one of the
    /// host's orders over a splat set: back to front, weighted BTF, sorted by depth, PBTF by octant.
    #[arg(long, default_value = "pbtf", value_parser = ["btf", "wbtf", "pbtf", "sorted", "pbtf-octant"])]
    pub order: String,
}

impl SceneArgs {
    /// `--shade`'s answer: lit, unlit, or the preset's default (`None`).
    pub fn shading(&self) -> Option<bool> {
        self.shade.as_deref().map(|s| s == "on")
    }
}

impl Default for SceneResearch {
    /// What `voxsplat` draws with: each switch's default.
    fn default() -> Self {
        Self { bisect: None, dense: false, order: "pbtf".into() }
    }
}
