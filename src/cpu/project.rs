//! Mirror of `project.comp`: a projection mode's blended (key, weight) per pixel mapped through
//! the colour map into the premultiplied frame.
use super::bindings::Bindings;
use super::ImageF32;
use crate::constants::COLOR_MAP_SIZE;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::ProjectPush;

/// The colour map's straight RGB at value `v` (clamped to [0, 1]), linear between entries.
pub fn mapped(map: &[[f32; 4]], v: f32) -> [f32; 3] {
    let t = v.clamp(0.0, 1.0) * (COLOR_MAP_SIZE - 1) as f32;
    let i = (t as usize).min(COLOR_MAP_SIZE as usize - 2);
    let f = t - i as f32;
    [0, 1, 2].map(|c| map[i][c] + (map[i + 1][c] - map[i][c]) * f)
}

/// Mirror of project.comp's `SURFACE_AMBIENT`, `SURFACE_DIFFUSE`, `SURFACE_SPECULAR`.
pub const SURFACE_LIGHT: [f32; 3] = [0.3, 0.7, 0.25];

/// One pixel's colour from its blended (key, weight); the isosurface's from its (sum of w
/// lambert, sum of w specular, sum of w, depth).
pub fn project_pixel(push: &ProjectPush, map: &[[f32; 4]], acc: [f32; 4]) -> [f32; 4] {
    if push.mode == crate::options::Mode::Iso.code() {
        let [ambient, diffuse, specular] = SURFACE_LIGHT;
        let c = mapped(map, push.iso);
        let lit = if acc[2] > 0.0 {
            c.map(|c| c * (ambient + diffuse * acc[0] / acc[2]) + specular * acc[1] / acc[2])
        } else {
            [0.0; 3]
        };
        let a = (acc[2] / push.centre).clamp(0.0, 1.0);
        return [lit[0] * a, lit[1] * a, lit[2] * a, a];
    }
    let ratio = if acc[1] > 0.0 { acc[0] / acc[1] } else { 0.0 };
    let (v, a) = match push.mode {
        1 => (ratio, acc[1]),
        2 => (1.0 - ratio, acc[1]),
        3 => (ratio, acc[1] / push.centre),
        _ => (1.0, 1.0 - (-acc[0]).exp()),
    };
    let a = a.clamp(0.0, 1.0);
    let c = mapped(map, v);
    [c[0] * a, c[1] * a, c[2] * a, a]
}

/// Mirror of `project.comp`, written into `accum`.
pub fn project(push: &ProjectPush, map: &[[f32; 4]], accum: &mut ImageF32, color: &ImageF32) {
    for (i, px) in accum.pixels.iter_mut().enumerate() {
        let acc = if push.source == 1 { *px } else { color.pixels[i] };
        *px = project_pixel(push, map, acc);
    }
}

/// The stage table's entry point.
pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, _: &Variant) -> Result<()> {
    let push = args.push_as::<ProjectPush>();
    if push.source != 1 {
        b.accum = ImageF32::new(b.width, b.height);
    }
    let map: Vec<[f32; 4]> = b.get::<[f32; 4]>(Res::ColorMap).to_vec();
    project(&push, &map, &mut b.accum, &b.color);
    Ok(())
}
