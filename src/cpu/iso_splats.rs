//! Mirror of `iso_splats.comp` and of `glsl/shared/surface.glsl`: each crossed cell's surface
//! splat, and the surface's shading (shared with the ray caster's mirror).
use super::bindings::Bindings;
use super::iso_count::IsoInputs;
use super::splat_params::{frame_grid, CULL_RADII};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{Frame, SplatParams};
use glam::Vec3;
use rayon::prelude::*;

/// Mirror of `SURFACE_SHININESS`.
pub const SURFACE_SHININESS: f32 = 20.0;

/// Mirror of `ISO_DISC_VOXELS`.
pub const ISO_DISC_VOXELS: f32 = 1.25;

fn corner(c: usize) -> Vec3 {
    Vec3::new((c & 1) as f32, (c >> 1 & 1) as f32, (c >> 2 & 1) as f32)
}

/// Mirror of `cell_value`: the cell's corner values reconstructed at local point `p`.
pub fn cell_value(v: &[f32; 8], p: Vec3) -> f32 {
    (0..8)
        .map(|c| {
            let w = Vec3::ONE - p + (2.0 * p - Vec3::ONE) * corner(c);
            v[c] * w.x * w.y * w.z
        })
        .sum()
}

/// Mirror of `cell_gradient`: that reconstruction's gradient (index units) at `p`.
pub fn cell_gradient(v: &[f32; 8], p: Vec3) -> Vec3 {
    let mut g = Vec3::ZERO;
    for (c, &vc) in v.iter().enumerate() {
        let d = corner(c);
        let w = Vec3::ONE - p + (2.0 * p - Vec3::ONE) * d;
        g += vc * (2.0 * d - Vec3::ONE) * Vec3::new(w.y * w.z, w.x * w.z, w.x * w.y);
    }
    g
}

/// Mirror of `surface_light`: (Lambert, Phong specular) under a headlight along unit `w`.
pub fn surface_light(n: Vec3, w: Vec3) -> [f32; 2] {
    let n = if n.dot(w) > 0.0 { -n } else { n };
    let lambert = n.dot(-w).max(0.0);
    let r = w - 2.0 * w.dot(n) * n;
    [lambert, r.dot(-w).max(0.0).powf(SURFACE_SHININESS)]
}

/// Mirror of `world_gradient`: U^-T g.
pub fn world_gradient(frame: &Frame, g: Vec3) -> Vec3 {
    let (s, h) = (frame.spacing, frame.shear);
    let x = g.x / s[0];
    let y = (g.y - h[0] * x) / s[1];
    Vec3::new(x, y, (g.z - h[1] * x - h[2] * y) / s[2])
}

/// Mirror of `surface_params`: the disc at world point `c` normal to world gradient `g`.
pub fn surface_params(frame: &Frame, c: Vec3, g: Vec3, band: f32) -> SplatParams {
    let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let (eye, forward, right) = (v3(frame.eye), v3(frame.forward), v3(frame.right));
    let depth = (c - eye).dot(forward);
    let radius = ISO_DISC_VOXELS * frame.spacing[3] / frame.origin[3];
    let clear = (depth - frame.forward[3]).min(frame.right[3] - depth);
    let mut visible = clear >= CULL_RADII * radius;
    for q in &frame.clip[..frame.rect[1] as usize] {
        visible = visible && Vec3::new(q[0], q[1], q[2]).dot(c) + q[3] >= 0.0;
    }
    let w = if frame.eye[3] > 0.5 { (c - eye).normalize() } else { forward };
    let gl = g.length();
    let mut n = if gl > 0.0 { g / gl } else { -w };
    if n.dot(w) > 0.0 {
        n = -n;
    }
    let t = n.cross(w);
    let tl = t.length();
    let t = if tl > 1e-6 { t / tl } else { (right - right.dot(n) * n).normalize() };
    let b = n.cross(t);
    let light = surface_light(n, w);
    let pixels = if frame.eye[3] > 0.5 { radius * frame.up[3] / depth.max(1e-6) } else { radius * frame.up[3] };
    let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
    SplatParams {
        center: v4(c, if visible { 1.0 } else { 0.0 }),
        axis_u: v4(t * radius, 1.0),
        axis_v: v4(b * radius, t.dot(forward) * radius),
        emit: [light[0], light[1], 0.0, band],
        screen: [depth, b.dot(forward) * radius, pixels, 1.0],
    }
}

/// The surface splat of crossed cell `cell` (as `iso_cells` lists it).
pub fn cell_splat(inputs: &IsoInputs<'_>, cell: [u32; 2]) -> SplatParams {
    let iso = inputs.push.iso;
    let c0 = [(cell[0] & 0xffff) as i32 - 1, (cell[0] >> 16) as i32 - 1, (cell[1] & 0xffff) as i32 - 1];
    let m = cell[1] >> 16;
    let v: [f32; 8] = std::array::from_fn(|c| {
        inputs.value(c0[0] + (c & 1) as i32, c0[1] + (c >> 1 & 1) as i32, c0[2] + (c >> 2 & 1) as i32) as f32
            / crate::iso::ISO_Q
    });
    let (mut sum, mut crossings) = (Vec3::ZERO, 0.0f32);
    for c in 0..8 {
        for b in [1usize, 2, 4] {
            if c & b != 0 || (m >> c & 1) == (m >> (c | b) & 1) {
                continue;
            }
            let t = ((iso - v[c]) / (v[c | b] - v[c])).clamp(0.0, 1.0);
            sum += corner(c).lerp(corner(c | b), t);
            crossings += 1.0;
        }
    }
    let mut p = sum / crossings;
    for _ in 0..2 {
        let g = cell_gradient(&v, p);
        let gg = g.dot(g);
        if gg > 1e-12 {
            p = (p - (cell_value(&v, p) - iso) * g / gg).clamp(Vec3::ZERO, Vec3::ONE);
        }
    }
    let at = Vec3::new(c0[0] as f32, c0[1] as f32, c0[2] as f32) + p;
    let frame = inputs.frame;
    surface_params(frame, frame_grid(frame).point(at), world_gradient(frame, cell_gradient(&v, p)), inputs.push.band)
}

/// Every surface splat from its cell, and the draw list (the storage order).
pub fn iso_splats(inputs: &IsoInputs<'_>, cells: &[[u32; 2]], params: &mut [SplatParams], order: &mut [u32]) {
    params.par_iter_mut().zip(cells).for_each(|(p, &cell)| *p = cell_splat(inputs, cell));
    for (i, o) in order.iter_mut().enumerate() {
        *o = i as u32;
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut params_words = b.take(Res::Params);
    let mut order = b.take(Res::Order);
    {
        let inputs =
            IsoInputs { field: b.get(Res::IsoField), rows: b.get(Res::IsoRows), frame: &b.frame, push: d.push_as() };
        let n = inputs.push.splats as usize;
        let words = std::mem::size_of::<SplatParams>() / 4;
        let params: &mut [SplatParams] = bytemuck::cast_slice_mut(&mut params_words[..n * words]);
        let cells: &[[u32; 2]] = &b.get::<[u32; 2]>(Res::IsoCells)[..n];
        iso_splats(&inputs, cells, params, &mut order[..n]);
    }
    b.put(Res::Params, params_words);
    b.put(Res::Order, order);
    Ok(())
}
