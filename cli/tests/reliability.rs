//! Long runs do not leak, renderers are Send and deterministic.
use crate::common;
use voxsplat::{scene, Camera, Composite, RenderOptions};

/// GPU allocations must not drift (host memory: the next test, in a child process).
#[test]
fn a_100_frame_soak_keeps_gpu_allocations_flat() {
    let mut r = common::gpu();
    let rep = voxsplat_cli::soak::soak(&mut r, 100, 64, |_| {}).unwrap();
    eprintln!("gpu per cycle {:?}", rep.gpu);
    eprintln!("rss per cycle (MiB) {:?}", rep.rss.iter().map(|b| b / (1 << 20)).collect::<Vec<_>>());
    // After the first cycle (warm-up) every cycle starts with the same live allocations. lavapipe's
    // memory requirement for a re-created image can differ by an alignment step (32 bytes seen), so
    // the byte total may move by that much but must not grow with the cycles.
    assert!(rep.gpu.len() >= 8);
    for g in &rep.gpu[2..] {
        assert_eq!(g.0, rep.gpu[1].0, "the number of live GPU allocations drifts: {:?}", rep.gpu);
        assert!(g.1.abs_diff(rep.gpu[1].1) <= 4096, "GPU bytes drift: {:?}", rep.gpu);
    }
    assert_eq!(rep.validation_messages, 0);
    common::assert_clean(&r);
}

/// Host memory must not grow after warm-up. In a child process so that the test harness's own
/// allocations do not count and the allocator can be configured (see `SoakReport::rss_growth`).
/// Before the frame constants moved from a uniform to a storage buffer, lavapipe grew by
/// 0.2-0.7 MB per frame here, about 5 MiB per cycle.
#[test]
fn a_120_frame_soak_keeps_host_memory_flat() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_voxsplat"))
        .args(["lab", "soak", "--frames", "120", "--size", "64", "--validation"])
        .env("MALLOC_MMAP_THRESHOLD_", "131072")
        .env("MALLOC_ARENA_MAX", "1")
        .output()
        .expect("run voxsplat lab soak");
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success());
    let figure = |prefix: &str| -> f64 {
        text.lines()
            .find_map(|l| l.strip_prefix(prefix))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .expect(prefix)
    };
    // A leak moves every cycle: the old uniform-buffer leak measured ~5 MiB per 12-frame cycle here.
    // One-off steps (driver pools, allocator arenas) move one cycle and leave the median alone.
    let step = figure("rss median step per cycle after warm-up: ");
    eprintln!("peak growth {} MiB", figure("rss peak growth after warm-up: "));
    assert!(step < 1.0, "host RSS grows {step} MiB per cycle after warm-up");
    assert!(text.contains("validation messages: 0"));
}

#[test]
fn two_renderers_in_two_threads_render_identical_images() {
    let set = scene::build("cube40").unwrap();
    let cam = Camera::framing(set.grid(), 80, 64);
    let run = move |set: voxsplat::SplatSet| {
        std::thread::spawn(move || {
            let mut r = common::gpu();
            r.set_scene(set).unwrap();
            let mut out = Vec::new();
            for composite in [Composite::Splat, Composite::Sheet, Composite::Slab] {
                let mut o = RenderOptions::default();
                o.composite = composite;
                out.push(r.render(&cam, &o).unwrap().image);
            }
            common::assert_clean(&r);
            out
        })
    };
    let (a, b) = (run(set.clone()), run(set));
    let (a, b) = (a.join().unwrap(), b.join().unwrap());
    for (x, y) in a.iter().zip(&b) {
        // Two blank frames would agree too.
        assert!(common::covered(x) > 80 * 64 / 10, "the cube is drawn ({} px)", common::covered(x));
        assert_eq!(x.pixels, y.pixels, "threads disagree");
    }
}

#[test]
fn the_same_inputs_give_bit_identical_images_run_to_run() {
    let set = scene::build("cube40-attenuated").unwrap();
    let cam = Camera::framing(set.grid(), 72, 56);
    for gpu in [false, true] {
        let mut r = if gpu { common::gpu() } else { common::cpu() };
        r.set_scene(set.clone()).unwrap();
        for composite in [Composite::Splat, Composite::Sheet, Composite::Slab] {
            let mut o = RenderOptions::default();
            o.composite = composite;
            let first = r.render(&cam, &o).unwrap().image;
            assert!(common::covered(&first) > 72 * 56 / 10, "gpu={gpu} {composite:?}: the cube is drawn");
            for _ in 0..3 {
                assert_eq!(r.render(&cam, &o).unwrap().image.pixels, first.pixels, "gpu={gpu} {composite:?}");
            }
        }
    }
}

/// Device loss (injected at the queue: a CPU device cannot be made to lose itself) reaches the
/// caller as `DeviceLost`, stays lost for every later call without touching the device, and the
/// renderer then drops cleanly.
#[test]
fn device_loss_is_an_error_that_sticks_and_the_renderer_drops_cleanly() {
    let mut r = common::gpu();
    r.set_scene(scene::build("cube40").unwrap()).unwrap();
    let cam = Camera::framing(r.scene().unwrap().grid(), 48, 48);
    r.render(&cam, &RenderOptions::default()).unwrap();
    let ctx = r.context().expect("gpu").clone();
    assert!(!ctx.is_lost());
    ctx.inject_submit_fault(voxsplat::vk::ash::vk::Result::ERROR_DEVICE_LOST);
    let err = r.render(&cam, &RenderOptions::default()).unwrap_err();
    assert!(matches!(err, voxsplat::Error::DeviceLost(_)), "{err}");
    assert!(err.to_string().contains("create a new one"), "{err}");
    assert!(ctx.is_lost());
    let mut sheet = RenderOptions::default();
    sheet.composite = Composite::Sheet;
    assert!(matches!(r.render(&cam, &sheet), Err(voxsplat::Error::DeviceLost(_))));
    let rc = voxsplat::RaycastOptions::default();
    assert!(matches!(r.raycast(&cam, &rc), Err(voxsplat::Error::DeviceLost(_))));
    common::assert_clean(&r);
    drop(ctx);
    drop(r);
}

/// Out-of-memory from a submission is an error, and transient: the next frame renders the same
/// image as before.
#[test]
fn out_of_memory_at_submit_is_an_error_and_the_next_frame_renders() {
    let mut r = common::gpu();
    r.set_scene(scene::build("cube40").unwrap()).unwrap();
    let cam = Camera::framing(r.scene().unwrap().grid(), 48, 48);
    let before = r.render(&cam, &RenderOptions::default()).unwrap().image;
    r.context().unwrap().inject_submit_fault(voxsplat::vk::ash::vk::Result::ERROR_OUT_OF_DEVICE_MEMORY);
    let err = r.render(&cam, &RenderOptions::default()).unwrap_err();
    assert!(matches!(err, voxsplat::Error::OutOfMemory(_)), "{err}");
    let after = r.render(&cam, &RenderOptions::default()).unwrap().image;
    assert_eq!(before.pixels, after.pixels);
    common::assert_clean(&r);
}
