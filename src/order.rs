//! Visibility orders for rectilinear grids (chapter 2): BTF (Fig. 2.1), WBTF (Fig. 2.3), PBTF
//! (section 2.3), and a reference order by exact distance to the eye; plus a validator.
//!
//! Orders are computed front to back and reversed for back to front. All of them return indices
//! into [`SplatSet::splats`].
//!
//! ```
//! use voxsplat::order::{visibility_order, Direction, OrderKind};
//! use voxsplat::{scene, Camera};
//! // The PBTF order on the host: each splat once, back to front for this camera.
//! let set = scene::build("cube40")?;
//! let camera = Camera::framing(set.grid(), 64, 64);
//! let order = visibility_order(&set, &camera, OrderKind::Pbtf, Direction::BackToFront);
//! assert_eq!(order.len(), set.len());
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::volume::SplatSet;
use glam::DVec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
/// A visibility order of the grid's splats.
pub enum OrderKind {
    /// Frieder et al.: one traversal direction per axis, z outermost.
    Btf,
    /// Westover: BTF with the axis most perpendicular to the view plane outermost.
    Wbtf,
    /// Swan's perspective back-to-front order: split at the eye, traverse outward.
    #[default]
    Pbtf,
    /// Reference: sorted by exact distance to the eye (to the view plane in orthographic views).
    Sorted,
    /// PBTF with Westover's nesting in each octant (`octant_axes`): the same octants and
    /// outward traversal, the axis along which the eye sees the octant's middle farthest
    /// outermost. WBTF exactly in orthographic views, close to it in perspective views from
    /// outside the grid; computed on the host (`--order pbtf-octant`).
    PbtfOctant,
}

impl std::str::FromStr for OrderKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "btf" => Ok(Self::Btf),
            "wbtf" => Ok(Self::Wbtf),
            "pbtf" => Ok(Self::Pbtf),
            "sorted" => Ok(Self::Sorted),
            "pbtf-octant" => Ok(Self::PbtfOctant),
            _ => Err(Error::InvalidArgument(format!("unknown order '{s}' (btf, wbtf, pbtf, sorted, pbtf-octant)"))),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
/// Which way an order runs.
pub enum Direction {
    /// Nearest splats first.
    FrontToBack,
    /// Farthest splats first.
    BackToFront,
}

/// Where the viewer is, in grid index coordinates: a point (perspective) or a direction at
/// infinity (orthographic).
#[derive(Clone, Copy, Debug)]
pub enum Viewer {
    /// A perspective eye at this grid-index point.
    Eye(DVec3),
    /// An orthographic viewer looking along this grid-index direction.
    Toward(DVec3),
}

impl Viewer {
    /// The viewer of `camera`, in `set`'s grid index coordinates. On a rectilinear grid a
    /// perspective eye maps through its per-axis coordinates; an orthographic direction keeps its
    /// signs, all the orders and the validator read of it, scaled by the grid's spacing (the mean
    /// gaps, `SplatSet::with_coordinates`).
    pub fn of(set: &SplatSet, camera: &Camera) -> Self {
        if set.coordinates().is_none() || !camera.is_perspective() {
            return Self::of_grid(set.grid(), camera);
        }
        Viewer::Eye(set.index_point(camera.eye.as_dvec3()))
    }

    /// The viewer of `camera`, in `g`'s index coordinates.
    /// An affine map of grid and eye together keeps a visibility order (docs/MODEL.md), so a
    /// sheared grid is ordered from the eye mapped by its inverse cell matrix.
    pub fn of_grid(g: &crate::volume::Grid, camera: &Camera) -> Self {
        if camera.is_perspective() {
            Viewer::Eye(g.index_point(camera.eye.as_dvec3()))
        } else {
            // Index space scales each axis: directions scale by 1/spacing too.
            Viewer::Toward(g.index_dir(camera.forward().as_dvec3()))
        }
    }

    /// Which of two 6-neighbours along `axis` (at `lo` and `lo + 1`) is in front: `Some(true)` for
    /// the lower one, `Some(false)` for the upper one, `None` when the separating grid plane holds
    /// the eye (either order is correct).
    pub fn lower_in_front(&self, axis: usize, lo: u32) -> Option<bool> {
        match *self {
            Viewer::Eye(e) => {
                let mid = lo as f64 + 0.5;
                let e = e[axis];
                if e < mid {
                    Some(true)
                } else if e > mid {
                    Some(false)
                } else {
                    None
                }
            }
            Viewer::Toward(d) => {
                if d[axis] > 0.0 {
                    Some(true)
                } else if d[axis] < 0.0 {
                    Some(false)
                } else {
                    None
                }
            }
        }
    }
}

/// Voxels per axis on the eye's low side: indices `< split[a]` are visited downward from
/// `split[a] - 1`, the others upward. The split sits at the grid plane nearest the eye, so every
/// pair of 6-neighbours is ordered by the plane between them.
pub fn pbtf_split(set: &SplatSet, camera: &Camera) -> [u32; 3] {
    let dims = set.grid().dims;
    match Viewer::of(set, camera) {
        Viewer::Eye(e) => [0, 1, 2].map(|a| {
            let s = (e[a] + 0.5).floor() + 1.0;
            s.clamp(0.0, dims[a] as f64) as u32
        }),
        Viewer::Toward(d) => [0, 1, 2].map(|a| if d[a] < 0.0 { dims[a] } else { 0 }),
    }
}

/// The pure-Rust PBTF order, front to back: octants one after another, and inside each octant rows
/// (k outer, j inner) and voxels (i) visited outward from the eye.
pub fn pbtf(set: &SplatSet, split: [u32; 3]) -> Vec<u32> {
    let [_, ny, nz] = set.grid().dims;
    let mut out = Vec::with_capacity(set.len());
    let outward = |n: u32, s: u32, side: u32| -> Vec<u32> {
        if side == 0 {
            (0..s).rev().collect()
        } else {
            (s..n).collect()
        }
    };
    for octant in 0..8u32 {
        let (si, sj, sk) = (octant & 1, (octant >> 1) & 1, (octant >> 2) & 1);
        for k in outward(nz, split[2], sk) {
            for j in outward(ny, split[1], sj) {
                let r = set.row_index(j, k);
                let (s, e) = (set.row_start()[r] as usize, set.row_start()[r + 1] as usize);
                let row = &set.splats()[s..e];
                let low = row.partition_point(|sp| sp.ijk[0] < split[0]);
                if si == 0 {
                    out.extend((s..s + low).rev().map(|x| x as u32));
                } else {
                    out.extend((s + low..e).map(|x| x as u32));
                }
            }
        }
    }
    out
}

/// Two-level PBTF, front to back, over bricks of `brick`³ voxels (docs/MODEL.md,
/// "Two-level PBTF"): the bricks in PBTF order over the brick grid, and inside each brick its voxels
/// in PBTF order, both split at the eye's cell. A CPU reference (a comparison sort on the two-level
/// key); `brick` 1 and a brick covering the grid both give `pbtf` itself.
pub fn pbtf_bricked(set: &SplatSet, camera: &Camera, brick: u32) -> Result<Vec<u32>> {
    if brick == 0 {
        return Err(Error::InvalidArgument("the brick side must be at least one voxel".into()));
    }
    let voxel_split = pbtf_split(set, camera);
    let brick_split = brick_split(set, camera, brick);
    // (octant bits, then the outward rank along k, j, i) of index `v` split at `s`.
    let outward = |v: u32, s: u32| if v < s { (0u64, (s - 1 - v) as u64) } else { (1, (v - s) as u64) };
    let level = |ijk: [u32; 3], split: [u32; 3]| {
        let [(si, ri), (sj, rj), (sk, rk)] = [0, 1, 2].map(|a| outward(ijk[a], split[a]));
        (si | sj << 1 | sk << 2, rk, rj, ri)
    };
    Ok(by_key(set, |s| {
        let [i, j, k, _] = set.splats()[s].ijk;
        (level([i / brick, j / brick, k / brick], brick_split), level([i, j, k], voxel_split))
    }))
}

/// A bricked volume's draw order, front to back: the bricks as the k-d tree `tree`
/// (`kdtree`) orders them, every node's near side first and its leaves' boxes as octrees of aligned
/// blocks (each block's children by PBTF), and inside each brick its voxels in PBTF order. A CPU reference (a comparison sort on the path
/// through the tree, then the two PBTF keys).
pub fn tree_bricked(set: &SplatSet, camera: &Camera, brick: u32, tree: &[crate::kdtree::Node]) -> Result<Vec<u32>> {
    if brick == 0 {
        return Err(Error::InvalidArgument("the brick side must be at least one voxel".into()));
    }
    let voxel_split = pbtf_split(set, camera);
    let split = brick_split(set, camera, brick);
    let grid = set.grid().dims.map(|d| d.div_ceil(brick));
    let outward = |v: u32, s: u32| if v < s { (0u64, (s - 1 - v) as u64) } else { (1, (v - s) as u64) };
    let level = |ijk: [u32; 3], split: [u32; 3]| {
        let [(si, ri), (sj, rj), (sk, rk)] = [0, 1, 2].map(|a| outward(ijk[a], split[a]));
        (si | sj << 1 | sk << 2, rk, rj, ri)
    };
    // Per brick: the near (0) / far (1) turns down the tree, and the PBTF key in its leaf's box.
    let brick_key = |b: [u32; 3]| {
        let (mut lo, mut hi, mut path) = ([0u32; 3], grid, Vec::new());
        let mut n = if tree.is_empty() { crate::kdtree::LEAF } else { 0 };
        while n != crate::kdtree::LEAF {
            let node = &tree[n as usize];
            let (axis, plane) = crate::kdtree::cut(node);
            let high = b[axis] >= plane;
            path.push(u8::from(high == crate::kdtree::lower_in_front(node, split)));
            if high {
                lo[axis] = plane;
            } else {
                hi[axis] = plane;
            }
            n = node[1 + usize::from(high)];
        }
        // Inside the leaf, per block of its octree the child holding b by PBTF over the block's
        // 2 x 2 x 2 children.
        let blocks: Vec<_> = octree_descent(b, lo, hi, split).map(|step| level(step.child, step.split)).collect();
        (path, blocks)
    };
    Ok(by_key(set, |s| {
        let [i, j, k, _] = set.splats()[s].ijk;
        (brick_key([i / brick, j / brick, k / brick]), level([i, j, k], voxel_split))
    }))
}

/// One block on the way down a k-d leaf's octree to a brick (`octree_descent`).
pub struct OctreeStep {
    /// The block's lowest brick.
    pub origin: [u32; 3],
    /// Its children's side, in bricks.
    pub half: u32,
    /// Per axis, how many of its two children lie on the eye's low side (0, 1 or 2): the PBTF
    /// split of its 2 x 2 x 2 children (a child is on the low side when its lowest brick is).
    pub split: [u32; 3],
    /// The child holding the brick: 1 per axis where it is the high one.
    pub child: [u32; 3],
}

/// The blocks from the smallest aligned block (2^l bricks a side at multiples of 2^l) holding
/// the box `lo..hi` of bricks down to brick `b`, for the eye's brick split `split`: the order of a
/// k-d leaf's bricks, each block's children by PBTF (`tree_bricked`; `cpu::brick::octree_pbtf`
/// counts the bricks before `b` along it, as brick.glsl's `octree_pbtf` does).
pub fn octree_descent(b: [u32; 3], lo: [u32; 3], hi: [u32; 3], split: [u32; 3]) -> impl Iterator<Item = OctreeStep> {
    let mut l = 0;
    while (0..3).any(|a| lo[a] >> l != (hi[a] - 1) >> l) {
        l += 1;
    }
    let mut origin = lo.map(|c| c >> l << l);
    std::iter::from_fn(move || {
        if l == 0 {
            return None;
        }
        let half = 1u32 << (l - 1);
        let below = |a: usize| (split[a] as i64 - origin[a] as i64 + half as i64 - 1) / half as i64;
        let step = OctreeStep {
            origin,
            half,
            split: [0, 1, 2].map(|a| below(a).clamp(0, 2) as u32),
            child: [0, 1, 2].map(|a| u32::from(b[a] >= origin[a] + half)),
        };
        origin = [0, 1, 2].map(|a| origin[a] + step.child[a] * half);
        l -= 1;
        Some(step)
    })
}

/// Brick `b`'s shell in the front-to-back shell order of a brick grid whose eye's PBTF split is
/// `split` (`brick_split`): its distance toward the eye in bricks, summed over the axes (0 for the
/// bricks at the eye). A ray from a brick to the eye moves toward the split along every axis, so
/// whatever lies in front of a brick lies in a lower shell and bricks of one shell hide none of
/// each other: bricks sorted by shell, ties in a valid order (the k-d tree's), are a valid
/// visibility order. Its prefixes are thin shells around the eye that cover the picture, where
/// the tree's are slabs along its first cut (docs/MODEL.md, "Hidden bricks").
pub fn brick_shell(b: [u32; 3], split: [u32; 3]) -> u32 {
    (0..3).map(|a| if b[a] < split[a] { split[a] - 1 - b[a] } else { b[a] - split[a] }).sum()
}

/// The eye's PBTF split of the grid of `brick`-voxel bricks over `set`'s grid (`brick` > 0).
pub fn brick_split(set: &SplatSet, camera: &Camera, brick: u32) -> [u32; 3] {
    let dims = set.grid().dims;
    let voxel_split = pbtf_split(set, camera);
    match Viewer::of(set, camera) {
        // Brick b lies on the eye's low side when its lowest voxel does.
        Viewer::Eye(_) => [0, 1, 2].map(|a| voxel_split[a].div_ceil(brick)),
        Viewer::Toward(d) => [0, 1, 2].map(|a| if d[a] < 0.0 { dims[a].div_ceil(brick) } else { 0 }),
    }
}

/// Order by a per-splat key, ascending (a comparison sort: fine for the CPU reference orders).
fn by_key<K: PartialOrd>(set: &SplatSet, key: impl Fn(usize) -> K) -> Vec<u32> {
    let keys: Vec<K> = (0..set.len()).map(key).collect();
    let mut idx: Vec<u32> = (0..set.len() as u32).collect();
    idx.sort_by(|&a, &b| {
        keys[a as usize].partial_cmp(&keys[b as usize]).unwrap_or(std::cmp::Ordering::Equal).then(a.cmp(&b))
    });
    idx
}

/// BTF-family orders: loop nesting `axes` (outermost first), each axis traversed in the direction
/// of the view vector (front to back).
fn nested(set: &SplatSet, camera: &Camera, axes: [usize; 3]) -> Vec<u32> {
    let f = camera.forward();
    let dims = set.grid().dims;
    let rank = |a: usize, v: u32| -> u64 {
        if f[a] >= 0.0 {
            v as u64
        } else {
            (dims[a] - 1 - v) as u64
        }
    };
    by_key(set, |s| nesting_key(set.splats()[s].ijk, dims, axes, rank))
}

/// A voxel's place in loops nested as `axes` (outermost first) over a grid of `dims`, each loop
/// running by `rank(axis, index)`.
fn nesting_key(ijk: [u32; 4], dims: [u32; 3], axes: [usize; 3], rank: impl Fn(usize, u32) -> u64) -> u64 {
    let (d1, d2) = (dims[axes[1]] as u64, dims[axes[2]] as u64);
    (rank(axes[0], ijk[axes[0]]) * d1 + rank(axes[1], ijk[axes[1]])) * d2 + rank(axes[2], ijk[axes[2]])
}

/// The three axes ordered by `d`, largest first (ties keep axis order).
fn axes_by(d: [f64; 3]) -> [usize; 3] {
    let mut axes = [0usize, 1, 2];
    axes.sort_by(|&a, &b| d[b].total_cmp(&d[a]));
    axes
}

/// PBTF with the loops inside octant o (bit a: the high side of axis a) nested as `axes(o)`
/// (outermost first), front to back: the seed's "or duals" freedom (any nesting is a visibility
/// order inside an octant, each axis traversed outward from the eye). `pbtf` nests [2, 1, 0] in
/// every octant; Westover-style choices (per view, `wbtf_axes`, or per octant) are what this project
/// measures against the overlapping-splat seams.
pub fn pbtf_nested(set: &SplatSet, split: [u32; 3], axes: impl Fn(u32) -> [usize; 3]) -> Vec<u32> {
    let dims = set.grid().dims;
    let outward = |a: usize, v: u32| -> u64 {
        if v < split[a] {
            (split[a] - 1 - v) as u64
        } else {
            (v - split[a]) as u64
        }
    };
    let per_octant: Vec<[usize; 3]> = (0..8).map(&axes).collect();
    by_key(set, |s| {
        let ijk = set.splats()[s].ijk;
        let octant = (0..3).map(|a| u32::from(ijk[a] >= split[a]) << a).sum::<u32>();
        (octant, nesting_key(ijk, dims, per_octant[octant as usize], outward))
    })
}

/// Westover's nesting per PBTF octant: the axes ordered by how far the eye's view of the
/// octant's middle runs along them, farthest outermost (in an orthographic view, `wbtf_axes` in
/// every octant).
pub fn octant_axes(set: &SplatSet, camera: &Camera, split: [u32; 3]) -> [[usize; 3]; 8] {
    let dims = set.grid().dims;
    let Viewer::Eye(eye) = Viewer::of(set, camera) else { return [wbtf_axes(camera); 8] };
    std::array::from_fn(|o| {
        axes_by(std::array::from_fn(|a| {
            let s = split[a] as f64;
            let mid = if o >> a & 1 == 0 { s * 0.5 } else { (s + dims[a] as f64) * 0.5 };
            (mid - eye[a]).abs()
        }))
    })
}

/// Westover's axis permutation: most perpendicular to the view plane outermost.
pub fn wbtf_axes(camera: &Camera) -> [usize; 3] {
    let f = camera.forward().abs();
    axes_by([f.x as f64, f.y as f64, f.z as f64])
}

/// The draw sequence of `kind` in `direction`.
pub fn visibility_order(set: &SplatSet, camera: &Camera, kind: OrderKind, direction: Direction) -> Vec<u32> {
    let mut order = match kind {
        OrderKind::Pbtf => pbtf(set, pbtf_split(set, camera)),
        OrderKind::Btf => nested(set, camera, [2, 1, 0]),
        OrderKind::Wbtf => nested(set, camera, wbtf_axes(camera)),
        OrderKind::PbtfOctant => {
            let split = pbtf_split(set, camera);
            let axes = octant_axes(set, camera, split);
            pbtf_nested(set, split, |o| axes[o as usize])
        }
        OrderKind::Sorted => {
            let eye = camera.eye.as_dvec3();
            let fwd = camera.forward().as_dvec3();
            let persp = camera.is_perspective();
            by_key(set, |s| {
                let ijk = set.splats()[s].ijk;
                let p = set.position([ijk[0], ijk[1], ijk[2]]).as_dvec3();
                if persp {
                    (p - eye).length()
                } else {
                    (p - eye).dot(fwd)
                }
            })
        }
    };
    if direction == Direction::BackToFront {
        order.reverse();
    }
    order
}

/// Pairs of 6-neighbour splats drawn in the wrong order with respect to the grid plane between
/// them and the eye. `order` must be a permutation of the splats.
pub fn count_violations(set: &SplatSet, camera: &Camera, order: &[u32], direction: Direction) -> Result<u64> {
    let pos = positions(set, order)?;
    let viewer = Viewer::of(set, camera);
    let mut violations = 0u64;
    for (s, sp) in set.splats().iter().enumerate() {
        let [i, j, k, _] = sp.ijk;
        for axis in 0..3 {
            let n = match axis {
                0 => set.find(i + 1, j, k),
                1 => set.find(i, j + 1, k),
                _ => set.find(i, j, k + 1),
            };
            let Some(t) = n else { continue };
            let Some(lower_front) = viewer.lower_in_front(axis, sp.ijk[axis]) else { continue };
            let lower_first = pos[s] < pos[t];
            let want_lower_first = lower_front == (direction == Direction::FrontToBack);
            if lower_first != want_lower_first {
                violations += 1;
            }
        }
    }
    Ok(violations)
}

/// Each splat's place in `order`, which must be a permutation of the splats.
fn positions(set: &SplatSet, order: &[u32]) -> Result<Vec<u32>> {
    if order.len() != set.len() {
        return Err(Error::InvalidArgument(format!("order has {} entries for {} splats", order.len(), set.len())));
    }
    let mut pos = vec![u32::MAX; set.len()];
    for (p, &s) in order.iter().enumerate() {
        let slot = pos
            .get_mut(s as usize)
            .ok_or_else(|| Error::InvalidArgument(format!("order names splat {s} of {}", set.len())))?;
        if *slot != u32::MAX {
            return Err(Error::InvalidArgument(format!("order names splat {s} twice")));
        }
        *slot = p as u32;
    }
    Ok(pos)
}

/// What the image-space validator found (`count_pixel_inversions`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PixelInversions {
    /// Pairs of splats covering one pixel drawn against their depth along its ray, over all pixels.
    pub inversions: u64,
    /// Pixels with at least one such pair.
    pub pixels: u64,
    /// The pairs among them whose depths along the ray differ by more than the kernel's diameter:
    /// kernels that do not overlap there, so one truly hides the other (the overlapping-splat
    /// problem of neighbours, which any per-splat order has, is not among them).
    pub separated: u64,
    /// Pixels some footprint covers.
    pub covered: u64,
}

/// The image-space validator: for each pixel, the splats whose footprints (`radius`
/// voxel spacings, the kernel's) cover its centre, in draw order, and the pairs of them drawn
/// against their exact depth along that pixel's ray (back to front: a nearer splat before a
/// farther one). Unlike the 6-neighbour count, it tells WBTF from BTF, and it sees the
/// overlapping-splat problem any per-splat order has (section 1.2.2.1).
pub fn count_pixel_inversions(
    set: &SplatSet,
    camera: &Camera,
    order: &[u32],
    direction: Direction,
    radius: f32,
) -> Result<PixelInversions> {
    positions(set, order)?;
    camera.validate()?;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let world = radius as f64 * set.kernel_spacing() as f64;
    let (eye, fwd) = (camera.eye.as_dvec3(), camera.forward().as_dvec3());
    let (right, up) = (camera.right().as_dvec3(), camera.true_up().as_dvec3());
    let scale = camera.pixels_per_unit() as f64;
    let persp = camera.is_perspective();
    // The whole frame's centre in this image's pixels (a window's frame may be larger).
    let (fw, fh) = camera.frame_size();
    let (ox, oy) = camera.window.map_or((0, 0), |v| (v.x, v.y));
    let centre = (fw as f64 * 0.5 - ox as f64, fh as f64 * 0.5 - oy as f64);
    let mut depths: Vec<Vec<f64>> = vec![Vec::new(); w * h];
    for &s in order {
        let ijk = set.splats()[s as usize].ijk;
        let p = set.position([ijk[0], ijk[1], ijk[2]]).as_dvec3() - eye;
        let z = p.dot(fwd);
        if !(z > camera.near as f64 && z < camera.far as f64) {
            continue;
        }
        let k = if persp { scale / z } else { scale };
        let (cx, cy) = (centre.0 + p.dot(right) * k, centre.1 - p.dot(up) * k);
        let r = world * k;
        let (x0, x1) = ((cx - r).floor().max(0.0) as usize, ((cx + r).ceil() as usize).min(w));
        let (y0, y1) = ((cy - r).floor().max(0.0) as usize, ((cy + r).ceil() as usize).min(h));
        for y in y0..y1 {
            for x in x0..x1 {
                let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                if dx * dx + dy * dy > r * r {
                    continue;
                }
                // Depth along this pixel's ray: the ray through the pixel centre (perspective),
                // or the view direction (orthographic).
                let t = if persp {
                    let ray = (fwd + right * ((x as f64 + 0.5 - w as f64 * 0.5) / scale)
                        - up * ((y as f64 + 0.5 - h as f64 * 0.5) / scale))
                        .normalize();
                    p.dot(ray)
                } else {
                    z
                };
                depths[y * w + x].push(t);
            }
        }
    }
    let mut out = PixelInversions::default();
    for d in &mut depths {
        if d.is_empty() {
            continue;
        }
        out.covered += 1;
        // Back to front wants depths falling; count pairs that rise (front to back: the reverse).
        if direction == Direction::FrontToBack {
            d.iter_mut().for_each(|t| *t = -*t);
        }
        let (n, apart) = rising_pairs(d, 2.0 * world);
        out.separated += apart;
        out.inversions += n;
        out.pixels += u64::from(n > 0);
    }
    Ok(out)
}

/// Pairs i < j with v[j] > v[i], and those with v[j] - v[i] > gap, in one merge sort into
/// falling order (`v` is reordered).
fn rising_pairs(v: &mut [f64], gap: f64) -> (u64, u64) {
    if v.len() < 2 {
        return (0, 0);
    }
    let mid = v.len() / 2;
    let (l, r) = (rising_pairs(&mut v[..mid], gap), rising_pairs(&mut v[mid..], gap));
    let (a, b) = (v[..mid].to_vec(), v[mid..].to_vec());
    // Both halves fall: for each right element, the left ones more than `g` below it are a
    // suffix of the left half, which starts later as the right elements fall.
    let across = |g: f64| {
        let (mut i, mut n) = (0, 0u64);
        for &y in &b {
            while i < a.len() && a[i] >= y - g {
                i += 1;
            }
            n += (a.len() - i) as u64;
        }
        n
    };
    let n = (l.0 + r.0 + across(0.0), l.1 + r.1 + across(gap));
    let (mut i, mut j) = (0, 0);
    for slot in v.iter_mut() {
        if j < b.len() && (i == a.len() || b[j] > a[i]) {
            *slot = b[j];
            j += 1;
        } else {
            *slot = a[i];
            i += 1;
        }
    }
    n
}

/// The validator over a sequence of cells of mixed sizes (levels of detail): `cells`
/// in draw order, each (i, j, k, side), the cube of `side` voxels a side from voxel (i, j, k),
/// clipped to `grid`. Counts pairs of 6-neighbour voxels in different cells whose cells are drawn
/// in the wrong order with respect to the grid plane between them and the eye (the plane between
/// two cells that share a face). Cells must not overlap.
pub fn count_cell_violations(
    grid: &crate::volume::Grid,
    camera: &Camera,
    cells: &[[u32; 4]],
    direction: Direction,
) -> Result<u64> {
    let [nx, ny, nz] = grid.dims.map(|d| d as usize);
    let mut pos = vec![u32::MAX; nx * ny * nz];
    for (p, &[i, j, k, side]) in cells.iter().enumerate() {
        if side == 0 || i as usize >= nx || j as usize >= ny || k as usize >= nz {
            return Err(Error::InvalidArgument(format!("cell {p} ({i}, {j}, {k}; side {side}) is not in the grid")));
        }
        for z in k as usize..(k as usize + side as usize).min(nz) {
            for y in j as usize..(j as usize + side as usize).min(ny) {
                for x in i as usize..(i as usize + side as usize).min(nx) {
                    let slot = &mut pos[x + nx * (y + ny * z)];
                    if *slot != u32::MAX {
                        return Err(Error::InvalidArgument(format!("cells {} and {p} overlap", *slot)));
                    }
                    *slot = p as u32;
                }
            }
        }
    }
    let viewer = Viewer::of_grid(grid, camera);
    let mut violations = 0u64;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let a = pos[x + nx * (y + ny * z)];
                if a == u32::MAX {
                    continue;
                }
                let v = [x, y, z];
                for axis in 0..3 {
                    let mut n = v;
                    n[axis] += 1;
                    if n[axis] >= grid.dims[axis] as usize {
                        continue;
                    }
                    let b = pos[n[0] + nx * (n[1] + ny * n[2])];
                    if b == u32::MAX || b == a {
                        continue;
                    }
                    let Some(lower_front) = viewer.lower_in_front(axis, v[axis] as u32) else { continue };
                    if (a < b) != (lower_front == (direction == Direction::FrontToBack)) {
                        violations += 1;
                    }
                }
            }
        }
    }
    Ok(violations)
}
