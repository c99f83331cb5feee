//! Sort-last rendering without a transport (issue 28): a volume cut into k-d boxes, each box's
//! store read by offset and drawn alone, the images composited in the boxes' visibility order,
//! equals the whole volume drawn in one piece.
mod common;
use common::gpu;
use glam::Vec3;
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::classify::TransferFunction;
use voxsplat::distributed::{self, Partition};
use voxsplat::{Camera, Grid, ImageF32, RenderOptions, Renderer};

const STENT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/stent/stent.nrrd");

/// The frame of `path` cut into `ranks` boxes, drawn box by box on `r` and composited.
fn parts(r: &mut Renderer, path: &str, tf: &TransferFunction, ranks: u32, cam: &Camera, o: &RenderOptions) -> ImageF32 {
    let hints = Default::default();
    let mut reader = distributed::open(path.as_ref(), &hints).unwrap();
    let nb = reader.dims.map(|d| d.div_ceil(voxsplat::bricks::BRICK));
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
        r.set_bricks(scene).unwrap();
        images.push(r.render(cam, o).unwrap().image);
    }
    let flat: Vec<Vec<f32>> = images.iter().map(|i| i.pixels.iter().flatten().copied().collect()).collect();
    let refs: Vec<&[f32]> = flat.iter().map(|v| v.as_slice()).collect();
    let split = distributed::eye_split(&grid, cam).unwrap();
    let all = distributed::composite_all(&p, split, &refs);
    let mut out = ImageF32::new(cam.width, cam.height);
    for (px, c) in out.pixels.iter_mut().zip(all.chunks_exact(4)) {
        *px = [c[0], c[1], c[2], c[3]];
    }
    out
}

#[test]
fn boxes_composited_in_order_equal_the_whole() {
    let mut r = gpu();
    let tf = TransferFunction::preset("ct").unwrap();
    let store = BrickStore::load(STENT.as_ref(), &Default::default()).unwrap();
    let grid = Grid::centered(store.dims, store.spacing).unwrap();
    let outside = Camera::framing(&grid, 256, 256);
    let mut inside = outside;
    inside.eye = grid.center() + Vec3::new(10.0, -20.0, 30.0);
    inside.target = grid.center() + Vec3::new(-30.0, 40.0, -60.0);
    let o = RenderOptions::default();
    for (name, cam) in [("outside", outside), ("inside", inside)] {
        r.set_bricks(BrickScene::new(store.clone(), tf.clone(), None).unwrap()).unwrap();
        let whole = r.render(&cam, &o).unwrap().image;
        for ranks in [1, 2, 3, 4] {
            let img = parts(&mut r, STENT, &tf, ranks, &cam, &o);
            let (max, mean) = common::diff(&whole, &img);
            let worst = whole
                .pixels
                .iter()
                .zip(&img.pixels)
                .enumerate()
                .max_by(|a, b| {
                    let d = |p: &[f32; 4], q: &[f32; 4]| (0..4).map(|c| (p[c] - q[c]).abs()).fold(0.0f32, f32::max);
                    d(a.1 .0, a.1 .1).total_cmp(&d(b.1 .0, b.1 .1))
                })
                .map(|(i, _)| (i as u32 % cam.width, i as u32 / cam.width));
            eprintln!(
                "{name} {ranks}: max {max:.2e} mean {mean:.2e} covered {} at {worst:?} split {:?}",
                common::covered(&whole),
                distributed::eye_split(&grid, &cam).unwrap()
            );
        }
    }
    common::assert_clean(&r);
}
