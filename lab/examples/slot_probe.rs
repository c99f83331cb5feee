//! Issue 26 item 5: how many time slots a blurred frame needs. Each animation's frame 20 drawn as
//! 1 to 4 sub-frames, each with arc+tapered splats over its share of the shutter (WBTF, graphics
//! quads), against 64 sub-frames, as a multiple of accum:5's error. `splat:slotted` is the
//! two-slot case in one geometry pass.
use voxsplat::animate::{render_frame, Animation, Blur};
use voxsplat::{
    options::BlurProfile, options::Motion, options::Raster, order::OrderKind, RenderOptions, Renderer, RendererOptions,
};
fn main() -> voxsplat::Result<()> {
    let mut r = Renderer::new(&RendererOptions::default())?;
    for name in ["rotating-box", "spinning-box", "rotating-terrain-ortho"] {
        let anim = Animation::builtin(name)?;
        let set = voxsplat::scene::build(&anim.scene)?;
        let grid = *set.grid();
        r.set_scene(set)?;
        let mut o = RenderOptions::default();
        o.order = OrderKind::Wbtf;
        o.raster = Raster::Graphics;
        let truth = render_frame(&mut r, &anim, &grid, 20, Blur::Accum(64), &o)?;
        let a5 = render_frame(&mut r, &anim, &grid, 20, Blur::Accum(5), &o)?;
        let e5 = voxsplat::metrics::compare(&a5, &truth)?.rmse;
        for m in [1u32, 2, 3, 4] {
            let t = 20.0f32;
            let mut acc = voxsplat::image::ImageF32::new(truth.width, truth.height);
            for k in 0..m {
                let t1 = t - anim.shutter + (k + 1) as f32 / m as f32 * anim.shutter;
                let t0 = t1 - anim.shutter / m as f32;
                let mut oo = o.clone();
                oo.motion = Some(Motion {
                    previous: anim.motion(&grid, t0, t1),
                    middle: Some(anim.motion(&grid, 0.5 * (t0 + t1), t1)),
                    delta_px: 0.5,
                    profile: BlurProfile::Tapered,
                });
                let img = r.render(&anim.object_camera(&grid, t1), &oo)?.image;
                for (a, p) in acc.pixels.iter_mut().zip(&img.pixels) {
                    for c in 0..4 {
                        a[c] += p[c] / m as f32;
                    }
                }
            }
            let e = voxsplat::metrics::compare(&acc, &truth)?.rmse;
            println!("{name}: {m} slots of arc+tapered: rmse {e:.5} = {:.2}x accum:5", e / e5);
        }
    }
    Ok(())
}
