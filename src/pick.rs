//! Picking (`Renderer::pick`, `voxsplat pick`): the point of the volume a pixel shows, found on the
//! host along the pixel's ray through the ray caster's trilinear field (the reference the splats are
//! compared with), so a viewer can show the value under its cursor without a frame.
use crate::bricks::BRICK;
use crate::camera::Camera;
use crate::cpu::raycast::{ray_index, trilinear_by as trilinear};
use crate::error::{Error, Result};
use crate::options::{Mode, RaycastOptions, RenderOptions};
use crate::plan::Prepared;
use glam::Vec3;

/// Accumulated opacity at which a ray's first hit is taken (compositing, average and X-ray).
pub const PICK_OPACITY: f32 = 0.5;

/// Samples per voxel spacing along a picked ray.
const PICK_STEPS_PER_VOXEL: f32 = 8.0;

/// What a pixel shows: its ray's first point where the accumulated opacity passes
/// one half (in MIP and MinIP, the point of the extreme value). `Renderer::pick` finds it.
///
/// ```
/// use voxsplat::{scene, Backend, Camera, RenderOptions, Renderer, RendererOptions};
/// let mut o = RendererOptions::default();
/// o.backend = Backend::Cpu;
/// let mut r = Renderer::new(&o)?;
/// let set = scene::build("cube40")?;
/// let camera = Camera::framing(set.grid(), 64, 64);
/// r.set_scene(set)?;
/// let corner = r.pick(&camera, &RenderOptions::default(), 0.5, 0.5)?;
/// assert!(corner.is_none(), "the corner pixel's ray misses the cube");
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pick {
    /// The point, in world coordinates.
    pub world: Vec3,
    /// The grid index of the voxel nearest the point.
    pub voxel: [u32; 3],
    /// That voxel's value in [0, 1] (its normalised density; the value the projections take),
    /// or, where the voxel was not extracted, the value reconstructed there from its neighbours.
    pub value: f32,
    /// The point's eye-space depth (its distance along the view direction from the eye).
    pub depth: f32,
}

/// Pick at pixel position (`x`, `y`) of `camera` (pixels from the top left corner; a pixel's
/// centre is at + 0.5), with `opts`' mode and clipping.
pub fn pick(prep: &Prepared, camera: &Camera, opts: &RenderOptions, x: f32, y: f32) -> Result<Option<Pick>> {
    camera.validate()?;
    let (w, h) = (camera.width as f32, camera.height as f32);
    if !(x.is_finite() && y.is_finite() && (0.0..=w).contains(&x) && (0.0..=h).contains(&y)) {
        return Err(Error::InvalidArgument(format!(
            "pick at ({x}, {y}): outside the {} x {} image",
            camera.width, camera.height
        )));
    }
    if opts.mode == Mode::Iso {
        // The isosurface's values: every voxel's, as the surface splats and the ray caster read them.
        crate::options::check_iso(opts.mode, opts.iso)?;
        let field = prep.iso_field()?;
        let q = crate::iso::ISO_Q;
        return march(prep, camera, opts, x, y, |i, j, k| [field.at(i, j, k) as f32 / q, 1.0, 0.0, 0.0]);
    }
    match &prep.bricks {
        Some(scene) => {
            let voxel = bricked_voxel(scene)?;
            march(prep, camera, opts, x, y, voxel)
        }
        None => {
            let field = prep.field_for(Mode::Mip)?;
            march(prep, camera, opts, x, y, |i, j, k| field.at(i, j, k))
        }
    }
}

/// A bricked store's voxel as the projection field holds it: (value, 1, 0, tau) where the
/// transfer function draws it (its opacity gradient-weighted as the brick stages weigh it),
/// zero elsewhere; read through the store, so no dense copy is made.
fn bricked_voxel(scene: &crate::bricks::BrickScene) -> Result<impl Fn(i64, i64, i64) -> [f32; 4] + '_> {
    let (a, b) = scene.remap();
    let tf = scene.transfer_function();
    let grid = scene.store.grid()?;
    let weight = tf.gradient_weight;
    let gmax = if weight > 0.0 { (a * scene.gmax_stored()).max(1e-12) } else { 1.0 };
    let d = move |i: i64, j: i64, k: i64| a * scene.store.value_at(i, j, k) + b;
    let stored = move |i: i64, j: i64, k: i64| {
        let [nx, ny, nz] = scene.store.dims.map(|n| n as i64);
        (0..nx).contains(&i) && (0..ny).contains(&j) && (0..nz).contains(&k) && {
            let v = [i, j, k].map(|c| c as u32);
            let h = scene.store.header_of(v);
            h != u32::MAX && {
                let l = (v[0] % BRICK + BRICK * (v[1] % BRICK) + BRICK * BRICK * (v[2] % BRICK)) as usize;
                scene.store.masks[h as usize][l / 64] >> (l % 64) & 1 == 1
            }
        }
    };
    Ok(move |i: i64, j: i64, k: i64| {
        if !stored(i, j, k) {
            return [0.0; 4];
        }
        let value = d(i, j, k);
        if value < tf.threshold {
            return [0.0; 4];
        }
        let mut opacity = tf.eval(value)[3];
        if weight > 0.0 && opacity > 0.0 {
            let g = glam::Vec3::from(grid.gradient([
                d(i + 1, j, k) - d(i - 1, j, k),
                d(i, j + 1, k) - d(i, j - 1, k),
                d(i, j, k + 1) - d(i, j, k - 1),
            ]));
            opacity *= (g.length() / gmax).powf(weight);
        }
        if opacity <= 0.0 {
            return [0.0; 4];
        }
        [value.clamp(0.0, 1.0), 1.0, 0.0, crate::volume::optical_depth(opacity)]
    })
}

/// The pick along the pixel's ray through the field `voxel` gives.
fn march(
    prep: &Prepared,
    camera: &Camera,
    opts: &RenderOptions,
    x: f32,
    y: f32,
    voxel: impl Fn(i64, i64, i64) -> [f32; 4],
) -> Result<Option<Pick>> {
    let step_vox = 1.0 / PICK_STEPS_PER_VOXEL;
    let ro = RaycastOptions { step: step_vox, clip: opts.clip, mode: opts.mode, ..Default::default() };
    let rc = crate::plan::raycast_params(&prep.set, camera, &ro);
    let Some(ray) = ray_index(&rc, x, y) else { return Ok(None) };
    let step = rc.box_min[3];
    let n = ((ray.t1 - ray.t0) / step).ceil() as u64;
    let at = |t: f32| ray.a + ray.dir * t;
    let extreme = matches!(opts.mode, Mode::Mip | Mode::Minip);
    // Extreme modes: the best (key, t); else the transmittance so far.
    let (mut best, mut trans) = (None::<(f32, f32)>, 1.0f32);
    let mut hit = None;
    // The isosurface: the first crossing from below (the ray caster's), refined between samples.
    let iso = (opts.mode == Mode::Iso).then(|| opts.iso.unwrap_or(0.0));
    let mut below = None::<(f32, f32)>;
    for s in 0..n {
        let t = ray.t0 + (s as f32 + 0.5) * step;
        let v = trilinear(&voxel, ray.index(t));
        if let Some(iso) = iso {
            if v[0] < iso {
                below = Some((t, v[0]));
            } else if let Some((tb, vb)) = below {
                hit = Some(tb + (iso - vb) / (v[0] - vb) * (t - tb));
                break;
            }
            continue;
        }
        if v[3] <= 0.0 {
            continue;
        }
        if extreme {
            let key = if opts.mode == Mode::Mip { v[0] } else { v[1] - v[0] };
            if best.is_none_or(|(b, _)| key > b) {
                best = Some((key, t));
            }
            continue;
        }
        // The optical depth over this sample's step: where inside it the opacity passes the
        // threshold (the transmittance falls exponentially along it).
        let sigma = v[3] * rc.origin[3];
        let after = trans * (-sigma * step).exp();
        if 1.0 - after >= PICK_OPACITY {
            let into = ((trans / (1.0 - PICK_OPACITY)).ln() / sigma).clamp(0.0, step);
            hit = Some(t - 0.5 * step + into);
            break;
        }
        trans = after;
    }
    let t = if extreme { best.map(|b| b.1) } else { hit };
    let voxel_at = voxel;
    Ok(t.map(|t| {
        let world = at(t);
        let u = ray.index(t);
        let g = &prep.set.grid().dims;
        let voxel = [0, 1, 2].map(|a| (u[a].round().max(0.0) as u32).min(g[a] - 1));
        let here = voxel_at(voxel[0] as i64, voxel[1] as i64, voxel[2] as i64);
        let value = if here[1] > 0.0 {
            here[0]
        } else {
            let v = trilinear(&voxel_at, u);
            if v[1] > 0.0 {
                v[0] / v[1]
            } else {
                0.0
            }
        };
        Pick { world, voxel, value, depth: (world - camera.eye).dot(camera.forward()) }
    }))
}
