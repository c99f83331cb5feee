//! The k-d tree over a bricked volume's brick grid: each node cuts its box across its
//! longest side where its non-empty bricks divide in halves (or, over sort-last ranks, in their
//! proportion), down to `TREE_DEPTH` levels. Drawn at every node near side first (or far side first, back to front), it orders the bricks (PBTF
//! within its leaves' boxes: a visibility order, as PBTF's is); its top levels are the boxes of
//! sort-last rendering's ranks. For a power of two ranks the tree is the one-process tree, so the
//! bricks of a rank's box are consecutive in the one-process order and the ranks' frames
//! composited in box order draw exactly what one process draws.

/// Most levels: up to 1024 leaves, and as many ranks.
pub const TREE_DEPTH: u32 = 10;
/// A child that is a leaf.
pub const LEAF: u32 = u32::MAX;

/// A node: `[axis | plane << 2, low child, high child, 0]` (plane in bricks; the low child's box
/// lies below it; a child index of `LEAF` is a leaf).
pub type Node = [u32; 4];

/// The tree of a grid of `grid` bricks whose non-empty ones `occupied(id)` names
/// (id = x + gx (y + gy z)), cut for `ranks` ranks: a node over n > 1 ranks gives its lower side
/// floor(n/2) of them and cuts where that share of its non-empty bricks lies below; a node of one
/// rank (and every node of a one-process tree) cuts in halves. For a power of two the ranks' cuts
/// are the halving cuts, so the tree is the one-process tree and its nodes at depth log2 R are
/// the ranks' boxes; other counts get boxes of equal shares and a tree of their own. Nodes in
/// depth-first order, the root first (none for one brick).
pub fn build(grid: [u32; 3], ranks: u32, occupied: impl Fn(usize) -> bool) -> Vec<Node> {
    let mut nodes = Vec::new();
    split(&mut nodes, grid, [[0; 3], grid], ranks.max(1), 0, &occupied);
    nodes
}

fn split(
    nodes: &mut Vec<Node>,
    g: [u32; 3],
    b: [[u32; 3]; 2],
    ranks: u32,
    depth: u32,
    occ: &dyn Fn(usize) -> bool,
) -> u32 {
    let [lo, hi] = b;
    let axis = (0..3).max_by_key(|&a| (hi[a] - lo[a], 2 - a)).unwrap_or(0);
    if depth == TREE_DEPTH || hi[axis] - lo[axis] < 2 {
        return LEAF;
    }
    let mut layers = vec![0u64; (hi[axis] - lo[axis]) as usize];
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                if occ((x + g[0] * (y + g[1] * z)) as usize) {
                    layers[([x, y, z][axis] - lo[axis]) as usize] += 1;
                }
            }
        }
    }
    let total: u64 = layers.iter().sum();
    // The lower side's share low/n: the first plane with at least that share of the non-empty
    // bricks below it (without any: of the layers), leaving a brick on each side.
    let (n, low) = if ranks > 1 { (ranks as u64, (ranks / 2) as u64) } else { (2, 1) };
    let mut plane = lo[axis] + ((hi[axis] - lo[axis]) as u64 * low / n) as u32;
    if total > 0 {
        let mut below = 0;
        for (i, c) in layers.iter().enumerate() {
            below += c;
            if below * n >= total * low {
                plane = lo[axis] + i as u32 + 1;
                break;
            }
        }
    }
    let plane = plane.clamp(lo[axis] + 1, hi[axis] - 1);
    let at = nodes.len();
    nodes.push([axis as u32 | plane << 2, LEAF, LEAF, 0]);
    let (mut low_hi, mut high_lo) = (hi, lo);
    (low_hi[axis], high_lo[axis]) = (plane, plane);
    let (r_low, r_high) = if ranks > 1 { (ranks / 2, ranks - ranks / 2) } else { (1, 1) };
    let low = split(nodes, g, [lo, low_hi], r_low, depth + 1, occ);
    let high = split(nodes, g, [high_lo, hi], r_high, depth + 1, occ);
    (nodes[at][1], nodes[at][2]) = (low, high);
    at as u32
}

/// Node `n`'s axis and plane.
pub fn cut(n: &Node) -> (usize, u32) {
    ((n[0] & 3) as usize, n[0] >> 2)
}

/// Whether the node's low side lies nearer the eye, for the eye's brick split `split`
/// (`order::brick_split`: brick b is on the eye's high side along an axis when b >= split): the
/// high side is the far one when its first brick is on the eye's high side.
pub fn lower_in_front(n: &Node, split: [u32; 3]) -> bool {
    let (axis, plane) = cut(n);
    plane >= split[axis]
}
