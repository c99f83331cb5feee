//! Sort-last rendering without a transport (issue 28): a volume cut into k-d boxes, each box's
//! store read by offset and drawn alone, the images composited in the boxes' visibility order,
//! equals the whole volume drawn in one piece.
use super::common;
use crate::bricks::{BrickScene, BrickStore};
use crate::classify::TransferFunction;
use crate::distributed::{self, Partition};
use crate::{Camera, Grid, ImageF32, RenderOptions, Renderer};
use common::gpu;
use glam::Vec3;

const STENT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/stent/stent.nrrd");

/// The frame of `path` cut into `ranks` boxes, drawn box by box on `r` and composited, and the
/// tree that ordered the bricks.
fn parts(
    r: &mut Renderer,
    path: &str,
    tf: &TransferFunction,
    ranks: u32,
    cam: &Camera,
    o: &RenderOptions,
) -> (ImageF32, Vec<crate::kdtree::Node>) {
    let hints = Default::default();
    let mut reader = distributed::open(path.as_ref(), &hints).unwrap();
    let nb = reader.dims.map(|d| d.div_ceil(crate::bricks::BRICK));
    let mut scan = distributed::scan(&mut reader, distributed::scan_layers(nb, ranks, 0)).unwrap();
    for s in 1..ranks {
        scan.merge(&distributed::scan(&mut reader, distributed::scan_layers(nb, ranks, s)).unwrap());
    }
    let p = Partition::new(nb, &scan.occupied(), ranks).unwrap();
    let spacing = reader.spacing;
    let grid = Grid::centered(reader.dims, spacing).unwrap();
    let mut images = Vec::new();
    for b in &p.boxes {
        let store = distributed::load_part(&mut reader, spacing, scan.range(), b).unwrap();
        let mut scene = BrickScene::new(store, tf.clone(), None).unwrap();
        scene.set_part(b.lo, b.hi).unwrap();
        scene.set_tree(p.tree.clone()).unwrap();
        r.set_bricks(scene).unwrap();
        images.push(r.render(cam, o).unwrap().image);
    }
    let refs: Vec<&[f32]> = images.iter().map(|i| bytemuck::cast_slice(&i.pixels)).collect();
    let split = distributed::eye_split(&grid, cam).unwrap();
    let all = distributed::composite_all(&p, split, &refs);
    let out = ImageF32 { width: cam.width, height: cam.height, pixels: bytemuck::cast_slice(&all).to_vec() };
    (out, p.tree)
}

#[test]
fn boxes_composited_in_order_equal_the_whole() {
    let mut r = gpu();
    let tf = TransferFunction::preset("ct").unwrap();
    let store = BrickStore::load(STENT.as_ref(), &Default::default()).unwrap();
    let grid = Grid::centered(store.dims, store.spacing).unwrap();
    let outside = Camera::framing(&grid, 256, 256);
    let mut inside = outside;
    inside.eye = grid.center() + Vec3::new(5.0, -10.0, 40.0);
    inside.target = grid.center() + Vec3::new(0.0, 0.0, -100.0);
    (inside.near, inside.far) = (0.1, 1000.0);
    // Sort-last composites the boxes in the k-d tree's order, so the one-process frame it equals
    // draws the bricks in that order: without early termination (front to back with it, a frame
    // draws its bricks in shells around the eye, which interleave the boxes: docs/MODEL.md).
    let mut o = RenderOptions::default();
    o.early_termination = 0.0;
    for (name, cam) in [("outside", outside), ("inside", inside)] {
        r.set_bricks(BrickScene::new(store.clone(), tf.clone(), None).unwrap()).unwrap();
        let whole = r.render(&cam, &o).unwrap().image;
        assert!(common::covered(&whole) > 10_000, "{name}: the stent in view");
        for ranks in [1, 2, 3, 4] {
            let (img, tree) = parts(&mut r, STENT, &tf, ranks, &cam, &o);
            let (max, mean) = common::diff(&whole, &img);
            eprintln!("{name}, {ranks} ranks: max {max:.2e} mean {mean:.2e} from the one-process frame");
            if ranks.is_power_of_two() {
                // The ranks' tree is the one-process tree.
                assert!(max <= 2e-3, "{name}, {ranks} ranks: max {max} from the one-process frame");
            } else {
                // Three boxes of equal shares: a tree of their own, which one process draws alike.
                let mut scene = BrickScene::new(store.clone(), tf.clone(), None).unwrap();
                scene.set_tree(tree).unwrap();
                r.set_bricks(scene).unwrap();
                let same_tree = r.render(&cam, &o).unwrap().image;
                let (max, _) = common::diff(&same_tree, &img);
                assert!(max <= 2e-3, "{name}, {ranks} ranks: max {max} from one process on their tree");
            }
        }
    }
    common::assert_clean(&r);
}

#[test]
fn the_partition_is_the_top_of_the_brick_tree_balanced_by_non_empty_bricks() {
    // Non-empty bricks in one corner octant of a 8 x 8 x 16 brick grid.
    let grid = [8u32, 8, 16];
    let occupied: Vec<bool> = (0..8 * 8 * 16).map(|i| i % 8 < 4 && (i / 8) % 8 < 4 && i / 64 < 8).collect();
    for ranks in [1u32, 2, 3, 4, 5, 8] {
        let p = Partition::new(grid, &occupied, ranks).unwrap();
        assert_eq!(p.boxes.len(), ranks as usize);
        let bricks: u64 = p.boxes.iter().map(|b| b.bricks()).sum();
        assert_eq!(bricks, 8 * 8 * 16, "{ranks}: the boxes tile the grid");
        let full = |b: &distributed::BrickBox| {
            let mut n = 0;
            for z in b.lo[2]..b.hi[2] {
                for y in b.lo[1]..b.hi[1] {
                    for x in b.lo[0]..b.hi[0] {
                        n += occupied[(x + 8 * (y + 8 * z)) as usize] as u32;
                    }
                }
            }
            n
        };
        let counts: Vec<u32> = p.boxes.iter().map(full).collect();
        // Each box its share of the 128 non-empty bricks, to within one layer of them.
        let share = 128.0 / ranks as f64;
        assert!(counts.iter().all(|&c| (c as f64 - share).abs() <= 16.0), "{ranks}: balanced {counts:?}");
        if ranks.is_power_of_two() {
            assert!(counts.iter().all(|&c| c == 128 / ranks), "{ranks}: balanced {counts:?}");
            let one = crate::kdtree::build(grid, 1, |id| occupied[id]);
            assert_eq!(p.tree, one, "{ranks}: the one-process tree");
        }
        // Every eye: a back-to-front order of all ranks.
        for split in [[0, 0, 0], [4, 4, 8], [8, 8, 16], [2, 7, 3]] {
            let mut order = p.back_to_front(split);
            order.sort();
            assert_eq!(order, (0..ranks).collect::<Vec<_>>());
        }
    }
    // More ranks than the grid has bricks: the extra boxes are empty and still ranked.
    let p = Partition::new([2, 1, 1], &[true, false], 4).unwrap();
    assert_eq!(p.boxes.iter().filter(|b| b.bricks() == 0).count(), 2);
    assert_eq!(p.back_to_front([0, 0, 0]).len(), 4);
    assert!(Partition::new([2, 1, 1], &[true], 2).is_err());
}
