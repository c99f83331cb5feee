//! Per-frame decisions made without a device: the frame uniforms, sheet batches, push constants
//! and workgroup counts the recording (`crate::stages`) hands to either engine; and `Prepared`, a
//! scene's per-axis slice lists.
use crate::bricks::{BrickScene, BRICK};
use crate::camera::Camera;
use crate::constants::{COMPOSITE_TILE, MAX_GROUPS_X, WORKGROUP_SIZE};
use crate::error::{Error, Result};
use crate::gpu_types::{
    BrickFrame, CompositePush, FootprintPush, Frame, RaycastParams, SHEET_MODE_AXIS, SHEET_MODE_BINNED,
};
use crate::kernel::Kernel;
use crate::options::{Antialias, Motion, RaycastOptions, RenderOptions, EWA_LOWPASS_PX};
use crate::order::{self, Direction};
use crate::volume::SplatSet;
use glam::Vec3;

mod bricked;
mod frame;
mod layout;
mod pass;
pub mod slab;
pub use bricked::{
    bricked_min_budget, bricked_resident_bytes, texel_bytes, BrickedPlan, BrickedSheets, BATCH_BYTES_PER_SPLAT,
};
pub use frame::{frame, mode_color_map, DepthSource, Draw, FramePlan, OrderSource, Projection, SplatRaster};
pub(crate) use layout::NO_NORMAL;
pub use layout::{
    cell_footprint_scale, footprint_scale, node_and_cut_words, node_grid, node_levels, node_words, occlusion_len,
    over_bits, present_push, pyramid_bytes, tile_counts, tile_grid, CELL_WORDS, LOD_BUFFERS, LOD_CELLS, LOD_LEVELS,
    NODE_PIXELS, NODE_WORDS, PYRAMID_BYTES, SLOTTED_LOD_BUFFERS, SLOT_CELLS, STREAMED_LOD_BUFFERS, SUMMARY_WORDS,
};
pub use pass::{SheetPass, TileRule};

/// A scene ready to draw: the splat rows plus, per axis, the splats grouped by slice and each
/// slice's rank among non-empty slices (what the sheet batches index).
pub struct Prepared {
    /// The splats.
    pub set: SplatSet,
    /// Per axis, the splats grouped by slice and each slice's first entry.
    pub slices: [(Vec<u32>, Vec<u32>); 3],
    /// Per axis in turn, each slice's rank among the non-empty slices.
    pub ranks: Vec<u32>,
    /// Where each axis's ranks begin in `ranks`.
    pub rank_offsets: [u32; 3],
    /// A bricked volume (then `set` holds no splats, only the grid): its splats are made per frame.
    pub bricks: Option<crate::bricks::BrickScene>,
    /// The CPU ray caster's dense (colour * tau, tau) field, built on first use and kept with the
    /// scene (the GPU path uploads it to a 3D texture and drops the host copy).
    field: std::sync::OnceLock<crate::volume::DenseField>,
    /// The projection modes' field (`DenseField::projection`), likewise.
    projection_field: std::sync::OnceLock<crate::volume::DenseField>,
    /// The isosurface's field (`iso::IsoField`), built on its first frame.
    iso_field: std::sync::OnceLock<crate::iso::IsoField>,
    /// The ray caster's isosurface field (`FieldKind::Iso`) on the CPU, likewise.
    iso_dense: std::sync::OnceLock<crate::volume::DenseField>,
}

/// Which dense field the ray caster samples for a mode (`Prepared::field_for`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldKind {
    /// (colour x tau, tau): compositing.
    Composite,
    /// (value, 1, 0, tau): the projections.
    Projection,
    /// (value, 1, 0, 0) from every voxel (`iso::IsoField`): the isosurface.
    Iso,
}

impl FieldKind {
    /// The field `mode` reads.
    pub fn of(mode: crate::options::Mode) -> Self {
        match mode {
            crate::options::Mode::Composite => FieldKind::Composite,
            crate::options::Mode::Iso => FieldKind::Iso,
            _ => FieldKind::Projection,
        }
    }
}

impl Prepared {
    /// A dense splat set's scene.
    pub fn new(set: SplatSet) -> Self {
        let slices = [0, 1, 2].map(|a| set.slices(a));
        let mut ranks = Vec::new();
        let mut rank_offsets = [0; 3];
        for a in 0..3 {
            rank_offsets[a] = ranks.len() as u32;
            ranks.extend(SplatSet::sheet_ranks(&slices[a].0));
        }
        Self {
            set,
            slices,
            ranks,
            rank_offsets,
            bricks: None,
            field: std::sync::OnceLock::new(),
            projection_field: std::sync::OnceLock::new(),
            iso_field: std::sync::OnceLock::new(),
            iso_dense: std::sync::OnceLock::new(),
        }
    }

    /// A bricked volume's scene.
    pub fn bricked(scene: crate::bricks::BrickScene) -> Result<Self> {
        let mut prep = Self::new(SplatSet::empty(scene.store.grid()?)?);
        prep.bricks = Some(scene);
        Ok(prep)
    }

    /// The dense field for ray casting, built once per scene.
    pub fn dense_field(&self) -> Result<&crate::volume::DenseField> {
        if let Some(f) = self.field.get() {
            return Ok(f);
        }
        let f = crate::volume::DenseField::new(&self.set)?;
        Ok(self.field.get_or_init(|| f))
    }

    /// The isosurface's field, built once.
    pub fn iso_field(&self) -> Result<&crate::iso::IsoField> {
        if let Some(f) = self.iso_field.get() {
            return Ok(f);
        }
        let f = crate::iso::IsoField::of(&self.set, self.bricks.as_ref())?;
        Ok(self.iso_field.get_or_init(|| f))
    }

    /// The ray caster's field for `mode`, built once: compositing's (colour x tau, tau), the
    /// projections' (value, 1, 0, tau) or the isosurface's (value, 1, 0, 0; `iso::IsoField`).
    pub fn field_for(&self, mode: crate::options::Mode) -> Result<&crate::volume::DenseField> {
        match FieldKind::of(mode) {
            FieldKind::Composite => return self.dense_field(),
            FieldKind::Iso => {
                if let Some(f) = self.iso_dense.get() {
                    return Ok(f);
                }
                let f = self.iso_field()?.dense();
                return Ok(self.iso_dense.get_or_init(|| f));
            }
            FieldKind::Projection => {}
        }
        if let Some(f) = self.projection_field.get() {
            return Ok(f);
        }
        let f = crate::volume::DenseField::projection(&self.set)?;
        Ok(self.projection_field.get_or_init(|| f))
    }
}

/// The per-frame uniforms shared by every stage.
pub fn make_frame(
    set: &SplatSet,
    camera: &Camera,
    kernel: Kernel,
    antialias: Antialias,
    motion: Option<&Motion>,
    split: [u32; 3],
    back_to_front: bool,
) -> Frame {
    let g = set.grid();
    let radius_vox = kernel.radius();
    let f = camera.forward();
    let r = camera.right();
    let u = camera.true_up();
    let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
    Frame {
        view_proj: camera.view_proj().to_cols_array_2d(),
        eye: v4(camera.eye, if camera.is_perspective() { 1.0 } else { 0.0 }),
        forward: v4(f, camera.near),
        right: v4(r, camera.far),
        up: v4(u, camera.pixels_per_unit()),
        origin: [g.origin[0], g.origin[1], g.origin[2], radius_vox],
        spacing: [g.spacing[0], g.spacing[1], g.spacing[2], radius_vox * set.kernel_spacing()],
        shear: [g.shear[0], g.shear[1], g.shear[2], set.opacity_length()],
        dims: [g.dims[0], g.dims[1], g.dims[2], set.len() as u32],
        split: [split[0], split[1], split[2], back_to_front as u32],
        aa: [antialias.code(), kernel.footprint_sigma() as f32, EWA_LOWPASS_PX, 0.0],
        motion: motion.map(|m| m.previous).unwrap_or(glam::Mat4::IDENTITY).to_cols_array_2d(),
        blur: [
            motion.map(|m| m.delta_px.max(1e-6)).unwrap_or(0.0),
            kernel.motion_g() as f32,
            camera.width as f32,
            camera.height as f32,
        ],
        motion_mid: motion.and_then(|m| m.middle).unwrap_or(glam::Mat4::IDENTITY).to_cols_array_2d(),
        sweep: [
            motion.is_some_and(|m| m.middle.is_some()) as u32 as f32,
            motion.map(|m| m.profile.code()).unwrap_or(0.0),
            0.0,
            0.0,
        ],
        rect: [set.coordinates().is_some() as u32, 0, 0, 0],
        clip: [[0.0; 4]; crate::options::CLIP_SLOTS],
    }
}

/// The per-frame constants for rendering `set` from `camera` with `opts`.
pub fn frame_for(set: &SplatSet, camera: &Camera, opts: &RenderOptions) -> Frame {
    let split = order::pbtf_split(set, camera);
    let btf = opts.direction() == Direction::BackToFront;
    let mut frame = make_frame(set, camera, opts.kernel, opts.antialias, opts.motion.as_ref(), split, btf);
    (frame.clip, frame.rect[1]) = opts.clip.uniforms();
    frame
}

/// One batch of sheets drawn into summation layers and composited together.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    /// The batch's first entry of the draw list.
    pub first_instance: u32,
    /// Its entries.
    pub instances: u32,
    /// Its sheets, one summation layer each.
    pub layers: u32,
    /// Its footprint stages' push constants.
    pub push: FootprintPush,
}

/// The grid axis whose index planes face the view most: the axis-aligned sheets' normal. On a
/// sheared grid the planes' own normals (the rows of the inverse cell matrix) decide, not the
/// frame's axes: a plane of constant j leans with the shear.
pub fn sheet_axis(grid: &crate::volume::Grid, camera: &Camera) -> usize {
    let f = if grid.is_sheared() {
        // |f . n_a| / |n_a| with n_a row a of U^-1 (so f . n_a is (U^-1 f)_a).
        let inv = grid.cell_matrix().inverse();
        let (along, rows) = (inv * camera.forward().as_dvec3(), inv.transpose());
        glam::DVec3::new(along.x / rows.x_axis.length(), along.y / rows.y_axis.length(), along.z / rows.z_axis.length())
            .abs()
            .as_vec3()
    } else {
        camera.forward().abs()
    };
    if f.x >= f.y && f.x >= f.z {
        0
    } else if f.y >= f.z {
        1
    } else {
        2
    }
}

/// The sheet axis (the grid axis most perpendicular to the view plane) and its batches in visiting
/// order. Empty sheets are skipped; a batch never straddles the eye's plane, so its splats are one
/// contiguous run of the slice-grouped draw list.
pub fn sheet_plan(prep: &Prepared, camera: &Camera, direction: Direction, max_layers: u32) -> (usize, Vec<Batch>) {
    let axis = sheet_axis(prep.set.grid(), camera);
    let split = order::pbtf_split(&prep.set, camera)[axis];
    let base = prep.rank_offsets[axis];
    let push =
        FootprintPush { sheet_mode: SHEET_MODE_AXIS, axis: axis as u32, rank_offset: base, ..Default::default() };
    let rank_of = |s: u32| Some(prep.ranks[(base + s) as usize]);
    (axis, sheet_batches(&prep.slices[axis].0, split, &rank_of, push, direction, max_layers))
}

/// The sheet batches of a bricked volume's frame, whose sheets `binned_sheets` grouped by index
/// (`offsets`: each sheet's first entry, sheets + 1 entries) on the device: ranked by index, so a
/// batch's layers include its empty sheets (a batch of empty sheets only is dropped).
pub fn binned_sheet_plan(
    offsets: &[u32],
    axis: usize,
    split: u32,
    direction: Direction,
    max_layers: u32,
) -> Vec<Batch> {
    let push = FootprintPush { sheet_mode: SHEET_MODE_BINNED, axis: axis as u32, ..Default::default() };
    sheet_batches(offsets, split, &|_| None, push, direction, max_layers)
}

/// Batches of at most `max_layers` sheets of a slice-grouped list (`offsets`), per side of the
/// eye's plane (`split`), in visiting order. `rank_of` gives a sheet's rank among non-empty sheets
/// (empty sheets skipped), or `None`: sheets ranked by index.
fn sheet_batches(
    offsets: &[u32],
    split: u32,
    rank_of: &dyn Fn(u32) -> Option<u32>,
    push: FootprintPush,
    direction: Direction,
    max_layers: u32,
) -> Vec<Batch> {
    let n = offsets.len().saturating_sub(1) as u32;
    let split = split.min(n);
    let nonempty = |s: &u32| offsets[*s as usize + 1] > offsets[*s as usize] || rank_of(*s).is_none();
    let low: Vec<u32> = (0..split).rev().filter(nonempty).collect();
    let high: Vec<u32> = (split..n).filter(nonempty).collect();
    let mut sides = vec![low, high];
    if direction == Direction::BackToFront {
        sides.reverse();
        for s in &mut sides {
            s.reverse();
        }
    }
    let mut batches = Vec::new();
    for side in &sides {
        for chunk in side.chunks(max_layers.max(1) as usize) {
            let (first, last) = (chunk[0], chunk[chunk.len() - 1]);
            let (lo, hi) = (first.min(last), first.max(last));
            let start = offsets[lo as usize];
            let end = offsets[hi as usize + 1];
            if end == start {
                continue;
            }
            batches.push(Batch {
                first_instance: start,
                instances: end - start,
                layers: chunk.len() as u32,
                push: FootprintPush {
                    rank_base: rank_of(first).unwrap_or(first),
                    rank_dir: if last >= first { 1 } else { -1 },
                    ..push
                },
            });
        }
    }
    batches
}

/// Push constants of `sheet_tiles.comp` for a frame's sheet batches: every entry of the sheet
/// list from 0, layers numbered by global sheet (rank base 0, direction +1), no occlusion culling.
pub fn sheet_tiles_push(batches: &[Batch], first: &Batch) -> FootprintPush {
    FootprintPush { rank_base: 0, rank_dir: 1, first: 0, count: sheet_entries(batches), occluded: 0.0, ..first.push }
}

/// Entries of the frame's sheet list that the batches draw (they cover it from 0).
fn sheet_entries(batches: &[Batch]) -> u32 {
    batches.iter().map(|b| b.first_instance + b.instances).max().unwrap_or(0)
}

/// Whether finding each tile's sheet range (`sheet_tiles`) can pay for itself: the composite must
/// read at least `SHEET_TILES_MIN_RATIO` layer pixels per entry of the sheet list (measured on
/// lavapipe: the pass costs 30–70 ns per entry, the composite ~8 ns per layer pixel). A single
/// sheet seen head-on (the raster sweep) falls below, the volume scenes far above.
pub fn sheet_tiles_pay(batches: &[Batch], width: u32, height: u32) -> bool {
    let entries = sheet_entries(batches) as u64;
    let layer_pixels: u64 = batches.iter().map(|b| b.layers as u64).sum::<u64>() * width as u64 * height as u64;
    entries > 0 && layer_pixels >= SHEET_TILES_MIN_RATIO * entries
}

/// See `sheet_tiles_pay`.
pub const SHEET_TILES_MIN_RATIO: u64 = 8;

/// Per-tile sheet ranges that let the composite read every layer (the `sheet_tiles` pass skipped):
/// lowest 0, highest + 1 `i32::MAX`.
pub const ALL_SHEETS: [u32; 2] = [0, i32::MAX as u32];

/// Push constants of `composite.comp` for batch `b`.
pub fn composite_push(b: &Batch, btf: bool, width: u32, height: u32) -> CompositePush {
    CompositePush {
        layers: b.layers,
        back_to_front: btf as u32,
        width,
        height,
        rank_base: b.push.rank_base,
        rank_dir: b.push.rank_dir,
        tiles: width.div_ceil(COMPOSITE_TILE) * height.div_ceil(COMPOSITE_TILE),
        pad: 0,
    }
}

/// Workgroup counts for `n` invocations of a 1D stage (spilling into y past `MAX_GROUPS_X`).
pub fn groups_1d(n: u32) -> [u32; 3] {
    let g = n.div_ceil(WORKGROUP_SIZE).max(1);
    [g.min(MAX_GROUPS_X), g.div_ceil(MAX_GROUPS_X), 1]
}

/// Workgroups for one workgroup per item (`n` items), spilling into y past `MAX_GROUPS_X`.
pub fn groups_per_item(n: u32) -> [u32; 3] {
    let g = n.max(1);
    [g.min(MAX_GROUPS_X), g.div_ceil(MAX_GROUPS_X), 1]
}

/// Most cells of the tile x chunk count matrix (4 bytes each: 64 MiB).
pub const MAX_TILE_CELLS: u64 = 1 << 24;

/// The ray caster's uniforms, read by the GPU stage and its mirror.
pub fn raycast_params(set: &SplatSet, camera: &Camera, opts: &RaycastOptions) -> RaycastParams {
    let g = set.grid();
    let o = Vec3::from(g.origin);
    let s = Vec3::from(g.spacing);
    let hi = Vec3::from(g.dims.map(|d| d as f32));
    let step = opts.step * s.min_element();
    // The inverse cell matrix, upper triangular as the cell matrix is.
    let inv = g.cell_matrix().inverse();
    let inv_shear = [inv.y_axis.x, inv.z_axis.x, inv.z_axis.y].map(|v| v as f32);
    let (clip, clip_count) = opts.clip.uniforms();
    RaycastParams {
        inv_view_proj: camera.view_proj().inverse().to_cols_array_2d(),
        box_min: [-1.0, -1.0, -1.0, step],
        box_max: [hi.x, hi.y, hi.z, opts.min_transmittance],
        origin: [o.x, o.y, o.z, 1.0 / g.kernel_spacing()],
        inv_spacing: [1.0 / s.x, 1.0 / s.y, 1.0 / s.z, opts.mode.code() as f32],
        // w: the isosurface's value.
        inv_shear: [inv_shear[0], inv_shear[1], inv_shear[2], opts.iso.unwrap_or(0.0)],
        dims: [g.dims[0], g.dims[1], g.dims[2], opts.max_steps],
        // The isosurface reads values where nothing is drawn: no empty-space skipping.
        image: [
            camera.width,
            camera.height,
            if opts.mode == crate::options::Mode::Iso { 0 } else { opts.brick },
            clip_count,
        ],
        clip,
    }
}

/// The brick stages' uniforms for a frame of `scene` whose brick grid is split at `split`.
pub fn brick_frame(scene: &BrickScene, split: [u32; 3]) -> BrickFrame {
    let part = scene.part();
    let nb = scene.store.dims.map(|d| d.div_ceil(BRICK));
    let (a, b) = scene.remap();
    let weight = scene.transfer_function().gradient_weight;
    let gmax = if weight > 0.0 { (a * scene.gmax_stored()).max(1e-12) } else { 1.0 };
    let (light, shade) = match scene.shading() {
        Some(s) => ([s.light.x, s.light.y, s.light.z, 1.0], [s.ambient, s.diffuse, s.specular, s.shininess]),
        None => ([0.0; 4], [0.0; 4]),
    };
    BrickFrame {
        grid: [nb[0], nb[1], nb[2], scene.store.headers.len() as u32],
        split: [split[0], split[1], split[2], 0],
        tf: [a, b, 0.0, weight],
        light,
        shade,
        grad: [gmax, 0.0, 0.0, 0.0],
        lo: [part[0][0], part[0][1], part[0][2], scene.tree().len() as u32],
        hi: [part[1][0], part[1][1], part[1][2], 0],
    }
}

/// Refuse a frame `target` cannot take: a camera of another size; a render scale below 1 (the frame
/// is then drawn on a coarser grid and the blit stretches it) with the host's depth or colour,
/// which are read pixel for pixel; a background over the host's image.
pub(crate) fn check_host_frame(target: &crate::vk::HostTarget, camera: &Camera, options: &RenderOptions) -> Result<()> {
    let (width, height) = target.size();
    if (camera.width, camera.height) != (width, height) {
        return Err(Error::InvalidArgument(format!(
            "the camera's {} x {} frame does not fit the {width} x {height} target",
            camera.width, camera.height
        )));
    }
    let refuse = |m: &str| Err(Error::InvalidArgument(m.into()));
    if options.render_scale != 1.0 && (target.depth().is_some() || target.is_over()) {
        return refuse("the host's depth and colour images are read pixel for pixel: draw at render scale 1");
    }
    if target.is_over() && options.background.is_some() {
        return refuse("a frame drawn over the host's image has that image for its background: give no background");
    }
    Ok(())
}
