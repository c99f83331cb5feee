//! The projection modes (`--mode mip|minip|average|xray`): against the host's projections of the
//! classified volume with the same kernel, the GPU against the CPU mirrors in every raster, and
//! what they refuse.
use super::common;
use crate::classify::{classify, TransferFunction};
use crate::cpu::footprint::PROJECT_FULL;
use crate::cpu::splat_params::PROJECT_SHRINK;
use crate::kernel::sample_radial;
use crate::volume::ScalarVolume;
use crate::{Camera, Composite, Kernel, Mode, Projection, Raster, RenderOptions, SplatSet};
use common::{assert_clean, assert_mirrors, cpu, gpu, Rng};
use glam::Vec3;

const PROJECTIONS: [Mode; 4] = [Mode::Mip, Mode::Minip, Mode::Average, Mode::Xray];

/// A lumpy ball with a brighter core and empty space around it, on unit spacing.
fn ball(dims: [u32; 3]) -> ScalarVolume {
    let c = dims.map(|d| (d as f32 - 1.0) / 2.0);
    let mut values = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = [i, j, k].map(|v| v as f32);
                let r = ((0..3).map(|a| ((p[a] - c[a]) / (c[a] + 0.5)).powi(2)).sum::<f32>()).sqrt();
                let wobble = 0.2 * ((p[0] * 0.9).sin() * (p[1] * 0.6).cos() + (p[2] * 1.3).sin());
                values.push(if r < 0.95 { (1.1 - r + wobble).max(0.0) * 100.0 } else { 0.0 });
            }
        }
    }
    ScalarVolume { dims, spacing: [1.0; 3], values }
}

fn tf() -> TransferFunction {
    TransferFunction {
        points: vec![(0.05, [0.0, 0.0, 0.0, 0.0]), (0.3, [0.9, 0.4, 0.2, 0.2]), (1.0, [0.9, 0.9, 1.0, 0.7])],
        gradient_weight: 0.0,
        range: None,
        threshold: 0.0,
    }
}

/// An orthographic view down -z whose pixel centres fall on the voxel columns (one pixel a voxel),
/// `pad` pixels of margin on each side.
fn column_camera(dims: [u32; 3], pad: u32) -> Camera {
    scaled_column_camera(dims, pad, 1)
}

/// `column_camera` with `ppv` pixels a voxel (`pad` voxels of margin).
fn scaled_column_camera(dims: [u32; 3], pad: u32, ppv: u32) -> Camera {
    let (w, h) = (dims[0] + 2 * pad, dims[1] + 2 * pad);
    Camera {
        eye: Vec3::new(0.0, 0.0, 100.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Orthographic { height: h as f32 },
        near: 1.0,
        far: 200.0,
        width: w * ppv,
        height: h * ppv,
        window: None,
    }
}

fn options(mode: Mode, raster: Raster) -> RenderOptions {
    let mut o = RenderOptions::default();
    // The host projection below and the pixel-exact sprite sizes are the Gaussian's.
    o.kernel = Kernel::Gaussian;
    o.mode = mode;
    o.raster = raster;
    o
}

/// The host's projection of the classified volume with the kernel's footprint, computed voxel by
/// voxel (no splats, no tiles): per pixel (key, weight) as the modes blend them, MIP and MinIP
/// over the per-column maximum projection, the average and X-ray summed over every voxel.
fn host_projection(vol: &ScalarVolume, tf: &TransferFunction, mode: Mode, cam: &Camera) -> Vec<[f32; 2]> {
    let [nx, ny, nz] = vol.dims;
    let (lo, hi) = vol.values.iter().fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let table = Kernel::Gaussian.radial_table();
    // MIP and MinIP draw narrower footprints, full from a share of the centre's weight.
    let max = mode == Mode::Mip || mode == Mode::Minip;
    let radius = Kernel::Gaussian.radius() * if max { PROJECT_SHRINK } else { 1.0 };
    let centre = |d: u32, i: u32| i as f32 - (d as f32 - 1.0) / 2.0;
    // Per column: the largest key of its extracted voxels (MIP: d, MinIP: 1 - d), and its sums.
    let mut columns = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (mut best, mut any, mut sum_key, mut sum_w) = (0.0f32, false, 0.0f32, 0.0f32);
            for k in 0..nz {
                let d = (vol.values[(i + nx * (j + ny * k)) as usize] - lo) / (hi - lo);
                let a = tf.eval(d)[3];
                if a <= 0.0 {
                    continue;
                }
                any = true;
                let tau = -(1.0 - a.min(0.999)).ln();
                let key = match mode {
                    Mode::Minip => 1.0 - d,
                    Mode::Xray => 1.0,
                    _ => d,
                };
                best = best.max(key);
                // The average weighs by the footprint alone, X-ray by the optical depth.
                let w = if mode == Mode::Average { 1.0 } else { tau };
                sum_key += key * w;
                sum_w += w;
            }
            if any {
                columns.push((Vec3::new(centre(nx, i), centre(ny, j), 0.0), best, sum_key, sum_w));
            }
        }
    }
    let (w, h) = (cam.width, cam.height);
    let mut out = vec![[0.0f32; 2]; (w * h) as usize];
    for py in 0..h {
        for px in 0..w {
            // Pixels per voxel: the camera's height covers its view height in voxels.
            let ppv = match cam.projection {
                Projection::Orthographic { height } => h as f32 / height,
                _ => 1.0,
            };
            let p = Vec3::new(px as f32 + 0.5 - w as f32 / 2.0, h as f32 / 2.0 - (py as f32 + 0.5), 0.0) / ppv;
            let mut acc = [0.0f32; 2];
            for &(c, best, sum_key, sum_w) in &columns {
                let s = (p - c).length_squared() / (radius * radius);
                if s >= 1.0 {
                    continue;
                }
                let f = sample_radial(&table, s);
                if max {
                    let wgt = (f / (PROJECT_FULL * table[0])).min(1.0);
                    acc = [acc[0].max(best * wgt), acc[1].max(wgt)];
                } else {
                    acc = [acc[0] + sum_key * f, acc[1] + sum_w * f];
                }
            }
            out[(py * w + px) as usize] = acc;
        }
    }
    out
}

/// The host's (key, weight) mapped as `project.comp` maps them through the grey ramp.
fn host_pixel(mode: Mode, acc: [f32; 2], centre: f32) -> [f32; 2] {
    let ratio = if acc[1] > 0.0 { acc[0] / acc[1] } else { 0.0 };
    let (v, a) = match mode {
        Mode::Mip => (ratio, acc[1]),
        Mode::Minip => (1.0 - ratio, acc[1]),
        Mode::Average => (ratio, acc[1] / centre),
        _ => (1.0, 1.0 - (-acc[0]).exp()),
    };
    let a = a.clamp(0.0, 1.0);
    [v.clamp(0.0, 1.0) * a, a]
}

#[test]
fn an_axis_aligned_projection_equals_the_host_projection_of_the_classified_volume() {
    let vol = ball([20, 16, 12]);
    let set = classify(&vol, &tf(), None).unwrap();
    // Five pixels a voxel: MIP's point sprites (2 x 0.65 x 2 voxels) are then whole pixels wide,
    // which lavapipe's point-size rounding keeps exact.
    let cam = scaled_column_camera(vol.dims, 4, 5);
    let centre = Kernel::Gaussian.radial_table()[0];
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let mut c = cpu();
    c.set_scene(set).unwrap();
    for mode in PROJECTIONS {
        let want: Vec<[f32; 2]> =
            host_projection(&vol, &tf(), mode, &cam).into_iter().map(|acc| host_pixel(mode, acc, centre)).collect();
        assert!(want.iter().filter(|p| p[1] > 0.0).count() > 100, "{mode}: the host projection covers the ball");
        for raster in [Raster::Compute, Raster::Graphics, Raster::Points] {
            for (engine, r) in [("gpu", &mut g), ("cpu", &mut c)] {
                let img = r.render(&cam, &options(mode, raster)).unwrap().image;
                let worst = img
                    .pixels
                    .iter()
                    .zip(&want)
                    .map(|(p, q)| (p[0] - q[0]).abs().max((p[3] - q[1]).abs()))
                    .fold(0.0f32, f32::max);
                // Tolerance: f32 rounding of the footprint's position (through the inverse
                // projective map on the device); measured at most 1.4e-5 (the average, at five
                // pixels a voxel) on lavapipe.
                eprintln!("{mode} {raster} {engine}: largest difference {worst:.2e}");
                assert!(worst < 5e-5, "{mode} {raster} {engine}: largest difference {worst}");
            }
        }
    }
    assert_clean(&g);
}

#[test]
fn every_projection_mode_mirrors_on_the_cpu_in_every_raster() {
    let vol = ball([18, 14, 16]);
    let set: SplatSet = classify(&vol, &tf(), None).unwrap();
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let mut c = cpu();
    c.set_scene(set.clone()).unwrap();
    let mut rng = Rng(46);
    for (i, mode) in PROJECTIONS.into_iter().enumerate() {
        for raster in [Raster::Compute, Raster::Graphics, Raster::Points] {
            let kind = if i % 2 == 0 { common::ViewKind::Outside } else { common::ViewKind::Orthographic };
            let cam = common::random_camera(&mut rng, set.grid(), kind);
            let mut o = options(mode, raster);
            o.colormap = Some(tf());
            let (gi, ci) = (g.render(&cam, &o).unwrap().image, c.render(&cam, &o).unwrap().image);
            assert_mirrors(&gi, &ci, &format!("{mode} {raster}"));
        }
    }
    assert_clean(&g);
}

#[test]
fn a_projection_runs_no_order_stage_and_says_so_in_its_plan() {
    let set = classify(&ball([12, 12, 12]), &tf(), None).unwrap();
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 48, 48);
    for raster in [Raster::Compute, Raster::Graphics] {
        let o = options(Mode::Mip, raster);
        let plan = g.plan(&cam, &o).unwrap().to_string();
        assert!(plan.contains("mip projection") && plan.contains("order      none"), "{plan}");
        let r = g.render(&cam, &o).unwrap();
        let stages: Vec<&str> = r.timings.iter().map(|t| t.stage).collect();
        assert!(!stages.iter().any(|s| s.starts_with("order")), "{raster}: {stages:?}");
        assert!(stages.contains(&"project"), "{raster}: {stages:?}");
        let composite = g.render(&cam, &options(Mode::Composite, raster)).unwrap();
        assert!(composite.timings.iter().any(|t| t.stage.starts_with("order")), "the composite frame orders");
    }
    assert_clean(&g);
}

#[test]
fn the_mip_colour_map_colours_the_largest_value() {
    // Two voxels along one ray: the MIP pixel takes the larger value's colour, whatever the order.
    let grid = crate::Grid::centered([1, 1, 2], [1.0; 3]).unwrap();
    let set = SplatSet::from_fn_valued(grid, |_, _, k| Some(([0.5; 4], if k == 0 { 0.25 } else { 0.75 }))).unwrap();
    let mut r = cpu();
    r.set_scene(set).unwrap();
    let mut cam = column_camera([1, 1, 2], 2);
    for (eye, name) in [(100.0, "from +z"), (-100.0, "from -z")] {
        cam.eye = Vec3::new(0.0, 0.0, eye);
        let mut o = options(Mode::Mip, Raster::Compute);
        // Red below a half, green above.
        o.colormap = Some(TransferFunction {
            points: vec![(0.0, [1.0, 0.0, 0.0, 1.0]), (0.5, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 1.0, 0.0, 1.0])],
            gradient_weight: 0.0,
            range: None,
            threshold: 0.0,
        });
        let img = r.render(&cam, &o).unwrap().image;
        let centre = img.pixels[(cam.height / 2 * cam.width + cam.width / 2) as usize];
        assert!(centre[1] > 0.99 && centre[0] < 1e-6 && centre[3] > 0.99, "{name}: {centre:?}");
    }
}

#[test]
fn a_projection_refuses_what_cannot_apply() {
    let vol = ball([10, 10, 10]);
    let set = classify(&vol, &tf(), None).unwrap();
    let mut r = cpu();
    r.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 32, 32);
    let refused = |o: RenderOptions, r: &mut crate::Renderer| {
        let e = r.render(&cam, &o).unwrap_err().to_string();
        assert!(e.contains("--mode mip"), "{e}");
    };
    let mut o = options(Mode::Mip, Raster::Auto);
    o.composite = Composite::Sheet;
    refused(o, &mut r);
    let mut o = options(Mode::Mip, Raster::Auto);
    o.order = crate::OrderKind::Sorted;
    refused(o, &mut r);
    let mut o = options(Mode::Mip, Raster::Auto);
    o.direction = Some(crate::Direction::FrontToBack);
    refused(o, &mut r);
    let mut o = options(Mode::Mip, Raster::Auto);
    o.motion = Some(crate::Motion::straight(glam::Mat4::IDENTITY, 1.0));
    refused(o, &mut r);
    // A bricked volume takes no levels-of-detail flag it cannot apply: the plan draws every voxel.
    let mut b = cpu();
    let store = crate::bricks::BrickStore::build(&vol).unwrap();
    b.set_bricks(crate::bricks::BrickScene::new(store, tf(), None).unwrap()).unwrap();
    let plan = b.plan(&cam, &options(Mode::Mip, Raster::Auto)).unwrap().to_string();
    assert!(plan.contains("mip projection") && plan.contains("lod        off"), "{plan}");
    assert!(plan.contains("texels     3x3 a pixel"), "{plan}");
    let mut every = options(Mode::Mip, Raster::Auto);
    every.every_voxel = true;
    assert!(!b.plan(&cam, &every).unwrap().to_string().contains("texels"), "--every-voxel draws every voxel");
    // --every-voxel only changes what MIP and MinIP draw.
    let mut o = options(Mode::Average, Raster::Auto);
    o.every_voxel = true;
    let e = r.render(&cam, &o).unwrap_err().to_string();
    assert!(e.contains("--every-voxel") && e.contains("--mode average"), "{e}");
    // Values outside [0, 1] are refused where a set is made.
    let grid = crate::Grid::centered([2, 2, 2], [1.0; 3]).unwrap();
    let e = SplatSet::from_fn_valued(grid, |_, _, _| Some(([1.0; 4], 1.5))).unwrap_err().to_string();
    assert!(e.contains("value 1.5"), "{e}");
    assert!("maximum".parse::<Mode>().unwrap_err().to_string().contains("mip, minip"));
}

#[test]
fn the_ray_caster_projects_in_every_mode_and_mirrors_on_the_cpu() {
    let vol = ball([20, 16, 12]);
    let set = classify(&vol, &tf(), None).unwrap();
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let mut c = cpu();
    c.set_scene(set).unwrap();
    let cam = column_camera(vol.dims, 4);
    for mode in PROJECTIONS {
        let o = crate::RaycastOptions { mode, step: 0.25, ..Default::default() };
        let (gi, ci) = (g.raycast(&cam, &o).unwrap().image, c.raycast(&cam, &o).unwrap().image);
        assert_mirrors(&gi, &ci, &format!("ray-cast {mode}"));
        // Against the splats' projection of the same view: other reconstructions (trilinear
        // against the kernel), the same picture.
        let splats = g.render(&cam, &options(mode, Raster::Compute)).unwrap().image;
        let (worst, mean) = common::diff(&gi, &splats);
        eprintln!("{mode}: ray caster against splats, largest {worst:.3}, mean {mean:.4}");
        // Measured: mean 0.011 (MIP) to 0.035 (average, whose coverage the Gaussian's wider
        // footprints spread further); a mode mapped wrongly differs by far more.
        assert!(mean < 0.05, "{mode}: the ray caster and the splats differ by {mean} on average");
    }
    // Compositing is unchanged by the projection field: the two fields live apart.
    let o = crate::RaycastOptions::default();
    let (gi, ci) = (g.raycast(&cam, &o).unwrap().image, c.raycast(&cam, &o).unwrap().image);
    assert_mirrors(&gi, &ci, "ray-cast composite after the projections");
    assert_clean(&g);
}

#[test]
fn a_bricked_volume_projects_as_its_dense_splats_do() {
    let vol = ball([30, 26, 20]);
    let set = classify(&vol, &tf(), None).unwrap();
    let store = crate::bricks::BrickStore::build(&vol).unwrap();
    let scene = crate::bricks::BrickScene::new(store, tf(), None).unwrap();
    let mut g = gpu();
    let mut c = cpu();
    let mut rng = Rng(4601);
    for mode in PROJECTIONS {
        for raster in [Raster::Compute, Raster::Graphics] {
            let cam = common::random_camera(&mut rng, set.grid(), common::ViewKind::Outside);
            let o = options(mode, raster);
            // A dense set draws every voxel; MIP and MinIP of a store by default the brightest of
            // each texel (below).
            let extreme = matches!(mode, Mode::Mip | Mode::Minip);
            let mut every = o.clone();
            every.every_voxel = extreme;
            g.set_scene(set.clone()).unwrap();
            let dense = g.render(&cam, &o).unwrap().image;
            g.set_bricks(scene.clone()).unwrap();
            let bricked = g.render(&cam, &every).unwrap();
            c.set_bricks(scene.clone()).unwrap();
            assert_mirrors(&bricked.image, &c.render(&cam, &every).unwrap().image, &format!("bricked {mode} {raster}"));
            // The store holds values in 16 bits and draws its bricks in another order (sums
            // round otherwise): the same frame to within that.
            let (worst, _) = common::diff(&bricked.image, &dense);
            assert!(worst < 2e-3, "{mode} {raster}: bricked against dense, largest difference {worst}");
            assert_eq!(bricked.stats.bricks_coarse, 0, "no levels of detail in a projection");
            assert_eq!(bricked.stats.splats_outshone, 0, "{mode}: every voxel drawn");
            if extreme {
                // The brightest voxel of each texel: the mirror draws the same, and the frame
                // stays close to every voxel's.
                let texels = g.render(&cam, &o).unwrap();
                assert_mirrors(&texels.image, &c.render(&cam, &o).unwrap().image, &format!("texels {mode} {raster}"));
                let (worst, mean) = common::diff(&texels.image, &bricked.image);
                let dropped = texels.stats.splats_outshone as f64 / bricked.stats.splats as f64;
                eprintln!(
                    "{mode} {raster}: texels drop {dropped:.3} of the voxels; largest {worst:.3}, mean {mean:.5}"
                );
                assert!(texels.stats.splats_outshone > 0, "{mode} {raster}: the texels drop voxels");
                assert_eq!(texels.stats.splats + texels.stats.splats_outshone, bricked.stats.splats);
                assert!(mean < 2e-3, "{mode} {raster}: texels against every voxel, mean difference {mean}");
            }
        }
    }
    assert_clean(&g);
}

/// A bricked ball for the texel tests.
fn bricked_ball(dims: [u32; 3]) -> crate::bricks::BrickScene {
    let store = crate::bricks::BrickStore::build(&ball(dims)).unwrap();
    crate::bricks::BrickScene::new(store, tf(), None).unwrap()
}

#[test]
fn an_axis_aligned_projection_of_a_store_draws_one_voxel_a_column_and_the_same_frame() {
    // Down the columns every voxel of a column falls in one texel: MIP and MinIP draw its
    // brightest (darkest) voxel alone, whose footprint is every other's, so the frame is every
    // voxel's to the bit.
    let dims = [20, 16, 12];
    let scene = bricked_ball(dims);
    let cam = column_camera(dims, 4);
    let columns = {
        let vol = ball(dims);
        let (lo, hi) = vol.values.iter().fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        let shows = |i: u32, j: u32| {
            (0..dims[2])
                .any(|k| tf().eval((vol.values[(i + dims[0] * (j + dims[1] * k)) as usize] - lo) / (hi - lo))[3] > 0.0)
        };
        (0..dims[1]).flat_map(|j| (0..dims[0]).map(move |i| (i, j))).filter(|&(i, j)| shows(i, j)).count() as u64
    };
    for (engine, mut r) in [("gpu", gpu()), ("cpu", cpu())] {
        r.set_bricks(scene.clone()).unwrap();
        for mode in [Mode::Mip, Mode::Minip] {
            let o = options(mode, Raster::Compute);
            let mut every = o.clone();
            every.every_voxel = true;
            let (texels, all) = (r.render(&cam, &o).unwrap(), r.render(&cam, &every).unwrap());
            assert_eq!(texels.stats.splats, columns, "{mode} {engine}: one voxel a column");
            assert_eq!(texels.stats.splats + texels.stats.splats_outshone, all.stats.splats, "{mode} {engine}");
            assert_eq!(texels.image.pixels, all.image.pixels, "{mode} {engine}: the frame of every voxel");
        }
        assert_clean(&r);
    }
}

#[test]
fn a_projection_s_texels_keep_the_clipping_planes_and_the_image_s_edges() {
    // A voxel beyond a clipping plane, or too near the near plane, draws nothing and so may hide
    // nothing: bricks across a plane claim no texel. A view cut by the image's edges and by a plane
    // through the ball, with the camera close enough that the near plane crosses it too.
    let dims = [48, 40, 32];
    let scene = bricked_ball(dims);
    let mut g = gpu();
    g.set_bricks(scene.clone()).unwrap();
    let mut c = cpu();
    c.set_bricks(scene).unwrap();
    let mut cam = Camera::framing(&crate::Grid::centered(dims, [1.0; 3]).unwrap(), 56, 48);
    cam.eye = cam.target + (cam.eye - cam.target) * 0.8;
    cam.near = (cam.eye - cam.target).length() - 14.0;
    for mode in [Mode::Mip, Mode::Minip] {
        let mut o = options(mode, Raster::Compute);
        o.clip = crate::Clip::new(&[glam::Vec4::new(0.6, -0.3, 0.74, 1.5)], None).unwrap();
        let mut every = o.clone();
        every.every_voxel = true;
        let texels = g.render(&cam, &o).unwrap();
        assert_mirrors(&texels.image, &c.render(&cam, &o).unwrap().image, &format!("clipped {mode}"));
        let all = g.render(&cam, &every).unwrap();
        let (worst, mean) = common::diff(&texels.image, &all.image);
        eprintln!("clipped {mode}: {} outshone; largest {worst:.3}, mean {mean:.5}", texels.stats.splats_outshone);
        assert!(texels.stats.splats_outshone > 0, "{mode}: the texels drop voxels");
        // A voxel the plane or the near plane removes, left to claim, blanks what it outshines.
        assert!(
            worst < 0.35 && mean < 2e-3,
            "clipped {mode}: texels against every voxel, largest {worst}, mean {mean}"
        );
    }
    assert_clean(&g);
}

#[test]
fn mip_and_minip_of_a_store_keep_what_the_ray_caster_covers_at_every_size() {
    // The brightest voxel of a texel stands for the others only where their footprints nearly
    // coincide: texels of a third of a pixel dropped most of a thumbnail's coverage where voxels
    // project to a tenth of one (bonsai MIP at 64x64: 5.7 % of the frame against 24.3 %). Texels
    // now span at most half the smallest voxel spacing the view projects, so a frame covers what
    // the ray caster's does from 2x2 to 512x512, perspective, the volume in a corner of the view.
    let vol = ball([40, 34, 28]);
    let set = classify(&vol, &tf(), None).unwrap();
    let scene = bricked_ball([40, 34, 28]);
    let mut g = gpu();
    for side in [2u32, 4, 8, 16, 32, 64, 128, 256, 512] {
        let cam = Camera {
            eye: Vec3::new(70.0, 52.0, 95.0),
            target: Vec3::new(4.0, -3.0, 0.0),
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y_deg: 20.0 },
            near: 1.0,
            far: 400.0,
            width: side,
            height: side,
            window: None,
        };
        for mode in [Mode::Mip, Mode::Minip] {
            g.set_scene(set.clone()).unwrap();
            let ray = g.raycast(&cam, &crate::RaycastOptions { mode, step: 0.25, ..Default::default() }).unwrap();
            g.set_bricks(scene.clone()).unwrap();
            let drawn = g.render(&cam, &options(mode, Raster::Compute)).unwrap();
            let mut every = options(mode, Raster::Compute);
            every.every_voxel = true;
            let every = g.render(&cam, &every).unwrap();
            let (r, d) = (&ray.image.pixels, &drawn.image.pixels);
            let e = &every.image.pixels;
            let both_e: Vec<f32> =
                r.iter().zip(e).filter(|(p, q)| p[3] > 0.5 && q[3] > 0.5).map(|(p, q)| (p[0] - q[0]).abs()).collect();
            let mean_e = both_e.iter().sum::<f32>() / both_e.len().max(1) as f32;
            let missed = r.iter().zip(d).filter(|(p, q)| p[3] > 0.5 && q[3] == 0.0).count();
            let extra = r.iter().zip(d).filter(|(p, q)| p[3] == 0.0 && q[3] > 0.5).count();
            let both: Vec<f32> =
                r.iter().zip(d).filter(|(p, q)| p[3] > 0.5 && q[3] > 0.5).map(|(p, q)| (p[0] - q[0]).abs()).collect();
            let mean = both.iter().sum::<f32>() / both.len().max(1) as f32;
            let covered = common::covered(&ray.image);
            eprintln!(
                "{mode} {side}x{side}: ray caster covers {covered}, drawn misses {missed} and adds {extra}; \
                 mean value difference {mean:.4} (every voxel {mean_e:.4}); {} of {} voxels outshone",
                drawn.stats.splats_outshone,
                drawn.stats.splats + drawn.stats.splats_outshone
            );
            assert!(covered > 0, "{mode} {side}x{side}: the ray caster covers nothing");
            // A silhouette pixel may fall either way between the two reconstructions: at most one
            // pixel in twenty of the covered, and at least one allowed.
            let slack = (covered / 20).max(1);
            assert!(missed <= slack, "{mode} {side}x{side}: {missed} of {covered} covered pixels left empty");
            assert!(extra <= slack, "{mode} {side}x{side}: {extra} pixels covered that the ray caster leaves empty");
            // Measured: the texels within 0.004 of every voxel's mean difference, which is at most
            // 0.073 (MIP at 2x2, two pixels: the kernel against trilinear samples).
            assert!(mean < 0.1 && mean <= mean_e + 0.01, "{mode} {side}x{side}: mean value difference {mean}");
        }
    }
    assert_clean(&g);
}
