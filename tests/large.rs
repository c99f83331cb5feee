//! Scenes past a device limit: per-splat arrays longer than one storage binding may be (lavapipe's
//! maxStorageBufferRange is 2^27 bytes, 1.68 M of the 80-byte records) are bound as two pages, and
//! splat frames of scenes past two pages get a typed error (a ray cast takes them).
use super::common;
use crate::constants::{MAX_GPU_SPLATS, SPLAT_PAGE};
use crate::{Antialias, Camera, Composite, Error, Grid, Kernel, Raster, RenderOptions, SplatSet};
use common::{assert_clean, cpu, gpu};

/// `nx` x 100 x 100 translucent splats with a colour ramp, so neighbouring records differ.
fn block(nx: u32) -> SplatSet {
    let grid = Grid::centered([nx, 100, 100], [1.0; 3]).unwrap();
    SplatSet::from_fn(grid, |i, j, k| Some([i as f32 / nx as f32, j as f32 / 100.0, k as f32 / 100.0, 0.02])).unwrap()
}

/// The message of a `TooLarge` error; anything else fails the test.
fn too_large<T>(r: crate::Result<T>) -> String {
    match r {
        Err(Error::TooLarge(m)) => m,
        Err(e) => panic!("expected TooLarge, got {e}"),
        Ok(_) => panic!("expected TooLarge, got a result"),
    }
}

fn max_diff(a: &crate::ImageF32, b: &crate::ImageF32) -> f32 {
    a.pixels.iter().zip(&b.pixels).flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs())).fold(0.0, f32::max)
}

#[test]
fn per_splat_records_past_one_binding_range_are_paged() {
    let set = block(170);
    assert!(set.len() > SPLAT_PAGE as usize && set.len() * 80 > 1 << 27, "{} splats", set.len());
    let (mut g, mut c) = (gpu(), cpu());
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 40, 32);
    let gp = crate::low_level::splat_params(&mut g, &cam, Kernel::Gaussian, Antialias::None).unwrap();
    let cp = crate::low_level::splat_params(&mut c, &cam, Kernel::Gaussian, Antialias::None).unwrap();
    // The second page holds the last splats; unpaged, a binding clipped to the device's range lost them.
    let page = SPLAT_PAGE as usize;
    for (i, (a, b)) in gp.iter().zip(&cp).enumerate().skip(page - 2) {
        for (x, y) in [(a.center, b.center), (a.axis_u, b.axis_u), (a.emit, b.emit), (a.screen, b.screen)] {
            for k in 0..4 {
                assert!((x[k] - y[k]).abs() <= 1e-4 * (1.0 + y[k].abs()), "splat {i}: gpu {x:?} cpu {y:?}");
            }
        }
    }
    // Frames that read the second page: quads, compute sheet sums, and the tile compositor (whose
    // screen records are paged too).
    for (composite, raster) in
        [(Composite::Splat, Raster::Graphics), (Composite::Sheet, Raster::Compute), (Composite::Splat, Raster::Compute)]
    {
        let mut o = RenderOptions::default();
        o.composite = composite;
        o.raster = raster;
        let (a, b) = (g.render(&cam, &o).unwrap().image, c.render(&cam, &o).unwrap().image);
        let d = max_diff(&a, &b);
        assert!(d <= 1.0 / 255.0, "{composite:?} {raster:?}: GPU and mirror differ by {d}");
    }
    assert_clean(&g);
}

#[test]
fn scenes_past_two_pages_are_refused_with_a_typed_error() {
    let set = block(MAX_GPU_SPLATS / 10_000 + 1);
    assert!(set.len() > MAX_GPU_SPLATS as usize);
    let mut g = gpu();
    // Taken as a scene (a ray cast needs no splat arrays); a splat frame of it is refused.
    g.set_scene(set).unwrap();
    let cam = Camera::framing(&Grid::centered([MAX_GPU_SPLATS / 10_000 + 1, 100, 100], [1.0; 3]).unwrap(), 16, 16);
    let m = too_large(g.render(&cam, &RenderOptions::default()));
    assert!(m.contains("at most") && m.contains("CPU backend"), "{m}");
    assert_clean(&g);
}

/// llvmpipe ends every loop of a shader invocation once it has made 65535 iterations in all,
/// silently. Tile lists longer than one compositor dispatch can take (here up to ~10^5 entries),
/// front to back with and without early termination and back to front, composite in segments
/// that carry the accumulators; footprints so large that a binning chunk runs out are binned again
/// in shorter chunks. Both match the mirror, which has no such budget.
#[test]
fn work_past_llvmpipes_loop_budget_is_split_not_cut_short() {
    use crate::constants::TILE_SEGMENT;
    use crate::Direction;
    let (mut g, mut c) = (gpu(), cpu());
    let set = crate::scene::build("stripes128").unwrap();
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 32, 32);
    let mut o = RenderOptions::default();
    o.raster = Raster::Compute;
    let (starts, _) = super::probes::tile_lists(&mut g, &cam, &o).unwrap();
    let longest = starts.windows(2).map(|w| w[1] - w[0]).max().unwrap();
    assert!(longest > 8 * TILE_SEGMENT, "longest list {longest}");
    for (direction, stop) in
        [(None, 0.0), (Some(Direction::FrontToBack), 0.0), (Some(Direction::FrontToBack), 1.0 / 64.0)]
    {
        o.direction = direction;
        o.early_termination = stop;
        let d = max_diff(&g.render(&cam, &o).unwrap().image, &c.render(&cam, &o).unwrap().image);
        assert!(d <= 1.0 / 255.0, "{direction:?} stop {stop}: GPU and mirror differ by {d}");
    }

    // 1024 footprints 100 px wide: one binning chunk would visit ~190 000 tiles.
    let sheet = crate::scene::rate_scene(32).unwrap();
    let cam = crate::scene::rate_camera(sheet.grid(), 100.0).unwrap();
    g.set_scene(sheet.clone()).unwrap();
    c.set_scene(sheet).unwrap();
    o.direction = None;
    o.early_termination = 0.0;
    let (gs, ge) = super::probes::tile_lists(&mut g, &cam, &o).unwrap();
    let (cs, ce) = super::probes::tile_lists(&mut c, &cam, &o).unwrap();
    assert_eq!((gs.len(), ge.len()), (cs.len(), ce.len()), "tile lists");
    assert!(gs == cs && ge == ce, "the GPU's tile lists are the mirror's");
    let d = max_diff(&g.render(&cam, &o).unwrap().image, &c.render(&cam, &o).unwrap().image);
    assert!(d <= 1.0 / 255.0, "large footprints: GPU and mirror differ by {d}");
    assert_clean(&g);
}

/// The compute sheet sums give each footprint one invocation; one past the loop budget (a box of
/// 300 x 300 pixels) is a typed error naming the raster modes that draw it, not a cut footprint.
#[test]
fn sheet_sums_refuse_a_footprint_past_the_loop_budget() {
    let sheet = crate::scene::rate_scene(4).unwrap();
    let cam = crate::scene::rate_camera(sheet.grid(), 300.0).unwrap();
    let mut g = gpu();
    g.set_scene(sheet).unwrap();
    let mut o = RenderOptions::default();
    // rate_camera sizes the footprint by the Gaussian's radius: 300 px, past the budget.
    o.kernel = Kernel::Gaussian;
    o.composite = Composite::Sheet;
    o.raster = Raster::Compute;
    let m = too_large(g.render(&cam, &o));
    assert!(m.contains("--raster graphics"), "{m}");
    o.raster = Raster::Graphics;
    let img = g.render(&cam, &o).unwrap().image;
    assert!(img.pixels.iter().any(|p| p[3] > 0.0));
    assert_clean(&g);
}

/// The GPU ray caster's sample loop shares llvmpipe's loop budget: rays that could need more than
/// `MAX_GPU_RAY_STEPS` samples are a typed error, not rays cut short; so are rays longer than
/// `max_steps`, on both engines (issue 25: the mirror stopped there silently); under both it draws.
#[test]
fn gpu_rays_past_the_loop_budget_are_refused() {
    use crate::constants::MAX_GPU_RAY_STEPS;
    let set = crate::scene::build("cube40").unwrap();
    let cam = Camera::framing(set.grid(), 24, 24);
    let mut g = gpu();
    g.set_scene(set).unwrap();
    // A ~70-voxel diagonal at a 0.001-voxel step: 70 000 samples.
    let mut o = crate::RaycastOptions { step: 0.001, ..Default::default() };
    let m = too_large(g.raycast(&cam, &o));
    assert!(m.contains(&MAX_GPU_RAY_STEPS.to_string()), "{m}");
    o.step = 0.002;
    assert!(g.raycast(&cam, &o).unwrap().image.pixels.iter().any(|p| p[3] > 0.0));
    o.max_steps = 20_000;
    assert!(too_large(g.raycast(&cam, &o)).contains("max_steps"));
    assert_clean(&g);
}

/// The compute sheet sums keep a batch's fixed-point layers in one storage binding: at 512², the
/// default 256 MiB batch budget (64 layers of 4 MiB) would pass lavapipe's 128 MiB range, so the
/// batch is cut to fit; the frame matches the sheets drawn as quads.
#[test]
fn fixed_point_sheet_batches_fit_one_binding() {
    let set = crate::scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 512, 512);
    let mut g = gpu();
    g.set_scene(set).unwrap();
    let mut o = RenderOptions::default();
    // Without early termination, which caps a batch at EARLY_TERMINATION_BATCH layers.
    (o.composite, o.early_termination) = (Composite::Sheet, 0.0);
    assert!(o.batch_layers(512, 512) as u64 * 512 * 512 * 16 > 1 << 27, "the default budget passes one binding");
    o.raster = Raster::Compute;
    let sums = g.render(&cam, &o).unwrap().image;
    o.raster = Raster::Graphics;
    let quads = g.render(&cam, &o).unwrap().image;
    let d = max_diff(&sums, &quads);
    assert!(d <= 2.0 / 255.0, "sums and quads differ by {d}");
    assert_clean(&g);
}
