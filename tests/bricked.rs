//! Bricked volumes on the GPU path (issue 23): the brick stages (`brick_cull`, `brick_order`, `brick_params`)
//! against their CPU mirrors, the order they write (bricks by the k-d tree, voxels by PBTF) against `order::tree_bricked`
//! over a random view battery, streaming through a small budget, transfer-function changes, and
//! bad budgets. Validation on: any message fails.
use super::common;
use super::probes::splat_stage;
use crate::bricks::{BrickScene, BrickStore, BRICK};
use crate::classify::{classify, Shading, TransferFunction};
use crate::stages::{Res, StageId};
use crate::volume::ScalarVolume;
use crate::{Camera, Direction, Error, Lod, Raster, RenderOptions, Renderer, RendererOptions};
use common::{assert_clean, blob, blob_tf as tf, diff, random_camera, Rng, ViewKind};

fn renderer(gpu: bool, budget: Option<u64>) -> Renderer {
    let mut r = if gpu { common::gpu() } else { common::cpu() };
    if let Some(b) = budget {
        r.set_gpu_budget(b).unwrap();
    }
    r
}

fn opts(raster: Raster, direction: Direction) -> RenderOptions {
    let mut o = RenderOptions::default();
    (o.raster, o.direction) = (raster, Some(direction));
    o
}

fn compute(direction: Direction) -> RenderOptions {
    opts(Raster::Compute, direction)
}

#[test]
fn gpu_frames_match_the_cpu_mirrors_and_the_dense_classification() {
    let vol = blob([37, 29, 23]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 96, 80);
    let shading = Some(Shading::headlight(cam.forward()));
    let mut weighted = tf();
    weighted.gradient_weight = 0.5;
    for (tf, shading, what) in [(tf(), None, "plain"), (tf(), shading, "shaded"), (weighted, shading, "weighted")] {
        let (mut g, mut c) = (renderer(true, None), renderer(false, None));
        g.set_volume(&vol, &tf, shading).unwrap();
        c.set_volume(&vol, &tf, shading).unwrap();
        let mut dense = renderer(true, None);
        dense.set_scene(classify(&vol, &tf, shading).unwrap()).unwrap();
        for (raster, direction) in [
            (Raster::Compute, Direction::FrontToBack),
            (Raster::Compute, Direction::BackToFront),
            (Raster::Graphics, Direction::BackToFront),
            (Raster::Points, Direction::FrontToBack),
        ] {
            let o = opts(raster, direction);
            let a = g.render(&cam, &o).unwrap().image;
            let b = c.render(&cam, &o).unwrap().image;
            assert!(a.pixels.iter().any(|p| p[3] > 0.1), "{what} {raster:?}: something drawn");
            let (most, mean) = diff(&a, &b);
            assert!(most <= 2e-3 && mean <= 1e-5, "{what} {raster:?} {direction:?}: GPU vs mirror {most} / {mean}");
            // The same splats as the dense classification, in another valid visibility order.
            let d = dense.render(&cam, &o).unwrap().image;
            let (most, mean) = diff(&a, &d);
            assert!(most <= 0.05 && mean <= 2e-3, "{what} {raster:?} {direction:?}: bricked vs dense {most} / {mean}");
        }
        assert_clean(&g);
        assert_clean(&dense);
    }
}

/// The voxels of the frame's splats in draw order (read back once the splats are made).
fn drawn_sequence(r: &mut Renderer, cam: &Camera, o: &RenderOptions) -> Vec<[u32; 3]> {
    let got = r.probe(cam, o, splat_stage(o), &[Res::BrickSlots, Res::BrickVoxels]).unwrap();
    let total: u32 = got[0].iter().map(|w| w & 1023).sum();
    got[1].chunks_exact(2).take(total as usize).map(|v| crate::cpu::brick::voxel_ijk([v[0], v[1]])).collect()
}

#[test]
fn bricks_in_k_d_tree_order_then_voxels_in_pbtf_on_both_engines() {
    let vol = blob([37, 29, 23]);
    let store = BrickStore::build(&vol).unwrap();
    let set = store.classify(&tf(), None).unwrap();
    let grid = *set.grid();
    let nb = store.dims.map(|d| d.div_ceil(BRICK));
    let tree = crate::kdtree::build(nb, 1, |id| store.index[id] != u32::MAX);
    assert!(tree.len() >= 3, "the tree cuts the bricks: {tree:?}");
    let (mut g, mut c) = (renderer(true, None), renderer(false, None));
    g.set_volume(&vol, &tf(), None).unwrap();
    c.set_volume(&vol, &tf(), None).unwrap();
    let mut rng = Rng(2323);
    let mut views = 0;
    for kind in [ViewKind::Outside, ViewKind::Inside, ViewKind::OnGridPlane, ViewKind::Orthographic] {
        for v in 0..12 {
            let mut cam = random_camera(&mut rng, &grid, kind);
            if v % 3 == 0 {
                // The eye on a brick plane.
                let a = v as usize % 3;
                cam.eye[a] =
                    grid.origin[a] + (BRICK as f32 * (1 + v % 2) as f32 - 0.5 * (v % 2) as f32) * grid.spacing[a];
            }
            if cam.validate().is_err() {
                continue;
            }
            for direction in [Direction::FrontToBack, Direction::BackToFront] {
                // Voxels, at full detail (the mixed-level order is tests/lod.rs's).
                let mut o = opts(Raster::Graphics, direction);
                o.lod = Lod::Off;
                let got = drawn_sequence(&mut g, &cam, &o);
                assert_eq!(got, drawn_sequence(&mut c, &cam, &o), "{kind:?} {v}: GPU vs mirror sequence");
                let mut want: Vec<[u32; 3]> = crate::order::tree_bricked(&set, &cam, BRICK, &tree)
                    .unwrap()
                    .iter()
                    .map(|&s| {
                        let ijk = set.splats()[s as usize].ijk;
                        [ijk[0], ijk[1], ijk[2]]
                    })
                    .collect();
                if direction == Direction::BackToFront {
                    want.reverse();
                }
                // Culled bricks drop out; what is drawn keeps the reference's sequence.
                let kept: std::collections::HashSet<[u32; 3]> = got.iter().copied().collect();
                want.retain(|v| kept.contains(v));
                assert_eq!(got.len(), want.len(), "{kind:?} {v}: drawn voxels are the classified ones");
                assert_eq!(got, want, "{kind:?} {v} {direction:?}: tree order, then PBTF");
                // And the order validator on what is drawn: no 6-neighbour pair against its plane.
                let drawn =
                    crate::SplatSet::from_fn(grid, |i, j, k| kept.contains(&[i, j, k]).then_some([1.0, 1.0, 1.0, 0.5]))
                        .unwrap();
                let seq: Vec<u32> = got.iter().map(|v| drawn.find(v[0], v[1], v[2]).unwrap() as u32).collect();
                let bad = crate::order::count_violations(&drawn, &cam, &seq, direction).unwrap();
                assert_eq!(bad, 0, "{kind:?} {v} {direction:?}: validator violations");
                views += 1;
            }
        }
    }
    assert!(views >= 80, "{views} views checked");
    // From outside, framing the grid, nothing is culled.
    let cam = Camera::framing(&grid, 64, 64);
    let o = opts(Raster::Graphics, Direction::BackToFront);
    assert_eq!(drawn_sequence(&mut g, &cam, &o).len(), set.len());
    assert_clean(&g);
}

#[test]
fn streaming_through_a_small_budget_draws_the_same_frame() {
    let vol = blob([61, 53, 47]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 80, 80);
    for gpu in [true, false] {
        let mut whole = renderer(gpu, None);
        whole.set_volume(&vol, &tf(), None).unwrap();
        let scene = whole.volume().unwrap();
        // Room for about a fifth of the splats in each batch.
        let least = crate::plan::bricked_min_budget(scene, u64::MAX, 80, 80);
        let splats = scene.store.len() as u64;
        let budget = least + splats / 5 * crate::plan::BATCH_BYTES_PER_SPLAT;
        assert!(!scene.streams(budget), "the store stays resident");
        let mut streamed = renderer(gpu, Some(budget));
        streamed.set_volume(&vol, &tf(), None).unwrap();
        let slots = streamed.probe(&cam, &compute(Direction::FrontToBack), StageId::BrickCull, &[Res::BrickSlots]);
        let drawn: u64 = slots.unwrap()[0].iter().map(|w| (w & 1023) as u64).sum();
        assert!(drawn > 3 * (splats / 5 + 512), "{drawn} splats: several batches");
        for direction in [Direction::FrontToBack, Direction::BackToFront] {
            let o = compute(direction);
            let a = whole.render(&cam, &o).unwrap().image;
            let b = streamed.render(&cam, &o).unwrap();
            assert!(a.pixels.iter().any(|p| p[3] > 0.1));
            assert!(a.pixels == b.image.pixels, "gpu {gpu} {direction:?}: streamed batches change the frame");
            // The raster pipeline draws each later batch on the target (a loading render pass).
            for raster in [Raster::Graphics, Raster::Points] {
                let g = opts(raster, direction);
                let a = whole.render(&cam, &g).unwrap().image;
                assert!(a.pixels.iter().any(|p| p[3] > 0.1));
                let b = streamed.render(&cam, &g).unwrap().image;
                assert!(a.pixels == b.pixels, "gpu {gpu} {raster:?} {direction:?}: streamed batches change the frame");
            }
        }
        // A budget below the store and one brick of splats names the minimum.
        let mut tiny = renderer(gpu, Some(least - 1));
        tiny.set_volume(&vol, &tf(), None).unwrap();
        let err = tiny.render(&cam, &compute(Direction::FrontToBack)).unwrap_err();
        let mib = least.div_ceil(1 << 20);
        assert!(matches!(err, Error::TooLarge(ref m) if m.contains(&format!("minimum is {mib} MiB"))), "{err}");
        if gpu {
            assert_clean(&whole);
            assert_clean(&streamed);
        }
    }
}

#[test]
fn a_transfer_function_change_is_the_new_classification_and_empty_is_an_empty_frame() {
    let vol = blob([37, 29, 23]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 64, 64);
    let o = compute(Direction::FrontToBack);
    let mut other = tf();
    other.points = vec![(0.0, [0.2, 0.8, 0.3, 0.0]), (0.5, [0.2, 0.8, 0.3, 0.5]), (0.6, [0.0; 4])];
    other.range = Some((10.0, 90.0));
    let mut changed = renderer(true, None);
    changed.set_volume(&vol, &tf(), None).unwrap();
    let before = changed.render(&cam, &o).unwrap().image;
    changed.set_transfer_function(&other, None).unwrap();
    let after = changed.render(&cam, &o).unwrap().image;
    let mut fresh = renderer(true, None);
    fresh.set_volume(&vol, &other, None).unwrap();
    assert!(after.pixels == fresh.render(&cam, &o).unwrap().image.pixels);
    assert!(before.pixels != after.pixels);
    // Nothing extracted: an empty frame, no error (and every brick culled by its range).
    let nothing = TransferFunction { points: vec![(0.0, [1.0, 1.0, 1.0, 0.0])], ..tf() };
    changed.set_transfer_function(&nothing, None).unwrap();
    let empty = changed.render(&cam, &o).unwrap().image;
    assert!(empty.pixels.iter().all(|p| *p == [0.0; 4]));
    let slots = changed.probe(&cam, &o, StageId::BrickCull, &[Res::BrickSlots]).unwrap();
    assert!(slots[0].iter().all(|&w| w == 0));
    // A volume with nothing above its minimum draws what the TF makes of that one value, as the
    // dense path does: nothing under this ramp (tests/hostile.rs: an opaque one draws).
    let flat = ScalarVolume { dims: [9, 9, 9], spacing: [1.0; 3], values: vec![3.0; 729] };
    changed.set_volume(&flat, &tf(), None).unwrap();
    assert!(changed.render(&cam, &o).unwrap().image.pixels.iter().all(|p| *p == [0.0; 4]));
    assert_clean(&changed);
    // Not a bricked scene: a typed error.
    let mut dense = renderer(false, None);
    dense.set_scene(crate::scene::build("cube40").unwrap()).unwrap();
    assert!(matches!(dense.set_transfer_function(&other, None), Err(Error::InvalidArgument(_))));
    let _ = BrickScene::new; // the scene type embedders build themselves
    let _ = RendererOptions::default().gpu_budget_bytes;
}

/// Front to back with early termination (the default), bricks are drawn in shells around the eye
/// (`order::brick_shell`), the tree's order within a shell, so each wave covers the picture: on
/// random views (outside, inside, on a brick plane, orthographic) both engines draw the same
/// sequence, its shells never decrease, and no 6-neighbour pair is drawn against its plane.
#[test]
fn waves_front_to_back_draw_bricks_in_shells_around_the_eye() {
    let vol = blob([61, 47, 39]);
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let store = BrickStore::build(&vol).unwrap();
    let (mut g, mut c) = (renderer(true, None), renderer(false, None));
    g.set_volume(&vol, &tf(), None).unwrap();
    c.set_volume(&vol, &tf(), None).unwrap();
    let set = store.classify(&tf(), None).unwrap();
    let mut rng = Rng(4747);
    let (mut views, mut shells_seen) = (0, 0);
    for kind in [ViewKind::Outside, ViewKind::Inside, ViewKind::OnGridPlane, ViewKind::Orthographic] {
        for v in 0..8 {
            let mut cam = random_camera(&mut rng, &grid, kind);
            if v % 3 == 0 {
                // The eye on a brick plane.
                let a = v as usize % 3;
                cam.eye[a] = grid.origin[a] + BRICK as f32 * (1 + v % 2) as f32 * grid.spacing[a];
            }
            if cam.validate().is_err() {
                continue;
            }
            let mut o = compute(Direction::FrontToBack);
            (o.early_termination, o.lod) = (1.0 / 1024.0, Lod::Off);
            // Every visible brick drawn (one batch), in the order the waves cut.
            o.cull_hidden_bricks = false;
            let got = drawn_sequence(&mut g, &cam, &o);
            assert_eq!(got, drawn_sequence(&mut c, &cam, &o), "{kind:?} {v}: GPU vs mirror sequence");
            assert!(!got.is_empty(), "{kind:?} {v}");
            let split = crate::order::brick_split(&set, &cam, BRICK);
            let shells: Vec<u32> = got.iter().map(|v| crate::order::brick_shell(v.map(|c| c / BRICK), split)).collect();
            assert!(shells.windows(2).all(|w| w[0] <= w[1]), "{kind:?} {v}: shells out of order");
            shells_seen += usize::from(shells[0] < *shells.last().unwrap());
            let kept: std::collections::HashSet<[u32; 3]> = got.iter().copied().collect();
            let drawn =
                crate::SplatSet::from_fn(grid, |i, j, k| kept.contains(&[i, j, k]).then_some([1.0, 1.0, 1.0, 0.5]))
                    .unwrap();
            let seq: Vec<u32> = got.iter().map(|v| drawn.find(v[0], v[1], v[2]).unwrap() as u32).collect();
            let bad = crate::order::count_violations(&drawn, &cam, &seq, Direction::FrontToBack).unwrap();
            assert_eq!(bad, 0, "{kind:?} {v}: validator violations");
            views += 1;
        }
    }
    assert!(views >= 24 && shells_seen >= 20, "{views} views, {shells_seen} with several shells");
    assert_clean(&g);
}

#[test]
fn dropping_hidden_bricks_front_to_back_changes_nothing_and_drops_some() {
    let vol = blob([120, 100, 90]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 96, 96);
    // Opaque material: most bricks lie behind the front ones.
    let opaque = TransferFunction { points: vec![(0.05, [0.0; 4]), (0.1, [0.8, 0.5, 0.3, 0.95])], ..tf() };
    // At full detail, and with levels of detail (the default; at 192², since at 96² most bricks
    // draw coarser cells and the frame's splats fit one wave).
    for (lod, least, size) in [(Lod::Off, 10, 96), (Lod::Auto, 3, 192)] {
        let cam = Camera { width: size, height: size, ..cam };
        let mut stats = Vec::new();
        for gpu in [true, false] {
            let mut r = renderer(gpu, None);
            r.set_volume(&vol, &opaque, None).unwrap();
            let mut o = compute(Direction::FrontToBack);
            (o.early_termination, o.lod) = (1.0 / 1024.0, lod);
            let culled = r.render(&cam, &o).unwrap();
            let st = culled.stats;
            assert!(st.bricks_hidden > least, "gpu {gpu} {lod:?}: {st:?}");
            stats.push(st);
            o.cull_hidden_bricks = false;
            let kept = r.render(&cam, &o).unwrap();
            assert!(kept.image.pixels.iter().any(|p| p[3] > 0.5));
            assert_eq!(kept.stats.bricks_hidden, 0);
            // The same bricks visible; the hidden ones' splats drawn only when kept.
            assert_eq!(kept.stats.bricks_visible, culled.stats.bricks_visible);
            assert!(kept.stats.splats > culled.stats.splats, "{:?} {:?}", kept.stats, culled.stats);
            let culled = culled.image;
            assert!(culled.pixels == kept.image.pixels, "gpu {gpu} {lod:?}: dropping hidden bricks changed the frame");
            if gpu {
                assert_clean(&r);
            }
        }
        // The GPU stages and their mirrors drop the same bricks.
        assert_eq!(stats[0], stats[1], "{lod:?}");
    }
}

/// Front to back with early termination (the default), a translucent volume hides nothing from
/// the second wave on: the rest is drawn in one more batch, not in the remaining waves, and the
/// frame is the one drawn without dropping bricks (itself one batch: the waves are cut only to drop
/// bricks). Opaque material keeps its waves (`dropping_hidden_bricks_...`).
#[test]
fn waves_stop_where_nothing_is_hidden() {
    let vol = blob([120, 100, 90]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 96, 96);
    let faint = TransferFunction { points: vec![(0.05, [0.0; 4]), (0.1, [0.8, 0.5, 0.3, 0.02])], ..tf() };
    for gpu in [true, false] {
        let mut r = renderer(gpu, None);
        r.set_volume(&vol, &faint, None).unwrap();
        let mut o = compute(Direction::FrontToBack);
        o.lod = Lod::Off;
        let waved = r.render(&cam, &o).unwrap();
        assert_eq!(waved.stats.bricks_hidden, 0, "gpu {gpu}: {:?}", waved.stats);
        assert_eq!(waved.stats.waves, 2, "gpu {gpu}: the first wave, then the rest at once: {:?}", waved.stats);
        o.cull_hidden_bricks = false;
        let one = r.render(&cam, &o).unwrap();
        assert_eq!(one.stats.waves, 1, "gpu {gpu}: {:?}", one.stats);
        assert_eq!(one.stats.splats, waved.stats.splats);
        let (most, _) = diff(&one.image, &waved.image);
        assert!(most < 1e-5, "gpu {gpu}: {most}");
        if gpu {
            assert_clean(&r);
        }
    }
}

/// A store past one storage binding of records (`RECORD_PAGE`) binds them as pages: the brick
/// stages' paged builds read the same voxels as the mirrors, from the last page too (the eye on the
/// high-z side, so the first batch holds the bricks whose records come last).
#[test]
fn a_store_of_more_than_one_record_page_reads_every_page() {
    let dims = [340u32, 340, 300];
    let n = dims.iter().map(|&d| d as usize).product::<usize>();
    assert!(n > crate::constants::RECORD_PAGE as usize);
    let mut values = vec![200.0f32; n];
    values[0] = 0.0;
    for (i, v) in values.iter_mut().enumerate() {
        if i % 7 == 3 {
            *v = 120.0 + (i % 50) as f32;
        }
    }
    let vol = ScalarVolume { dims, spacing: [1.0; 3], values };
    let grid = crate::Grid::centered(dims, vol.spacing).unwrap();
    let store = BrickStore::build(&vol).unwrap();
    drop(vol);
    let scene = BrickScene::new(store, tf(), None).unwrap();
    let mut cam = Camera::framing(&grid, 48, 48);
    cam.eye = grid.center() + glam::Vec3::new(30.0, 40.0, 900.0);
    cam.far = 2000.0;
    // Full detail: this far, levels of detail would draw the bricks from their pyramids, which
    // read no records.
    let mut o = compute(Direction::FrontToBack);
    o.lod = crate::Lod::Off;
    let what = [Res::BrickSlots, Res::BrickVoxels];
    let (mut g, mut c) = (renderer(true, None), renderer(false, None));
    g.set_bricks(scene.clone()).unwrap();
    c.set_bricks(scene).unwrap();
    let a = g.probe(&cam, &o, StageId::BrickOrder, &what).unwrap();
    let b = c.probe(&cam, &o, StageId::BrickOrder, &what).unwrap();
    let differ: Vec<_> = a[0].iter().zip(&b[0]).enumerate().filter(|(_, (x, y))| x != y).take(4).collect();
    let count = a[0].iter().zip(&b[0]).filter(|(x, y)| x != y).count();
    assert_eq!(count, 0, "brick_cull's counts differ at {count} slots, first {differ:?}");
    // The first batch's splats: the bricks in slot order up to the batch capacity.
    let budget = crate::constants::DEFAULT_GPU_BUDGET;
    let resident = crate::plan::bricked_resident_bytes(g.volume().unwrap(), budget, 48, 48);
    let capacity =
        ((budget - resident) / crate::plan::BATCH_BYTES_PER_SPLAT).min(crate::constants::MAX_GPU_SPLATS as u64) as u32;
    let mut first = 0;
    for w in a[0].iter().filter(|&&w| w != 0) {
        if first + (w & 1023) > capacity {
            break;
        }
        first += w & 1023;
    }
    let batch = 2 * first as usize;
    assert!(batch > 0 && a[1].len() >= batch && b[1].len() >= batch);
    let count = a[1][..batch].iter().zip(&b[1][..batch]).filter(|(x, y)| x != y).count();
    assert_eq!(count, 0, "brick_order's voxels differ in {count} words");
    // The first batch reaches the last page: its voxels lie at the high-z end of the grid.
    let top = a[1][..batch].chunks(2).filter(|v| v[1] & 0xffff >= 290).count();
    assert!(top > 1000, "{top} voxels of the last slices in the first batch");
    assert_clean(&g);
}

/// A store whose records would take more than half the budget stays on the host: each batch
/// uploads its bricks' records. The same frame as the resident store, bit for bit, on both
/// engines; gradients (which read neighbouring bricks) are refused with the budget that keeps the
/// store resident.
#[test]
fn a_store_larger_than_the_budget_allows_streams_batch_by_batch() {
    let vol = blob([61, 53, 47]);
    // 64², so the images leave the streamed store's resident part (headers, masks with their
    // counts, index) and a brick of splats room under twice its records.
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 64, 64);
    for gpu in [true, false] {
        let mut resident = renderer(gpu, None);
        resident.set_volume(&vol, &tf(), None).unwrap();
        let scene = resident.volume().unwrap();
        let records = scene.store.records.len() as u64 * 4;
        // Under twice the records, the store streams; above the streamed minimum, it draws.
        let budget = 2 * records - 1;
        assert!(scene.streams(budget));
        let least = crate::plan::bricked_min_budget(scene, budget, 64, 64);
        assert!(least < budget, "{least} < {budget}");
        let mut streamed = renderer(gpu, Some(budget));
        streamed.set_volume(&vol, &tf(), None).unwrap();
        for raster in [Raster::Compute, Raster::Graphics] {
            for direction in [Direction::FrontToBack, Direction::BackToFront] {
                // Full detail: the budget is the full-detail minimum (levels of detail streamed
                // are tests/lod.rs's).
                let mut o = opts(raster, direction);
                o.lod = Lod::Off;
                let a = resident.render(&cam, &o).unwrap().image;
                assert!(a.pixels.iter().any(|p| p[3] > 0.1));
                let b = streamed.render(&cam, &o).unwrap().image;
                assert!(a.pixels == b.pixels, "gpu {gpu} {raster:?} {direction:?}: a streamed store changes the frame");
            }
        }
        let mut et = opts(Raster::Compute, Direction::FrontToBack);
        (et.early_termination, et.lod) = (1.0 / 1024.0, Lod::Off);
        let a = resident.render(&cam, &et).unwrap().image;
        assert!(a.pixels == streamed.render(&cam, &et).unwrap().image.pixels, "gpu {gpu}: hidden bricks, streamed");
        streamed.set_transfer_function(&tf(), Some(Shading::headlight(cam.forward()))).unwrap();
        let err = streamed.render(&cam, &et).unwrap_err();
        assert!(matches!(err, Error::Unsupported(ref m) if m.contains("keeps it resident")), "{err}");
        // A projection does not shade: the shaded store streams in MIP, as the unshaded one draws
        // (every voxel: a streamed store would upload its records twice for MIP's texels).
        let mut mip = RenderOptions::default();
        (mip.mode, mip.raster, mip.every_voxel) = (crate::Mode::Mip, Raster::Compute, true);
        resident.set_transfer_function(&tf(), None).unwrap();
        let plain = resident.render(&cam, &mip).unwrap().image;
        assert!(plain.pixels == streamed.render(&cam, &mip).unwrap().image.pixels, "gpu {gpu}: MIP, streamed, shaded");
        if gpu {
            assert_clean(&resident);
            assert_clean(&streamed);
        }
    }
}

/// The raster variants and directions the sheet-mode tests draw.
const SHEET_RASTERS: [(Raster, Direction); 4] = [
    (Raster::Compute, Direction::FrontToBack),
    (Raster::Compute, Direction::BackToFront),
    (Raster::Graphics, Direction::BackToFront),
    (Raster::Points, Direction::FrontToBack),
];

#[test]
fn sheet_and_slab_modes_draw_a_bricked_volume_as_they_draw_its_dense_classification() {
    use crate::Composite;
    let vol = blob([37, 29, 23]);
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let mut rng = Rng(23);
    // Outside, and inside the volume (the sheets split at the eye's plane).
    let cams = [Camera::framing(&grid, 96, 80), random_camera(&mut rng, &grid, ViewKind::Inside)];
    let shading = Some(Shading::headlight(cams[0].forward()));
    for (shading, what) in [(None, "plain"), (shading, "shaded")] {
        let (mut g, mut c) = (renderer(true, None), renderer(false, None));
        g.set_volume(&vol, &tf(), shading).unwrap();
        c.set_volume(&vol, &tf(), shading).unwrap();
        let mut dense = renderer(true, None);
        dense.set_scene(classify(&vol, &tf(), shading).unwrap()).unwrap();
        for (v, cam) in cams.iter().enumerate() {
            for composite in [Composite::Sheet, Composite::Slab] {
                for (raster, direction) in SHEET_RASTERS {
                    if v == 1 && raster == Raster::Points {
                        continue; // footprints next to the eye pass the widest point sprite
                    }
                    let mut o = opts(raster, direction);
                    o.composite = composite;
                    // Small batches: several batches of layers per frame.
                    o.sheet_budget_bytes = 6 * cam.width as u64 * cam.height as u64 * 16;
                    let tag = format!("{what} view {v} {composite:?} {raster:?} {direction:?}");
                    let a = g.render(cam, &o).unwrap().image;
                    let b = c.render(cam, &o).unwrap().image;
                    assert!(a.pixels.iter().any(|p| p[3] > 0.05), "{tag}: something drawn");
                    let (most, mean) = diff(&a, &b);
                    assert!(most <= 2e-3 && mean <= 1e-5, "{tag}: GPU vs mirror {most} / {mean}");
                    // The same splats in the same sheets: only the stored values' 16-bit
                    // quantisation (and, for float sums, the summation order) differ.
                    let d = dense.render(cam, &o).unwrap().image;
                    let (most, mean) = diff(&a, &d);
                    assert!(most <= 2e-3 && mean <= 2e-5, "{tag}: bricked vs dense {most} / {mean}");
                }
            }
        }
        assert_clean(&g);
        assert_clean(&dense);
    }
    // Through a budget that holds a fraction of the visible voxels, the sheets stream: per batch
    // of sheets, the bricks that reach it, part by part. Fixed-point sums are exact whatever the
    // order, so the compute frames are the same bit for bit; float sums differ in rounding only.
    let cam = &cams[0];
    let sheet_budget = 6 * cam.width as u64 * cam.height as u64 * 16;
    for gpu in [true, false] {
        let mut whole = renderer(gpu, None);
        whole.set_volume(&vol, &tf(), None).unwrap();
        let least = crate::plan::bricked_min_budget(whole.volume().unwrap(), u64::MAX, 96, 80);
        let splats = whole.volume().unwrap().store.len() as u64;
        let budget = least + 2 * sheet_budget + splats / 6 * crate::plan::BATCH_BYTES_PER_SPLAT;
        let mut small = renderer(gpu, Some(budget));
        small.set_volume(&vol, &tf(), None).unwrap();
        for composite in [Composite::Sheet, Composite::Slab] {
            for (raster, direction) in SHEET_RASTERS {
                let mut o = opts(raster, direction);
                (o.composite, o.sheet_budget_bytes) = (composite, sheet_budget);
                let tag = format!("gpu {gpu} {composite:?} {raster:?} {direction:?}");
                let a = whole.render(cam, &o).unwrap().image;
                let b = small.render(cam, &o).unwrap().image;
                assert!(a.pixels.iter().any(|p| p[3] > 0.05), "{tag}: something drawn");
                if raster == Raster::Compute {
                    assert!(a.pixels == b.pixels, "{tag}: streamed sheets change the frame");
                } else {
                    let (most, _) = diff(&a, &b);
                    assert!(most <= 1e-5, "{tag}: streamed sheets change the frame by {most}");
                }
            }
        }
        // Below the layers and one brick of splats: a typed error naming what to change.
        let mut tiny = renderer(gpu, Some(least + 4096));
        tiny.set_volume(&vol, &tf(), None).unwrap();
        let mut o = compute(Direction::FrontToBack);
        (o.composite, o.sheet_budget_bytes) = (Composite::Sheet, sheet_budget);
        let err = tiny.render(cam, &o).unwrap_err();
        assert!(matches!(err, Error::TooLarge(ref m) if m.contains("--sheet-budget-mib")), "{err}");
        if gpu {
            assert_clean(&whole);
            assert_clean(&small);
        }
    }
}

#[test]
fn a_built_in_scene_as_a_palette_volume_classifies_back_to_its_splats() {
    // The plane fills its grid (no empty voxel to be the store's minimum); the cubes are hollow.
    for name in ["plane", "cube40", "cube40-attenuated"] {
        let set = crate::scene::build(name).unwrap();
        let scene = BrickScene::from_palette(&set).unwrap();
        let back = scene.store.classify(scene.transfer_function(), None).unwrap();
        assert_eq!(back.len(), set.len(), "{name}: splats");
        for (a, b) in set.splats().iter().zip(back.splats()) {
            assert_eq!(a.ijk[..3], b.ijk[..3], "{name}");
            assert!(a.color.iter().zip(&b.color).all(|(x, y)| (x - y).abs() < 1e-6), "{name}: {a:?} vs {b:?}");
        }
    }
    let grid = crate::Grid::centered([70, 1, 1], [1.0; 3]).unwrap();
    let many = crate::SplatSet::from_fn(grid, |i, _, _| Some([i as f32 / 70.0, 0.5, 0.5, 0.5])).unwrap();
    let err = BrickScene::from_palette(&many).unwrap_err();
    assert!(matches!(err, crate::Error::InvalidArgument(_)), "{err}");
    assert!(err.to_string().contains("more than 64 colours"), "{err}");
}

/// A streamed store keeps the records it used on the device (`RecordCache`): the same view again
/// uploads none, a turned view only those its cache lacks, and the frames are the resident
/// store's bit for bit. (The CPU engine keeps nothing between frames: it uploads every frame.)
#[test]
fn a_streamed_store_uploads_only_the_records_its_cache_lacks() {
    let vol = blob([120, 110, 100]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 80, 80);
    let mut turned = cam;
    turned.eye = cam.target + glam::Quat::from_rotation_y(0.35) * (cam.eye - cam.target);
    for gpu in [true, false] {
        let mut resident = renderer(gpu, None);
        resident.set_volume(&vol, &tf(), None).unwrap();
        let records = resident.volume().unwrap().store.records.len() as u64 * 4;
        let budget = 2 * records - 1;
        let mut streamed = renderer(gpu, Some(budget));
        streamed.set_volume(&vol, &tf(), None).unwrap();
        assert!(streamed.volume().unwrap().streams(budget), "the store streams");
        // Levels of detail (the error bound lifted) keep the far bricks coarse: their cells need
        // no records, and the near bricks' fit the cache.
        let mut o = compute(Direction::FrontToBack);
        (o.lod_pixels, o.lod_error) = (1.0, crate::options::MAX_LOD_ERROR);
        let first = streamed.render(&cam, &o).unwrap();
        let again = streamed.render(&cam, &o).unwrap();
        let want = resident.render(&cam, &o).unwrap().image;
        assert!(want.pixels == first.image.pixels, "gpu {gpu}: the streamed frame is not the resident store's");
        assert!(want.pixels == again.image.pixels, "gpu {gpu}: the cached frame is not the resident store's");
        let t = streamed.render(&turned, &o).unwrap();
        assert!(resident.render(&turned, &o).unwrap().image.pixels == t.image.pixels, "gpu {gpu}: turned");
        if gpu {
            let st = again.stats;
            assert!(first.stats.bytes_uploaded > 0 && st.records_resident > 0, "{:?}", first.stats);
            assert!(st.bricks_visible > st.bricks_coarse, "some bricks draw their voxels: {st:?}");
            assert_eq!(st.bytes_uploaded, 0, "the same view again uploads nothing ({st:?})");
            // Every fine brick's records, were none cached.
            let fine = |s: &crate::FrameStats| (s.bricks_visible - s.bricks_coarse) as u64;
            assert!(
                t.stats.bytes_uploaded * 2 < fine(&t.stats) * st.records_resident / fine(&st),
                "a 20-degree turn re-uploads {} bytes ({:?})",
                t.stats.bytes_uploaded,
                t.stats
            );
            assert_clean(&streamed);
        }
    }
}

/// The occlusion map's two levels (each tile's largest transmittance, its open pixels as bits)
/// answer a pixel box exactly as the pixels do: a box is hidden when none of its pixels (clamped
/// to the frame) has more than the threshold left. Random frames of closed and open pixels, sizes
/// that leave partial tiles at the edges, boxes small and large, inside and across the border.
#[test]
fn the_occlusion_map_answers_a_box_as_its_pixels_do() {
    use crate::cpu::tile_occlusion::{box_hidden, tile_occlusion};
    use crate::plan::occlusion_len;
    let threshold = 1.0 / 1024.0;
    let mut rng = Rng(0x6f63_636c);
    let (mut hidden, mut open) = (0, 0);
    for (w, h, closed) in [(64, 48, 0.9), (37, 29, 0.97), (100, 70, 0.995), (9, 17, 0.5)] {
        let mut accum = crate::image::ImageF32::new(w, h);
        for p in accum.pixels.iter_mut() {
            // Closed: opaque or within the threshold; open: just past it, or clear.
            p[3] = if rng.f32() < closed { 1.0 - threshold * rng.f32() } else { 1.0 - threshold * (1.5 + rng.f32()) };
        }
        let mut map = vec![0u32; occlusion_len(w, h) as usize];
        tile_occlusion(&accum, threshold, &mut map);
        let mut frame: crate::gpu_types::Frame = bytemuck::Zeroable::zeroed();
        (frame.blur[2], frame.blur[3]) = (w as f32, h as f32);
        for _ in 0..4000 {
            let x0 = (rng.f32() * (w + 8) as f32) as i32 - 4;
            let y0 = (rng.f32() * (h + 8) as f32) as i32 - 4;
            let side = if rng.f32() < 0.8 { 1 + (rng.f32() * 6.0) as i32 } else { 1 + (rng.f32() * 40.0) as i32 };
            let bx = glam::IVec4::new(x0, y0, x0 + side - 1, y0 + (rng.f32() * side as f32) as i32);
            let clamp = |v: i32, n: u32| v.clamp(0, n as i32 - 1);
            let truth = (clamp(bx.y, h)..=clamp(bx.w, h)).all(|y| {
                (clamp(bx.x, w)..=clamp(bx.z, w))
                    .all(|x| 1.0 - accum.pixels[(y as u32 * w + x as u32) as usize][3] <= threshold)
            });
            assert_eq!(box_hidden(&frame, &map, bx), truth, "{w}x{h}: box {bx}");
            (hidden, open) = if truth { (hidden + 1, open) } else { (hidden, open + 1) };
        }
    }
    assert!(hidden > 1000 && open > 1000, "both answers tried: {hidden} hidden, {open} open");
}

/// A motion-blurred quad reaches back along its path, past the footprint box the hidden-brick
/// test projects: a blurred frame drops no brick between waves, and it is the frame drawn without
/// the test, bit for bit.
#[test]
fn motion_blurred_frames_drop_no_hidden_brick() {
    let vol = blob([120, 100, 90]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 96, 96);
    let opaque = TransferFunction { points: vec![(0.05, [0.0; 4]), (0.1, [0.8, 0.5, 0.3, 0.95])], ..tf() };
    for gpu in [true, false] {
        let mut r = renderer(gpu, None);
        r.set_volume(&vol, &opaque, None).unwrap();
        let mut o = compute(Direction::FrontToBack);
        (o.early_termination, o.lod) = (1.0 / 1024.0, Lod::Off);
        // Without blur the same frame drops bricks (the test above): the guard is what keeps them.
        assert!(r.render(&cam, &o).unwrap().stats.bricks_hidden > 10, "gpu {gpu}");
        o.motion = Some(crate::Motion::straight(glam::Mat4::from_translation(glam::Vec3::new(40.0, 0.0, 0.0)), 0.5));
        let blurred = r.render(&cam, &o).unwrap();
        assert_eq!(blurred.stats.bricks_hidden, 0, "gpu {gpu}: {:?}", blurred.stats);
        assert!(blurred.stats.waves > 1, "gpu {gpu}: {:?}", blurred.stats);
        o.cull_hidden_bricks = false;
        let kept = r.render(&cam, &o).unwrap();
        assert!(blurred.image.pixels == kept.image.pixels, "gpu {gpu}");
        if gpu {
            assert_clean(&r);
        }
    }
}

/// Issue 44: uniform bricks (no records; their value in the header) draw on the device as their
/// mirrors and the dense classification draw them, resident or streamed, with levels of detail
/// and without.
#[test]
fn uniform_bricks_draw_as_their_voxels_do() {
    let vol = common::flat_blocks([64, 56, 72]);
    let tf = TransferFunction {
        points: vec![(0.05, [0.0; 4]), (0.3, [0.9, 0.5, 0.2, 0.2]), (1.0, [1.0, 1.0, 0.9, 0.6])],
        gradient_weight: 0.0,
        range: None,
        threshold: 0.0,
    };
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let cam = Camera::framing(&grid, 72, 64);
    let mut dense = renderer(true, None);
    dense.set_scene(classify(&vol, &tf, None).unwrap()).unwrap();
    let mut whole = renderer(true, None);
    whole.set_volume(&vol, &tf, None).unwrap();
    let scene = whole.volume().unwrap();
    assert!(scene.store.headers.iter().filter(|h| h.is_uniform()).count() >= 12);
    let least = crate::plan::bricked_min_budget(scene, u64::MAX, 72, 64);
    let most = scene.store.records.len() as u64 * 8; // streams below twice the records
    assert!(least < most, "{least} {most}");
    let budget = (least + most) / 2;
    assert!(scene.streams(budget), "the store streams at {budget} bytes");
    for stream in [false, true] {
        let b = stream.then_some(budget);
        let (mut g, mut c) = (renderer(true, b), renderer(false, b));
        g.set_volume(&vol, &tf, None).unwrap();
        c.set_volume(&vol, &tf, None).unwrap();
        for lod in [Lod::Off, Lod::Auto] {
            let mut o = compute(Direction::FrontToBack);
            o.lod = lod;
            let a = g.render(&cam, &o).unwrap().image;
            assert!(a.pixels.iter().filter(|p| p[3] > 0.1).count() > 500, "stream {stream} {lod:?}: something drawn");
            let (most, mean) = diff(&a, &c.render(&cam, &o).unwrap().image);
            assert!(most <= 2e-3 && mean <= 1e-5, "stream {stream} {lod:?}: GPU vs mirror {most} / {mean}");
            if lod == Lod::Off {
                let (most, mean) = diff(&a, &dense.render(&cam, &o).unwrap().image);
                assert!(most <= 0.05 && mean <= 2e-3, "stream {stream}: bricked vs dense {most} / {mean}");
            }
        }
        assert_clean(&g);
    }
    assert_clean(&dense);
}

/// A shaded or gradient-weighted frame reads each voxel's precomputed differences where both
/// buffers fit half of what the store leaves of the budget, and its neighbours through the store
/// where they do not: the same gradients either way (the differences are exact), on both engines,
/// in the voxels' splats and in the coarse cells' normals (`brick_pyramid`).
#[test]
fn shaded_frames_read_the_same_gradients_precomputed_or_through_the_store() {
    let vol = blob([61, 53, 47]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 80, 80);
    let shading = Some(Shading::headlight(cam.forward()));
    let mut weighted = tf();
    weighted.gradient_weight = 0.5;
    let mut fine = compute(Direction::FrontToBack);
    fine.lod = Lod::Off;
    // Cells up to 4 px and no error bound: the far bricks drawn coarser, from the pyramid
    // (gradients are what this compares, not the cut).
    let mut coarse = compute(Direction::FrontToBack);
    (coarse.lod_pixels, coarse.lod_error) = (4.0, crate::options::MAX_LOD_ERROR);
    let made = |r: &crate::Rendered| r.timings.iter().any(|t| t.stage == "gradients");
    for (tf, what) in [(tf(), "shaded"), (weighted, "weighted")] {
        let mut frames = Vec::new();
        for gpu in [true, false] {
            let mut whole = renderer(gpu, None);
            whole.set_volume(&vol, &tf, shading).unwrap();
            let scene = whole.volume().unwrap();
            // Just under four times one buffer's bytes left by the store (and the pyramid, with
            // levels of detail): they do not fit.
            let bytes = scene.store.gradient_len() * 4;
            let pyramid = crate::plan::pyramid_bytes(crate::plan::LOD_BUFFERS, scene.store.headers.len());
            let resident = crate::plan::bricked_resident_bytes(scene, u64::MAX, 80, 80);
            assert!(!scene.streams(resident + 4 * bytes), "the store stays resident");
            for (o, which, held) in [(&fine, "full detail", 0), (&coarse, "coarse cells", pyramid)] {
                let budget = resident + held + 4 * bytes - 4;
                let mut tight = renderer(gpu, Some(budget));
                tight.set_volume(&vol, &tf, shading).unwrap();
                let a = whole.render(&cam, o).unwrap();
                let b = tight.render(&cam, o).unwrap();
                // The first frame makes them; the tight budget reads through the store.
                assert!(o.lod == Lod::Auto || made(&a), "{what} gpu {gpu}: precomputed");
                assert!(!made(&b), "{what} {which} gpu {gpu}: through the store");
                assert!(a.image.pixels.iter().any(|p| p[3] > 0.1), "{what}: something drawn");
                if o.lod == Lod::Auto {
                    assert!(a.stats.bricks_coarse > 0, "{what}: coarse bricks drawn");
                }
                let (most, mean) = diff(&a.image, &b.image);
                assert!(
                    most <= 1e-5 && mean <= 1e-7,
                    "{what} {which} gpu {gpu}: precomputed vs through the store {most} / {mean}"
                );
                frames.push((a.image, b.image));
                if gpu {
                    assert_clean(&tight);
                }
            }
            // The device keeps them for the classification (the CPU engine keeps nothing across
            // frames, so it makes them for each).
            assert!(!gpu || !made(&whole.render(&cam, &fine).unwrap()), "{what}: made once per classification");
            if gpu {
                assert_clean(&whole);
            }
        }
        // Made on the first frame: the GPU's frames, then the mirrors', in the same order.
        for (g, c) in frames[..2].iter().zip(&frames[2..]) {
            for (x, y) in [(&g.0, &c.0), (&g.1, &c.1)] {
                let (most, mean) = diff(x, y);
                assert!(most <= 2e-3 && mean <= 1e-5, "{what}: GPU vs mirror {most} / {mean}");
            }
        }
    }
}
