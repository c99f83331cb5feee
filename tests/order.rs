//! Visibility orders on the CPU: PBTF is free of violations everywhere; BTF and WBTF fail on the
//! close perspective view of Figs 2.25-2.26; the CPU mirror of the GPU order stages equals the
//! pure-Rust PBTF.
use super::common;
use crate::order::{count_violations, pbtf, pbtf_split, visibility_order};
use crate::{scene, Camera, Direction, OrderKind, Projection, SplatSet};
use common::{random_camera, random_sparse, Rng, ViewKind};
use glam::Vec3;

fn is_permutation(order: &[u32], n: usize) -> bool {
    let mut seen = vec![false; n];
    order.len() == n && order.iter().all(|&s| (s as usize) < n && !std::mem::replace(&mut seen[s as usize], true))
}

#[test]
fn pbtf_has_no_violations_on_1000_random_viewpoints() {
    let sets: Vec<SplatSet> = vec![scene::build("cube40").unwrap(), random_sparse(7, [13, 9, 11], 0.6)];
    let mut rng = Rng(0x5EED);
    let kinds = [ViewKind::Outside, ViewKind::Inside, ViewKind::OnGridPlane, ViewKind::Orthographic];
    let mut checked = 0;
    let mut total_pairs_violated_by_btf = 0;
    for v in 0..1000 {
        let set = &sets[v % 2];
        let kind = kinds[v % 4];
        let cam = random_camera(&mut rng, set.grid(), kind);
        for dir in [Direction::FrontToBack, Direction::BackToFront] {
            let order = visibility_order(set, &cam, OrderKind::Pbtf, dir);
            assert!(is_permutation(&order, set.len()));
            let n = count_violations(set, &cam, &order, dir).unwrap();
            assert_eq!(n, 0, "PBTF violations {n} for {kind:?} camera {cam:?} {dir:?}");
        }
        // The reference order agrees with the validator too.
        let sorted = visibility_order(set, &cam, OrderKind::Sorted, Direction::FrontToBack);
        assert_eq!(count_violations(set, &cam, &sorted, Direction::FrontToBack).unwrap(), 0, "{kind:?} {cam:?}");
        let btf = visibility_order(set, &cam, OrderKind::Btf, Direction::FrontToBack);
        total_pairs_violated_by_btf += count_violations(set, &cam, &btf, Direction::FrontToBack).unwrap();
        checked += 1;
    }
    assert_eq!(checked, 1000);
    // The same viewpoints break BTF, so the validator is not vacuous.
    assert!(total_pairs_violated_by_btf > 0);
}

/// The close, off-axis perspective view of Figs 2.25-2.27 (shared with the stability study).
fn close_view(set: &SplatSet) -> Camera {
    crate::scene::close_view(set.grid(), 256)
}

#[test]
fn btf_and_wbtf_fail_where_pbtf_does_not() {
    let set = scene::build("cube60").unwrap();
    let cam = close_view(&set);
    let count = |k| {
        let o = visibility_order(&set, &cam, k, Direction::BackToFront);
        count_violations(&set, &cam, &o, Direction::BackToFront).unwrap()
    };
    let (btf, wbtf, pbtf_v, sorted) =
        (count(OrderKind::Btf), count(OrderKind::Wbtf), count(OrderKind::Pbtf), count(OrderKind::Sorted));
    eprintln!("violations: btf {btf}, wbtf {wbtf}, pbtf {pbtf_v}, sorted {sorted}");
    assert!(btf > 0, "BTF should fail on this view");
    assert!(wbtf > 0, "WBTF should fail on this view");
    assert_eq!(pbtf_v, 0);
    assert_eq!(sorted, 0);
    // The orthographic view from the same direction is fine for all of them (Frieder, Westover).
    let mut ortho = cam;
    ortho.projection = Projection::Orthographic { height: 90.0 };
    ortho.near = -200.0;
    for k in [OrderKind::Btf, OrderKind::Wbtf, OrderKind::Pbtf] {
        let o = visibility_order(&set, &ortho, k, Direction::BackToFront);
        assert_eq!(count_violations(&set, &ortho, &o, Direction::BackToFront).unwrap(), 0, "{k:?} orthographic");
    }
}

#[test]
fn cpu_mirror_of_gpu_order_equals_pure_rust_pbtf() {
    let mut rng = Rng(42);
    let sets = [scene::build("cube40").unwrap(), random_sparse(3, [17, 5, 8], 0.4), scene::build("plane").unwrap()];
    let mut r = common::cpu();
    for (si, set) in sets.iter().enumerate() {
        r.set_scene(set.clone()).unwrap();
        for v in 0..60 {
            let kind = [ViewKind::Outside, ViewKind::Inside, ViewKind::OnGridPlane, ViewKind::Orthographic][v % 4];
            let cam = random_camera(&mut rng, set.grid(), kind);
            let want = pbtf(set, pbtf_split(set, &cam));
            let got = crate::low_level::pbtf_order(&mut r, &cam, Direction::FrontToBack).unwrap();
            assert_eq!(got, want, "set {si} {kind:?}");
            let mut back = crate::low_level::pbtf_order(&mut r, &cam, Direction::BackToFront).unwrap();
            back.reverse();
            assert_eq!(back, want);
        }
    }
}

#[test]
fn split_handles_eye_on_planes_and_outside() {
    let set = random_sparse(1, [10, 10, 10], 1.0);
    let g = *set.grid();
    let mut cam = Camera::framing(&g, 8, 8);
    // Eye exactly on voxel 4's plane in x, on the midplane 6.5 in y, beyond the grid in z.
    cam.eye = Vec3::new(
        g.origin[0] + 4.0 * g.spacing[0],
        g.origin[1] + 6.5 * g.spacing[1],
        g.origin[2] + 20.0 * g.spacing[2],
    );
    let split = pbtf_split(&set, &cam);
    assert_eq!(split[0], 5, "voxel 4 on the eye's plane goes to the low side");
    assert_eq!(split[1], 8, "eye on the 6.5 midplane");
    assert_eq!(split[2], 10, "eye beyond the grid: everything on the low side");
}

/// Every case of Table 2.3 (each eye coordinate below, inside or above the grid), with the eye
/// also exactly on the first and last voxel planes, on a voxel plane inside, and on a midplane.
#[test]
fn pbtf_is_correct_in_every_case_of_table_2_3() {
    let set = random_sparse(17, [9, 8, 7], 0.7);
    let g = *set.grid();
    let mut cases = 0;
    let positions = |a: usize| {
        let n = g.dims[a] as f32;
        [-6.0, 0.0, 2.0, 3.5, n - 1.0, n + 5.0].map(|idx| g.origin[a] + idx * g.spacing[a])
    };
    let (px, py, pz) = (positions(0), positions(1), positions(2));
    for &x in &px {
        for &y in &py {
            for &z in &pz {
                let eye = Vec3::new(x, y, z);
                let target = if (g.center() - eye).length() > 1e-3 { g.center() } else { g.center() + Vec3::X };
                let up = if (target - eye).normalize().cross(Vec3::Y).length() > 0.1 { Vec3::Y } else { Vec3::Z };
                let cam = Camera {
                    eye,
                    target,
                    up,
                    projection: Projection::Perspective { fov_y_deg: 60.0 },
                    near: 0.01,
                    far: 100.0,
                    width: 8,
                    height: 8,
                    window: None,
                };
                for dir in [Direction::FrontToBack, Direction::BackToFront] {
                    let o = visibility_order(&set, &cam, OrderKind::Pbtf, dir);
                    assert!(is_permutation(&o, set.len()));
                    assert_eq!(count_violations(&set, &cam, &o, dir).unwrap(), 0, "eye {eye}");
                }
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 216);
}

/// Two-level PBTF (bricks by PBTF over the brick grid, voxels by PBTF inside each brick) is a
/// visibility order wherever one-level PBTF is: the same random battery, brick sides that divide
/// the grid and sides that do not, and eyes placed on brick planes and inside bricks.
#[test]
fn two_level_pbtf_has_no_violations_on_random_and_brick_plane_viewpoints() {
    let sets: Vec<SplatSet> = vec![scene::build("cube40").unwrap(), random_sparse(11, [19, 13, 17], 0.6)];
    let mut rng = Rng(0xB12C);
    let kinds = [ViewKind::Outside, ViewKind::Inside, ViewKind::OnGridPlane, ViewKind::Orthographic];
    let mut btf_violations = 0;
    for v in 0..600 {
        let set = &sets[v % 2];
        let brick = [2, 3, 4, 8, 5][v % 5];
        let mut cam = random_camera(&mut rng, set.grid(), kinds[v % 4]);
        if v % 3 == 0 && cam.is_perspective() {
            // Move the eye onto brick planes (voxel index b * brick - 0.5) on one or more axes.
            let g = *set.grid();
            for a in 0..3 {
                if rng.f32() < 0.6 {
                    let b = (rng.f32() * (g.dims[a] / brick + 1) as f32) as u32;
                    cam.eye[a] = g.origin[a] + (b as f32 * brick as f32 - 0.5) * g.spacing[a];
                }
            }
            if cam.eye.distance(cam.target) < 1e-3 {
                continue;
            }
        }
        let ftb = crate::order::pbtf_bricked(set, &cam, brick).unwrap();
        assert!(is_permutation(&ftb, set.len()));
        let n = count_violations(set, &cam, &ftb, Direction::FrontToBack).unwrap();
        assert_eq!(n, 0, "two-level PBTF (brick {brick}) violations {n} for {cam:?}");
        let btf: Vec<u32> = ftb.iter().rev().copied().collect();
        assert_eq!(count_violations(set, &cam, &btf, Direction::BackToFront).unwrap(), 0);
        let btf_order = visibility_order(set, &cam, OrderKind::Btf, Direction::FrontToBack);
        btf_violations += count_violations(set, &cam, &btf_order, Direction::FrontToBack).unwrap();
    }
    assert!(btf_violations > 0, "the battery breaks BTF, so the validator is not vacuous");
}

#[test]
fn two_level_pbtf_is_pbtf_for_voxel_bricks_and_one_brick() {
    let set = random_sparse(3, [12, 10, 9], 0.5);
    let mut rng = Rng(77);
    for v in 0..40 {
        let kind = [ViewKind::Outside, ViewKind::Inside, ViewKind::OnGridPlane, ViewKind::Orthographic][v % 4];
        let cam = random_camera(&mut rng, set.grid(), kind);
        let one = pbtf(&set, pbtf_split(&set, &cam));
        assert_eq!(crate::order::pbtf_bricked(&set, &cam, 1).unwrap(), one, "{kind:?}");
        assert_eq!(crate::order::pbtf_bricked(&set, &cam, 16).unwrap(), one, "{kind:?}");
    }
    assert!(crate::order::pbtf_bricked(&set, &Camera::framing(set.grid(), 8, 8), 0).is_err());
}

/// Issue 26: the image-space validator counts, per pixel, splats drawn against their depth along
/// its ray. It is exact on a pair (every pixel both footprints cover counts once when the pair is
/// reversed), and unlike the 6-neighbour count it tells WBTF from BTF: on the view of Figs
/// 2.25/2.26 both have 6,136 neighbour violations, but not the same picture.
#[test]
fn the_image_space_validator_tells_wbtf_from_btf() {
    use crate::order::count_pixel_inversions;
    let grid = crate::Grid::centered([1, 1, 8], [1.0; 3]).unwrap();
    let pair = SplatSet::from_fn(grid, |_, _, k| (k == 0 || k == 7).then_some([1.0, 1.0, 1.0, 0.5])).unwrap();
    let cam = Camera {
        eye: glam::Vec3::new(0.0, 0.0, 30.0),
        target: glam::Vec3::ZERO,
        up: glam::Vec3::Y,
        projection: crate::Projection::Orthographic { height: 8.0 },
        near: 1.0,
        far: 60.0,
        width: 32,
        height: 32,
        window: None,
    };
    // Back to front is the far splat (k = 0, at z = -3.5) first.
    let right = count_pixel_inversions(&pair, &cam, &[0, 1], Direction::BackToFront, 2.0).unwrap();
    let wrong = count_pixel_inversions(&pair, &cam, &[1, 0], Direction::BackToFront, 2.0).unwrap();
    assert_eq!((right.inversions, right.pixels), (0, 0));
    // Both footprints cover the same disc of radius 2 (8 px): every covered pixel inverts once.
    assert!(wrong.covered > 150 && wrong.inversions == wrong.covered && wrong.pixels == wrong.covered, "{wrong:?}");
    assert_eq!(wrong.separated, wrong.inversions, "7 voxels apart: more than a kernel diameter");
    assert!(count_pixel_inversions(&pair, &cam, &[0, 0], Direction::BackToFront, 2.0).is_err());

    let set = scene::build("cube60").unwrap();
    let view = |eye: glam::Vec3, target: glam::Vec3| Camera {
        eye,
        target,
        projection: crate::Projection::Perspective { fov_y_deg: 75.0 },
        width: 128,
        height: 128,
        ..Camera::framing(set.grid(), 128, 128)
    };
    let a = view(glam::Vec3::new(70.0, 20.0, 12.0), glam::Vec3::ZERO);
    let count = |cam: &Camera, kind: OrderKind| {
        let seq = visibility_order(&set, cam, kind, Direction::BackToFront);
        let v = count_violations(&set, cam, &seq, Direction::BackToFront).unwrap();
        (v, count_pixel_inversions(&set, cam, &seq, Direction::BackToFront, 2.0).unwrap())
    };
    let (btf, wbtf, sorted) = (count(&a, OrderKind::Btf), count(&a, OrderKind::Wbtf), count(&a, OrderKind::Sorted));
    assert_eq!(btf.0, wbtf.0, "the neighbour count cannot tell them apart");
    assert!(btf.1.inversions > 2 * wbtf.1.inversions, "btf {:?} wbtf {:?}", btf.1, wbtf.1);
    // Drawn by exact distance to the eye: the fewest inversions, none between splats apart.
    assert!(sorted.1.inversions * 10 < wbtf.1.inversions && sorted.1.separated == 0, "{:?}", sorted.1);
}

/// Issue 26: the nesting inside PBTF's octants is the seed's "or duals" freedom: `pbtf_nested`
/// with k, j, i is `pbtf`, and any other nesting is a visibility order too (0 violations).
#[test]
fn pbtf_nesting_inside_octants_is_free() {
    use crate::order::pbtf_nested;
    let mut rng = Rng(26);
    for seed in 0..4 {
        let set = random_sparse(seed, [13, 9, 11], 0.3);
        for _ in 0..8 {
            let cam = random_camera(&mut rng, set.grid(), ViewKind::Inside);
            let split = pbtf_split(&set, &cam);
            assert_eq!(pbtf_nested(&set, split, |_| [2, 1, 0]), pbtf(&set, split));
            for axes in [[0, 1, 2], [1, 2, 0], crate::order::wbtf_axes(&cam)] {
                let seq = pbtf_nested(&set, split, |_| axes);
                assert_eq!(count_violations(&set, &cam, &seq, Direction::FrontToBack).unwrap(), 0, "{axes:?}");
            }
            // Westover's nesting per octant (`--order pbtf-octant`), and in orthographic views.
            for kind in [ViewKind::Inside, ViewKind::Outside, ViewKind::Orthographic] {
                let cam = random_camera(&mut rng, set.grid(), kind);
                let seq = visibility_order(&set, &cam, OrderKind::PbtfOctant, Direction::BackToFront);
                assert_eq!(count_violations(&set, &cam, &seq, Direction::BackToFront).unwrap(), 0, "{kind:?}");
            }
            // A different nesting in every octant is one too.
            let mixed = pbtf_nested(&set, split, |o| [[0, 1, 2], [2, 0, 1], [1, 0, 2]][o as usize % 3]);
            assert_eq!(count_violations(&set, &cam, &mixed, Direction::FrontToBack).unwrap(), 0);
        }
    }
}

/// Issue 26 item 6: PBTF on a rectilinear grid (chapter 2's U, V, W: spacing varying along each
/// axis). The eye's cell comes from the per-axis coordinates; everything else is index space.
#[test]
fn pbtf_orders_rectilinear_grids_from_the_eyes_cell() {
    use crate::order::{count_pixel_inversions, count_violations, pbtf, pbtf_split, Direction};
    let grid = crate::Grid::centered([10, 9, 12], [1.0; 3]).unwrap();
    let solid = crate::SplatSet::from_fn(grid, |_, _, _| Some([1.0, 1.0, 1.0, 0.2])).unwrap();
    // CT-like slices: z gaps from 0.25 to 3, x and y gently irregular.
    let x: Vec<f32> = (0..10).map(|i| i as f32 * 1.2 + 0.1 * (i * i) as f32).collect();
    let y: Vec<f32> = (0..9).map(|j| j as f32 + 0.3 * (j % 2) as f32).collect();
    let z: Vec<f32> = (0..12).map(|k| [0.0, 0.25, 0.5, 3.5, 4.0, 7.0, 7.5, 8.0, 11.0, 11.25, 12.0, 15.0][k]).collect();
    let rect = solid.clone().with_coordinates([x.clone(), y.clone(), z.clone()]).unwrap();
    // An eye inside the grid, in z between slices 4 and 5 (world 4.0 and 7.0), past their midpoint.
    let cam = Camera {
        eye: glam::Vec3::new(6.0, 3.9, 5.8),
        target: glam::Vec3::new(6.0, 20.0, 5.8),
        up: glam::Vec3::Z,
        projection: crate::Projection::Perspective { fov_y_deg: 90.0 },
        near: 0.01,
        far: 100.0,
        width: 64,
        height: 64,
        window: None,
    };
    let split = pbtf_split(&rect, &cam);
    // z 5.8 lies in slice 5's cell (from 5.5, the midpoint of slices 4 and 5 at 4.0 and 7.0): slices
    // 0..=5 run downward from it.
    assert_eq!(split[2], 6);
    let order = pbtf(&rect, split);
    assert_eq!(count_violations(&rect, &cam, &order, Direction::FrontToBack).unwrap(), 0);
    // The uniform grid's reading of the same eye puts it in another cell, and its order breaks
    // the rectilinear grid's visibility.
    let uniform = pbtf(&solid, pbtf_split(&solid, &cam));
    assert_ne!(pbtf_split(&solid, &cam), split);
    let wrong = count_violations(&rect, &cam, &uniform, Direction::FrontToBack).unwrap();
    assert!(wrong > 0, "the uniform split misorders the rectilinear grid");
    // The image-space validator places splats at their coordinates too.
    let btf = |o: &[u32]| o.iter().rev().cloned().collect::<Vec<u32>>();
    let good = count_pixel_inversions(&rect, &cam, &btf(&order), Direction::BackToFront, 0.5).unwrap();
    let bad = count_pixel_inversions(&rect, &cam, &btf(&uniform), Direction::BackToFront, 0.5).unwrap();
    eprintln!("rectilinear: 6-neighbour violations 0 vs {wrong}; pixel inversions {good:?} vs {bad:?}");
    assert!(good.inversions < bad.inversions);
    // Bad coordinates are refused with the axis named.
    let e = solid.clone().with_coordinates([x.clone(), y.clone(), vec![0.0; 12]]).unwrap_err().to_string();
    assert!(e.contains("z coordinates must increase"), "{e}");
    let e = solid.clone().with_coordinates([x.clone(), y[..8].to_vec(), z.clone()]).unwrap_err().to_string();
    assert!(e.contains("8 y coordinates for 9"), "{e}");
    let mut nan = z.clone();
    nan[3] = f32::NAN;
    assert!(solid.with_coordinates([x, y, nan]).is_err());
    drop(rect);
}

/// Issue 26 item 6: a rectilinear grid renders at its coordinates. A ball sampled on irregular z
/// slices (gaps 0.5 and 1.0 alternating) against the same ball on a uniform 0.5 grid: nearer than
/// the same samples drawn as if the slices were evenly spaced, and the GPU equals its mirror.
#[test]
fn a_rectilinear_grid_renders_at_its_coordinates() {
    use crate::{Grid, RenderOptions, SplatSet};
    let ball = |p: Vec3| p.length() < 6.0;
    let (a, tau) = (0.3f32, -(1.0f32 - 0.3).ln());
    // Uniform reference, spacing 0.5: a voxel-length is 0.5 there, half the rectilinear grid's
    // widest gap (the length its opacities are per), so half the optical depth per voxel.
    let fine = Grid::centered([29, 29, 29], [0.5; 3]).unwrap();
    let a_fine = 1.0 - (-0.5 * tau).exp();
    let reference =
        SplatSet::from_fn(fine, |i, j, k| ball(fine.position([i, j, k])).then_some([1.0, 0.6, 0.3, a_fine])).unwrap();
    let mut z = vec![-7.0f32];
    while z.len() < 19 {
        let gap = if z.len() % 2 == 1 { 0.5 } else { 1.0 };
        z.push(z[z.len() - 1] + gap);
    }
    let xy: Vec<f32> = (0..29).map(|i| -7.0 + 0.5 * i as f32).collect();
    let g = Grid::centered([29, 29, z.len() as u32], [0.5, 0.5, 0.75]).unwrap();
    let at = |i: u32, j: u32, k: u32| Vec3::new(xy[i as usize], xy[j as usize], z[k as usize]);
    let samples = SplatSet::from_fn(g, |i, j, k| ball(at(i, j, k)).then_some([1.0, 0.6, 0.3, a])).unwrap();
    let rect = samples.clone().with_coordinates([xy.clone(), xy.clone(), z.clone()]).unwrap();
    assert_eq!(rect.grid().spacing, [0.5, 0.5, (z[18] - z[0]) / 18.0]);
    let cam = Camera {
        eye: Vec3::new(20.0, 6.0, 9.0),
        target: Vec3::ZERO,
        up: Vec3::Z,
        projection: Projection::Perspective { fov_y_deg: 40.0 },
        near: 1.0,
        far: 100.0,
        width: 96,
        height: 96,
        window: None,
    };
    let o = RenderOptions::default();
    let mut gpu = common::gpu();
    let mut render = |set: SplatSet| {
        gpu.set_scene(set).unwrap();
        gpu.render(&cam, &o).unwrap().image
    };
    // The ball on a uniform grid of the widest gap (1.0): footprints as wide as the rectilinear
    // grid's, half the samples.
    let coarse = Grid::centered([15, 15, 15], [1.0; 3]).unwrap();
    let coarse = SplatSet::from_fn(coarse, |i, j, k| ball(coarse.position([i, j, k])).then_some([1.0, 0.6, 0.3, a]));
    let truth = render(reference);
    let drawn = render(rect.clone());
    let as_if_even = render(samples);
    let widest = render(coarse.unwrap());
    let psnr = |img: &crate::ImageF32| crate::metrics::compare(img, &truth).unwrap().psnr;
    let (near, far, wide) = (psnr(&drawn), psnr(&as_if_even), psnr(&widest));
    eprintln!(
        "against the ball on the 0.5 grid: rectilinear {near:.2} dB; the same samples evenly spaced {far:.2} dB; \
         the ball on a uniform 1.0 grid {wide:.2} dB"
    );
    assert!(near > far + 3.0 && near > 25.0 && near > wide - 1.0);
    common::assert_clean(&gpu);
    let mut cpu = common::cpu();
    cpu.set_scene(rect.clone()).unwrap();
    let c = cpu.render(&cam, &o).unwrap().image;
    common::assert_mirrors(&drawn, &c, "rectilinear");
    // What samples a uniform grid refuses the set.
    assert!(crate::truth::volumetric_summation(&rect, &cam, &Default::default()).is_err());
}

/// Issue 76: one gap 37 times the others in the middle of a rectilinear grid (a `--positions`
/// sidecar with one far position) drew every footprint as wide as that gap, and every opacity
/// per that gap: the ball on its near side came out 37 times wider and fainter. Now each splat is
/// as wide as its own cell and opacities are per the widest gap that is not an outlier, so the
/// ball, clear of the gap's neighbours, draws as it does on the uniform grid of its slices alone;
/// the GPU equals its mirror.
#[test]
fn a_far_position_widens_only_its_neighbours() {
    use crate::{Grid, RenderOptions};
    let ball = |p: Vec3| (p - Vec3::new(0.0, 0.0, -1.0)).length() < 5.0;
    let color = |p: Vec3| ball(p).then_some([0.9, 0.7, 0.4, 0.35]);
    // Slices z = -8..=7 one apart, then 8 more beyond a gap of 37: empty, as are the two slices
    // either side of the gap.
    let mut z: Vec<f32> = (-8..=7).map(|k| k as f32).collect();
    z.extend((0..8).map(|k| 7.0 + 37.0 + k as f32));
    let xy: Vec<f32> = (-8..=8).map(|i| i as f32).collect();
    let g = Grid::centered([17, 17, z.len() as u32], [1.0; 3]).unwrap();
    let at = |i: u32, j: u32, k: u32| Vec3::new(xy[i as usize], xy[j as usize], z[k as usize]);
    let rect = SplatSet::from_fn(g, |i, j, k| if k < 14 { color(at(i, j, k)) } else { None })
        .unwrap()
        .with_coordinates([xy.clone(), xy.clone(), z.clone()])
        .unwrap();
    // The slices before the gap alone, as a uniform grid.
    let near = Grid::centered([17, 17, 16], [1.0; 3]).unwrap();
    let shift = Vec3::new(0.0, 0.0, -8.0 - near.position([0, 0, 0]).z);
    let alone = SplatSet::from_fn(near, |i, j, k| color(near.position([i, j, k]) + shift)).unwrap();
    let cam = |at: Vec3| Camera {
        eye: at + Vec3::new(30.0, 14.0, 18.0),
        target: at,
        up: Vec3::Z,
        projection: Projection::Perspective { fov_y_deg: 35.0 },
        near: 5.0,
        far: 200.0,
        width: 96,
        height: 96,
        window: None,
    };
    let o = RenderOptions::default();
    let mut gpu = common::gpu();
    gpu.set_scene(rect.clone()).unwrap();
    let drawn = gpu.render(&cam(Vec3::new(0.0, 0.0, -1.0)), &o).unwrap().image;
    gpu.set_scene(alone).unwrap();
    let truth = gpu.render(&cam(Vec3::new(0.0, 0.0, -1.0) - shift), &o).unwrap().image;
    let m = crate::metrics::compare(&drawn, &truth).unwrap();
    eprintln!(
        "a far position: {:.2} dB over {} covered pixels against the slices alone ({} px drawn, {} px alone)",
        m.covered_psnr,
        m.covered_pixels,
        common::covered(&drawn),
        common::covered(&truth)
    );
    assert!(common::covered(&truth) > 1000);
    assert!(m.covered_psnr > 40.0, "{:.2} dB", m.covered_psnr);
    common::assert_clean(&gpu);
    // Like for like: on this scene auto picks quads on the device and point sprites on the CPU,
    // whose widest sprite is wider.
    let mut quads = RenderOptions::default();
    quads.raster = crate::Raster::Graphics;
    let at = cam(Vec3::new(0.0, 0.0, -1.0));
    gpu.set_scene(rect.clone()).unwrap();
    let g = gpu.render(&at, &quads).unwrap().image;
    let mut cpu = common::cpu();
    cpu.set_scene(rect).unwrap();
    let c = cpu.render(&at, &quads).unwrap().image;
    common::assert_mirrors(&g, &c, "a far position");
    common::assert_clean(&gpu);
}

/// A k-d leaf's bricks as an octree of aligned blocks (`octree_pbtf`, what the device's brick
/// slots use inside a leaf): over random boxes (aligned or not) and eye splits (inside, on block
/// planes, outside), the positions are a permutation of the box's bricks, every aligned block
/// inside the box takes consecutive positions (so a node above the brick may stand at any of its
/// bricks' places), and every 6-adjacent pair is ordered as PBTF orders it: the brick on the eye's
/// side first, or the low-side one first where the split runs between them.
#[test]
fn octree_order_in_a_leaf_is_a_visibility_order_with_consecutive_blocks() {
    use crate::cpu::brick::octree_pbtf;
    let mut rng = Rng(777);
    let mut below = |n: u32| (rng.next_u64() % n as u64) as u32;
    for _ in 0..200 {
        let lo = [0, 1, 2].map(|_| below(20));
        let hi = [0, 1, 2].map(|a| lo[a] + 1 + below(13));
        let s = [0, 1, 2].map(|a| match below(4) {
            0 => 0,
            1 => hi[a] + 3,
            2 => (lo[a] + hi[a]) / 2 / 4 * 4,
            _ => lo[a] + below(hi[a] - lo[a] + 1),
        });
        let n = (0..3).map(|a| (hi[a] - lo[a]) as usize).product::<usize>();
        let mut pos = std::collections::HashMap::new();
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    pos.insert([x, y, z], octree_pbtf([x, y, z], lo, hi, s));
                }
            }
        }
        let order: Vec<u32> = pos.values().copied().collect();
        assert!(is_permutation(&order, n), "{lo:?}..{hi:?} split {s:?}: not a permutation");
        for (b, &p) in &pos {
            for a in 0..3 {
                let mut c = *b;
                c[a] += 1;
                if let Some(&q) = pos.get(&c) {
                    // b is c's low neighbour: c first where c lies on the eye's low side.
                    assert_eq!(q < p, c[a] < s[a], "{lo:?}..{hi:?} split {s:?}: {b:?} against {c:?}");
                }
            }
        }
        for k in 1..4u32 {
            for (b, _) in pos.iter().filter(|(b, _)| b.iter().all(|&c| c % (1 << k) == 0)) {
                let inside = (0..3).all(|a| b[a] >= lo[a] && b[a] + (1 << k) <= hi[a]);
                if !inside {
                    continue;
                }
                let mut block: Vec<u32> =
                    pos.iter().filter(|(c, _)| (0..3).all(|a| c[a] >> k == b[a] >> k)).map(|(_, &p)| p).collect();
                block.sort_unstable();
                assert_eq!(
                    block.last().unwrap() - block[0] + 1,
                    block.len() as u32,
                    "{b:?} block of {k}: not consecutive"
                );
            }
        }
    }
}
