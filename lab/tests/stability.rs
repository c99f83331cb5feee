//! Issue 8: the failures of section 1.2.2.3 reproduced as qualitative facts, and the image-aligned
//! sheet buffer (slabs) that avoids them. Figures go to the bench (docs/RESULTS.md).
use crate::common;
use glam::Vec3;
use voxsplat::image::ImageF32;
use voxsplat::output::diff_rgba8;
use voxsplat::{
    camera::Projection, kernel::Kernel, options::Composite, order::Direction, order::OrderKind, Camera, Grid,
    RenderOptions, SplatSet,
};
use voxsplat_lab::stability::{self, Variant};

#[test]
fn slice_table_starts_at_zero_rises_and_ends_at_the_footprint() {
    let n = voxsplat::low_level::FOOTPRINT_TABLE_SIZE as usize;
    for kernel in [Kernel::Gaussian, Kernel::Cubic] {
        let t = kernel.slice_table();
        let rr = kernel.radius() as f64;
        let (mut peak, mut err) = (0.0f64, 0.0f64);
        for x in 0..n {
            assert_eq!(t[x], 0.0, "first row is the empty slice");
            for y in 1..n {
                assert!(t[y * n + x] >= t[(y - 1) * n + x], "cumulative along z");
            }
            // The last row is the whole footprint at r = x / (n-1): the line integral, normalised
            // like the footprint table (read its normaliser from a texel the table holds exactly).
            let r = x as f64 / (n - 1) as f64 * rr;
            let want = kernel.integrated(r);
            peak = peak.max(want);
            err = err.max((t[(n - 1) * n + x] as f64 - want * norm(kernel)).abs());
        }
        assert!(err <= 1e-4 * peak * norm(kernel), "{kernel:?}: last row off the footprint by {err}");
    }
}

/// The footprint table's normaliser: its texel value over the unnormalised line integral there.
fn norm(kernel: Kernel) -> f64 {
    let n = voxsplat::low_level::FOOTPRINT_TABLE_SIZE as usize;
    let rr = kernel.radius() as f64;
    let c = n / 2;
    let u = ((c as f64 + 0.5) / n as f64 * 2.0 - 1.0) * rr;
    kernel.footprint_table()[c * n + c] as f64 / kernel.integrated((2.0 * u * u).sqrt())
}

fn one_voxel() -> SplatSet {
    let grid = Grid::centered([1, 1, 1], [1.0; 3]).unwrap();
    SplatSet::from_fn(grid, |_, _, _| Some([0.9, 0.6, 0.3, 0.7])).unwrap()
}

/// One splat's slabs composite to exactly its whole footprint (alpha = 1 - exp(-sum of slices)),
/// whatever the slab thickness: slab mode equals per-splat mode for a single voxel.
#[test]
fn a_single_splat_sliced_into_slabs_equals_the_whole_footprint() {
    let mut r = common::gpu();
    r.set_scene(one_voxel()).unwrap();
    let cam = Camera {
        eye: Vec3::new(0.4, 0.3, 6.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 50.0 },
        near: 0.5,
        far: 20.0,
        width: 64,
        height: 64,
        window: None,
    };
    let whole = r.render(&cam, &RenderOptions::default()).unwrap().image;
    assert!(common::covered(&whole) > 20, "the splat is drawn ({} px)", common::covered(&whole));
    for thickness in [0.25, 0.7, 1.0, 3.0, 8.0] {
        for direction in [Direction::FrontToBack, Direction::BackToFront] {
            let mut o = RenderOptions::default();
            o.composite = Composite::Slab;
            o.slab_thickness = thickness;
            o.direction = Some(direction);
            let sliced = r.render(&cam, &o).unwrap().image;
            let (mean, max) = diff_rgba8(&sliced, &whole).unwrap();
            eprintln!("thickness {thickness} {direction:?}: mean {mean:.4}/255, max {max}/255");
            assert!(max <= 2, "thickness {thickness} {direction:?}: max diff {max}/255");
        }
    }
    common::assert_clean(&r);
}

#[test]
fn thinner_slabs_converge_towards_the_truth() {
    let mut r = common::gpu();
    let set = voxsplat::scene::build("cube40").unwrap();
    let cam = Camera::framing(set.grid(), 96, 96);
    let truth = voxsplat::truth::volumetric_summation(&set, &cam, &Default::default()).unwrap();
    r.set_scene(set).unwrap();
    let err = |o: &RenderOptions, r: &mut voxsplat::Renderer| {
        voxsplat::metrics::compare(&r.render(&cam, o).unwrap().image, &truth).unwrap().rmse
    };
    let mut o = RenderOptions::default();
    let splat = err(&o, &mut r);
    o.composite = Composite::Sheet;
    let sheet = err(&o, &mut r);
    o.composite = Composite::Slab;
    let mut slab = Vec::new();
    for t in [2.0, 1.0, 0.5] {
        o.slab_thickness = t;
        slab.push(err(&o, &mut r));
    }
    eprintln!("rmse: splat {splat:.4}, sheet {sheet:.4}, slabs 2/1/0.5 {slab:.4?}");
    assert!(slab[0] > slab[1] && slab[1] > slab[2], "error falls with thickness: {slab:?}");
    assert!(slab[1] < sheet && slab[1] < splat);
    common::assert_clean(&r);
}

#[test]
fn bad_slab_thickness_is_an_error() {
    let mut r = common::gpu();
    r.set_scene(one_voxel()).unwrap();
    let cam = Camera::framing(r.scene().unwrap().grid(), 16, 16);
    for t in [0.0, 0.1, -1.0, f32::NAN, f32::INFINITY] {
        let mut o = RenderOptions::default();
        o.composite = Composite::Slab;
        o.slab_thickness = t;
        let e = r.render(&cam, &o).unwrap_err();
        assert!(matches!(e, voxsplat::Error::InvalidArgument(_)), "{t}: {e}");
    }
}

/// (a) Figs 1.9 / 1.16: the axis-aligned sheet buffer jumps when its axis switches; slabs do not.
#[test]
fn the_axis_aligned_sheet_pops_at_the_axis_switch_and_slabs_do_not() {
    let mut r = common::gpu();
    let variants = [Variant::Sheet, Variant::Slab(1.0), Variant::Splat(OrderKind::Pbtf)];
    let rows = stability::axis_switch_study(&mut r, "cube60", 96, 8, &variants, 0).unwrap();
    for row in &rows {
        eprintln!("{row:?}");
    }
    let (sheet, slab) = (&rows[0], &rows[1]);
    assert!(sheet.switch_popping > 1.5, "the sheet buffer pops: {}", sheet.switch_popping);
    assert!(slab.switch_popping < 1.2, "slabs do not: {}", slab.switch_popping);
    common::assert_clean(&r);
}

/// (b) Fig. 1.17's view crowds several times more splats into some pixels than others; brightness
/// must not follow (the metric itself is checked on a synthetic image that does brighten).
#[test]
fn brightness_does_not_follow_splat_density_and_the_metric_sees_it_when_it_does() {
    let mut r = common::gpu();
    let rows = stability::brightening_study(&mut r, 96, &[Variant::Sheet, Variant::Slab(1.0)]).unwrap();
    for row in &rows {
        eprintln!("{row:?}");
        assert!(row.density_ratio > 2.0, "the view crowds splats: {}", row.density_ratio);
        assert!(row.brightening.abs() < 0.05, "{}: brightening {}", row.variant, row.brightening);
    }
    // Control: an image whose brightness grows with density is caught.
    let truth = ImageF32 { width: 4, height: 4, pixels: vec![[0.5, 0.5, 0.5, 1.0]; 16] };
    let density: Vec<f32> = (0..16).map(|i| 1.0 + i as f32).collect();
    let mut img = truth.clone();
    for (p, d) in img.pixels.iter_mut().zip(&density) {
        *p = [0.5 * (1.0 + 0.02 * d), 0.5 * (1.0 + 0.02 * d), 0.5 * (1.0 + 0.02 * d), 1.0];
    }
    assert!(stability::brightening(&img, &truth, &density) > 0.2);
    common::assert_clean(&r);
}

/// (c) Figs 1.13 / 1.14: per-splat compositing depends on the order of overlapping splats; with
/// attenuated splats far less; sheet summation not at all.
#[test]
fn overlapping_opaque_splats_depend_on_order_and_attenuated_ones_much_less() {
    let mut r = common::gpu();
    let rows = stability::overlap_study(&mut r, 96, 2).unwrap();
    for row in &rows {
        eprintln!("{row:?}");
        assert_eq!(row.sheet_sensitivity, 0.0);
    }
    assert!(rows[0].order_sensitivity > 5.0 * rows[1].order_sensitivity);
    common::assert_clean(&r);
}

/// (d) Figs 2.25, 2.26, 5.1: BTF and WBTF break in perspective, PBTF does not, and on the close
/// cube view it shows in the image.
#[test]
fn btf_and_wbtf_visibility_errors_show_in_the_image() {
    let mut r = common::gpu();
    let rows = stability::visibility_study(&mut r, 96).unwrap();
    for row in &rows {
        eprintln!("{row:?}");
    }
    for view in rows.chunks(3) {
        let (btf, wbtf, pbtf) = (&view[0], &view[1], &view[2]);
        assert!(btf.violations > 0 && wbtf.violations > 0);
        assert_eq!(pbtf.violations, 0);
        // On the close cube view the wrong order shows; on the fly-over PBTF's own octant seams
        // weigh about as much as WBTF's violations (docs/RESULTS.md), so no image claim there.
        if btf.view.starts_with("cube60") {
            assert!(btf.rmse_vs_truth > pbtf.rmse_vs_truth, "{}", btf.view);
        }
    }
    common::assert_clean(&r);
}

fn max_abs(a: &ImageF32, b: &ImageF32) -> f32 {
    a.pixels.iter().zip(&b.pixels).flat_map(|(p, q)| (0..4).map(move |i| (p[i] - q[i]).abs())).fold(0.0, f32::max)
}

/// Front-to-back early termination changes no pixel by more than its transmittance threshold, does
/// cull something on opaque data, and the GPU matches the CPU mirror with it on.
#[test]
fn early_termination_stays_within_its_threshold_and_matches_the_mirror() {
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    let set = voxsplat::scene::build("solid40").unwrap();
    let cam = Camera::framing(set.grid(), 96, 80);
    gpu.set_scene(set.clone()).unwrap();
    cpu.set_scene(set).unwrap();
    for composite in [Composite::Sheet, Composite::Slab] {
        let mut o = RenderOptions::default();
        o.composite = composite;
        o.early_termination = 0.0;
        let full = gpu.render(&cam, &o).unwrap().image;
        for threshold in [1.0 / 1024.0, 0.3] {
            o.early_termination = threshold;
            let g = gpu.render(&cam, &o).unwrap().image;
            let d = max_abs(&g, &full);
            eprintln!("{composite:?} threshold {threshold}: max |change| {d}");
            assert!(d <= threshold * 1.001 + 1e-6, "{composite:?}: {d} > {threshold}");
            if threshold >= 0.3 {
                assert!(d > 0.0, "{composite:?}: nothing was culled");
            }
            let c = cpu.render(&cam, &o).unwrap().image;
            common::assert_mirrors(&g, &c, &format!("{composite:?} threshold {threshold}"));
        }
    }
    let mut bad = RenderOptions::default();
    bad.early_termination = 1.0;
    assert!(gpu.render(&cam, &bad).is_err());
    common::assert_clean(&gpu);
}

/// The GPU binning stages produce exactly the mirror's pairs: grouped by slab in visiting order and,
/// within a slab, in increasing splat order (stable, so sums are reproducible).
#[test]
fn gpu_slab_binning_equals_the_mirror_and_is_stable() {
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    let mut rng = common::Rng(8);
    let sets = [voxsplat::scene::build("cube40").unwrap(), common::random_sparse(3, [37, 11, 29], 0.4)];
    for (si, set) in sets.into_iter().enumerate() {
        gpu.set_scene(set.clone()).unwrap();
        cpu.set_scene(set.clone()).unwrap();
        for v in 0..8 {
            let kind = [common::ViewKind::Outside, common::ViewKind::Inside, common::ViewKind::Orthographic][v % 3];
            let cam = common::random_camera(&mut rng, set.grid(), kind);
            let mut o = RenderOptions::default();
            o.composite = Composite::Slab;
            o.slab_thickness = [1.0, 0.5, 2.5][v % 3];
            o.direction = Some([Direction::FrontToBack, Direction::BackToFront][v % 2]);
            o.antialias = [voxsplat::options::Antialias::None, voxsplat::options::Antialias::Swan][v % 2];
            let g = voxsplat::low_level::slab_pairs(&mut gpu, &cam, &o).unwrap();
            let c = voxsplat::low_level::slab_pairs(&mut cpu, &cam, &o).unwrap();
            assert_eq!(g, c, "set {si} view {v} {kind:?}");
            eprintln!("set {si} view {v} {kind:?}: {} pairs", g.len() / 2);
            if kind == common::ViewKind::Outside {
                assert!(g.len() / 2 > set.len(), "every splat spans at least one slab, most more");
            }
            let ftb = o.direction == Some(Direction::FrontToBack);
            for w in g.chunks(2).collect::<Vec<_>>().windows(2) {
                let (a, b) = ((w[0][0], w[0][1]), (w[1][0], w[1][1]));
                let forward = if ftb { b.1 > a.1 } else { b.1 < a.1 };
                assert!(forward || (a.1 == b.1 && b.0 > a.0), "set {si} view {v}: {a:?} then {b:?}");
            }
        }
    }
    common::assert_clean(&gpu);
}
