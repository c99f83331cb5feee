//! Mirrors of the footprint stage's raster variants. `footprint` mirrors `footprint.vert` +
//! `footprint.frag` and the fixed-function blend: each splat's eye-facing quad is rasterised by
//! intersecting every covered pixel's ray with the quad's plane (what perspective-correct
//! interpolation computes on the GPU), or its point sprite by the point rule; weighted by the
//! footprint table; blended. Its helpers (the footprint tables, `screen_quad`, the motion-blur
//! sweeps) serve `footprint_sum.rs`, `sheet_tiles.rs` and the tile compositor's mirrors too.
use super::ImageF32;
use crate::constants::{FOOTPRINT_TABLE_SIZE, SUM_FIXED_SCALE};
use crate::dispatch::{Args, Pass, Variant};
use crate::error::Result;
use crate::gpu_types::{FootprintPush, Frame, SplatParams, SHEET_MODE_AXIS, SHEET_MODE_BINNED, SHEET_MODE_SLAB};
pub use crate::kernel::sample_radial;
use glam::{DMat4, DVec3, DVec4, IVec4, Mat3, Mat4, Vec2, Vec3, Vec4};

use super::bindings::Bindings;
pub use super::bindings::FootprintInputs;

pub use crate::dispatch::Blend;

/// Mirror of `sample_table` in `glsl/shared/footprint_table.glsl`.
pub fn sample_table(table: &[f32], u: f32, v: f32) -> f32 {
    let n = FOOTPRINT_TABLE_SIZE as i32;
    let tx = (u * 0.5 + 0.5) * n as f32 - 0.5;
    let ty = (v * 0.5 + 0.5) * n as f32 - 0.5;
    let (fx, fy) = (tx.floor(), ty.floor());
    let (wx, wy) = (tx - fx, ty - fy);
    let c = |i: i32| i.clamp(0, n - 1) as usize;
    let (x0, x1, y0, y1) = (c(fx as i32), c(fx as i32 + 1), c(fy as i32), c(fy as i32 + 1));
    let at = |x: usize, y: usize| table[y * n as usize + x];
    let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * wx;
    let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * wx;
    top + (bottom - top) * wy
}

/// Mirror of `sample_slice_table` in `glsl/shared/footprint_table.glsl`.
pub fn sample_slice_table(table: &[f32], r: f32, z: f32) -> f32 {
    let n = FOOTPRINT_TABLE_SIZE as usize;
    let m = (n - 1) as f32;
    let (tx, ty) = (r.clamp(0.0, 1.0) * m, (z.clamp(-1.0, 1.0) * 0.5 + 0.5) * m);
    let (x0, y0) = ((tx.floor() as usize).min(n - 2), (ty.floor() as usize).min(n - 2));
    let (wx, wy) = (tx - x0 as f32, ty - y0 as f32);
    let at = |x: usize, y: usize| table[y * n + x];
    let top = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * wx;
    let bottom = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * wx;
    top + (bottom - top) * wy
}

/// Mirror of `entry_splat` + `entry_layer` in `glsl/shared/footprint.glsl`: draw-list entry `e`'s
/// splat, its summation layer within the batch and how it is weighed; `None` when it is culled.
pub(crate) fn entry<'a>(
    inputs: &FootprintInputs<'a>,
    push: &FootprintPush,
    e: u32,
) -> Option<(usize, usize, Weight<'a>)> {
    let slab_mode = push.sheet_mode == SHEET_MODE_SLAB;
    let pairs = slab_mode || push.sheet_mode == SHEET_MODE_BINNED;
    let splat = if pairs { inputs.draw_list[2 * e as usize] } else { inputs.draw_list[e as usize] } as usize;
    let p = &inputs.params[splat];
    if p.center[3] == 0.0 || (push.occluded > 0.0 && occluded(inputs, p, push.occluded)) {
        return None;
    }
    let mut weight = Weight::Footprint(inputs.table);
    let layer = if slab_mode {
        let slab = inputs.draw_list[2 * e as usize + 1];
        // The quad spans 1 + |bend| radii along axis_v; in depth the kernel keeps its own radius.
        let radius =
            Vec3::new(p.axis_v[0], p.axis_v[1], p.axis_v[2]).length() / (1.0 + p.screen[1].abs()) / p.screen[3];
        let near_face = push.slab_z0 + slab as f32 * push.slab_dz - p.screen[0];
        let faces = [near_face / radius, (near_face + push.slab_dz) / radius];
        weight = Weight::Slice(inputs.slice_table, faces);
        if push.rank_dir > 0 {
            slab.wrapping_sub(push.rank_base)
        } else {
            push.rank_base.wrapping_sub(slab)
        }
    } else if push.sheet_mode == SHEET_MODE_AXIS || push.sheet_mode == SHEET_MODE_BINNED {
        // Binned sheets (a bricked volume's) are ranked by their index: empty ones keep a layer.
        let rank = if pairs {
            inputs.draw_list[2 * e as usize + 1]
        } else {
            inputs.sheet_rank[(push.rank_offset + inputs.splats[splat].ijk[push.axis as usize]) as usize]
        };
        if push.rank_dir > 0 {
            rank.wrapping_sub(push.rank_base)
        } else {
            push.rank_base.wrapping_sub(rank)
        }
    } else {
        0
    } as usize;
    Some((splat, layer, weight))
}

/// Draw `instances` draw-list entries starting at `first_instance` into `layers`, as instanced
/// quads or, with `points`, as point sprites; with `slots`, every fragment into the two layers
/// (`Pass::Slots`: the halves of the shutter).
#[allow(clippy::too_many_arguments)]
pub fn footprint(
    inputs: &FootprintInputs<'_>,
    push: &FootprintPush,
    blend: Blend,
    points: bool,
    slots: bool,
    first_instance: u32,
    instances: u32,
    layers: &mut [ImageF32],
) {
    let vp = Mat4::from_cols_array_2d(&inputs.frame.view_proj);
    let inv = vp.as_dmat4().inverse();
    for e in first_instance..first_instance + instances {
        let Some((splat, layer, weight)) = entry(inputs, push, e) else { continue };
        let target = if slots { layers.get_mut(..2) } else { layers.get_mut(layer..=layer) };
        let Some(target) = target else { continue };
        let p = &inputs.params[splat];
        let sheet = push.sheet_mode != 0;
        let depth = (inputs.frame.rect[3] != 0).then_some(inputs.host_depth);
        let shading = Shading { sheet, blend, weight, sweep: Sweep::of(inputs.frame, p), slots, depth };
        if points {
            raster_point(p, shading, vp, target);
        } else {
            raster_quad(p, shading, vp, &inv, target);
        }
    }
}

/// Mirror of `screen_quad` in `glsl/shared/footprint.glsl`: the inverse projective map from pixel
/// centres to quad coordinates and the inclusive pixel box; `None` when culled, behind the eye or
/// off screen.
pub fn screen_quad(frame: &Frame, p: &SplatParams) -> Option<(Mat3, IVec4)> {
    if p.center[3] == 0.0 {
        return None;
    }
    let vp = Mat4::from_cols_array_2d(&frame.view_proj);
    let size = Vec2::new(frame.blur[2], frame.blur[3]);
    let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let c0 = vp * v3(p.center).extend(1.0);
    let cu = vp * v3(p.axis_u).extend(0.0);
    let cv = vp * v3(p.axis_v).extend(0.0);
    let m = |c: Vec4| Vec3::new((c.x + c.w) * 0.5 * size.x, (c.y + c.w) * 0.5 * size.y, c.w);
    let (m0, mu, mv) = (m(c0), m(cu), m(cv));
    let (mut lo, mut hi) = (Vec2::splat(1e30), Vec2::splat(-1e30));
    for (cx, cy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let q = m0 + cx * mu + cy * mv;
        if q.z <= 0.0 {
            return None;
        }
        let s = Vec2::new(q.x, q.y) / q.z;
        lo = lo.min(s);
        hi = hi.max(s);
    }
    let a = (lo - 0.5).ceil().max(Vec2::ZERO);
    let b = (hi - 0.5).floor().min(size - 1.0);
    let bx = IVec4::new(a.x as i32, a.y as i32, b.x as i32, b.y as i32);
    if bx.x > bx.z || bx.y > bx.w {
        return None;
    }
    Some((Mat3::from_cols(mu, mv, m0).inverse(), bx))
}

/// Mirror of `quad_uv`: quad coordinates of pixel (x, y).
pub fn quad_uv(inv: &Mat3, x: i32, y: i32) -> Vec2 {
    let q = *inv * Vec3::new(x as f32 + 0.5, y as f32 + 0.5, 1.0);
    Vec2::new(q.x, q.y) / q.z
}

/// Mirror of `fixed_point` in `footprint_sum.comp`.
pub(crate) fn fixed_point(v: f32) -> u32 {
    (v.min(64.0) * SUM_FIXED_SCALE as f32 + 0.5) as u32
}

/// Mirror of the fixed-point read in `composite.comp` (SUMS_FIXED): one layer as floats.
pub fn fixed_layer(sums: &[u32], layer: usize, width: u32, height: u32) -> ImageF32 {
    let n = width as usize * height as usize;
    let s = SUM_FIXED_SCALE as f32;
    let pixels = sums[4 * layer * n..4 * (layer + 1) * n]
        .chunks_exact(4)
        .map(|c| [0, 1, 2, 3].map(|i| c[i] as f32 / s))
        .collect();
    ImageF32 { width, height, pixels }
}

/// Mirror of `occluded` in `footprint.vert`: the quad lies wholly over tiles with at most
/// `threshold` transmittance left (footprints over more than 16 tiles are always drawn).
pub fn occluded(inputs: &FootprintInputs<'_>, p: &SplatParams, threshold: f32) -> bool {
    let vp = Mat4::from_cols_array_2d(&inputs.frame.view_proj);
    let size = glam::Vec2::new(inputs.frame.blur[2], inputs.frame.blur[3]);
    let (mut lo, mut hi) = (glam::Vec2::splat(1e30), glam::Vec2::splat(-1e30));
    let v3 = |v: [f32; 4]| glam::Vec3::new(v[0], v[1], v[2]);
    for (cx, cy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let q = v3(p.center) + cx * v3(p.axis_u) + cy * v3(p.axis_v);
        let c = vp * q.extend(1.0);
        if c.w <= 0.0 {
            return false;
        }
        let s = (glam::Vec2::new(c.x, c.y) / c.w * 0.5 + 0.5) * size;
        lo = lo.min(s);
        hi = hi.max(s);
    }
    let tile = crate::constants::COMPOSITE_TILE as f32;
    let tiles_x = (size.x / tile).ceil() as i64;
    let t = |v: glam::Vec2| (v.clamp(glam::Vec2::ZERO, size - 1.0) / tile).floor();
    let (t0, t1) = (t(lo), t(hi));
    if (t1.x - t0.x + 1.0) * (t1.y - t0.y + 1.0) > 16.0 {
        return false;
    }
    for y in t0.y as i64..=t1.y as i64 {
        for x in t0.x as i64..=t1.x as i64 {
            if inputs.occlusion.get((y * tiles_x + x) as usize).is_none_or(|&o| o > threshold) {
                return false;
            }
        }
    }
    true
}

/// Segments of a bent motion path (`ARC_SEGMENTS` in `glsl/shared/sweep.glsl`).
pub(crate) const ARC_SEGMENTS: u32 = 8;
/// Most time samples of a tapered or teardrop footprint (`MAX_SWEEP_SAMPLES`).
pub(crate) const MAX_SWEEP_SAMPLES: i32 = 64;

/// A motion-blurred footprint's path and profile (`glsl/shared/sweep.glsl`): from t_{i-1} at
/// (-stretch, 0) to t_i at (stretch, 0) through (0, bend), radius units about the quad's centre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sweep {
    /// Half the path's length along x.
    pub stretch: f32,
    /// The arc's height at its middle.
    pub bend: f32,
    /// `BlurProfile::code`.
    pub profile: f32,
}

impl Sweep {
    /// A splat's sweep: its stretch and bend with the frame's profile.
    pub fn of(frame: &Frame, p: &SplatParams) -> Self {
        Self { stretch: p.axis_v[3], bend: p.screen[1], profile: frame.sweep[1] }
    }
}

/// Mirror of `sweep_point`: the path's point at time t in [0, 1].
pub fn sweep_point(stretch: f32, bend: f32, t: f32) -> Vec2 {
    Vec2::new(stretch * (2.0 * t - 1.0), 4.0 * bend * t * (1.0 - t))
}

pub(crate) fn sweep_coords(uv: Vec2, stretch: f32, bend: f32) -> Vec2 {
    Vec2::new(uv.x * (1.0 + stretch), uv.y * (1.0 + bend.abs()))
}

/// Mirror of `sweep_length`: the path's length in radius units.
pub fn sweep_length(stretch: f32, bend: f32) -> f32 {
    if bend == 0.0 {
        return 2.0 * stretch;
    }
    let mut a = sweep_point(stretch, bend, 0.0);
    let mut l = 0.0;
    for k in 1..=ARC_SEGMENTS {
        let b = sweep_point(stretch, bend, k as f32 / ARC_SEGMENTS as f32);
        l += (b - a).length();
        a = b;
    }
    l
}

/// Mirror of `footprint_r2`: r² at quad coordinates uv, the squared distance to the path.
pub fn sweep_r2(uv: Vec2, stretch: f32, bend: f32) -> f32 {
    let x = sweep_coords(uv, stretch, bend);
    if bend == 0.0 {
        let along = (x.x.abs() - stretch).max(0.0);
        return along * along + x.y * x.y;
    }
    let mut best = 1e30f32;
    let mut a = sweep_point(stretch, bend, 0.0);
    for k in 1..=ARC_SEGMENTS {
        let b = sweep_point(stretch, bend, k as f32 / ARC_SEGMENTS as f32);
        let ab = b - a;
        let h = ((x - a).dot(ab) / ab.dot(ab).max(1e-12)).clamp(0.0, 1.0);
        let d = x - a - h * ab;
        best = best.min(d.dot(d));
        a = b;
    }
    best
}

/// Mirror of `sweep_samples`.
pub(crate) fn sweep_samples(stretch: f32, bend: f32) -> i32 {
    (1 + (4.0 * (2.0 * stretch + 2.0 * bend.abs())).ceil() as i32).clamp(2, MAX_SWEEP_SAMPLES)
}

/// Mirror of `sweep_window`: the time samples (k of `n`) within a radius of x along u.
pub(crate) fn sweep_window(x: Vec2, stretch: f32, n: i32) -> std::ops::RangeInclusive<i32> {
    let (lo, hi) = ((x.x + stretch - 1.0) / (2.0 * stretch), (x.x + stretch + 1.0) / (2.0 * stretch));
    ((lo * n as f32 - 0.5).ceil() as i32).max(0)..=((hi * n as f32 - 0.5).floor() as i32).min(n - 1)
}

/// Mirror of `sweep_sample`: time sample k of n and r² from x to the path there.
pub(crate) fn sweep_sample(x: Vec2, stretch: f32, bend: f32, k: i32, n: i32) -> (f32, f32) {
    let t = (k as f32 + 0.5) / n as f32;
    let e = x - sweep_point(stretch, bend, t);
    (t, e.dot(e))
}

/// What a fragment weighs: the whole pre-integrated footprint, or the slice between two slab
/// faces (radius units, relative to the splat's centre).
#[derive(Clone, Copy)]
pub(crate) enum Weight<'a> {
    Footprint(&'a [f32]),
    Slice(&'a [f32], [f32; 2]),
}

impl Weight<'_> {
    /// Mirror of `kernel_at` in `glsl/shared/footprint_table.glsl`: the weight at r² s.
    pub(crate) fn kernel_at(self, s: f32) -> f32 {
        match self {
            Weight::Footprint(table) => sample_radial(table, s),
            Weight::Slice(table, [za, zb]) => {
                let r = s.sqrt();
                sample_slice_table(table, r, zb) - sample_slice_table(table, r, za)
            }
        }
    }

    /// Mirror of `footprint_value`: the optical depth a footprint of scale `tau` deposits at quad
    /// coordinates uv or, with `opacity`, its alpha.
    pub(crate) fn value(self, uv: Vec2, sweep: Sweep, tau: f32, opacity: bool) -> f32 {
        let Sweep { stretch, bend, profile } = sweep;
        if profile == crate::BlurProfile::Uniform.code() || stretch == 0.0 {
            let d = tau * self.kernel_at(sweep_r2(uv, stretch, bend));
            return if opacity { 1.0 - (-d).exp() } else { d };
        }
        let x = sweep_coords(uv, stretch, bend);
        let n = sweep_samples(stretch, bend);
        let teardrop = profile == crate::BlurProfile::Teardrop.code();
        let mut sum = 0.0;
        for k in sweep_window(x, stretch, n) {
            let (t, s) = sweep_sample(x, stretch, bend, k, n);
            if s >= 1.0 {
                continue;
            }
            let d = tau * self.kernel_at(s);
            let w = if teardrop { 2.0 * t / n as f32 } else { 1.0 / n as f32 };
            sum += w * if opacity { 1.0 - (-d).exp() } else { d };
        }
        sum
    }
}

/// Mirror of `footprint_slots`: the alpha a footprint of scale `tau` deposits at uv in each half
/// of the shutter (`Pass::Slots`).
pub(crate) fn footprint_slots(weight: Weight<'_>, uv: Vec2, sweep: Sweep, tau: f32) -> [f32; 2] {
    let Sweep { stretch, bend, .. } = sweep;
    if stretch == 0.0 {
        let a = 1.0 - (-tau * weight.kernel_at(sweep_r2(uv, 0.0, 0.0))).exp();
        return [a, a];
    }
    let x = sweep_coords(uv, stretch, bend);
    let n = 2 * ((sweep_samples(stretch, bend) + 1) / 2);
    let mut sum = [0.0f32; 2];
    for k in sweep_window(x, stretch, n) {
        let (_, s) = sweep_sample(x, stretch, bend, k, n);
        if s >= 1.0 {
            continue;
        }
        let a = 1.0 - (-tau * weight.kernel_at(s)).exp();
        sum[usize::from(2 * k >= n)] += a;
    }
    sum.map(|v| v * (2.0 / n as f32))
}

/// The whole footprint's optical depth (or, with `opacity`, alpha) at quad coordinates uv for a
/// footprint of scale `tau` (the tile compositor's case).
pub fn footprint_value(table: &[f32], uv: Vec2, sweep: Sweep, tau: f32, opacity: bool) -> f32 {
    Weight::Footprint(table).value(uv, sweep, tau, opacity)
}

/// What the fragment shader and the blend do with a footprint.
#[derive(Clone, Copy)]
pub(crate) struct Shading<'a> {
    sheet: bool,
    blend: Blend,
    weight: Weight<'a>,
    sweep: Sweep,
    /// Two time slots (`Pass::Slots`): one value per target.
    slots: bool,
    /// The host's eye-space depth per pixel, when it hides what lies behind it.
    depth: Option<&'a [f32]>,
}

/// Mirror of footprint_table.glsl's `PROJECT_FULL`: MIP and MinIP cover a pixel fully where a
/// footprint weighs this share of its centre's.
pub const PROJECT_FULL: f32 = 0.7;

/// The fragment shader's output at quad coordinates (u, v), blended into the pixel at `at` of
/// `targets` (one, or the two slots).
pub(crate) fn shade(p: &SplatParams, s: Shading<'_>, u: f32, v: f32, targets: &mut [ImageF32], at: usize) {
    if s.depth.is_some_and(|d| p.screen[0] > d[at]) {
        return;
    }
    let tau = p.emit[3] * p.axis_u[3];
    // A projection (footprint.frag's PROJECT): by maximum, the key weighed by the footprint over
    // its centre's and the coverage; summed, the key and 1 weighed by the optical depth.
    let project = match (s.blend, s.sheet, s.weight) {
        (Blend::Max, _, Weight::Footprint(table)) => {
            Some((s.weight.value(Vec2::new(u, v), s.sweep, 1.0, false) / (PROJECT_FULL * table[0])).min(1.0))
        }
        (Blend::Add, false, _) => Some(s.weight.value(Vec2::new(u, v), s.sweep, tau, false)),
        _ => None,
    };
    if let Some(w) = project {
        if w > 0.0 {
            blend(s.blend, [p.emit[0] * w, w, 0.0, 0.0], &mut targets[0].pixels[at]);
        }
        return;
    }
    // Optical depth (sheets) or alpha (per splat), per target.
    let values = if s.slots {
        footprint_slots(s.weight, Vec2::new(u, v), s.sweep, tau)
    } else {
        [s.weight.value(Vec2::new(u, v), s.sweep, tau, !s.sheet), 0.0]
    };
    if values[..targets.len()].iter().all(|&a| a <= 0.0) {
        return;
    }
    for (target, &a) in targets.iter_mut().zip(&values) {
        blend(s.blend, [p.emit[0] * a, p.emit[1] * a, p.emit[2] * a, a], &mut target.pixels[at]);
    }
}

/// The fixed-function blend of premultiplied `src` into `dst`.
pub(crate) fn blend(mode: Blend, src: [f32; 4], dst: &mut [f32; 4]) {
    match mode {
        Blend::Over => {
            let k = 1.0 - src[3];
            *dst = [0, 1, 2, 3].map(|i| src[i] + k * dst[i]);
        }
        Blend::Under => {
            let k = 1.0 - dst[3];
            *dst = [0, 1, 2, 3].map(|i| k * src[i] + dst[i]);
        }
        Blend::Add => *dst = [0, 1, 2, 3].map(|i| src[i] + dst[i]),
        Blend::Max => *dst = [0, 1, 2, 3].map(|i| src[i].max(dst[i])),
    }
}

/// A point sprite `2 * screen radius` pixels wide centred on the projected centre: the pixels whose
/// centres fall inside it, with gl_PointCoord mapped to [-1, 1]².
pub(crate) fn raster_point(p: &SplatParams, shading: Shading<'_>, vp: Mat4, targets: &mut [ImageF32]) {
    let (width, height) = (targets[0].width, targets[0].height);
    let clip = vp * Vec4::new(p.center[0], p.center[1], p.center[2], 1.0);
    if clip.w <= 0.0 {
        return;
    }
    let (w, h) = (width as f32, height as f32);
    let (sx, sy) = ((clip.x / clip.w * 0.5 + 0.5) * w, (clip.y / clip.w * 0.5 + 0.5) * h);
    let half = p.screen[2];
    if half <= 0.0 {
        return;
    }
    let x0 = (sx - half - 0.5).ceil().max(0.0) as i64;
    let x1 = (sx + half - 0.5).floor().min(w - 1.0) as i64;
    let y0 = (sy - half - 0.5).ceil().max(0.0) as i64;
    let y1 = (sy + half - 0.5).floor().min(h - 1.0) as i64;
    for y in y0..=y1 {
        for x in x0..=x1 {
            let (u, v) = ((x as f32 + 0.5 - sx) / half, (y as f32 + 0.5 - sy) / half);
            shade(p, shading, u, v, targets, (y as u32 * width + x as u32) as usize);
        }
    }
}

pub(crate) fn raster_quad(p: &SplatParams, shading: Shading<'_>, vp: Mat4, inv: &DMat4, targets: &mut [ImageF32]) {
    let v3 = |v: [f32; 4]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
    let (c, au, av) = (v3(p.center), v3(p.axis_u), v3(p.axis_v));
    let width = targets[0].width;
    let (w, h) = (width as f64, targets[0].height as f64);
    let (mut minx, mut maxx, mut miny, mut maxy) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (cx, cy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let q = c + cx * au + cy * av;
        let clip = vp * Vec4::new(q.x as f32, q.y as f32, q.z as f32, 1.0);
        if clip.w <= 0.0 {
            return;
        }
        let (sx, sy) = ((clip.x / clip.w * 0.5 + 0.5) as f64 * w, (clip.y / clip.w * 0.5 + 0.5) as f64 * h);
        minx = minx.min(sx);
        maxx = maxx.max(sx);
        miny = miny.min(sy);
        maxy = maxy.max(sy);
    }
    let x0 = (minx - 0.5).ceil().max(0.0) as i64;
    let x1 = (maxx - 0.5).floor().min(w - 1.0) as i64;
    let y0 = (miny - 0.5).ceil().max(0.0) as i64;
    let y1 = (maxy - 0.5).floor().min(h - 1.0) as i64;
    let n = au.cross(av);
    let (uu, vv) = (au.length_squared(), av.length_squared());
    for y in y0..=y1 {
        for x in x0..=x1 {
            let ndc = DVec4::new((x as f64 + 0.5) / w * 2.0 - 1.0, (y as f64 + 0.5) / h * 2.0 - 1.0, 0.0, 1.0);
            let a = *inv * ndc;
            let b = *inv * DVec4::new(ndc.x, ndc.y, 1.0, 1.0);
            let (a, b) = (a.truncate() / a.w, b.truncate() / b.w);
            let dir = b - a;
            let denom = dir.dot(n);
            if denom.abs() < 1e-30 {
                continue;
            }
            let hit = a + dir * ((c - a).dot(n) / denom);
            let d = hit - c;
            let (u, v) = (d.dot(au) / uu, d.dot(av) / vv);
            if u.abs() > 1.0 || v.abs() > 1.0 {
                continue;
            }
            shade(p, shading, u as f32, v as f32, targets, (y as u32 * width + x as u32) as usize);
        }
    }
}

/// The draw: the raster target or the summation layers are cleared (the render pass's load) and
/// the footprints drawn into them; a later part of a bricked frame (`carry` 1) draws on them as
/// they are.
pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let state = v.draw.expect("footprint variants are draws");
    let push: FootprintPush = d.push_as();
    let mut layers = match state.pass {
        Pass::Target if push.carry != 0 => vec![std::mem::replace(&mut b.color, ImageF32::new(0, 0))],
        Pass::Target => vec![ImageF32::new(b.width, b.height)],
        Pass::Sheet if push.carry != 0 => std::mem::take(&mut b.sums),
        Pass::Sheet => vec![ImageF32::new(b.width, b.height); b.sums.len()],
        Pass::Slots => vec![ImageF32::new(b.width, b.height); 2],
    };
    let inputs = b.inputs(d.list);
    let slots = state.pass == Pass::Slots;
    footprint(&inputs, &push, state.blend, state.points, slots, d.groups[0], d.groups[1], &mut layers);
    match state.pass {
        Pass::Target => b.color = layers.remove(0),
        Pass::Sheet => b.sums = layers,
        Pass::Slots => {
            b.accum = layers.pop().expect("two slots");
            b.color = layers.pop().expect("two slots");
        }
    }
    Ok(())
}
