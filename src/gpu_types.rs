//! `#[repr(C)]` mirrors of the structs in `glsl/shared/types.glsl`. Keep in sync with that header;
//! the size asserts catch drift.
// Each field's meaning is documented once, beside its GLSL twin in glsl/shared/types.glsl.
#![allow(missing_docs)]
use bytemuck::{Pod, Zeroable};

/// One extracted (non-empty) voxel.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Splat {
    /// Grid index i, j, k; the fourth lane: the voxel's value in [0, 1], as `f32` bits (what the
    /// projection modes take: a classified volume's normalised density, else the opacity).
    pub ijk: [u32; 4],
    /// Straight RGB and the opacity of one voxel-length of material.
    pub color: [f32; 4],
}

/// Output of `splat_params`, input of `footprint`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SplatParams {
    /// World centre; w = 1 if drawn, 0 if culled.
    pub center: [f32; 4],
    /// Half-extent vector of the quad; w = energy scale.
    pub axis_u: [f32; 4],
    /// Second half-extent vector; w = motion stretch (half blur length / radius).
    pub axis_v: [f32; 4],
    /// RGB colour; a = optical depth of the voxel (tau).
    pub emit: [f32; 4],
    /// Eye-space depth z_e; the motion path's bend (its middle's offset across the chord along
    /// `axis_v`, radius units; 0 = straight); footprint radius in pixels; anti-aliasing radius scale.
    pub screen: [f32; 4],
}

/// A footprint in screen space (`screen_quads` writes one per splat for the tile stages).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ScreenQuad {
    /// Rows of the inverse projective map, pixel centre -> homogeneous quad coordinates;
    /// `inv[0][3]` is the motion stretch, `inv[1][3]` the motion bend, `inv[2][3]` the splat's
    /// eye-space depth.
    pub inv: [[f32; 4]; 3],
    /// Inclusive pixel box x0, y0, x1, y1 (empty when culled: x0 > x1).
    pub bx: [i32; 4],
    /// RGB; a: optical depth scale (tau x energy).
    pub emit: [f32; 4],
}

/// Per-frame uniforms (std140, vec4 members only).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Frame {
    /// World to clip space.
    pub view_proj: [[f32; 4]; 4],
    /// The eye; w: 1 for a perspective camera.
    pub eye: [f32; 4],
    /// The view direction; w: near plane.
    pub forward: [f32; 4],
    /// The camera's right; w: far plane.
    pub right: [f32; 4],
    /// The camera's true up; w: pixels per world unit at unit depth.
    pub up: [f32; 4],
    /// The grid's origin; w: the kernel's radius in voxels.
    pub origin: [f32; 4],
    /// The grid's spacing; w: the kernel's world radius.
    pub spacing: [f32; 4],
    /// The cell matrix above its diagonal (`Grid::shear`); w: the length a splat's opacity is per
    /// (`SplatSet::opacity_length`).
    pub shear: [f32; 4],
    /// The grid's dims; w: splats.
    pub dims: [u32; 4],
    /// The PBTF split per axis; w: 1 back to front.
    pub split: [u32; 4],
    /// Anti-aliasing: mode (0 none, 1 Swan, 2 EWA), footprint std in voxels, EWA low-pass std in pixels.
    pub aa: [f32; 4],
    /// Grid point -> its position at t_{i-1} relative to the eye at t_i (identity when still).
    pub motion: [[f32; 4]; 4],
    /// Motion blur: delta in pixels (0 = off), G (across-line integral over area), image width, height.
    pub blur: [f32; 4],
    /// Arc paths: grid point -> where it was halfway through the shutter.
    pub motion_mid: [[f32; 4]; 4],
    /// Motion blur: 1 = arc path (0 = straight), the profile's code (`BlurProfile::code`), unused, unused.
    pub sweep: [f32; 4],
    /// x: 1 = a rectilinear grid (voxel positions from the `Coords` buffer); y: clipping planes
    /// in use (`clip`); z: the projection mode (`Mode::code`, 0: compositing); w: 1 = the host's
    /// depth buffer hides what lies behind it (`Res::HostDepth`).
    pub rect: [u32; 4],
    /// Clipping planes (n, d): a splat is drawn where n · centre + d >= 0 for every one in use.
    pub clip: [[f32; 4]; crate::constants::CLIP_SLOTS],
}

/// Uniforms of `raycast.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RaycastParams {
    /// Clip to world space.
    pub inv_view_proj: [[f32; 4]; 4],
    /// The volume's box in voxel coordinates, low corner; w: the step in world units.
    pub box_min: [f32; 4],
    /// Its high corner; w: the transmittance below which a ray stops.
    pub box_max: [f32; 4],
    /// The grid's origin; w: 1 / the kernel spacing.
    pub origin: [f32; 4],
    /// 1 / the grid's spacing; w: the projection mode (`Mode::code`, 0: compositing).
    pub inv_spacing: [f32; 4],
    /// The inverse cell matrix above its diagonal (a sheared grid's; zero when axis-aligned).
    pub inv_shear: [f32; 4],
    /// The grid's dims; w: most steps per ray.
    pub dims: [u32; 4],
    /// Width, height, empty-space brick side, clipping planes in use.
    pub image: [u32; 4],
    /// Clipping planes (n, d): each ray is cut to where n · x + d >= 0 for every one in use.
    pub clip: [[f32; 4]; crate::constants::CLIP_SLOTS],
}

/// Push constants of the footprint stage in every raster variant (`footprint.vert` / `.frag`,
/// `footprint_sum.comp`, `tile_*.comp`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FootprintPush {
    /// `SHEET_MODE_*`.
    pub sheet_mode: u32,
    pub axis: u32,
    pub rank_offset: u32,
    /// Sheet modes: the batch's first sheet.
    pub rank_base: u32,
    pub rank_dir: i32,
    pub slab_z0: f32,
    pub slab_dz: f32,
    /// Early termination: skip footprints over tiles with at most this transmittance (0 = off);
    /// the tile compositor stops a pixel once its transmittance is at most this.
    pub occluded: f32,
    /// Compute raster: first draw-list entry of the batch and the entry count. Tile compositing:
    /// `first` is the segment (entries `first * TILE_SEGMENT..` of every tile's list).
    pub first: u32,
    pub count: u32,
    /// Tile binning: chunks of the draw list (columns of the tile x chunk count matrix), each
    /// `ceil(count / chunks)` entries.
    pub chunks: u32,
    /// Tile compositing: 1 = the list runs back to front (over), 0 = front to back (under).
    pub back_to_front: u32,
    /// 1: carry on from what an earlier part drew (a bricked volume's later batch: the target,
    /// the tile compositor's image, or a sheet batch's layers), 0: start from cleared images.
    pub carry: u32,
}

/// `sheet_mode` values (glsl/shared/types.glsl).
pub const SHEET_MODE_SPLAT: u32 = 0;
pub const SHEET_MODE_AXIS: u32 = 1;
pub const SHEET_MODE_SLAB: u32 = 2;
/// Axis-aligned sheets whose draw list holds (splat, sheet) pairs binned on the device (a bricked
/// volume's splats have no host-side slice lists).
pub const SHEET_MODE_BINNED: u32 = 3;

/// Push constants of the slab binning stages (`glsl/shared/slab.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SlabPush {
    pub z0: f32,
    pub dz: f32,
    pub slabs: u32,
    pub chunks: u32,
    pub ftb: u32,
    pub n: u32,
    /// `AXIS_SHEETS` builds: the sheet axis (the slabs are the grid's voxel planes along it).
    pub axis: u32,
    pub pad: u32,
}

/// Push constants of `present.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PresentPush {
    /// The background, premultiplied (zero: none).
    pub background: [f32; 4],
    pub width: u32,
    pub height: u32,
    /// Bit 0: the accumulation image, bit 1: the raster target; both: their mean (slotted blur).
    /// `PRESENT_OVER` and the host image's `PRESENT_HOST_*` bits: over the host's image.
    pub sources: u32,
    /// 1: write linear values, for a target that encodes them itself (sRGB, float).
    pub linear: u32,
}

/// `PresentPush::sources`: the frame goes over the host's image (`Res::HostColor`), whose texels
/// are 8-bit RGBA unless `PRESENT_HOST_BGRA` (8-bit BGRA) or `PRESENT_HOST_HALF` (16-bit float)
/// (glsl/shared/types.glsl).
pub const PRESENT_OVER: u32 = 4;
pub const PRESENT_HOST_BGRA: u32 = 8;
pub const PRESENT_HOST_HALF: u32 = 16;

/// Push constants of `host_depth.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DepthPush {
    /// The host's projection inverted: its clip space to its eye space.
    pub inv_proj: [[f32; 4]; 4],
    pub width: u32,
    pub height: u32,
    /// `DepthFormat::code`: 0 D32 float, 1 D24 unorm (the low 24 bits of each word).
    pub format: u32,
    pub pad: u32,
}

/// Push constants of `project.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ProjectPush {
    /// `Mode::code` (`PROJECT_*`).
    pub mode: u32,
    pub width: u32,
    pub height: u32,
    /// 1: the accumulation image (the tile compositor), 2: the raster target (the footprint draw).
    pub source: u32,
    /// The radial table's value at a footprint's centre.
    pub centre: f32,
    /// `Mode::Iso`: the iso value (its colour is the colour map's there).
    pub iso: f32,
    pub pad: [u32; 2],
}

/// Push constants of the isosurface stages (`iso_count`, `iso_scan`, `iso_splats`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct IsoPush {
    /// The iso value, normalised to [0, 1].
    pub iso: f32,
    /// The least quantised value (`IsoField`, 16 bits) at or above it: a corner is inside the
    /// surface when its value is at least this.
    pub threshold: u32,
    /// Rows of cells, (ny + 1)(nz + 1): a cell (i, j, k) spans voxels i..=i+1, j..=j+1, k..=k+1,
    /// from -1 (voxels outside the grid hold 0).
    pub rows: u32,
    /// The depth band (world units) over which the nearest surface's discs blend.
    pub band: f32,
    /// The frame's surface splats (`iso_splats`' lanes; read back after `iso_scan`).
    pub splats: u32,
    pub pad: [u32; 3],
}

/// `project.comp`'s blend codes (glsl/shared/types.glsl `BLEND_*`): compositing, maximum, sum.
pub const BLEND_COMPOSITE: u32 = 0;
pub const BLEND_MAX: u32 = 1;
pub const BLEND_SUM: u32 = 2;
/// The isosurface's second pass: the discs within a band of each pixel's visible depth summed.
pub const BLEND_SURFACE: u32 = 3;
/// The isosurface's first pass: each pixel's visible depth, the nearest of the discs that weigh
/// enough there.
pub const BLEND_SURFACE_DEPTH: u32 = 4;

/// Push constants of `composite.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CompositePush {
    pub layers: u32,
    pub back_to_front: u32,
    pub width: u32,
    pub height: u32,
    /// Global sheet of layer 0 and the batch's direction (the footprint push's rank_base, rank_dir).
    pub rank_base: u32,
    pub rank_dir: i32,
    /// Composite tiles in the image (the second half of the sheet_tiles buffer starts there).
    pub tiles: u32,
    pub pad: u32,
}

/// Per-frame uniforms of the brick stages (`glsl/shared/brick.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BrickFrame {
    /// Bricks along x, y, z; w: non-empty bricks (headers).
    pub grid: [u32; 4],
    /// The eye's PBTF split of the brick grid; w: transfer-function points.
    pub split: [u32; 4],
    /// x, y: a stored value d is the TF's density d x + y; z: extraction threshold; w: gradient
    /// weight (0: off).
    pub tf: [f32; 4],
    /// Direction the light travels; w: 1 = headlight shading.
    pub light: [f32; 4],
    /// Ambient, diffuse, specular, shininess.
    pub shade: [f32; 4],
    /// x: largest gradient magnitude of the volume (gradient weighting); y: levels of detail,
    /// the largest cell spacing in pixels (0: off); z: their largest error; w: their morphing
    /// band, in octaves of projected size (0: none).
    pub grad: [f32; 4],
    /// The bricks drawn, `lo <= b < hi`: a rank's box in sort-last rendering, else the grid; the
    /// store may hold voxels outside it for the gradients at its faces. lo.w: the k-d tree's
    /// nodes, after the brick index (`kdtree`); hi.w unused.
    pub lo: [u32; 4],
    pub hi: [u32; 4],
}

/// Push constants of `brick_order.comp` and `brick_params.comp`: the batch's entries of the
/// visible-brick list and its splats.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BrickPush {
    /// First entry of `Res::BrickList` in this batch.
    pub first: u32,
    /// Entries (bricks) in this batch.
    pub count: u32,
    /// Splats in this batch.
    pub splats: u32,
    /// `brick_hidden`: the early-termination threshold.
    pub occluded: f32,
}

const _: () = assert!(std::mem::size_of::<BrickFrame>() == 128);
const _: () = assert!(std::mem::size_of::<BrickPush>() == 16);
const _: () = assert!(std::mem::size_of::<Splat>() == 32);
const _: () = assert!(std::mem::size_of::<SplatParams>() == 80);
const _: () = assert!(std::mem::size_of::<ScreenQuad>() == 80);
const _: () = assert!(std::mem::size_of::<Frame>() == 592);
const _: () = assert!(std::mem::size_of::<CompositePush>() == 32);
const _: () = assert!(std::mem::size_of::<PresentPush>() == 32);
const _: () = assert!(std::mem::size_of::<ProjectPush>() == 32);
const _: () = assert!(std::mem::size_of::<IsoPush>() == 32);
const _: () = assert!(std::mem::size_of::<DepthPush>() == 80);
const _: () = assert!(std::mem::size_of::<FootprintPush>() == 52);
const _: () = assert!(std::mem::size_of::<RaycastParams>() == 368);
const _: () = assert!(std::mem::size_of::<SlabPush>() == 32);
