//! Issue 44: no silently wrong frame, as a property. Over random scenes, cameras, image sizes and
//! every mode, wherever the reference ray cast of the same scene and camera covers pixels, the
//! splatted frame covers them too, or the call is refused with a typed error.
//!
//! The reference samples as the mode does, and the stated factor is 2:
//! - without anti-aliasing a splat is its kernel's footprint at each pixel centre, as one ray per
//!   pixel samples it: of the pixels the ray cast covers (alpha > `RAY_ALPHA`) the splatted frame
//!   covers (alpha > `SPLAT_ALPHA`) at least half;
//! - with anti-aliasing (Swan's, EWA) a splat smaller than a pixel spreads its energy over the
//!   pixel, each fainter, as a box-filtered ray cast (`SUPERSAMPLE`² rays per pixel) averages it:
//!   the frame's coverage, its alpha summed over the pixels, is at least half the ray cast's.
//!
//! The scene projects to 2-64 pixels across, so far views are in; the eye stays beyond the cull
//! margin (`Camera::cull_margin`: splats nearer a plane than that are not drawn), and the near and
//! far planes are fitted as tightly as it lets them, as a user fits them to the scene. What this catches: a frame drawn empty or cut away (metre-scale
//! spacing, anti-aliasing that erased far objects: the defects issue 44 found by hand).
//!
//! Run through the library (classified sets and bricked stores, spacings from 1e-4 to 1e3, the CPU
//! mirrors and the GPU under validation) and through the binary (built-in scenes and a volume file).
//! A fixed seed and a bounded case count in CI; `PROPTEST_CASES=N` for a longer hunt.
use crate::cmd;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};
use std::sync::Mutex;
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::classify::TransferFunction;
use voxsplat::glam::Vec3;
use voxsplat::options::RaycastOptions;
use voxsplat::options::{Antialias, Composite, Lod};
use voxsplat::order::OrderKind;
use voxsplat::volume::ScalarVolume;
use voxsplat::{
    camera::Projection, image::ImageF32, kernel::Kernel, options::Raster, Backend, Camera, Grid, RenderOptions,
    Renderer, RendererOptions, SplatSet,
};

const RAY_ALPHA: f32 = 0.05;
const SPLAT_ALPHA: f32 = 0.005;
const COVERAGE_FACTOR: f32 = 2.0;
const SUPERSAMPLE: u32 = 4;

/// The cases of one property: `PROPTEST_CASES`, else `default`; a fixed seed.
fn runner(default: u32) -> TestRunner {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default);
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[44; 32]))
}

/// (the ray cast's coverage, the splatted frame's of it): pixels, or with `summed` alpha summed.
fn coverage(ray: &ImageF32, splat: &ImageF32, summed: bool) -> (f32, f32) {
    if summed {
        let sum = |i: &ImageF32| i.pixels.iter().map(|p| p[3]).sum::<f32>();
        return (sum(ray), sum(splat));
    }
    let ray_px: Vec<bool> = ray.pixels.iter().map(|p| p[3] > RAY_ALPHA).collect();
    let both = ray_px.iter().zip(&splat.pixels).filter(|(&r, s)| r && s[3] > SPLAT_ALPHA).count();
    (ray_px.iter().filter(|&&r| r).count() as f32, both as f32)
}

fn renderer(backend: Backend) -> Renderer {
    let mut o = RendererOptions::default();
    o.backend = backend;
    o.validation = backend == Backend::Gpu;
    Renderer::new(&o).expect("a renderer (run scripts/setup.sh for the GPU one)")
}

/// A scene as the library takes it: a classified set, or a scalar volume drawn as a bricked store.
#[derive(Clone, Debug)]
enum Scene {
    Set { dims: [u32; 3], spacing: [f32; 3], fill: f32, opacity: f32, seed: u64 },
    Bricked { dims: [u32; 3], spacing: [f32; 3] },
}

impl Scene {
    fn grid(&self) -> Grid {
        let (Scene::Set { dims, spacing, .. } | Scene::Bricked { dims, spacing }) = self;
        Grid::centered(*dims, *spacing).unwrap()
    }

    /// The classified set (what the ray cast draws).
    fn set(&self) -> SplatSet {
        match self {
            &Scene::Set { fill, opacity, seed, .. } => {
                let mut s = seed;
                SplatSet::from_fn(self.grid(), |i, j, k| {
                    s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    ((s >> 40) as f32 / (1u64 << 24) as f32 <= fill)
                        .then(|| [(i % 3) as f32 / 2.0, (j % 2) as f32, (k % 5) as f32 / 4.0, opacity])
                })
                .unwrap()
            }
            Scene::Bricked { .. } => self.store().classify(&tf(), None).unwrap(),
        }
    }

    fn store(&self) -> BrickStore {
        let Scene::Bricked { dims, spacing } = self else { unreachable!() };
        // A ball with a hollow: empty bricks around it and inside.
        let c = dims.map(|d| (d as f32 - 1.0) / 2.0);
        let mut values = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let p = [i, j, k].map(|v| v as f32);
                    let r = (0..3).map(|a| ((p[a] - c[a]) / c[a].max(0.5)).powi(2)).sum::<f32>().sqrt();
                    values.push(if (0.35..1.0).contains(&r) { 100.0 * (1.0 - r) + 20.0 } else { 0.0 });
                }
            }
        }
        BrickStore::build(&ScalarVolume { dims: *dims, spacing: *spacing, values }).unwrap()
    }
}

fn tf() -> TransferFunction {
    TransferFunction {
        points: vec![(0.05, [0.0; 4]), (0.2, [0.9, 0.5, 0.2, 0.5]), (1.0, [1.0, 1.0, 0.9, 0.9])],
        gradient_weight: 0.0,
        range: None,
        threshold: 0.0,
    }
}

fn scene() -> impl Strategy<Value = Scene> {
    let dims = [2u32..20, 2u32..20, 2u32..20];
    // One scale over four orders of magnitude each way (metres to kilometres a voxel), with up to
    // 3:1 anisotropy.
    let spacing =
        (-4.0f32..3.0, [1.0f32..3.0, 1.0f32..3.0, 1.0f32..3.0]).prop_map(|(e, a)| a.map(|x| 10f32.powf(e) * x));
    prop_oneof![
        (dims.clone(), spacing.clone(), 0.2f32..1.0, 0.2f32..1.0, any::<u64>())
            .prop_map(|(dims, spacing, fill, opacity, seed)| Scene::Set { dims, spacing, fill, opacity, seed }),
        ([4u32..24, 4u32..24, 4u32..24], spacing).prop_map(|(dims, spacing)| Scene::Bricked { dims, spacing }),
    ]
}

/// A camera looking at the scene from `dir`, at which it projects `span` pixels across (or
/// larger, where that would bring the eye within the cull margin), perspective or orthographic,
/// with near and far planes fitted to it as tightly as the cull margin lets them.
fn camera(grid: &Grid, dir: Vec3, span: f32, fov: Option<f32>, (w, h): (u32, u32)) -> Camera {
    let r = 0.5 * grid.diagonal();
    let margin = Camera::cull_margin(grid.kernel_spacing());
    let target = grid.center();
    let closest = r + margin * 1.01;
    let (projection, d) = match fov {
        // The scene's 2r at depth d spans 2r h / (2 d tan(fov / 2)) pixels.
        Some(f) => {
            let d = r * h as f32 / (span * (f.to_radians() / 2.0).tan());
            (Projection::Perspective { fov_y_deg: f }, d.max(closest))
        }
        None => (Projection::Orthographic { height: 2.0 * r * h as f32 / span }, closest),
    };
    let eye = target + dir.normalize() * d;
    let up = if dir.normalize().cross(Vec3::Y).length() > 0.1 { Vec3::Y } else { Vec3::Z };
    let near = (d - r - margin * 1.01).max(d * 1e-4);
    Camera { eye, target, up, projection, near, far: d + r + margin * 1.01, width: w, height: h, window: None }
}

#[derive(Clone, Debug)]
struct Mode {
    composite: Composite,
    raster: Raster,
    kernel: Kernel,
    antialias: Antialias,
    order: OrderKind,
    early_termination: f32,
    lod: Lod,
    /// MIP or MinIP (issue 76: a thumbnail's MIP drew empty), else compositing.
    project: Option<voxsplat::options::Mode>,
}

fn mode() -> impl Strategy<Value = Mode> {
    (
        prop::sample::select(vec![Composite::Splat, Composite::Sheet, Composite::Slab]),
        prop::sample::select(vec![Raster::Auto, Raster::Graphics, Raster::Compute, Raster::Points]),
        prop::sample::select(vec![Kernel::Gaussian, Kernel::Cubic, Kernel::Narrow]),
        prop::sample::select(vec![Antialias::None, Antialias::Swan, Antialias::Ewa]),
        prop::sample::select(vec![OrderKind::Pbtf, OrderKind::Btf, OrderKind::Wbtf, OrderKind::Sorted]),
        prop::sample::select(vec![0.0f32, 0.004, 0.05]),
        prop::sample::select(vec![Lod::Auto, Lod::Off]),
        prop::sample::select(vec![
            None,
            None,
            Some(voxsplat::options::Mode::Mip),
            Some(voxsplat::options::Mode::Minip),
        ]),
    )
        .prop_map(|(composite, raster, kernel, antialias, order, early_termination, lod, project)| Mode {
            composite,
            raster,
            kernel,
            antialias,
            order,
            early_termination,
            lod,
            project,
        })
}

/// One renderer per backend for the whole run (a validated device takes a while to open).
static RENDERERS: Mutex<Vec<(Backend, Renderer)>> = Mutex::new(Vec::new());

fn with_renderer<T>(backend: Backend, f: impl FnOnce(&mut Renderer) -> T) -> T {
    let mut all = RENDERERS.lock().unwrap_or_else(|e| e.into_inner());
    if !all.iter().any(|(b, _)| *b == backend) {
        all.push((backend, renderer(backend)));
    }
    f(&mut all.iter_mut().find(|(b, _)| *b == backend).unwrap().1)
}

#[test]
fn the_library_covers_what_the_ray_cast_covers_or_refuses() {
    let strategy = (
        scene(),
        mode(),
        prop::array::uniform3(-1.0f32..1.0),
        2.0f32..64.0,
        prop::option::of(10f32..90.0),
        (2u32..48, 2u32..48),
        any::<bool>(),
    );
    // Cases that compared a covered ray cast with a frame, and cases refused.
    let (compared, refused) = (AtomicU32::new(0), AtomicU32::new(0));
    let projected = AtomicU32::new(0);
    let mut runner = runner(48);
    let cases = runner.config().cases;
    runner
        .run(&strategy, |(scene, mode, dir, span, fov, size, gpu)| {
            let dir = Vec3::from(dir);
            prop_assume!(dir.length() > 0.1);
            let grid = scene.grid();
            let cam = camera(&grid, dir, span, fov, size);
            let summed = mode.antialias != Antialias::None;
            let supersample = if summed { SUPERSAMPLE } else { 1 };
            let ray = with_renderer(Backend::Cpu, |r| {
                r.set_scene(scene.set()).unwrap();
                let mode = mode.project.unwrap_or_default();
                r.raycast(&cam, &RaycastOptions { step: 0.25, supersample, mode, ..Default::default() })
                    .map(|f| f.image)
            });
            let ray = match ray {
                Ok(image) => image,
                // A camera the reference refuses says nothing about the splats.
                Err(_) => return Ok(()),
            };
            let mut o = RenderOptions::default();
            (o.composite, o.raster, o.kernel, o.antialias) = (mode.composite, mode.raster, mode.kernel, mode.antialias);
            (o.order, o.early_termination, o.lod) = (mode.order, mode.early_termination, mode.lod);
            if let Some(p) = mode.project {
                // A projection draws in no order, every voxel's value (no early termination or
                // coarse cells): those choices are the compositing's.
                (o.mode, o.order, o.early_termination, o.lod) = (p, OrderKind::Pbtf, 0.0, Lod::Off);
            }
            let backend = if gpu { Backend::Gpu } else { Backend::Cpu };
            let frame = with_renderer(backend, |r| {
                match &scene {
                    Scene::Set { .. } => r.set_scene(scene.set())?,
                    Scene::Bricked { .. } => r.set_bricks(BrickScene::new(scene.store(), tf(), None)?)?,
                }
                let f = r.render(&cam, &o);
                prop_assert_eq!(r.validation_count(), 0, "{:?}", r.validation_messages());
                Ok(f)
            })?;
            let splat = match frame {
                Ok(f) => f.image,
                Err(e) => {
                    // Refused: a typed error that says why, never a frame.
                    prop_assert!(!e.to_string().is_empty());
                    refused.fetch_add(1, Relaxed);
                    return Ok(());
                }
            };
            prop_assert_eq!((splat.width, splat.height), size);
            let (ray, splat) = coverage(&ray, &splat, summed);
            if ray > 0.0 {
                compared.fetch_add(1, Relaxed);
                projected.fetch_add(mode.project.is_some() as u32, Relaxed);
            }
            prop_assert!(
                splat * COVERAGE_FACTOR >= ray,
                "coverage{}: the ray cast's {}, the splatted frame's {}",
                if summed { " (alpha summed)" } else { " (pixels)" },
                ray,
                splat
            );
            Ok(())
        })
        .unwrap();
    not_vacuous(&compared, &refused, cases);
    let projected = projected.load(Relaxed);
    eprintln!("{projected} of them MIP or MinIP");
    assert!(projected * 8 >= cases, "only {projected} of {cases} cases compared a projection's coverage");
}

/// A small volume file for the binary: a hollow ball, 24 x 20 x 16 bytes, in a raw NRRD.
fn ball_nrrd() -> std::path::PathBuf {
    let path = cmd::tmp_in("coverage", "ball.nrrd");
    let mut bytes = b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 24 20 16\nencoding: raw\n\n".to_vec();
    for k in 0..16 {
        for j in 0..20 {
            for i in 0..24 {
                let p = [(i as f32 - 11.5) / 11.5, (j as f32 - 9.5) / 9.5, (k as f32 - 7.5) / 7.5];
                let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                bytes.push(if (0.4..1.0).contains(&r) { (255.0 * (1.0 - r)) as u8 + 40 } else { 0 });
            }
        }
    }
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The coverage (as the library property states it) of an EXR the binary wrote.
fn read(path: &std::path::Path) -> ImageF32 {
    voxsplat::output::read_image(path).unwrap()
}

#[test]
fn the_binary_covers_what_its_ray_cast_covers_or_refuses() {
    let ball = ball_nrrd();
    let ball = ball.to_str().unwrap().to_string();
    let pick = |v: &[&'static str]| prop::sample::select(v.to_vec());
    let strategy = (
        // (scene flags, half diagonal in world units at spacing 1)
        prop::sample::select(vec![
            (vec!["--scene", "cube40"], 34.6f32),
            (vec!["--scene", "cube40-attenuated"], 34.6),
            (vec!["--scene", "solid40"], 34.6),
            (vec!["--scene", "plane"], 318.0),
            (vec!["--volume", "BALL", "--tf", "ramp"], 17.5),
        ]),
        -3.0f32..2.0,
        (prop::array::uniform3(-1.0f32..1.0), 0.1f32..2.5),
        prop::option::of(10f32..90.0),
        (2u32..48, 2u32..48),
        (
            pick(&["none", "swan", "ewa"]),
            pick(&["splat", "sheet", "slab"]),
            pick(&["auto", "graphics", "compute", "points"]),
        ),
        (pick(&["gaussian", "cubic", "narrow"]), pick(&["pbtf", "btf", "wbtf", "sorted"]), pick(&["auto", "off"])),
        any::<bool>(),
    );
    let (compared, refused) = (AtomicU32::new(0), AtomicU32::new(0));
    let mut runner = runner(24);
    let cases = runner.config().cases;
    runner
        .run(
            &strategy,
            |((scene, radius), scale, (dir, far), fov, (w, h), (aa, composite, raster), (kernel, order, lod), cpu)| {
                let dir = Vec3::from(dir);
                prop_assume!(dir.length() > 0.1);
                let volume = scene[0] == "--volume";
                // Only a file's spacing can be scaled (metres to kilometres a voxel).
                let spacing = if volume { 10f32.powf(scale) } else { 1.0 };
                let eye = dir.normalize() * radius * spacing * 10f32.powf(far);
                let (ray_out, out) = (cmd::tmp_in("coverage", "ray.exr"), cmd::tmp_in("coverage", "splat.exr"));
                let mut common: Vec<String> =
                    scene.iter().map(|a| if *a == "BALL" { ball.clone() } else { a.to_string() }).collect();
                common.extend([
                    "--size".into(),
                    format!("{w}x{h}"),
                    "--eye".into(),
                    format!("{},{},{}", eye.x, eye.y, eye.z),
                ]);
                if volume {
                    common.extend(["--spacing".into(), format!("{spacing},{spacing},{spacing}")]);
                }
                match fov {
                    Some(f) => common.extend(["--fov".into(), f.to_string()]),
                    None => common.extend(["--ortho".into(), (2.5 * radius * spacing).to_string()]),
                }
                let run = |extra: &[&str], out: &std::path::Path| {
                    let mut args: Vec<&str> = vec!["render"];
                    args.extend(common.iter().map(String::as_str));
                    args.extend(extra);
                    args.extend(["--out", out.to_str().unwrap()]);
                    let _ = std::fs::remove_file(out);
                    (cmd::voxsplat(&args), args.iter().map(|a| a.to_string()).collect::<Vec<_>>())
                };
                let summed = aa != "none";
                let (ray_run, ray_args) =
                    run(&["--raycast", "0.25", "--supersample", if summed { "4" } else { "1" }, "--cpu"], &ray_out);
                if !ray_run.status.success() {
                    return Ok(()); // a view the reference refuses says nothing about the splats
                }
                let mut extra = vec![
                    "--aa",
                    aa,
                    "--accumulate",
                    composite,
                    "--raster",
                    raster,
                    "--kernel",
                    kernel,
                    "--order",
                    order,
                ];
                if volume {
                    extra.extend(["--lod", lod]);
                }
                extra.push(if cpu { "--cpu" } else { "--validation" });
                let (splat_run, args) = run(&extra, &out);
                let err = String::from_utf8_lossy(&splat_run.stderr);
                prop_assert!(!err.contains("panicked") && !err.contains("validation"), "{args:?}: {err}");
                match splat_run.status.code() {
                    Some(0) => {}
                    Some(2) => {
                        prop_assert!(err.lines().any(|l| l.starts_with("error: ")), "{args:?}: {err}");
                        refused.fetch_add(1, Relaxed);
                        return Ok(());
                    }
                    other => prop_assert!(false, "{args:?}: exit {other:?}: {err}"),
                }
                let (ray, splat) = coverage(&read(&ray_out), &read(&out), summed);
                if ray > 0.0 {
                    compared.fetch_add(1, Relaxed);
                }
                prop_assert!(
                    splat * COVERAGE_FACTOR >= ray,
                    "{args:?} against {ray_args:?}: coverage {ray} -> {splat}"
                );
                Ok(())
            },
        )
        .unwrap();
    not_vacuous(&compared, &refused, cases);
}

/// Most cases compared a covered reference with a frame (a property that refused or skipped
/// everything would pass on anything).
fn not_vacuous(compared: &AtomicU32, refused: &AtomicU32, cases: u32) {
    let (compared, refused) = (compared.load(Relaxed), refused.load(Relaxed));
    eprintln!("{compared} of {cases} cases compared, {refused} refused");
    assert!(compared * 2 >= cases, "only {compared} of {cases} cases compared coverage");
}
