//! Picking (`Renderer::pick`, `voxsplat pick`): the point of the volume a pixel shows, found on the
//! host along the pixel's ray through the ray caster's trilinear field (the reference the splats are
//! compared with), so a viewer can show the value under its cursor without a frame.
use crate::camera::Camera;
use crate::cpu::raycast::{ray_index, trilinear};
use crate::error::{Error, Result};
use crate::options::{Mode, RaycastOptions, RenderOptions};
use crate::plan::Prepared;
use glam::Vec3;

/// Accumulated opacity at which a ray's first hit is taken (compositing, average and X-ray).
pub const PICK_OPACITY: f32 = 0.5;

/// Samples per voxel spacing along a picked ray.
const PICK_STEPS_PER_VOXEL: f32 = 8.0;

/// What a pixel shows: its ray's first point where the accumulated opacity passes
/// [`PICK_OPACITY`] (in MIP and MinIP, the point of the extreme value).
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
    if prep.bricks.is_some() {
        return Err(Error::Unsupported(
            "picking reads a dense scene's field; this volume is a bricked store (load it as host splats)".into(),
        ));
    }
    let step_vox = 1.0 / PICK_STEPS_PER_VOXEL;
    let ro = RaycastOptions { step: step_vox, clip: opts.clip, mode: opts.mode, ..Default::default() };
    let rc = crate::plan::raycast_params(&prep.set, camera, &ro);
    let field = prep.field_for(true)?;
    let Some(ray) = ray_index(&rc, x, y) else { return Ok(None) };
    let step = rc.box_min[3];
    let n = ((ray.t1 - ray.t0) / step).ceil() as u64;
    let at = |t: f32| ray.a + ray.dir * t;
    let extreme = matches!(opts.mode, Mode::Mip | Mode::Minip);
    // Extreme modes: the best (key, t); else the transmittance so far.
    let (mut best, mut trans) = (None::<(f32, f32)>, 1.0f32);
    let mut hit = None;
    for s in 0..n {
        let t = ray.t0 + (s as f32 + 0.5) * step;
        let v = trilinear(field, ray.index(t));
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
    Ok(t.map(|t| {
        let world = at(t);
        let u = ray.index(t);
        let g = &prep.set.grid().dims;
        let voxel = [0, 1, 2].map(|a| (u[a].round().max(0.0) as u32).min(g[a] - 1));
        let here = field.at(voxel[0] as i64, voxel[1] as i64, voxel[2] as i64);
        let value = if here[1] > 0.0 {
            here[0]
        } else {
            let v = trilinear(field, u);
            if v[1] > 0.0 {
                v[0] / v[1]
            } else {
                0.0
            }
        };
        Pick { world, voxel, value, depth: (world - camera.eye).dot(camera.forward()) }
    }))
}
