//! Sort-last rendering over MPI (feature `mpi`, rsmpi over the system's MPI): every rank reads
//! its box of the volume and draws it; the frames meet in the boxes' visibility order by
//! direct-send or binary-swap, through MPI collectives and point-to-point messages; rank 0 holds
//! the image. A failure on any rank (a file it cannot read, a device error) is agreed on before
//! the next collective, so every rank returns the same error instead of waiting forever.
//!
//! Every rank runs the same program (started by `mpirun -n R`):
//!
//! ```no_run
//! use voxsplat::distributed::{mpi::{rsmpi, Distributed}, Scheme};
//! use voxsplat::{Camera, RenderOptions, Renderer, RendererOptions};
//! let universe = rsmpi::initialize().expect("MPI initialised once");
//! let renderer = Renderer::new(&RendererOptions::default())?;
//! let tf = voxsplat::classify::TransferFunction::preset("ct")?;
//! let path = std::path::Path::new("stent.nrrd");
//! let mut d = Distributed::load(universe.world(), renderer, path, &Default::default(), tf, None, Scheme::Auto)?;
//! let camera = Camera::framing(d.grid(), 512, 512);
//! // Rank 0 gets the frame; every rank must call render with the same camera and options.
//! if let Some(frame) = d.render(&camera, &RenderOptions::default())? {
//!     voxsplat::output::write_image(&frame.image, std::path::Path::new("stent.png"))?;
//! }
//! # Ok::<(), voxsplat::Error>(())
//! ```
use super::{eye_split, load_part, over_into, piece, scan, scan_layers, swap_range, BrickBox, Partition, Scan, Scheme};
use crate::bricks::{BrickScene, BRICK};
use crate::camera::Camera;
use crate::classify::{Shading, TransferFunction};
use crate::error::{Error, Result};
use crate::image::ImageF32;
use crate::options::{Composite, RenderOptions, StageTime};
use crate::volume::Grid;
use crate::Renderer;
use ::mpi::collective::SystemOperation;
use ::mpi::datatype::{Partition as Parts, PartitionMut};
use ::mpi::traits::*;
use std::time::Instant;

/// The MPI crate this module runs on (rsmpi), for hosts that initialise it.
pub use ::mpi as rsmpi;

/// Whether this process was started by an MPI launcher (`mpirun`/`mpiexec` set these): without
/// one, the CLI renders as a single process and never initialises MPI.
pub fn launched() -> bool {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"].iter().any(|v| std::env::var_os(v).is_some())
}

/// A distributed frame, at rank 0.
#[derive(Clone, Debug)]
pub struct DistributedFrame {
    /// The composited frame (premultiplied, no background).
    pub image: ImageF32,
    /// `render` (the slowest rank's), `composite` (from the last rank done drawing to the image at
    /// rank 0) and `render rank 0`'s stages.
    pub timings: Vec<StageTime>,
}

/// A renderer on a communicator: one box of a volume per rank.
pub struct Distributed<C: Communicator> {
    comm: C,
    renderer: Renderer,
    partition: Partition,
    grid: Grid,
    scheme: Scheme,
    stored: u64,
    store_bytes: u64,
    visible: Option<[[u32; 3]; 2]>,
}

impl<C: Communicator> Distributed<C> {
    /// Every rank of `comm` calls this: the volume `path` is scanned (each rank a share of its
    /// z-slices: value range and non-empty bricks), cut into one box per rank balanced by
    /// non-empty bricks, and each rank reads its box (and the voxel layer around it) by offset
    /// into a bricked store on `renderer`. A gzip file is inflated through by every rank.
    pub fn load(
        comm: C,
        mut renderer: Renderer,
        path: &std::path::Path,
        hints: &crate::loaders::VolumeHints,
        tf: TransferFunction,
        shading: Option<Shading>,
        scheme: Scheme,
    ) -> Result<Self> {
        let (rank, ranks) = (comm.rank() as u32, comm.size() as u32);
        let scheme = scheme.resolve(ranks)?;
        let opened = super::open(path, hints).and_then(|mut reader| {
            let nb = reader.dims.map(|d| d.div_ceil(BRICK));
            let s = scan(&mut reader, scan_layers(nb, ranks, rank))?;
            Ok((reader, s))
        });
        let (mut reader, local) = agree(&comm, opened)?;
        let whole = merge(&comm, local);
        let nb = reader.dims.map(|d| d.div_ceil(BRICK));
        let partition = Partition::new(nb, &whole.occupied(), ranks)?;
        let spacing = match hints.spacing {
            Some(s) => {
                crate::loaders::check_spacing(s, &path.display().to_string())?;
                s
            }
            None => reader.spacing,
        };
        // Placed as the file says (a sheared grid's shear), as `load_orientation` places it.
        let placement = crate::orient::respaced(reader.orientation, hints.spacing)?;
        let grid = crate::orient::placed_grid(reader.dims, spacing, placement.as_ref())?;
        let b: BrickBox = partition.boxes[rank as usize];
        let built = load_part(&mut reader, spacing, whole.range(), &b).and_then(|mut store| {
            if let Some(o) = &placement {
                store.place(o)?;
            }
            let mut scene = BrickScene::new(store, tf.clone(), shading)?;
            scene.set_part(b.lo, b.hi)?;
            scene.set_tree(partition.tree.clone())?;
            Ok(scene)
        });
        let mut scene = agree(&comm, built)?;
        if tf.gradient_weight > 0.0 {
            let mut g = 0.0f32;
            comm.all_reduce_into(&scene.gradient_max(), &mut g, SystemOperation::max());
            scene.set_gradient_max(g);
        }
        let (stored, store_bytes) = (scene.store.len() as u64, scene.store.bytes());
        // The whole volume's visible box: each rank's (its box and the voxel layer around it).
        let [lo, hi] = scene.visible_bounds().unwrap_or([[u32::MAX; 3], [0; 3]]);
        let (mut wlo, mut whi) = ([0u32; 3], [0u32; 3]);
        comm.all_reduce_into(&lo[..], &mut wlo[..], SystemOperation::min());
        comm.all_reduce_into(&hi[..], &mut whi[..], SystemOperation::max());
        let visible = (wlo[0] <= whi[0]).then_some([wlo, whi]);
        let set = renderer.set_bricks(scene);
        agree(&comm, set)?;
        Ok(Self { comm, renderer, partition, grid, scheme, stored, store_bytes, visible })
    }

    /// The box of voxels the transfer function shows across every rank (`BrickScene::visible_bounds`
    /// of the whole volume): what a camera frames.
    pub fn visible_bounds(&self) -> Option<[[u32; 3]; 2]> {
        self.visible
    }

    /// Bytes of this rank's store (its box and the voxel layer around it; `BrickStore::bytes`).
    pub fn store_bytes(&self) -> u64 {
        self.store_bytes
    }

    /// The partition of the volume over the ranks.
    pub fn partition(&self) -> &Partition {
        &self.partition
    }

    /// The grid the camera frames.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The compositing scheme run.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// This rank's renderer (its validation messages, its device).
    pub fn renderer(&self) -> &Renderer {
        &self.renderer
    }

    /// Voxels stored on each rank (at rank 0; others get an empty list).
    pub fn stored_per_rank(&self) -> Vec<u64> {
        self.gather(self.stored)
    }

    /// `local` agreed on across the ranks (`agree`): call it on a rank-local result before the
    /// next collective.
    pub fn agree<T>(&self, local: Result<T>) -> Result<T> {
        agree(&self.comm, local)
    }

    /// `v` from every rank, in rank order, at rank 0 (others get an empty list).
    pub fn gather(&self, v: u64) -> Vec<u64> {
        gather_u64(&self.comm, v)
    }

    /// Every rank calls this with the same camera and options: each draws its box (per-splat
    /// modes only: the sheet and slab modes sum along sheets that cross the boxes), then the
    /// frames are composited. `Some` at rank 0, `None` elsewhere; a background is laid under the
    /// composite at rank 0.
    pub fn render(&mut self, camera: &Camera, opts: &RenderOptions) -> Result<Option<DistributedFrame>> {
        let checked = check_options(opts);
        agree(&self.comm, checked)?;
        let mut o = opts.clone();
        o.background = None;
        let t = Instant::now();
        let drawn = self.renderer.render(camera, &o);
        let local_ms = t.elapsed().as_secs_f64() * 1e3;
        let mut frame = agree(&self.comm, drawn)?;
        let t = Instant::now();
        let split = eye_split(&self.grid, camera)?;
        // The frame's own pixels, as the floats MPI moves: no copy.
        let pixels: &mut [f32] = bytemuck::cast_slice_mut(&mut frame.image.pixels);
        let image = match self.scheme {
            Scheme::BinarySwap => binary_swap(&self.comm, &self.partition, split, pixels),
            _ => direct_send(&self.comm, &self.partition, split, pixels),
        };
        let composite_ms = t.elapsed().as_secs_f64() * 1e3;
        let mut slowest = 0.0f64;
        self.comm.all_reduce_into(&local_ms, &mut slowest, SystemOperation::max());
        let Some(pixels) = image else { return Ok(None) };
        let mut image = ImageF32 { width: camera.width, height: camera.height, pixels };
        if opts.background.is_some() {
            let push = crate::plan::present_push(opts.background, 1, false, camera.width, camera.height);
            crate::cpu::present::present(&push, &mut image, &ImageF32::new(0, 0), &[]);
        }
        let mut timings =
            vec![StageTime { stage: "render", ms: slowest }, StageTime { stage: "composite", ms: composite_ms }];
        timings.extend(frame.timings);
        Ok(Some(DistributedFrame { image, timings }))
    }
}

/// What a distributed frame cannot do, refused on every rank alike.
fn check_options(opts: &RenderOptions) -> Result<()> {
    if opts.composite != Composite::Splat {
        return Err(Error::Unsupported(
            "distributed rendering composites per-splat frames; the sheet and slab modes sum sheets across the whole \
             volume, which would need every rank's partial sums per sheet (docs/SCALE.md)"
                .into(),
        ));
    }
    if opts.render_scale != 1.0 {
        return Err(Error::Unsupported(
            "distributed rendering composites full-size frames: resampling each rank's frame and compositing them \
             is not resampling their composite; drop the render scale"
                .into(),
        ));
    }
    Ok(())
}

/// Every rank's scan merged, at every rank.
fn merge<C: Communicator>(comm: &C, local: Scan) -> Scan {
    let mut whole = local.clone();
    comm.all_reduce_into(&local.lo, &mut whole.lo, SystemOperation::min());
    comm.all_reduce_into(&local.hi, &mut whole.hi, SystemOperation::max());
    comm.all_reduce_into(&local.brick_max[..], &mut whole.brick_max[..], SystemOperation::max());
    whole
}

fn gather_u64<C: Communicator>(comm: &C, v: u64) -> Vec<u64> {
    let root = comm.process_at_rank(0);
    if comm.rank() == 0 {
        let mut all = vec![0u64; comm.size() as usize];
        root.gather_into_root(&v, &mut all[..]);
        all
    } else {
        root.gather_into(&v);
        Vec::new()
    }
}

/// Agree on `local` across the ranks: `Ok` everywhere, or on every rank the error of the lowest
/// failing rank (sent from there), so that none waits in a later collective.
pub fn agree<C: Communicator, T>(comm: &C, local: Result<T>) -> Result<T> {
    let (rank, ranks) = (comm.rank() as u32, comm.size() as u32);
    let mine = if local.is_err() { rank } else { u32::MAX };
    let mut first = u32::MAX;
    comm.all_reduce_into(&mine, &mut first, SystemOperation::min());
    if first == u32::MAX {
        return local;
    }
    let mut wire = match &local {
        Err(e) if rank == first => to_wire(e),
        _ => Vec::new(),
    };
    let root = comm.process_at_rank(first as i32);
    let mut len = wire.len() as u64;
    root.broadcast_into(&mut len);
    wire.resize(len as usize, 0);
    root.broadcast_into(&mut wire[..]);
    Err(Error::OnRank { rank: first, ranks, source: Box::new(from_wire(&wire)) })
}

/// An error as bytes: its kind, then its text fields separated by NUL.
fn to_wire(e: &Error) -> Vec<u8> {
    let (kind, fields): (u8, Vec<String>) = match e {
        Error::InvalidArgument(m) => (0, vec![m.clone()]),
        Error::InvalidCamera(m) => (1, vec![m.clone()]),
        Error::TooLarge(m) => (2, vec![m.clone()]),
        Error::Unsupported(m) => (3, vec![m.clone()]),
        Error::OutOfMemory(m) => (4, vec![m.clone()]),
        Error::DeviceLost(m) => (5, vec![m.clone()]),
        Error::Loader(m) => (6, vec![m.clone()]),
        Error::Io { path, source } => (7, vec![path.clone(), source.to_string()]),
        Error::ImageRead { path, message } => (8, vec![path.clone(), message.clone()]),
        Error::Image { path, message } => (9, vec![path.clone(), message.clone()]),
        Error::OnRank { source, .. } => return to_wire(source),
        other => (3, vec![other.to_string()]),
    };
    let mut out = vec![kind];
    out.extend(fields.join("\0").into_bytes());
    out
}

/// The error `to_wire` wrote (a Vulkan error arrives as `Unsupported` with its text).
fn from_wire(w: &[u8]) -> Error {
    let text = String::from_utf8_lossy(w.get(1..).unwrap_or_default()).into_owned();
    let mut f = text.split('\0').map(str::to_string);
    let mut next = || f.next().unwrap_or_default();
    match w.first().copied().unwrap_or(3) {
        0 => Error::InvalidArgument(next()),
        1 => Error::InvalidCamera(next()),
        2 => Error::TooLarge(next()),
        4 => Error::OutOfMemory(next()),
        5 => Error::DeviceLost(next()),
        6 => Error::Loader(next()),
        7 => Error::Io { path: next(), source: std::io::Error::other(next()) },
        8 => Error::ImageRead { path: next(), message: next() },
        9 => Error::Image { path: next(), message: next() },
        _ => Error::Unsupported(next()),
    }
}

/// Counts and displacements, in floats, of pixel ranges.
fn spans(ranges: impl Iterator<Item = std::ops::Range<usize>>) -> (Vec<i32>, Vec<i32>) {
    ranges.map(|r| ((r.len() * 4) as i32, (r.start * 4) as i32)).unzip()
}

/// Direct-send: piece i of every rank's frame goes to rank i (one all-to-all), which composites
/// the R layers in box order; rank 0 gathers the pieces.
fn direct_send<C: Communicator>(comm: &C, p: &Partition, split: [u32; 3], frame: &[f32]) -> Option<Vec<[f32; 4]>> {
    let (rank, ranks) = (comm.rank() as usize, comm.size() as usize);
    let pixels = frame.len() / 4;
    let (send_counts, send_displs) = spans((0..ranks).map(|i| piece(pixels, ranks, i)));
    let mine = piece(pixels, ranks, rank);
    let n = mine.len() * 4;
    let mut layers = vec![0f32; n * ranks];
    let recv_counts = vec![n as i32; ranks];
    let recv_displs: Vec<i32> = (0..ranks).map(|i| (i * n) as i32).collect();
    {
        let send = Parts::new(frame, &send_counts[..], &send_displs[..]);
        let mut recv = PartitionMut::new(&mut layers[..], &recv_counts[..], &recv_displs[..]);
        comm.all_to_all_varcount_into(&send, &mut recv);
    }
    let order = p.back_to_front(split);
    let mut acc = layers[order[0] as usize * n..][..n].to_vec();
    for &r in &order[1..] {
        over_into(&layers[r as usize * n..][..n], &mut acc);
    }
    gather(comm, pixels, &acc, |r| piece(pixels, ranks, r))
}

/// Binary-swap: in round k, ranks that differ in bit k (siblings under a k-d node) swap halves of
/// what they hold and composite by which side of the node's plane is nearer the eye; after
/// log2 R rounds each holds 1/R of the frame, which rank 0 gathers.
fn binary_swap<C: Communicator>(comm: &C, p: &Partition, split: [u32; 3], frame: &mut [f32]) -> Option<Vec<[f32; 4]>> {
    let (rank, ranks) = (comm.rank() as u32, comm.size() as u32);
    let pixels = frame.len() / 4;
    let rounds = ranks.trailing_zeros();
    for k in 0..rounds {
        let keep = swap_range(pixels, rank, k + 1);
        let give = swap_range(pixels, rank ^ (1 << k), k + 1);
        let mut got = vec![0f32; keep.len() * 4];
        let partner = comm.process_at_rank((rank ^ (1 << k)) as i32);
        ::mpi::point_to_point::send_receive_into(
            &frame[give.start * 4..give.end * 4],
            &partner,
            &mut got[..],
            &partner,
        );
        let first = rank & !((2 << k) - 1);
        let lower_front = p.node(first, first + (2 << k)).is_some_and(|s| Partition::lower_in_front(s, split));
        let mine = &mut frame[keep.start * 4..keep.end * 4];
        if (rank >> k & 1 == 0) == lower_front {
            over_into(mine, &mut got);
            mine.copy_from_slice(&got);
        } else {
            over_into(&got, mine);
        }
    }
    let mine = swap_range(pixels, rank, rounds);
    gather(comm, pixels, &frame[mine.start * 4..mine.end * 4], |r| swap_range(pixels, r as u32, rounds))
}

/// Rank 0 gathers each rank's composited pixels `range(r)` into the frame.
fn gather<C: Communicator>(
    comm: &C,
    pixels: usize,
    part: &[f32],
    range: impl Fn(usize) -> std::ops::Range<usize>,
) -> Option<Vec<[f32; 4]>> {
    let root = comm.process_at_rank(0);
    if comm.rank() != 0 {
        root.gather_varcount_into(part);
        return None;
    }
    let mut out = vec![[0f32; 4]; pixels];
    let (counts, displs) = spans((0..comm.size() as usize).map(range));
    let mut recv = PartitionMut::new(bytemuck::cast_slice_mut::<_, f32>(&mut out), &counts[..], &displs[..]);
    root.gather_varcount_into_root(part, &mut recv);
    Some(out)
}
