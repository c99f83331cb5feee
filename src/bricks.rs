//! The bricked, compact store of a scalar volume (host side):
//! the grid cut into bricks of `BRICK`³ voxels, each non-empty brick a 16-byte header and a 64-byte
//! occupancy mask, each candidate voxel (value above the volume's minimum) a 4-byte record of its
//! position in the brick and its value quantised to 16 bits. Empty voxels are not stored: their
//! value is the minimum, which normalises to 0, so every value (and so every gradient) of the
//! volume is recovered from the store (`value_at`), up to the quantisation.
//!
//! B = 8 by measurement on the real volumes: 16-byte headers cost 0.05-0.19 bytes per stored voxel
//! at B = 8 (0.33-0.75 at B = 4), while at B = 16 nearly every brick of the stent holds a voxel and
//! nothing is left to cull. With the 64-byte masks (for the neighbour lookups of gradients) and,
//! on the device, 32 bytes of their running counts (`mask_words`), the store takes 4.36 bytes per
//! stored voxel on bonsai and 4.76 on the stent (4.26 and 4.54 without the counts; tests/bricks.rs).
//! On the device the store is resident and `BrickScene` draws it: the brick stages
//! (`glsl/brick_*.comp`) cull bricks, classify voxels and order them in two-level PBTF each frame.
//!
//! ```
//! use voxsplat::{bricks::BrickStore, classify::TransferFunction, loaders::ScalarVolume};
//! // A volume kept as 8^3 bricks (empty ones dropped), classified through a transfer function.
//! let dims = [16, 16, 16];
//! let values = (0..16 * 16 * 16).map(|i| (i % 16) as f32 / 15.0).collect();
//! let store = BrickStore::build(&ScalarVolume { dims, spacing: [1.0; 3], values })?;
//! let set = store.classify(&TransferFunction::preset("ramp")?, None)?;
//! assert!(set.len() > 0);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::classify::{classify_field, Shading, TransferFunction};
use crate::error::{Error, Result};
use crate::volume::{Grid, ScalarVolume, SplatSet};

mod build;
mod gradients;
mod header;
mod histogram;
mod planes;
mod series;
pub use build::{keeps, record_at, store_range, UNIFORM_RECORDS};
pub use gradients::{pack_differences, unpack_differences};
pub use header::BrickHeader;
pub use histogram::{Histogram, MAX_BINS};
pub use planes::Plane;
pub use series::Patch;

/// Voxels along each side of a brick.
pub const BRICK: u32 = crate::constants::BRICK_SIDE;
const BRICK_VOXELS: usize = (BRICK * BRICK * BRICK) as usize;
/// Largest value of a quantised scalar.
const Q: f32 = 65535.0;

/// Words of a brick's mask on the device (`mask_words`): 16 of bits, 8 of counts.
const MASK_DEVICE_WORDS: usize = BRICK_VOXELS / 32 * 3 / 2;

/// A scalar volume as bricks of compact records.
///
/// ```
/// use voxsplat::bricks::BrickStore;
/// use voxsplat::volume::ScalarVolume;
/// // A 32³ ramp: bricks of 8³ voxels, each with its summary and occupancy mask.
/// let values = (0..32 * 32 * 32).map(|i| (i % 32) as f32 / 31.0).collect();
/// let volume = ScalarVolume { dims: [32; 3], spacing: [1.0; 3], values };
/// let store = BrickStore::build(&volume)?;
/// assert_eq!(store.headers.len(), 64);
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct BrickStore {
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing (the cell matrix's diagonal, `Grid::spacing`).
    pub spacing: [f32; 3],
    /// A sheared grid's cell matrix above its diagonal (`Grid::shear`; zero when axis-aligned).
    pub shear: [f32; 3],
    /// The raw values normalisation maps to [0, 1] (the volume's finite min and max).
    pub range: (f32, f32),
    /// Non-empty bricks, in brick order (x fastest).
    pub headers: Vec<BrickHeader>,
    /// Per non-empty brick, which of its voxels are stored (bit x + 8y + 64z).
    pub masks: Vec<[u64; BRICK_VOXELS / 64]>,
    /// Records: local index (x + 8y + 64z, 9 bits) | quantised value << 16, brick by brick, in
    /// local index order.
    pub records: Vec<u32>,
    /// Brick id (x + nbx (y + nby z)) -> index into `headers`, or `u32::MAX` when empty.
    pub index: Vec<u32>,
}

impl BrickStore {
    /// Load a volume file as a store (`hints` as `loaders::load_volume` takes them): NRRD (raw
    /// or gzip), NIfTI and raw files stream slice by slice (gzip inflated as it is read), never
    /// held whole (volumes past the dense loader's `MAX_VOXELS` too); an `.npy` is loaded, cut
    /// and dropped. With `hints.crop`, an OME-Zarr image reads only the region it needs
    /// (`VolumeHints::crop`). A streamed file reports its slices read to `hints.progress`.
    #[cfg(feature = "io")]
    pub fn load(path: &std::path::Path, hints: &crate::loaders::VolumeHints) -> Result<Self> {
        let progress = hints.progress.as_ref().map(|p| p.as_fn());
        if let Some((reader, region)) = crate::loaders::SliceReader::part(path, hints)? {
            return Self::load_cropped(reader, region, progress);
        }
        let mut store = match crate::loaders::SliceReader::open(path, hints)? {
            Some(mut reader) => {
                let (dims, spacing) = (reader.dims, reader.spacing);
                let all = [[0; 3], dims];
                Self::from_slices_over(dims, spacing, all, f32::INFINITY, true, progress, |z0, count, out| {
                    reader.read(z0, count, out)
                })?
            }
            None => Self::build(&crate::loaders::load_volume(path, hints)?)?,
        };
        if let Some(s) = hints.spacing {
            crate::loaders::check_spacing(s, &path.display().to_string())?;
            store.spacing = s;
        }
        Ok(store)
    }

    /// Load one time point of a series (`hints.time`) as a store normalised by `range` (the
    /// series' first time point's, so that `Renderer::update_volume` takes it): one pass over
    /// the file, slice by slice where the format streams. Values below the range read as empty
    /// and values above it as its top; the second value returned counts those voxels.
    #[cfg(feature = "io")]
    pub fn load_in_range(
        path: &std::path::Path,
        hints: &crate::loaders::VolumeHints,
        range: (f32, f32),
    ) -> Result<(Self, u64)> {
        let mut outside = 0u64;
        let mut count = |values: &[f32]| {
            outside += values.iter().filter(|&&v| v.is_finite() && (v < range.0 || v > range.1)).count() as u64
        };
        if let Some((mut reader, region)) = crate::loaders::SliceReader::part(path, hints)? {
            let (dims, spacing) = (reader.dims, reader.spacing);
            let store = Self::from_region(dims, spacing, range, region, |z0, n, out| {
                reader.read_region(z0, n, region, out)?;
                count(out);
                Ok(())
            })?;
            return Ok((store, outside));
        }
        let mut store = match crate::loaders::SliceReader::open(path, hints)? {
            Some(mut reader) => {
                let (dims, spacing) = (reader.dims, reader.spacing);
                Self::from_region(dims, spacing, range, [[0; 3], dims], |z0, n, out| {
                    reader.read(z0, n, out)?;
                    count(out);
                    Ok(())
                })?
            }
            None => {
                let v = crate::loaders::load_volume(path, hints)?;
                count(&v.values);
                let plane = v.dims[0] as usize * v.dims[1] as usize;
                Self::from_region(v.dims, v.spacing, range, [[0; 3], v.dims], |z0, n, out| {
                    out.clear();
                    out.extend_from_slice(&v.values[z0 as usize * plane..(z0 + n) as usize * plane]);
                    Ok(())
                })?
            }
        };
        if let Some(s) = hints.spacing {
            crate::loaders::check_spacing(s, &path.display().to_string())?;
            store.spacing = s;
        }
        Ok((store, outside))
    }

    /// The grid the store's voxels lie on, centred on the origin.
    pub fn grid(&self) -> Result<Grid> {
        Grid::centered_sheared(self.dims, self.spacing, self.shear)
    }

    /// Lay the store on the grid its file's `placement` draws (a sheared grid's cell matrix,
    /// `Orientation::grid`; the rotation moves the camera, `Orientation::camera_to_grid`).
    pub fn place(&mut self, placement: &crate::orient::Orientation) -> Result<()> {
        let g = crate::orient::placed_grid(self.dims, self.spacing, Some(placement))?;
        (self.spacing, self.shear) = (g.spacing, g.shear);
        Ok(())
    }

    /// Stored voxels (a uniform brick's too, which have no records).
    pub fn len(&self) -> usize {
        self.headers.iter().map(|h| h.count as usize).sum()
    }

    /// Whether no voxel is stored.
    pub fn is_empty(&self) -> bool {
        self.headers.is_empty()
    }

    /// Bytes the store takes on a device: headers, masks with their counts (`mask_words`) and
    /// records.
    pub fn bytes(&self) -> u64 {
        let mask = MASK_DEVICE_WORDS * 4;
        (self.headers.len() * (std::mem::size_of::<BrickHeader>() + mask) + self.records.len() * 4) as u64
    }

    /// The masks as the device reads them (`Res::BrickMasks`): per brick its 16 mask words, then
    /// per word the stored voxels in the words before it, 16 bits each (two to a word, the even
    /// word's low).
    pub fn mask_words(&self) -> Vec<u32> {
        let mut w = Vec::with_capacity(self.masks.len() * MASK_DEVICE_WORDS);
        for m in &self.masks {
            let words: &[u32] = bytemuck::cast_slice(m);
            w.extend_from_slice(words);
            let mut below = [0u32; BRICK_VOXELS / 32];
            for i in 1..below.len() {
                below[i] = below[i - 1] + words[i - 1].count_ones();
            }
            w.extend(below.chunks(2).map(|p| p[0] | p[1] << 16));
        }
        w
    }

    /// The header of the brick holding voxel `v` (`u32::MAX`: an empty brick; `header_of` in
    /// glsl/shared/brick.glsl).
    pub fn header_of(&self, v: [u32; 3]) -> u32 {
        let nb = self.dims.map(|d| d.div_ceil(BRICK));
        self.index[(v[0] / BRICK + nb[0] * (v[1] / BRICK + nb[1] * (v[2] / BRICK))) as usize]
    }

    /// The normalised value in [0, 1] at voxel (i, j, k), indices clamped to the grid (as the
    /// CPU classification reads it): 0 where nothing is stored.
    pub fn value_at(&self, i: i64, j: i64, k: i64) -> f32 {
        let [x, y, z] = [i, j, k].map(|c| c.max(0) as u32);
        let [x, y, z] = [x.min(self.dims[0] - 1), y.min(self.dims[1] - 1), z.min(self.dims[2] - 1)];
        let Some((h, l)) = self.stored([x, y, z]) else { return 0.0 };
        let rec = record_at(&self.records, self.headers[h as usize].first + self.stored_below(h, l));
        (rec >> 16) as f32 / Q
    }

    /// Where voxel `v` (inside the grid) is stored: its brick's header and its local index there,
    /// or None where its brick is empty or its occupancy bit is unset.
    pub fn stored(&self, v: [u32; 3]) -> Option<(u32, usize)> {
        let h = self.header_of(v);
        if h == u32::MAX {
            return None;
        }
        let l = (v[0] % BRICK + BRICK * (v[1] % BRICK) + BRICK * BRICK * (v[2] % BRICK)) as usize;
        (self.masks[h as usize][l / 64] >> (l % 64) & 1 != 0).then_some((h, l))
    }

    /// The rank of local voxel `l`'s record among header `h`'s: the brick's stored voxels below it
    /// in local index order.
    pub fn stored_below(&self, h: u32, l: usize) -> u32 {
        let mask = &self.masks[h as usize];
        mask[..l / 64].iter().map(|w| w.count_ones()).sum::<u32>()
            + (mask[l / 64] & ((1u64 << (l % 64)) - 1)).count_ones()
    }

    /// Classify the stored volume (as `classify::classify` does a dense one), reading every value
    /// and gradient through the store.
    pub fn classify(&self, tf: &TransferFunction, shading: Option<Shading>) -> Result<SplatSet> {
        let (a, b) = remap(self, tf);
        // The transfer function's own range, if it sets one, re-maps the stored normalisation.
        let remap = |d: f32| if tf.range.is_some() { a * d + b } else { d };
        classify_field(self.grid()?, tf, shading, |i, j, k| remap(self.value_at(i, j, k)))
    }
}

/// A bricked volume as a scene: the store, resident on the device, and the transfer function and
/// shading its voxels are classified with on every frame (a TF change is a small buffer write).
///
/// ```
/// use voxsplat::bricks::{BrickScene, BrickStore};
/// use voxsplat::classify::TransferFunction;
/// use voxsplat::volume::ScalarVolume;
/// use voxsplat::{Backend, Camera, Grid, RenderOptions, Renderer, RendererOptions};
/// // A 24³ ramp, its store classified by the `ramp` preset on every frame (here by the CPU mirrors).
/// let values = (0..24 * 24 * 24).map(|i| (i % 24) as f32 / 23.0).collect();
/// let volume = ScalarVolume { dims: [24; 3], spacing: [1.0; 3], values };
/// let scene = BrickScene::new(BrickStore::build(&volume)?, TransferFunction::preset("ramp")?, None)?;
/// let mut options = RendererOptions::default();
/// options.backend = Backend::Cpu;
/// let mut renderer = Renderer::new(&options)?;
/// renderer.set_bricks(scene)?;
/// let camera = Camera::framing(&Grid::centered(volume.dims, volume.spacing)?, 48, 48);
/// let frame = renderer.render(&camera, &RenderOptions::default())?;
/// assert!(frame.image.pixels.iter().any(|p| p[3] > 0.0));
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct BrickScene {
    /// The store.
    pub store: BrickStore,
    tf: TransferFunction,
    shading: Option<Shading>,
    /// `tf` tabulated per quantised value (`tf_words`).
    table: Vec<u32>,
    /// Per non-empty brick, the voxels `tf` draws (a streamed store's `Res::BrickCounts`).
    drawn: std::sync::OnceLock<Vec<u32>>,
    /// The largest gradient magnitude in stored units (gradient weighting needs it), built once.
    gmax: std::sync::OnceLock<f32>,
    /// Names this store under this classification (TF and shading): what a device's level-of-detail
    /// pyramid was built from (`Engine::tag`). Unique in the process.
    classification: u64,
    /// The bricks drawn, `lo..hi` in brick coordinates (`set_part`).
    part: [[u32; 3]; 2],
    /// The k-d tree that orders the bricks (`kdtree`).
    tree: Vec<crate::kdtree::Node>,
    /// Which bricks' records a device holds when the store streams (`RecordCache`).
    pub(crate) records_cache: crate::residency::CacheCell,
}

/// The next `BrickScene::classification` (0 is never one).
fn next_classification() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// (a, b): stored value d is `tf`'s density a d + b.
fn remap(store: &BrickStore, tf: &TransferFunction) -> (f32, f32) {
    // In f64: the spans of f32 ranges may pass f32's largest value.
    let (lo, hi) = (store.range.0 as f64, store.range.1 as f64);
    let span = if hi > lo { hi - lo } else { 1.0 };
    match tf.range {
        Some((tlo, thi)) => {
            let (tlo, thi) = (tlo as f64, thi as f64);
            let tspan = if thi > tlo { thi - tlo } else { 1.0 };
            ((span / tspan) as f32, ((lo - tlo) / tspan) as f32)
        }
        None => (1.0, 0.0),
    }
}

/// The (x, y, z) within its brick of local index `l` (x + 8y + 64z, a record's low 9 bits).
pub fn local_cell(l: u32) -> [u32; 3] {
    [l % BRICK, (l / BRICK) % BRICK, l / (BRICK * BRICK)]
}

/// Whether the TF table `table` (`BrickScene::tf_words`) extracts voxels of quantised value `q`
/// (glsl/shared/brick.glsl's `emits`).
pub fn emits(table: &[u32], q: u32) -> bool {
    table[4 * crate::constants::TF_ENTRIES as usize + (q >> 5) as usize] >> (q & 31) & 1 != 0
}

/// Whether the TF table `table` extracts any quantised value in `lo..=hi` (a brick of that range
/// draws a voxel; `!tf_empty` in glsl/shared/brick.glsl, counting with `emitted_below`).
pub fn draws_any(table: &[u32], lo: u32, hi: u32) -> bool {
    let bits = 4 * crate::constants::TF_ENTRIES as usize;
    let prefix = bits + crate::constants::TF_ENTRIES as usize / 32;
    let below = |q: u32| {
        let w = (q >> 5) as usize;
        table[prefix + w] + if q & 31 == 0 { 0 } else { (table[bits + w] & ((1u32 << (q & 31)) - 1)).count_ones() }
    };
    below(hi + 1) != below(lo)
}

/// `tf` tabulated per quantised value (see `BrickScene::tf_words`): the classification of a
/// stored value is exact (the quantised value is all the store keeps), so a table of 2^16 entries
/// loses nothing and turns the per-voxel TF walk into one load.
fn tf_table(tf: &TransferFunction, (a, b): (f32, f32)) -> Vec<u32> {
    let n = crate::constants::TF_ENTRIES as usize;
    let mut color = Vec::with_capacity(4 * n);
    let mut bits = vec![0u32; n / 32];
    for q in 0..n {
        let d = q as f32 / Q * a + b;
        let c = tf.eval(d);
        color.extend(c.map(f32::to_bits));
        if d >= tf.threshold && c[3] > 0.0 {
            bits[q / 32] |= 1 << (q % 32);
        }
    }
    let mut prefix = vec![0u32; n / 32 + 1];
    for w in 0..n / 32 {
        prefix[w + 1] = prefix[w] + bits[w].count_ones();
    }
    color.extend(bits);
    color.extend(prefix);
    color
}

/// Bricks along x, y, z of `store`'s grid.
fn store_bricks(store: &BrickStore) -> [u32; 3] {
    store.dims.map(|d| d.div_ceil(BRICK))
}

/// Most non-empty bricks a scene holds (a brick's draw-order slot packs its header in 22 bits).
pub const MAX_BRICKS: usize = 1 << 22;

/// A brick's draw-order slot word (`brick_cull`: header << 10 | code) as (header, level of
/// detail, splats): the code is the count at level 0 (1-512), 512 + the count at level 1 (1-64),
/// 576 + the count at level 2 (1-8), 585 at level 3, 585 + k for a node k levels above. Mirror of `slot_code`.
pub fn slot_entry(word: u32) -> (u32, u32, u32) {
    let c = word & 1023;
    let (level, count) = match c {
        0..=512 => (0, c),
        513..=576 => (1, c - 512),
        577..=584 => (2, c - 576),
        _ => (c - 582, 1),
    };
    (word >> 10, level, count)
}

/// Most colours `BrickScene::from_palette` takes.
pub const MAX_PALETTE: usize = 64;

impl BrickScene {
    /// A scene of `store` classified with `tf` and `shading`.
    pub fn new(store: BrickStore, tf: TransferFunction, shading: Option<Shading>) -> Result<Self> {
        if store.headers.len() > MAX_BRICKS {
            return Err(Error::TooLarge(format!(
                "{} non-empty bricks: a bricked volume holds at most {MAX_BRICKS}",
                store.headers.len()
            )));
        }
        tf.validate()?;
        let table = tf_table(&tf, remap(&store, &tf));
        Ok(Self {
            tf,
            shading,
            table,
            drawn: std::sync::OnceLock::new(),
            gmax: std::sync::OnceLock::new(),
            classification: next_classification(),
            records_cache: Default::default(),
            part: [[0; 3], store_bricks(&store)],
            tree: crate::kdtree::build(store_bricks(&store), 1, |id| store.index[id] != u32::MAX),
            store,
        })
    }

    /// Draw only the bricks `lo..hi` (brick coordinates): a rank's box in sort-last rendering
    /// (`distributed`), whose store also holds the voxels around the box that its faces'
    /// gradients read. The whole grid by default.
    pub fn set_part(&mut self, lo: [u32; 3], hi: [u32; 3]) -> Result<()> {
        let nb = store_bricks(&self.store);
        if (0..3).any(|a| lo[a] > hi[a] || hi[a] > nb[a]) {
            return Err(Error::InvalidArgument(format!("the part {lo:?}..{hi:?} lies outside the {nb:?} brick grid")));
        }
        self.part = [lo, hi];
        self.gmax = std::sync::OnceLock::new();
        Ok(())
    }

    /// The k-d tree that orders the bricks: the store's own, or (`set_tree`) the whole volume's
    /// when the store holds one rank's part of it.
    pub fn tree(&self) -> &[crate::kdtree::Node] {
        &self.tree
    }

    /// Order the bricks by `tree` (the whole volume's, `kdtree::build`), refused when it does not
    /// cut this grid.
    pub fn set_tree(&mut self, tree: Vec<crate::kdtree::Node>) -> Result<()> {
        let nb = store_bricks(&self.store);
        let bad = tree.iter().any(|n| {
            let (axis, plane) = crate::kdtree::cut(n);
            axis > 2
                || plane == 0
                || plane >= nb[axis]
                || [n[1], n[2]].iter().any(|&c| c != u32::MAX && c as usize >= tree.len())
        });
        if bad || tree.len() >= 1 << crate::kdtree::TREE_DEPTH {
            return Err(Error::InvalidArgument(format!(
                "a k-d tree of {} nodes that does not cut the {nb:?} brick grid",
                tree.len()
            )));
        }
        self.tree = tree;
        Ok(())
    }

    /// The brick index and, after it, the k-d tree: the device's `Res::BrickIndex`.
    pub fn index_words(&self) -> Vec<u32> {
        let mut w = self.store.index.clone();
        w.extend(self.tree.iter().flatten());
        w
    }

    /// The bricks drawn (`set_part`).
    pub fn part(&self) -> [[u32; 3]; 2] {
        self.part
    }

    /// The largest gradient magnitude, in stored units, over the drawn part (gradient weighting
    /// divides by it).
    pub fn gradient_max(&self) -> f32 {
        self.gmax_stored()
    }

    /// Set the largest gradient magnitude (stored units): the whole volume's, when this scene
    /// draws one part of it.
    pub fn set_gradient_max(&mut self, g: f32) {
        self.gmax = std::sync::OnceLock::from(g);
    }

    /// A scene of few colours (a built-in scene's splats) as a bricked volume, so the bricked path
    /// and its levels of detail can be measured on the same objects as the dense splats: colour p
    /// (in first-seen order) is stored value p + 1 and a flat stretch of the transfer function, so
    /// classification reproduces every splat's colour and opacity exactly. More than
    /// `MAX_PALETTE` colours is an error.
    pub fn from_palette(set: &SplatSet) -> Result<Self> {
        let mut palette: Vec<[f32; 4]> = Vec::new();
        let mut index = Vec::with_capacity(set.len());
        for s in set.splats() {
            let p = match palette.iter().position(|c| *c == s.color) {
                Some(p) => p,
                None if palette.len() < MAX_PALETTE => {
                    palette.push(s.color);
                    palette.len() - 1
                }
                None => {
                    return Err(Error::InvalidArgument(format!(
                        "the scene has more than {MAX_PALETTE} colours: a palette volume holds at most that many"
                    )))
                }
            };
            index.push(p);
        }
        let g = set.grid();
        if g.origin != Grid::centered_sheared(g.dims, g.spacing, g.shear)?.origin {
            return Err(Error::InvalidArgument("a palette volume's grid must be centred on the origin".into()));
        }
        let n = palette.len().max(1) as f32;
        let mut values = vec![0.0f32; g.dims.iter().map(|&d| d as usize).product()];
        for (s, &p) in set.splats().iter().zip(&index) {
            let [i, j, k, _] = s.ijk.map(|c| c as usize);
            values[i + g.dims[0] as usize * (j + g.dims[1] as usize * k)] = (p + 1) as f32;
        }
        // Value p + 1 normalises to (p + 1) / n; a plateau of half a step either side absorbs the
        // store's 16-bit quantisation.
        let mut points = vec![(0.0, [0.0; 4])];
        for (p, c) in palette.iter().enumerate() {
            let at = (p + 1) as f32 / n;
            points.push((at - 0.25 / n, *c));
            points.push((at + 0.25 / n, *c));
        }
        let tf = TransferFunction { points, gradient_weight: 0.0, range: Some((0.0, n)), threshold: 0.5 / n };
        let vol = ScalarVolume { dims: g.dims, spacing: g.spacing, values };
        let store = BrickStore { shear: g.shear, ..BrickStore::build_over(&vol, 0.0)? };
        Self::new(store, tf, None)
    }

    /// Make the store `next`, the scene's next time point (`BrickStore::patch`: the same grid and
    /// range), keeping its classification, part and what a device holds of the bricks that did
    /// not change. A scene drawing one rank's part is refused (its tree cuts the whole volume).
    pub fn update(&mut self, next: BrickStore) -> Result<Patch> {
        if self.part != [[0; 3], store_bricks(&self.store)] {
            return Err(Error::InvalidArgument("a time point replaces a scene that draws one rank's part".into()));
        }
        let patch = self.store.patch(next)?;
        if patch.layout {
            let s = &self.store;
            self.tree = crate::kdtree::build(store_bricks(s), 1, |id| s.index[id] != u32::MAX);
        }
        (self.drawn, self.gmax) = (std::sync::OnceLock::new(), std::sync::OnceLock::new());
        self.classification = next_classification();
        let mut cache = self.records_cache.0.lock().map_err(|_| Error::Unsupported("record cache poisoned".into()))?;
        if patch.layout || patch.compacted {
            cache.forget();
        } else {
            cache.evict(&patch.headers);
        }
        Ok(patch)
    }

    /// Classify with another transfer function and shading from the next frame on.
    pub fn set_transfer_function(&mut self, tf: TransferFunction, shading: Option<Shading>) -> Result<()> {
        tf.validate()?;
        self.table = tf_table(&tf, remap(&self.store, &tf));
        self.drawn = std::sync::OnceLock::new();
        (self.tf, self.shading) = (tf, shading);
        self.classification = next_classification();
        Ok(())
    }

    /// This store under its current transfer function and shading, as a tag unique in the process.
    pub fn classification(&self) -> u64 {
        self.classification
    }

    /// The transfer function.
    pub fn transfer_function(&self) -> &TransferFunction {
        &self.tf
    }

    /// The shading.
    pub fn shading(&self) -> Option<Shading> {
        self.shading
    }

    /// (a, b): a stored value d is the transfer function's density a d + b (its own range, if it
    /// sets one, re-maps the store's normalisation; `BrickStore::classify`).
    pub fn remap(&self) -> (f32, f32) {
        remap(&self.store, &self.tf)
    }

    /// The box of stored voxels the transfer function gives some opacity (`None`: none does),
    /// smallest and largest grid index: what a camera frames.
    pub fn visible_bounds(&self) -> Option<[[u32; 3]; 2]> {
        let (mut lo, mut hi) = ([u32::MAX; 3], [0u32; 3]);
        for h in &self.store.headers {
            let base = h.coords().map(|c| c * BRICK);
            let mut take = |v: [u32; 3]| {
                (0..3).for_each(|x| (lo[x], hi[x]) = (lo[x].min(base[x] + v[x]), hi[x].max(base[x] + v[x])))
            };
            if h.is_uniform() {
                // Every voxel of a full brick, without making its records: its two far corners.
                if emits(&self.table, h.range & 0xffff) {
                    take([0; 3]);
                    take([BRICK - 1; 3]);
                }
                continue;
            }
            for &rec in self.store.brick_records(h).iter().filter(|&&r| emits(&self.table, r >> 16)) {
                take(local_cell(rec & 511));
            }
        }
        (lo[0] <= hi[0]).then_some([lo, hi])
    }

    /// The store's `gradient_words` (`Res::BrickGradients`) for the bricks the transfer function
    /// draws: made when a device lacks them for this classification, and not kept (8 bytes a
    /// stored voxel).
    pub fn gradient_words(&self) -> [Vec<u32>; 2] {
        self.store.gradient_words(|hd| draws_any(&self.table, hd.range & 0xffff, hd.range >> 16))
    }

    /// Whether a frame classifies with gradients: shaded, or gradient-weighted opacity.
    pub fn reads_gradients(&self) -> bool {
        self.shading.is_some() || self.tf.gradient_weight > 0.0
    }

    /// The TF buffer (`Res::Tf`, glsl/shared/brick.glsl): per quantised value q its straight
    /// RGBA, then a bit per q (extracted: at or above the threshold with opacity > 0), then per
    /// 32-value word the extracted values below it (and the total).
    pub fn tf_words(&self) -> &[u32] {
        &self.table
    }

    /// Whether the store stays on the host under a device budget of `budget` bytes, its records
    /// streamed batch by batch: when they would take more than half the budget.
    pub fn streams(&self, budget: u64) -> bool {
        self.store.records.len() as u64 * 4 > budget / 2
    }

    /// Per non-empty brick, the voxels the transfer function draws (extracted values, by the
    /// table's bits), counted once per transfer function: a streamed store's brick counts.
    pub fn drawn_counts(&self) -> &[u32] {
        self.drawn.get_or_init(|| {
            let s = &self.store;
            s.headers.iter().map(|h| s.drawn_in(h, |q| emits(&self.table, q))).collect()
        })
    }

    /// The largest central-difference gradient magnitude over the grid, in stored units: only
    /// voxels in or next to a non-empty brick can have one.
    pub(crate) fn gmax_stored(&self) -> f32 {
        *self.gmax.get_or_init(|| {
            let s = &self.store;
            let nb = s.dims.map(|d| d.div_ceil(BRICK) as i64);
            let filled = |x: i64, y: i64, z: i64| {
                (0..nb[0]).contains(&x)
                    && (0..nb[1]).contains(&y)
                    && (0..nb[2]).contains(&z)
                    && s.index[(x + nb[0] * (y + nb[1] * z)) as usize] != u32::MAX
            };
            let sp = s.spacing;
            let mut most = 0.0f32;
            let [lo, hi] = self.part.map(|c| c.map(i64::from));
            for bz in lo[2]..hi[2] {
                for by in lo[1]..hi[1] {
                    for bx in lo[0]..hi[0] {
                        let near =
                            (-1..=1).any(|dz| (-1..=1).any(|dy| (-1..=1).any(|dx| filled(bx + dx, by + dy, bz + dz))));
                        if !near {
                            continue;
                        }
                        let b = BRICK as i64;
                        for z in bz * b..((bz + 1) * b).min(s.dims[2] as i64) {
                            for y in by * b..((by + 1) * b).min(s.dims[1] as i64) {
                                for x in bx * b..((bx + 1) * b).min(s.dims[0] as i64) {
                                    let g = glam::Vec3::new(
                                        (s.value_at(x + 1, y, z) - s.value_at(x - 1, y, z)) / (2.0 * sp[0]),
                                        (s.value_at(x, y + 1, z) - s.value_at(x, y - 1, z)) / (2.0 * sp[1]),
                                        (s.value_at(x, y, z + 1) - s.value_at(x, y, z - 1)) / (2.0 * sp[2]),
                                    );
                                    most = most.max(g.length());
                                }
                            }
                        }
                    }
                }
            }
            most
        })
    }
}
