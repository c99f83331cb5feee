//! Chapter 4's order choice and chapter 5's terrain blur. The seed draws its
//! moving object (Fig. 4.5) and the turning terrain (Figs 5.4-5.6) with WBTF, because PBTF's seams
//! lie on planes through the eye and march across a moving object from frame to frame. Measured
//! here per animation: each order's still frames against the exactly sorted order's (static error)
//! and how far their frame-to-frame change departs from the sorted order's (temporal error); and
//! on the orthographic terrain drawn with WBTF, blurred splats against the accumulation buffer.
use std::fmt::Write as _;
use voxsplat::animate::{render_frame_timed, Animation, Blur, SplatBlur};
use voxsplat::{
    image::ImageF32, options::BlurProfile, options::Raster, order::OrderKind, RenderOptions, Renderer, RendererOptions,
    Result,
};

/// The turn of `rotating-box` seen in perspective by an eye level with the box (inside its y
/// slab): PBTF splits at the eye's plane there, so its seams cross the moving faces, the case the
/// seed avoided by drawing Fig. 4.5 with WBTF.
const SEAMS: &str = "rotating-box, perspective, eye level with it";

/// `SEAMS`: `rotating-box` with view A's eye, a 75° field and the near and far planes an
/// animation file's perspective camera gets.
fn seams() -> Result<Animation> {
    let mut a = Animation::builtin("rotating-box")?;
    let (eye, target) = (voxsplat::glam::Vec3::new(70.0, 20.0, 12.0), voxsplat::glam::Vec3::ZERO);
    let dist = (target - eye).length();
    a.camera = voxsplat::Camera {
        eye,
        target,
        projection: voxsplat::camera::Projection::Perspective { fov_y_deg: 75.0 },
        near: 0.05 * dist,
        far: 4.0 * dist.max(1.0),
        ..a.camera
    };
    a.camera.validate()?;
    Ok(a)
}

/// One order on one animation.
pub struct OrderRow {
    pub animation: &'static str,
    pub order: OrderKind,
    /// Mean PSNR of its still frames against the sorted order's.
    pub static_psnr: f64,
    /// Mean RMSE of (its change from the previous frame) minus (the sorted order's change).
    pub temporal_rmse: f64,
}

/// One blur method on one animation (WBTF) through one raster choice.
pub struct BlurRow {
    pub animation: &'static str,
    pub method: String,
    /// `auto` (a CPU device's default: the compute tile compositor for the seed's shape, graphics
    /// quads for the others) or `graphics`.
    pub raster: Raster,
    pub rmse: f64,
    pub ms: f64,
}

/// The blur methods compared: still, the seed's blurred splats, chapter 4's future work (arc
/// paths, tapered and teardrop profiles, alone and together), and the accumulation buffer.
fn blur_methods() -> Vec<(String, Blur)> {
    let mut m = vec![("still".to_string(), Blur::None)];
    for arc in [false, true] {
        for profile in [BlurProfile::Uniform, BlurProfile::Tapered, BlurProfile::Teardrop, BlurProfile::Slotted] {
            let shape = SplatBlur { arc, profile };
            m.push((shape.name(), Blur::Splat(shape)));
        }
    }
    m.push(("accum:5".to_string(), Blur::Accum(5)));
    m
}

fn options(order: OrderKind) -> RenderOptions {
    let mut o = crate::lab_options();
    o.order = order;
    o
}

fn change(a: &ImageF32, b: &ImageF32) -> Vec<[f32; 4]> {
    a.pixels.iter().zip(&b.pixels).map(|(p, q)| [0, 1, 2, 3].map(|c| p[c] - q[c])).collect()
}

/// Orders on the three built-in animations over frames `first..first + frames`, and the blur
/// methods on the orthographic terrain at frame `first + frames`, `rounds` timed renders each.
pub fn study(first: u32, frames: u32, rounds: usize) -> Result<(Vec<OrderRow>, Vec<BlurRow>)> {
    let mut r = Renderer::new(&RendererOptions::default())?;
    let mut orders = Vec::new();
    for name in ["rotating-box", "rotating-terrain", "rotating-terrain-ortho", SEAMS] {
        let anim = if name == SEAMS { seams()? } else { Animation::builtin(name)? };
        let set = voxsplat::scene::build(&anim.scene)?;
        let grid = *set.grid();
        r.set_scene(set)?;
        let run = |r: &mut Renderer, order| -> Result<Vec<ImageF32>> {
            (first..=first + frames)
                .map(|i| Ok(render_frame_timed(r, &anim, &grid, i, Blur::None, &options(order))?.0))
                .collect()
        };
        let sorted = run(&mut r, OrderKind::Sorted)?;
        for order in [OrderKind::Pbtf, OrderKind::PbtfOctant, OrderKind::Wbtf, OrderKind::Btf] {
            let seq = run(&mut r, order)?;
            let mut psnr = 0.0;
            for (a, b) in seq.iter().zip(&sorted) {
                psnr += voxsplat::metrics::compare(a, b)?.psnr;
            }
            let mut temporal = 0.0;
            for t in 1..seq.len() {
                let (d, e) = (change(&seq[t], &seq[t - 1]), change(&sorted[t], &sorted[t - 1]));
                let se: f64 =
                    d.iter().zip(&e).flat_map(|(p, q)| (0..4).map(move |c| ((p[c] - q[c]) as f64).powi(2))).sum();
                temporal += (se / (4 * d.len()) as f64).sqrt();
            }
            orders.push(OrderRow {
                animation: name,
                order,
                static_psnr: psnr / seq.len() as f64,
                temporal_rmse: temporal / (seq.len() - 1) as f64,
            });
        }
    }
    // Fig. 4.5's box, a faster turn whose arcs bend, and Figs 5.4-5.6's orthographic terrain, WBTF
    // as the seed draws them, against 64 sub-frames; every method through the default raster choice
    // and through graphics quads.
    let mut blurs = Vec::new();
    let methods: Vec<(String, Blur, Raster)> = [Raster::Auto, Raster::Graphics]
        .into_iter()
        .flat_map(|raster| blur_methods().into_iter().map(move |(name, blur)| (name, blur, raster)))
        .collect();
    for name in ["rotating-box", "spinning-box", "rotating-terrain-ortho"] {
        let anim = Animation::builtin(name)?;
        let set = voxsplat::scene::build(&anim.scene)?;
        let grid = *set.grid();
        r.set_scene(set)?;
        let at = first + frames;
        let truth = render_frame_timed(&mut r, &anim, &grid, at, Blur::Accum(64), &options(OrderKind::Wbtf))?.0;
        let mut images = vec![None; methods.len()];
        // The methods alternate frame by frame (a warm-up round first); summed stage times.
        let medians = crate::bench::alternating_medians(methods.len(), 1, rounds, |k| {
            let mut o = options(OrderKind::Wbtf);
            o.raster = methods[k].2;
            let (img, ms) = render_frame_timed(&mut r, &anim, &grid, at, methods[k].1, &o)?;
            images[k] = Some(img);
            Ok(ms)
        })?;
        for (((method, _, raster), ms), img) in methods.iter().zip(medians).zip(images) {
            let img = img.expect("a round");
            let rmse = voxsplat::metrics::compare(&img, &truth)?.rmse;
            blurs.push(BlurRow { animation: name, method: method.clone(), raster: *raster, rmse, ms });
        }
    }
    Ok((orders, blurs))
}

/// The study's markdown section.
pub fn markdown(orders: &[OrderRow], blurs: &[BlurRow], first: u32, frames: u32) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Orders under motion, blur shapes (chapters 4 and 5)\n\n`voxsplat-lab motion-orders`: still frames {first} to {} \
         of each built-in animation; static error = mean PSNR against the exactly sorted order's frames; temporal error = \
         mean RMSE of each frame-to-frame change against the sorted order's change (what the order adds to the motion).\n\n\
         | animation | order | static PSNR dB | temporal RMSE |\n|---|---|---:|---:|",
        first + frames
    );
    for r in orders {
        let order = match r.order {
            OrderKind::PbtfOctant => "PBTF, Westover's nesting per octant".to_string(),
            other => format!("{other:?}").to_uppercase(),
        };
        let _ = writeln!(s, "| {} | {order} | {:.2} | {:.5} |", r.animation, r.static_psnr, r.temporal_rmse);
    }
    let _ = writeln!(
        s,
        "\nFig. 4.5's box, the same box turning 30° a frame (`spinning-box`) and Figs 5.4-5.6's orthographic terrain \
         drawn with WBTF as the seed draws them, frame {}, against 64 sub-frames (summed stage times, all methods \
         alternating, medians). `auto` is the default raster choice (on a CPU device the tile compositor for the \
         seed's shape and for accum:5; graphics quads for the arc and tapered shapes, which only that pipeline draws); \
         the last two columns are against accum:5 through the same raster choice (the target for blurred \
         splats: error ≤ 1.5× at ≤ 0.5× the time):\n\n\
         | animation | method | raster | RMSE | ms | error vs accum:5 | time vs accum:5 |\n|---|---|---|---:|---:|---:|---:|",
        first + frames
    );
    for b in blurs {
        let accum = blurs
            .iter()
            .find(|a| a.animation == b.animation && a.raster == b.raster && a.method == "accum:5")
            .expect("accum:5 row");
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.5} | {:.1} | {:.2}× | {:.2}× |",
            b.animation,
            b.method,
            b.raster,
            b.rmse,
            b.ms,
            b.rmse / accum.rmse,
            b.ms / accum.ms
        );
    }
    s
}
