//! Renderers are Send and deterministic; device loss and out-of-memory are errors (the long runs
//! that must not leak: the lab's tests, lab/tests/soak.rs).
use super::common;
use crate::{options::Composite, scene, Camera, RenderOptions};

#[test]
fn two_renderers_in_two_threads_render_identical_images() {
    let set = scene::build("cube40").unwrap();
    let cam = Camera::framing(set.grid(), 80, 64);
    let run = move |set: crate::SplatSet| {
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
    ctx.inject_submit_fault(crate::vk::ash::vk::Result::ERROR_DEVICE_LOST);
    let err = r.render(&cam, &RenderOptions::default()).unwrap_err();
    assert!(matches!(err, crate::Error::DeviceLost(_)), "{err}");
    assert!(err.to_string().contains("create a new one"), "{err}");
    assert!(ctx.is_lost());
    let mut sheet = RenderOptions::default();
    sheet.composite = Composite::Sheet;
    assert!(matches!(r.render(&cam, &sheet), Err(crate::Error::DeviceLost(_))));
    let rc = crate::options::RaycastOptions::default();
    assert!(matches!(r.raycast(&cam, &rc), Err(crate::Error::DeviceLost(_))));
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
    r.context().unwrap().inject_submit_fault(crate::vk::ash::vk::Result::ERROR_OUT_OF_DEVICE_MEMORY);
    let err = r.render(&cam, &RenderOptions::default()).unwrap_err();
    assert!(matches!(err, crate::Error::OutOfMemory(_)), "{err}");
    let after = r.render(&cam, &RenderOptions::default()).unwrap().image;
    assert_eq!(before.pixels, after.pixels);
    common::assert_clean(&r);
}
