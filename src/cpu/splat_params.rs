//! Mirror of `splat_params.comp` and of `glsl/shared/params.glsl`.
use super::bindings::Bindings;
use super::footprint::sweep_length;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{Frame, Splat, SplatParams};
use crate::plan::cell_footprint_scale;
use glam::{Mat4, Vec2, Vec3};

pub use crate::constants::CULL_RADII;

pub use crate::volume::optical_depth;

/// Mirror of `params_of` in `glsl/shared/params.glsl`: a splat's parameters from its grid index
/// and colour (the dense path's `splat_params` and the bricks' `brick_params` share it).
pub fn params_of(frame: &Frame, ijk: [u32; 3], color: [f32; 4]) -> SplatParams {
    let at = Vec3::new(ijk[0] as f32, ijk[1] as f32, ijk[2] as f32);
    params_at(frame, at, 1.0, 1.0, [color[0], color[1], color[2]], optical_depth(color[3]))
}

/// Mirror of `params_at`: a splat `cell` voxels a side at grid position `at`, widened by `grow`
/// (energy / grow²), of straight colour `rgb` and optical depth `tau` per cell.
pub fn params_at(frame: &Frame, at: Vec3, cell: f32, grow: f32, rgb: [f32; 3], tau: f32) -> SplatParams {
    params_world(frame, frame_grid(frame).point(at), cell, grow, rgb, tau)
}

/// The grid `frame` places voxels on (its origin, cell matrix and dimensions): the mirrors of
/// `grid_point`, `voxel_box` and `gradient_at` are its `point`, `world_box` and `gradient`.
pub fn frame_grid(frame: &Frame) -> crate::volume::Grid {
    let v3 = |v: [f32; 4]| [v[0], v[1], v[2]];
    let [nx, ny, nz, _] = frame.dims;
    crate::volume::Grid {
        dims: [nx, ny, nz],
        spacing: v3(frame.spacing),
        origin: v3(frame.origin),
        shear: v3(frame.shear),
    }
}

/// Mirror of params.glsl's `PROJECT_SHRINK`: MIP's and MinIP's footprints at this share of the
/// kernel's radius.
pub const PROJECT_SHRINK: f32 = 0.65;

/// Mirror of `params_world`: `params_at` with the splat's world centre given.
pub fn params_world(frame: &Frame, center: Vec3, cell: f32, grow: f32, rgb: [f32; 3], tau: f32) -> SplatParams {
    let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let (eye, forward, right) = (v3(frame.eye), v3(frame.forward), v3(frame.right));
    let depth = (center - eye).dot(forward);
    // The kernel clear of the near and far planes; the widening, in perspective, short of the eye.
    let mut base = grow * cell * frame.spacing[3];
    if [crate::options::Mode::Mip, crate::options::Mode::Minip].iter().any(|m| m.code() == frame.rect[2]) {
        base *= PROJECT_SHRINK;
    }
    let clear = (depth - frame.forward[3]).min(frame.right[3] - depth);
    let mut visible = clear >= CULL_RADII * base;
    let eye_room = if frame.eye[3] > 0.5 { depth / (CULL_RADII * base) } else { 1e30 };
    let scale = cell_footprint_scale(frame, depth, cell).clamp(1.0, eye_room.max(1.0));
    let radius = base * scale;
    for q in &frame.clip[..frame.rect[1] as usize] {
        visible = visible && Vec3::new(q[0], q[1], q[2]).dot(center) + q[3] >= 0.0;
    }
    let w = if frame.eye[3] > 0.5 { (center - eye).normalize() } else { forward };
    let mut u = (right - right.dot(w) * w).normalize();
    let mut v = w.cross(u);
    let mut stretch = 0.0f32;
    let mut bend = 0.0f32;
    let mut quad_center = center;
    let mut energy = 1.0 / (scale * scale * grow * grow);
    if frame.blur[0] > 0.0 && visible {
        let m = Mat4::from_cols_array_2d(&frame.motion);
        let vp = Mat4::from_cols_array_2d(&frame.view_proj);
        let prev = (m * center.extend(1.0)).truncate();
        let c1 = vp * center.extend(1.0);
        let c0 = vp * prev.extend(1.0);
        let moved = (c1.truncate().truncate() / c1.w - c0.truncate().truncate() / c0.w)
            * 0.5
            * Vec2::new(frame.blur[2], frame.blur[3]);
        let d = center - prev;
        let dp = d - d.dot(w) * w;
        let len = dp.length();
        let mut moved_px = moved.length();
        let mut off = Vec3::ZERO;
        if frame.sweep[0] > 0.5 {
            let mid = (Mat4::from_cols_array_2d(&frame.motion_mid) * center.extend(1.0)).truncate();
            let cm = vp * mid.extend(1.0);
            let xy = |c: glam::Vec4| c.truncate().truncate() / c.w;
            let bulge = (xy(cm) - 0.5 * (xy(c0) + xy(c1))) * 0.5 * Vec2::new(frame.blur[2], frame.blur[3]);
            if cm.w > 0.0 {
                moved_px = moved_px.max(2.0 * bulge.length());
            }
            let m = mid - 0.5 * (center + prev);
            off = m - m.dot(w) * w;
        }
        if c0.w > 0.0 && moved_px > frame.blur[0] && len > 1e-6 * radius {
            u = dp / len;
            v = w.cross(u);
            stretch = 0.5 * len / radius;
            bend = off.dot(v) / radius;
            quad_center = center - 0.5 * dp;
            if frame.sweep[1] == crate::BlurProfile::Uniform.code() {
                energy /= 1.0 + sweep_length(stretch, bend) * frame.blur[1];
            }
        }
    }
    SplatParams {
        center: [quad_center.x, quad_center.y, quad_center.z, if visible && tau > 0.0 { 1.0 } else { 0.0 }],
        axis_u: [
            u.x * radius * (1.0 + stretch),
            u.y * radius * (1.0 + stretch),
            u.z * radius * (1.0 + stretch),
            energy,
        ],
        axis_v: [
            v.x * radius * (1.0 + bend.abs()),
            v.y * radius * (1.0 + bend.abs()),
            v.z * radius * (1.0 + bend.abs()),
            stretch,
        ],
        emit: [rgb[0], rgb[1], rgb[2], tau],
        screen: [
            depth,
            bend,
            if frame.eye[3] > 0.5 { radius * frame.up[3] / depth.max(1e-6) } else { radius * frame.up[3] },
            scale,
        ],
    }
}

/// Mirror of `cell_extent` in `splat_params.comp`: voxel `i`'s extent along axis `a` of a
/// rectilinear grid (`coords`: x, then y, then z coordinates).
fn cell_extent(frame: &Frame, coords: &[f32], a: usize, i: u32) -> f32 {
    let base = [0, frame.dims[0], frame.dims[0] + frame.dims[1]][a];
    let n = frame.dims[a];
    if n == 1 {
        return frame.spacing[a];
    }
    let lo = coords[(base + i.saturating_sub(1)) as usize];
    let hi = coords[(base + (i + 1).min(n - 1)) as usize];
    if i == 0 || i == n - 1 {
        hi - lo
    } else {
        0.5 * (hi - lo)
    }
}

/// Mirror of `params_rect`: a rectilinear grid's splat at its coordinates, as wide as its own
/// cell's widest extent (at most the widest gap), its optical depth weighted so that it deposits
/// its cell's volume over the length opacities are per (`SplatSet::opacity_length`).
pub fn params_rect(frame: &Frame, coords: &[f32], ijk: [u32; 3], color: [f32; 4]) -> SplatParams {
    let (nx, ny) = (frame.dims[0] as usize, frame.dims[1] as usize);
    let center = Vec3::new(coords[ijk[0] as usize], coords[nx + ijk[1] as usize], coords[nx + ny + ijk[2] as usize]);
    let ks = frame.spacing[3] / frame.origin[3];
    let e = [0, 1, 2].map(|a| cell_extent(frame, coords, a, ijk[a]));
    let cell = (e[0].max(e[1].max(e[2])) / ks).min(1.0);
    let r = cell * ks;
    let weight = e[0] * e[1] * e[2] / (frame.shear[3] * r * r);
    params_world(frame, center, cell, 1.0, [color[0], color[1], color[2]], optical_depth(color[3]) * weight)
}

/// Mirror of `project_emit` in `glsl/splat_params.comp`: a projection's emit, the key its blend
/// takes (MIP: the value, MinIP: one minus it, average: the value with tau 1, X-ray: 1).
pub fn project_emit(mode: u32, value: f32, tau: f32) -> [f32; 4] {
    let key = match mode {
        2 => 1.0 - value,
        4 => 1.0,
        _ => value,
    };
    [key, 0.0, 0.0, if mode == 3 { 1.0 } else { tau }]
}

/// `coords`: a rectilinear grid's x, y, z coordinates, read when `frame.rect[0]` is 1.
pub fn splat_params(frame: &Frame, splats: &[Splat], coords: &[f32], params: &mut [SplatParams]) {
    for (s, sp) in splats.iter().enumerate().take(frame.dims[3] as usize) {
        let ijk = [sp.ijk[0], sp.ijk[1], sp.ijk[2]];
        let mut p = if frame.rect[0] != 0 {
            params_rect(frame, coords, ijk, sp.color)
        } else {
            params_of(frame, ijk, sp.color)
        };
        if frame.rect[2] != 0 {
            p.emit = project_emit(frame.rect[2], f32::from_bits(sp.ijk[3]), p.emit[3]);
        }
        params[s] = p;
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let mut params = b.take(Res::Params);
    let coords = b.prep.set.coordinates().map(|c| c.concat()).unwrap_or_default();
    splat_params(&b.frame, b.prep.set.splats(), &coords, bytemuck::cast_slice_mut(&mut params));
    b.put(Res::Params, params);
    Ok(())
}
