//! Sort-last rendering, the parts that need no transport: the partition of a bricked
//! volume's brick grid into one convex box per rank (the top of the k-d tree that orders the
//! bricks, `kdtree`, balanced by non-empty bricks); the boxes' visibility order
//! for an eye (at every node of the tree the far side first); the scan that finds the whole
//! volume's range and non-empty bricks; the region a rank reads (its box and the layer of voxels
//! its faces' gradients need); and the `over` of premultiplied images and the pixel pieces the
//! compositing schemes exchange. The MPI side (feature `mpi`) is `distributed::mpi`.
//!
//! ```
//! use voxsplat::distributed::over_into;
//! // Sort-last compositing: a front rank's premultiplied pixels over a back rank's.
//! let front = [0.5, 0.0, 0.0, 0.5];
//! let mut back = [0.0, 0.0, 1.0, 1.0];
//! over_into(&front, &mut back);
//! assert_eq!(back, [0.5, 0.0, 0.5, 1.0]);
//!
//! ```
use crate::bricks::BRICK;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::volume::{Grid, SplatSet};

#[cfg(feature = "mpi")]
pub mod mpi;

/// A box of bricks, `lo..hi` in brick coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BrickBox {
    /// Lowest brick, inclusive.
    pub lo: [u32; 3],
    /// Highest brick, exclusive.
    pub hi: [u32; 3],
}

impl BrickBox {
    /// Bricks in the box.
    pub fn bricks(&self) -> u64 {
        (0..3).map(|a| (self.hi[a] - self.lo[a]) as u64).product()
    }

    /// The voxels a rank reads for this box of a `dims` grid: the box's own and one layer around
    /// it (the central differences of gradients at its faces), clipped to the grid.
    pub fn read_region(&self, dims: [u32; 3]) -> [[u32; 3]; 2] {
        if self.bricks() == 0 {
            return [[0; 3]; 2];
        }
        [
            [0, 1, 2].map(|a| (self.lo[a] * BRICK).saturating_sub(1)),
            [0, 1, 2].map(|a| (self.hi[a] * BRICK + 1).min(dims[a])),
        ]
    }
}

/// An inner node of the k-d tree: ranks `first..mid` lie below `plane` (in bricks) along `axis`,
/// ranks `mid..end` at or above it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split {
    /// The axis cut.
    pub axis: usize,
    /// The plane, in bricks.
    pub plane: u32,
    /// First rank of the node.
    pub first: u32,
    /// First rank above the plane.
    pub mid: u32,
    /// One past the node's last rank.
    pub end: u32,
}

/// The brick grid cut into one box per rank: the top of the k-d tree that orders the bricks
/// (`kdtree`), so a rank's bricks are consecutive in the one-process draw order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Bricks along x, y, z.
    pub grid: [u32; 3],
    /// Rank r's box (empty for a rank beyond the tree's leaves).
    pub boxes: Vec<BrickBox>,
    /// The cut's inner nodes, parents before children.
    pub splits: Vec<Split>,
    /// The whole tree (`kdtree::build`), which every rank's scene orders its bricks by.
    pub tree: Vec<crate::kdtree::Node>,
}

impl Partition {
    /// Cut a grid of `grid` bricks, non-empty where `occupied` (x fastest), into `ranks` boxes: the
    /// k-d tree built for `ranks` (`kdtree::build`), whose nodes over one rank are the boxes, in
    /// tree order; every box holds its share of the non-empty bricks (to a brick layer). For a
    /// power of two the tree is the one a single process orders the bricks by, so the composite
    /// equals its frame; for other counts it equals the frame of one process ordering by this
    /// tree (`BrickScene::set_tree`). A box may hold no non-empty brick, or, with more ranks than
    /// the grid has bricks to cut, no brick: its rank draws nothing and still takes part.
    pub fn new(grid: [u32; 3], occupied: &[bool], ranks: u32) -> Result<Self> {
        let n = grid.iter().map(|&g| g as usize).product::<usize>();
        if ranks == 0 || ranks > 1 << crate::kdtree::TREE_DEPTH || occupied.len() != n {
            return Err(Error::InvalidArgument(format!(
                "a partition of {grid:?} bricks into {ranks} boxes (at most {}) needs {n} occupancy flags, not {}",
                1 << crate::kdtree::TREE_DEPTH,
                occupied.len()
            )));
        }
        let tree = crate::kdtree::build(grid, ranks, |id| occupied[id]);
        let empty = BrickBox { lo: [0; 3], hi: [0; 3] };
        let mut p = Partition { grid, boxes: vec![empty; ranks as usize], splits: Vec::new(), tree };
        let root = if p.tree.is_empty() { crate::kdtree::LEAF } else { 0 };
        p.walk_ranks(root, BrickBox { lo: [0; 3], hi: grid }, 0, ranks);
        Ok(p)
    }

    /// Give ranks `first..end` the box `b` under tree node `node`: halves of them to its two
    /// sides, as `kdtree::build` cut it (a leaf over several ranks: the first takes the box).
    fn walk_ranks(&mut self, node: u32, b: BrickBox, first: u32, end: u32) {
        if end - first == 1 || node == crate::kdtree::LEAF {
            self.boxes[first as usize] = b;
            return;
        }
        let t = self.tree[node as usize];
        let (axis, plane) = crate::kdtree::cut(&t);
        let mid = first + (end - first) / 2;
        self.splits.push(Split { axis, plane, first, mid, end });
        let (mut low, mut high) = (b, b);
        (low.hi[axis], high.lo[axis]) = (plane, plane);
        self.walk_ranks(t[1], low, first, mid);
        self.walk_ranks(t[2], high, mid, end);
    }

    /// The node splitting ranks `first..end`.
    pub fn node(&self, first: u32, end: u32) -> Option<&Split> {
        self.splits.iter().find(|s| s.first == first && s.end == end)
    }

    /// Whether node `s`'s lower ranks lie nearer the eye (`kdtree::lower_in_front`).
    pub fn lower_in_front(s: &Split, split: [u32; 3]) -> bool {
        s.plane >= split[s.axis]
    }

    /// The ranks' boxes back to front for the eye's brick split: a visibility order of the boxes,
    /// the one the bricks are drawn in by one process (ranks without a box anywhere).
    pub fn back_to_front(&self, split: [u32; 3]) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.boxes.len());
        self.walk(0, self.boxes.len() as u32, split, &mut out);
        out
    }

    fn walk(&self, first: u32, end: u32, split: [u32; 3], out: &mut Vec<u32>) {
        let Some(s) = self.node(first, end).copied() else {
            out.extend(first..end);
            return;
        };
        let (low, high) = ((s.first, s.mid), (s.mid, s.end));
        let (back, front) = if Self::lower_in_front(&s, split) { (high, low) } else { (low, high) };
        self.walk(back.0, back.1, split, out);
        self.walk(front.0, front.1, split, out);
    }
}

/// The eye's brick split (`order::brick_split`) for a grid: what orders the boxes.
pub fn eye_split(grid: &Grid, camera: &Camera) -> Result<[u32; 3]> {
    let set = SplatSet::empty(*grid)?;
    Ok(crate::order::brick_split(&set, camera, BRICK))
}

/// Composite `front` over `back` (premultiplied RGBA, 4 floats a pixel) into `back`.
pub fn over_into(front: &[f32], back: &mut [f32]) {
    for (f, b) in front.chunks_exact(4).zip(back.chunks_exact_mut(4)) {
        let t = 1.0 - f[3];
        for c in 0..4 {
            b[c] = f[c] + t * b[c];
        }
    }
}

/// How the ranks' images are composited.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scheme {
    /// Direct-send: the frame cut into one piece per rank; every rank sends each piece to its
    /// owner, which composites the R layers in box order. One round, R - 1 messages per rank.
    DirectSend,
    /// Binary-swap (Ma et al. 1994): log2 R rounds; in each, partners across a k-d node exchange
    /// halves of what they hold and composite by which side of the node's plane is nearer.
    /// Powers of two only.
    BinarySwap,
    /// Direct-send below 4 ranks or when R is not a power of two, else binary-swap.
    #[default]
    Auto,
}

impl std::str::FromStr for Scheme {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "direct-send" | "direct" => Ok(Scheme::DirectSend),
            "binary-swap" => Ok(Scheme::BinarySwap),
            "auto" => Ok(Scheme::Auto),
            _ => Err(Error::InvalidArgument(format!("unknown exchange {s:?}: direct-send, binary-swap or auto"))),
        }
    }
}

impl Scheme {
    /// The scheme run for `ranks`: refused for binary-swap on a count that is not a power of two.
    pub fn resolve(self, ranks: u32) -> Result<Scheme> {
        match self {
            Scheme::Auto if ranks >= 4 && ranks.is_power_of_two() => Ok(Scheme::BinarySwap),
            Scheme::Auto => Ok(Scheme::DirectSend),
            Scheme::BinarySwap if !ranks.is_power_of_two() => Err(Error::InvalidArgument(format!(
                "binary-swap compositing needs a power of two ranks, not {ranks}: use direct-send"
            ))),
            s => Ok(s),
        }
    }

    /// The name the CLI and reports use.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::DirectSend => "direct-send",
            Scheme::BinarySwap => "binary-swap",
            Scheme::Auto => "auto",
        }
    }
}

/// Piece `i` of `n` of `pixels` pixels: contiguous, sizes differing by at most one.
pub fn piece(pixels: usize, n: usize, i: usize) -> std::ops::Range<usize> {
    pixels * i / n..pixels * (i + 1) / n
}

/// Binary-swap: the pixels rank `rank` holds after `rounds` rounds (round k pairs ranks that
/// differ in bit k; the one with the bit clear keeps the lower half of what both held).
pub fn swap_range(pixels: usize, rank: u32, rounds: u32) -> std::ops::Range<usize> {
    let mut r = 0..pixels;
    for k in 0..rounds {
        let mid = r.start + (r.end - r.start) / 2;
        r = if rank >> k & 1 == 0 { r.start..mid } else { mid..r.end };
    }
    r
}

/// The composite of the ranks' images `images` (rank order) in box order: what the schemes
/// compute, in one process (tests and the one-rank case).
pub fn composite_all(partition: &Partition, split: [u32; 3], images: &[&[f32]]) -> Vec<f32> {
    let order = partition.back_to_front(split);
    let mut acc = images[order[0] as usize].to_vec();
    for &r in &order[1..] {
        over_into(images[r as usize], &mut acc);
    }
    acc
}

/// What a rank's first pass over its share of the file finds: the value range, and per brick the
/// largest finite value (`-inf` where it read nothing), merged over the ranks into the whole
/// volume's.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// Smallest finite value read (`inf`: none).
    pub lo: f32,
    /// Largest finite value read (`-inf`: none).
    pub hi: f32,
    /// Per brick (x fastest) its largest finite value.
    pub brick_max: Vec<f32>,
}

impl Scan {
    /// Merge another rank's scan.
    pub fn merge(&mut self, other: &Scan) {
        (self.lo, self.hi) = (self.lo.min(other.lo), self.hi.max(other.hi));
        for (a, b) in self.brick_max.iter_mut().zip(&other.brick_max) {
            *a = a.max(*b);
        }
    }

    /// The range a bricked store normalises by (`BrickStore::from_slices`'s).
    pub fn range(&self) -> (f32, f32) {
        crate::bricks::store_range(self.lo, self.hi)
    }

    /// Per brick, whether the store keeps any of its voxels (above the minimum; every finite one
    /// of a constant volume).
    pub fn occupied(&self) -> Vec<bool> {
        let range = self.range();
        self.brick_max.iter().map(|&m| crate::bricks::keeps(m, range)).collect()
    }
}

/// Brick layers (z) `share` of `ranks`: what rank `share` scans.
pub fn scan_layers(grid: [u32; 3], ranks: u32, share: u32) -> std::ops::Range<u32> {
    let n = grid[2] as u64;
    (n * share as u64 / ranks as u64) as u32..(n * (share as u64 + 1) / ranks as u64) as u32
}

/// A volume file read in parts: raw, NRRD (raw or gzip) and NIfTI; an `.npy` is refused.
#[cfg(feature = "io")]
pub fn open(path: &std::path::Path, hints: &crate::loaders::VolumeHints) -> Result<crate::loaders::SliceReader> {
    crate::loaders::SliceReader::open(path, hints)?.ok_or_else(|| {
        Error::Unsupported(format!(
            "{}: distributed rendering reads raw, NRRD (raw or gzip) and NIfTI files in parts; convert this one",
            path.display()
        ))
    })
}

/// Pass one: the range and per-brick maxima of brick layers `layers` of the file, read
/// `BRICK` slices at a time.
#[cfg(feature = "io")]
pub fn scan(reader: &mut crate::loaders::SliceReader, layers: std::ops::Range<u32>) -> Result<Scan> {
    let dims = reader.dims;
    let nb = dims.map(|d| d.div_ceil(BRICK));
    let mut s = Scan {
        lo: f32::INFINITY,
        hi: f32::NEG_INFINITY,
        brick_max: vec![f32::NEG_INFINITY; nb.iter().map(|&n| n as usize).product()],
    };
    let mut slab = Vec::new();
    let plane = dims[0] as usize * dims[1] as usize;
    for bz in layers {
        let z0 = bz * BRICK;
        let count = BRICK.min(dims[2] - z0);
        reader.read(z0, count, &mut slab)?;
        for (i, &v) in slab.iter().enumerate().filter(|(_, v)| v.is_finite()) {
            (s.lo, s.hi) = (s.lo.min(v), s.hi.max(v));
            let (x, y) = ((i % plane) as u32 % dims[0], (i % plane) as u32 / dims[0]);
            let b = (x / BRICK + nb[0] * (y / BRICK + nb[1] * bz)) as usize;
            s.brick_max[b] = s.brick_max[b].max(v);
        }
    }
    Ok(s)
}

/// Pass two: the store of box `b` (and the voxels around it, `BrickBox::read_region`) normalised
/// by the whole volume's `range`, read by offset (`SliceReader::read_part`).
#[cfg(feature = "io")]
pub fn load_part(
    reader: &mut crate::loaders::SliceReader,
    spacing: [f32; 3],
    range: (f32, f32),
    b: &BrickBox,
) -> Result<crate::bricks::BrickStore> {
    let dims = reader.dims;
    let region = b.read_region(dims);
    let [r0, r1] = region;
    crate::bricks::BrickStore::from_region(dims, spacing, range, region, |z0, count, out| {
        reader.read_part(z0, count, [r0[0], r0[1]], [r1[0], r1[1]], out)
    })
}

/// This process's peak resident memory (Linux's VmHWM), or `None` where unknown.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
}
