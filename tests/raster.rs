//! The footprint stage's raster variants (issue 10): quads, point sprites and compute (tile
//! compositing, fixed-point sheet sums) against each other and their mirrors; the tile lists'
//! order; early termination; footprints larger than a tile; typed errors and the auto rule.
//! On lavapipe with validation: any validation message fails a test.
use super::common;
use crate::output::diff_rgba8;
use crate::ImageF32;
use crate::{scene, Camera, Composite, Direction, Error, Grid, Projection, Raster, RenderOptions, SplatSet};
use common::{assert_clean, random_camera, random_sparse, Rng, ViewKind};
use glam::Vec3;

fn opts(composite: Composite, raster: Raster) -> RenderOptions {
    let mut o = RenderOptions::default();
    o.composite = composite;
    o.raster = raster;
    o
}

/// Largest per-channel difference in float.
fn max_abs(a: &ImageF32, b: &ImageF32) -> f32 {
    a.pixels.iter().zip(&b.pixels).flat_map(|(p, q)| (0..4).map(move |i| (p[i] - q[i]).abs())).fold(0.0, f32::max)
}

/// A handful of voxels seen from close up: footprints 40-110 px wide, far larger than a tile, placed
/// off the tile grid so they straddle tile borders, overlapping one another.
fn close_up() -> (SplatSet, Camera) {
    let grid = Grid::centered([4, 3, 2], [1.0, 1.0, 1.0]).unwrap();
    let set = SplatSet::from_fn(grid, |i, j, k| {
        ((i + j + k) % 2 == 0).then_some([0.2 + 0.2 * i as f32, 0.3 * j as f32, 0.5 * k as f32 + 0.2, 0.6])
    })
    .unwrap();
    let cam = Camera {
        eye: Vec3::new(0.37, -0.21, 7.3),
        target: Vec3::new(0.11, 0.07, 0.0),
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 50.0 },
        near: 0.5,
        far: 40.0,
        width: 157,
        height: 131,
        window: None,
    };
    (set, cam)
}

#[test]
fn raster_variants_agree_with_the_graphics_path() {
    let mut gpu = common::gpu();
    let set = scene::build("cube40-attenuated").unwrap();
    gpu.set_scene(set.clone()).unwrap();
    let persp = Camera::framing(set.grid(), 160, 128);
    let ortho = Camera { projection: Projection::Orthographic { height: 80.0 }, ..persp };
    for composite in [Composite::Splat, Composite::Sheet, Composite::Slab] {
        for (view, cam) in [("perspective", &persp), ("orthographic", &ortho)] {
            let reference = gpu.render(cam, &opts(composite, Raster::Graphics)).unwrap().image;
            let compute = gpu.render(cam, &opts(composite, Raster::Compute)).unwrap().image;
            let points = gpu.render(cam, &opts(composite, Raster::Points)).unwrap().image;
            let (c_mean, c_max) = diff_rgba8(&compute, &reference).unwrap();
            let (p_mean, p_max) = diff_rgba8(&points, &reference).unwrap();
            eprintln!(
                "{composite:?} {view}: compute mean {c_mean:.4}/255 max {c_max}/255 (float {:.2e}); \
                 points mean {p_mean:.4}/255 max {p_max}/255",
                max_abs(&compute, &reference)
            );
            // Compute evaluates the same footprints at the same pixels: only summation order and
            // the fixed-point rounding (5e-7 per add) differ.
            assert!(max_abs(&compute, &reference) < 2e-3, "{composite:?} {view}: compute differs");
            // Points: a screen-aligned square of the centre's radius. Exact up to rasterisation in an
            // orthographic view; in perspective the eye-facing quad projects slightly wider off-axis
            // (docs/RESULTS.md). Measured 0.011/255 and 0.41/255 mean; bounds 0.05 and 0.6.
            let bound = if view == "orthographic" { 0.05 } else { 0.6 };
            assert!(p_mean < bound, "{composite:?} {view}: points mean {p_mean}");
        }
    }
    assert_clean(&gpu);
}

/// The validator: every tile's list is the subsequence of the draw order made of exactly the splats
/// whose footprint box overlaps the tile.
fn check_tile_lists(order: &[u32], boxes: &[Option<[i32; 4]>], tiles_x: u32, start: &[u32], entries: &[u32]) {
    let (tw, th) = (crate::constants::RASTER_TILE_W as i32, crate::constants::RASTER_TILE_H as i32);
    let mut pos = vec![u32::MAX; boxes.len()];
    for (i, &s) in order.iter().enumerate() {
        pos[s as usize] = i as u32;
    }
    let tiles = start.len() - 1;
    assert_eq!(start[tiles] as usize, entries.len());
    for t in 0..tiles {
        let (tx, ty) = ((t as u32 % tiles_x) as i32, (t as u32 / tiles_x) as i32);
        let list = &entries[start[t] as usize..start[t + 1] as usize];
        assert!(list.windows(2).all(|w| pos[w[0] as usize] < pos[w[1] as usize]), "tile {t} not in draw order");
        let want: Vec<u32> = order
            .iter()
            .copied()
            .filter(|&s| {
                boxes[s as usize]
                    .is_some_and(|b| b[0] / tw <= tx && tx <= b[2] / tw && b[1] / th <= ty && ty <= b[3] / th)
            })
            .collect();
        assert_eq!(list, &want[..], "tile {t} holds exactly the overlapping splats");
    }
}

#[test]
fn tile_lists_keep_the_pbtf_order_and_hold_exactly_the_overlapping_splats() {
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    let mut rng = Rng(1234);
    for set in [scene::build("cube40").unwrap(), random_sparse(8, [21, 9, 14], 0.4)] {
        gpu.set_scene(set.clone()).unwrap();
        cpu.set_scene(set.clone()).unwrap();
        for v in 0..6 {
            let kind = [ViewKind::Outside, ViewKind::Inside, ViewKind::Orthographic][v % 3];
            let mut cam = random_camera(&mut rng, set.grid(), kind);
            (cam.width, cam.height) = (77, 61);
            for direction in [Direction::FrontToBack, Direction::BackToFront] {
                let mut o = opts(Composite::Splat, Raster::Compute);
                o.direction = Some(direction);
                let (start, entries) = super::probes::tile_lists(&mut gpu, &cam, &o).unwrap();
                assert_eq!(
                    (start.clone(), entries.clone()),
                    super::probes::tile_lists(&mut cpu, &cam, &o).unwrap(),
                    "GPU = mirror"
                );
                let order = crate::low_level::pbtf_order(&mut gpu, &cam, direction).unwrap();
                let frame = crate::plan::frame_for(&set, &cam, &o);
                let mut params = vec![Default::default(); set.len()];
                crate::cpu::splat_params::splat_params(&frame, set.splats(), &[], &mut params);
                let boxes: Vec<_> = params
                    .iter()
                    .map(|p| crate::cpu::footprint::screen_quad(&frame, p).map(|(_, b)| b.to_array()))
                    .collect();
                let tiles_x = crate::plan::tile_grid(&frame).0;
                check_tile_lists(&order, &boxes, tiles_x, &start, &entries);
                assert!(!entries.is_empty() || boxes.iter().all(Option::is_none), "{kind:?}: something binned");
            }
        }
    }
    assert_clean(&gpu);
}

#[test]
fn early_termination_in_the_tile_compositor_changes_no_pixel_beyond_the_threshold() {
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    let set = scene::build("solid40").unwrap();
    let framed = Camera::framing(set.grid(), 96, 80);
    // Closer, off-centre and with partial tiles (101 x 83 is not a multiple of the tile): the solid
    // runs past the right and bottom edges, where a tile's lanes also hold columns outside the image
    // that must not count towards its early termination.
    let close = Camera {
        eye: framed.target + (framed.eye - framed.target) * 0.55 + Vec3::new(6.0, -5.0, 0.0),
        width: 101,
        height: 83,
        ..framed
    };
    gpu.set_scene(set.clone()).unwrap();
    cpu.set_scene(set).unwrap();
    for cam in [framed, close] {
        let mut o = opts(Composite::Splat, Raster::Compute);
        o.early_termination = 0.0;
        let full = gpu.render(&cam, &o).unwrap().image;
        check_early_termination(&mut gpu, &mut cpu, &cam, &full);
    }
    assert_clean(&gpu);
}

fn check_early_termination(gpu: &mut crate::Renderer, cpu: &mut crate::Renderer, cam: &Camera, full: &ImageF32) {
    for threshold in [crate::options::DEFAULT_EARLY_TERMINATION, 0.3] {
        let mut o = opts(Composite::Splat, Raster::Compute);
        o.early_termination = threshold;
        let g = gpu.render(cam, &o).unwrap().image;
        let c = cpu.render(cam, &o).unwrap().image;
        let change = max_abs(&g, full);
        let (max, mean) = common::assert_mirrors(&g, &c, &format!("early termination {threshold}"));
        eprintln!(
            "{}x{} threshold {threshold}: largest change {change:.5}; GPU vs mirror max {max:.2e} mean {mean:.2e}",
            cam.width, cam.height
        );
        assert!(change <= threshold + 1e-5, "threshold {threshold}: a pixel changed by {change}");
        if threshold >= 0.3 {
            assert!(change > 0.0, "early termination skipped nothing");
        }
    }
}

#[test]
fn footprints_larger_than_a_tile_and_straddling_tiles_render_correctly() {
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    let (set, cam) = close_up();
    gpu.set_scene(set.clone()).unwrap();
    cpu.set_scene(set).unwrap();
    for composite in [Composite::Splat, Composite::Sheet] {
        let reference = gpu.render(&cam, &opts(composite, Raster::Graphics)).unwrap().image;
        let covered = reference.pixels.iter().filter(|p| p[3] > 0.05).count();
        assert!(covered > 157 * 131 / 4, "{composite:?}: the splats fill the view ({covered} px)");
        let g = gpu.render(&cam, &opts(composite, Raster::Compute)).unwrap().image;
        let c = cpu.render(&cam, &opts(composite, Raster::Compute)).unwrap().image;
        eprintln!(
            "{composite:?}: compute vs graphics {:.2e}, GPU vs mirror {:.2e}",
            max_abs(&g, &reference),
            max_abs(&g, &c)
        );
        assert!(max_abs(&g, &reference) < 2e-3, "{composite:?}: compute = graphics");
        assert!(max_abs(&g, &c) < 2e-3, "{composite:?}: GPU = mirror");
    }
    assert_clean(&gpu);
}

/// The tile compositor's two builds (entries loaded one per lane and passed round by subgroup
/// shuffles, lanes synced by subgroup barriers; or loaded by every lane, synced by workgroup
/// barriers, with a shared open-pixel count) composite the same entries with the same arithmetic.
#[test]
fn tile_compositor_without_subgroup_shuffles_matches_the_shuffled_build() {
    let mut owner = common::gpu();
    assert!(owner.context().unwrap().subgroup_shuffle(), "lavapipe has compute subgroup shuffles");
    // SAFETY: the owning renderer's handles stay alive until the adopting renderer is dropped.
    let ctx = unsafe { crate::vk::Context::from_host(owner.context().unwrap().handles()) }.unwrap();
    ctx.disable_subgroup_shuffle();
    let mut guest = crate::Renderer::with_context(ctx).unwrap();
    let cube = scene::build("cube40-attenuated").unwrap();
    let solid = scene::build("solid40").unwrap();
    let (near, near_cam) = close_up();
    let cases = [
        (cube.clone(), Camera::framing(cube.grid(), 96, 80), None, 0.0),
        (cube.clone(), Camera::framing(cube.grid(), 96, 80), Some(Direction::BackToFront), 0.0),
        (solid.clone(), Camera::framing(solid.grid(), 96, 80), None, 0.3),
        (near, near_cam, None, 0.0),
    ];
    for (i, (set, cam, direction, threshold)) in cases.into_iter().enumerate() {
        owner.set_scene(set.clone()).unwrap();
        guest.set_scene(set).unwrap();
        let mut o = opts(Composite::Splat, Raster::Compute);
        o.direction = direction;
        o.early_termination = threshold;
        common::assert_same_frame(&mut owner, &mut guest, &cam, &o, &format!("case {i}, shuffled vs plain"));
    }
    drop(guest);
    assert_clean(&owner);
}

#[test]
fn compute_raster_is_bit_identical_run_to_run() {
    let mut gpu = common::gpu();
    let set = scene::build("cube40-attenuated").unwrap();
    let cam = Camera::framing(set.grid(), 96, 80);
    gpu.set_scene(set).unwrap();
    for composite in [Composite::Splat, Composite::Sheet, Composite::Slab] {
        let o = opts(composite, Raster::Compute);
        let a = gpu.render(&cam, &o).unwrap().image;
        let b = gpu.render(&cam, &o).unwrap().image;
        assert!(common::covered(&a) > 96 * 80 / 10, "{composite:?}: the cube is drawn");
        assert!(a == b, "{composite:?}: fixed-point sums and ordered tile lists repeat exactly");
    }
    assert_clean(&gpu);
}

/// Why `auto` takes point sprites in perspective views too: against the volumetric truth they
/// score as well as the eye-facing quads they stand in for, from a narrow to a wide field of view
/// (their difference from the quads is 3-8x below either one's error here).
#[test]
fn points_in_perspective_are_as_close_to_the_truth_as_the_quads() {
    use crate::metrics::compare;
    use crate::truth::{volumetric_summation, Reconstruction, TruthOptions};
    let mut gpu = common::gpu();
    let set = scene::build("cube40").unwrap();
    gpu.set_scene(set.clone()).unwrap();
    for fov in [20.0f32, 60.0] {
        // The 35-degree framing's eye: at 20 degrees the cube overflows the view, at 60 it is small.
        let mut cam = Camera::framing(set.grid(), 128, 128);
        cam.projection = Projection::Perspective { fov_y_deg: fov };
        // The truth reconstructs with the frames' kernel (the default).
        let reconstruction = Reconstruction::Kernel(RenderOptions::default().kernel);
        let truth = volumetric_summation(&set, &cam, &TruthOptions { reconstruction, ..Default::default() }).unwrap();
        let quads = gpu.render(&cam, &opts(Composite::Splat, Raster::Graphics)).unwrap().image;
        let points = gpu.render(&cam, &opts(Composite::Splat, Raster::Points)).unwrap().image;
        let (q, p) = (compare(&quads, &truth).unwrap().rmse, compare(&points, &truth).unwrap().rmse);
        let between = compare(&points, &quads).unwrap().rmse;
        eprintln!("fov {fov}: RMSE vs truth quads {q:.5} points {p:.5}; points vs quads {between:.5}");
        assert!(p <= q * 1.05, "fov {fov}: points {p} against quads {q}");
        assert!(between < 0.5 * q, "fov {fov}: points and quads differ by {between}, the error is {q}");
    }
    assert_clean(&gpu);
}

#[test]
fn points_refuse_motion_blur_and_footprints_wider_than_the_device_draws() {
    let mut gpu = common::gpu();
    let set = scene::build("cube40").unwrap();
    let cam = Camera::framing(set.grid(), 64, 48);
    gpu.set_scene(set).unwrap();
    let mut o = opts(Composite::Splat, Raster::Points);
    o.motion = Some(crate::Motion::straight(glam::Mat4::IDENTITY, 1.0));
    assert!(matches!(gpu.render(&cam, &o), Err(Error::InvalidArgument(m)) if m.contains("motion")));
    // A voxel a hair in front of the eye: its footprint is thousands of pixels wide.
    let (set, mut close) = close_up();
    close.eye = Vec3::new(0.0, 0.0, 1.2);
    close.width = 2048;
    close.height = 2048;
    gpu.set_scene(set).unwrap();
    let err = gpu.render(&close, &opts(Composite::Splat, Raster::Points)).unwrap_err();
    assert!(matches!(&err, Error::InvalidArgument(m) if m.contains("point sprite")), "{err}");
    assert!("triangles".parse::<Raster>().is_err());
    assert_clean(&gpu);
}

#[test]
fn auto_rule_compute_for_small_footprints_else_points_where_they_fit_else_graphics_and_says_so() {
    use crate::raster::{choose, Device};
    let set = scene::build("cube40").unwrap();
    let small = Camera::framing(set.grid(), 96, 80);
    let cpu = Device { cpu: true, point_size_max: 64.0, graphics: true };
    let wide_points = Device { cpu: true, point_size_max: 256.0, graphics: true };
    let pick = |set: &SplatSet, cam: &Camera, o: &RenderOptions, d: Device| choose(set, cam, o, d).unwrap();
    let mut blurred = opts(Composite::Splat, Raster::Auto);
    blurred.motion = Some(crate::Motion::straight(glam::Mat4::IDENTITY, 1.0));

    // Small footprints: the tile compositor (ahead of the sprites up to 15 px, docs/RESULTS.md).
    let c = pick(&set, &small, &opts(Composite::Splat, Raster::Auto), cpu);
    assert_eq!(c.raster, Raster::Compute, "{}", c.reason);
    assert!(c.reason.contains("tile compositor"), "{}", c.reason);
    // Wider ones: point sprites wherever they fit, in perspective too.
    let large = Camera::framing(set.grid(), 480, 384);
    let c = pick(&set, &large, &opts(Composite::Splat, Raster::Auto), cpu);
    assert_eq!(c.raster, Raster::Points, "{}", c.reason);
    assert!(c.reason.contains("perspective"), "{}", c.reason);
    // Sub-pixel footprints: the device would clamp a sprite to its smallest point; compute
    // samples pixel centres as the quads do.
    let tiny = Camera::framing(set.grid(), 24, 20);
    let c = pick(&set, &tiny, &opts(Composite::Splat, Raster::Auto), cpu);
    assert_eq!(c.raster, Raster::Compute, "{}", c.reason);
    let ortho = Camera { projection: Projection::Orthographic { height: 80.0 }, ..large };
    let c = pick(&set, &ortho, &opts(Composite::Splat, Raster::Auto), cpu);
    assert_eq!(c.raster, Raster::Points, "{}", c.reason);
    let c = pick(&set, &small, &opts(Composite::Sheet, Raster::Auto), cpu);
    assert_eq!(c.raster, Raster::Compute, "small sheet footprints: fixed-point sums: {}", c.reason);
    let c = pick(&set, &small, &blurred, cpu);
    assert_eq!(c.raster, Raster::Compute, "motion blur, small footprints: the tile compositor: {}", c.reason);
    let hw = Device { cpu: false, point_size_max: 64.0, graphics: true };
    assert_eq!(pick(&set, &small, &opts(Composite::Splat, Raster::Auto), hw).raster, Raster::Graphics);

    // Footprints 40-110 px: past a 64-px point size the quads; within a 256-px one point sprites,
    // sheets included; never points with motion blur.
    let (close, cam) = close_up();
    assert_eq!(pick(&close, &cam, &opts(Composite::Splat, Raster::Auto), cpu).raster, Raster::Graphics);
    assert_eq!(pick(&close, &cam, &opts(Composite::Sheet, Raster::Auto), cpu).raster, Raster::Graphics);
    assert_eq!(pick(&close, &cam, &opts(Composite::Splat, Raster::Auto), wide_points).raster, Raster::Points);
    assert_eq!(pick(&close, &cam, &opts(Composite::Sheet, Raster::Auto), wide_points).raster, Raster::Points);
    assert_eq!(pick(&close, &cam, &blurred, wide_points).raster, Raster::Graphics);

    // The renderer resolves auto per frame and reports what it drew.
    let mut gpu = common::gpu();
    gpu.set_scene(set).unwrap();
    let frame = gpu.render(&small, &opts(Composite::Splat, Raster::Auto)).unwrap();
    let choice = frame.raster.expect("a splatted frame reports its raster");
    assert!(choice.reason.starts_with("auto: CPU device"), "{}", choice.reason);
    assert_clean(&gpu);
}

/// Every pixel a sheet's footprints write lies on a composite tile whose sheet range holds that
/// sheet (so the composite, which reads only those layers, misses nothing), for quads and points:
/// all entries drawn at once into one layer per global sheet by the footprint mirror.
fn check_sheet_tiles_cover(set: &SplatSet, cam: &Camera, o: &RenderOptions, tiles: &[u32]) -> usize {
    use crate::cpu::footprint::{footprint, Blend, FootprintInputs};
    use crate::plan::{frame_for, sheet_plan, sheet_tiles_push, Prepared};
    let prep = Prepared::new(set.clone());
    let frame = frame_for(set, cam, o);
    let mut params = vec![Default::default(); set.len()];
    crate::cpu::splat_params::splat_params(&frame, set.splats(), &[], &mut params);
    let (draw, batches) = if o.composite == Composite::Sheet {
        let (axis, batches) = sheet_plan(&prep, cam, o.direction(), 1 << 16);
        (prep.slices[axis].1.clone(), batches)
    } else {
        let pc =
            crate::plan::slab::slab_geometry(&frame, set.grid(), set.len(), o.slab_thickness, o.direction()).unwrap();
        slab_bins(&pc, &params)
    };
    let push = sheet_tiles_push(&batches, &batches[0]);
    let sheets = batches.iter().map(|b| b.push.rank_base as usize + b.layers as usize).max().unwrap() + 1;
    let (table, slice_table) = (o.kernel.radial_table(), o.kernel.slice_table());
    let inputs = FootprintInputs {
        frame: &frame,
        params: &params,
        draw_list: &draw,
        splats: set.splats(),
        sheet_rank: &prep.ranks,
        table: &table,
        slice_table: &slice_table,
        occlusion: &[],
        host_depth: &[],
    };
    let mut layers = vec![ImageF32::new(cam.width, cam.height); sheets];
    let points = o.raster == Raster::Points;
    footprint(&inputs, &push, Blend::Add, points, false, 0, push.count, &mut layers);
    let tile = crate::constants::COMPOSITE_TILE;
    let (tiles_x, n) = (cam.width.div_ceil(tile), tiles.len() / 2);
    let mut written = 0;
    for (s, layer) in layers.iter().enumerate() {
        for (i, px) in layer.pixels.iter().enumerate() {
            if px.iter().all(|&c| c == 0.0) {
                continue;
            }
            let (x, y) = (i as u32 % cam.width, i as u32 / cam.width);
            let t = ((y / tile) * tiles_x + x / tile) as usize;
            let (lo, hi) = (tiles[t], tiles[n + t]);
            assert!(lo as usize <= s && s < hi as usize, "pixel ({x}, {y}) of sheet {s}: tile {t} holds {lo}..{hi}");
            written += 1;
        }
    }
    written
}

#[test]
fn sheet_tiles_match_the_mirror_and_cover_every_footprint() {
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    let mut rng = Rng(77);
    let (near_set, near_cam) = close_up();
    let mut cases = vec![(near_set, near_cam)];
    for set in [scene::build("cube40").unwrap(), random_sparse(3, [19, 11, 16], 0.3)] {
        for kind in [ViewKind::Outside, ViewKind::Inside, ViewKind::Orthographic] {
            let mut cam = random_camera(&mut rng, set.grid(), kind);
            (cam.width, cam.height) = (83, 69);
            cases.push((set.clone(), cam));
        }
    }
    let mut skipped_share = Vec::new();
    for (set, cam) in &cases {
        gpu.set_scene(set.clone()).unwrap();
        cpu.set_scene(set.clone()).unwrap();
        for composite in [Composite::Sheet, Composite::Slab] {
            for raster in [Raster::Graphics, Raster::Points, Raster::Compute] {
                let o = opts(composite, raster);
                let tiles = match super::probes::sheet_tiles(&mut gpu, cam, &o) {
                    Err(Error::InvalidArgument(_)) if raster == Raster::Points => continue, // wider than a point
                    t => t.unwrap(),
                };
                assert_eq!(
                    tiles,
                    super::probes::sheet_tiles(&mut cpu, cam, &o).unwrap(),
                    "{composite:?} {raster:?}: GPU = mirror"
                );
                let written = check_sheet_tiles_cover(set, cam, &o, &tiles);
                assert!(written > 0, "{composite:?} {raster:?}: something drawn");
                // The share of (tile, sheet) pairs the composite no longer visits.
                let n = tiles.len() / 2;
                let sheets = (0..n).filter(|&t| tiles[n + t] > 0).map(|t| tiles[n + t]).max().unwrap_or(0);
                let visited: u64 = (0..n).map(|t| tiles[n + t].saturating_sub(tiles[t].min(tiles[n + t])) as u64).sum();
                skipped_share.push(1.0 - visited as f64 / (n as u64 * sheets as u64) as f64);
            }
        }
    }
    // A single sheet seen head-on: too few layer pixels per splat for the pass to pay; every tile
    // then lets the composite read every layer.
    let sheet = crate::scene::rate_scene(64).unwrap();
    let cam = crate::scene::rate_camera(sheet.grid(), 5.0).unwrap();
    gpu.set_scene(sheet).unwrap();
    let tiles = super::probes::sheet_tiles(&mut gpu, &cam, &opts(Composite::Sheet, Raster::Compute)).unwrap();
    let n = tiles.len() / 2;
    let [lo, hi] = crate::plan::ALL_SHEETS;
    assert!(tiles[..n].iter().all(|&t| t == lo) && tiles[n..].iter().all(|&t| t == hi), "single sheet: all layers");
    // Not a bound on speed: that the ranges skip anything at all on these sparse scenes.
    let mean = skipped_share.iter().sum::<f64>() / skipped_share.len() as f64;
    assert!(mean > 0.2, "tile ranges skip {:.0}% of (tile, sheet) pairs", 100.0 * mean);
    assert_clean(&gpu);
}

/// The slab binning on the CPU mirrors, straight (the oracle beside the recording's): the pairs
/// and the batches.
fn slab_bins(
    pc: &crate::gpu_types::SlabPush,
    params: &[crate::gpu_types::SplatParams],
) -> (Vec<u32>, Vec<crate::plan::Batch>) {
    let mut counts = vec![0u32; (pc.slabs * pc.chunks) as usize];
    let mut start = vec![0u32; pc.slabs as usize + 1];
    crate::cpu::slab_count::slab_count(pc, params, None, &mut counts);
    crate::cpu::slab_scan::slab_scan(pc, &mut counts, &mut start);
    let batches = crate::plan::slab::slab_batches(pc, &start, 1 << 16).unwrap();
    let mut pairs = vec![0u32; 2 * start[pc.slabs as usize] as usize];
    crate::cpu::slab_scatter::slab_scatter(pc, params, None, &mut counts, &mut pairs);
    (pairs, batches)
}
