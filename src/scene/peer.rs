//! The peers' shared scene, built in as `peer128` and `peer256` (`../shared/peers/common/scene.py`): the same uint8 volume,
//! transfer function and camera that the VTK and taichi scripts render, so voxsplat's images line
//! up with theirs pixel for pixel.
//!
//! Coordinates: VTK puts voxel (i, j, k) at (i, j, k); voxsplat's grids are centred, so every VTK
//! point p maps to p - c with c = (n - 1) / 2 on each axis. The camera is VTK's: focal point at the
//! volume's centre, position c + (1.2, 0.8, 1.6)·n, view-up +y, a 30° (vertical) view angle.
use crate::camera::{Camera, Projection};
use crate::classify::TransferFunction;
use crate::error::{Error, Result};
use crate::volume::ScalarVolume;
use glam::Vec3;

/// Largest side accepted for the generated volume.
pub const MAX_PEER_SIDE: u32 = 512;

/// `make_volume(n)`: an open sphere shell (cut at x ≥ 0.25) plus three Gaussian blobs, scaled to
/// 0..255 and truncated to integers, in float32 like numpy. x fastest, as VTK and our loaders.
pub fn volume(n: u32) -> Result<ScalarVolume> {
    if !(2..=MAX_PEER_SIDE).contains(&n) {
        return Err(Error::InvalidArgument(format!("peer volume side {n} must be in 2..={MAX_PEER_SIDE}")));
    }
    let nn = n as usize;
    let axis: Vec<f32> = (0..nn).map(|i| (-1.0 + 2.0 * i as f64 / (nn - 1) as f64) as f32).collect();
    let blobs: [(f32, f32, f32, f32); 3] = [(0.3, 0.2, -0.1, 0.15), (-0.35, -0.25, 0.2, 0.12), (0.0, -0.4, -0.3, 0.1)];
    let mut v = vec![0.0f32; nn * nn * nn];
    for (k, &z) in axis.iter().enumerate() {
        for (j, &y) in axis.iter().enumerate() {
            for (i, &x) in axis.iter().enumerate() {
                let r = (x * x + y * y + z * z).sqrt();
                let mut d = if x < 0.25 { (-((r - 0.6) * (r - 0.6)) / (2.0 * 0.05 * 0.05)).exp() } else { 0.0 };
                for &(cx, cy, cz, s) in &blobs {
                    let q = (x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz);
                    d += (-q / (2.0 * s * s)).exp();
                }
                v[i + nn * (j + nn * k)] = d;
            }
        }
    }
    let max = v.iter().copied().fold(0.0f32, f32::max);
    for d in &mut v {
        *d = (*d / max * 255.0).clamp(0.0, 255.0).trunc();
    }
    Ok(ScalarVolume { dims: [n; 3], spacing: [1.0; 3], values: v })
}

/// The peers' transfer function: colour 0 → (0,0,0), 64 → (.9,.3,.1), 255 → (1,1,.8); opacity per
/// unit length (= one voxel here) 0 up to 20, 0.08 at 255 — both piecewise linear in the raw value,
/// merged into one point list (the colour at 20 and the opacity at 64 are interpolated, so the
/// functions are unchanged).
pub fn transfer_function() -> TransferFunction {
    let colour = |d: f32| {
        if d <= 64.0 {
            [0.9 * d / 64.0, 0.3 * d / 64.0, 0.1 * d / 64.0]
        } else {
            let t = (d - 64.0) / 191.0;
            [0.9 + 0.1 * t, 0.3 + 0.7 * t, 0.1 + 0.7 * t]
        }
    };
    let opacity = |d: f32| if d <= 20.0 { 0.0 } else { 0.08 * (d - 20.0) / 235.0 };
    let points = [0.0f32, 20.0, 64.0, 255.0]
        .iter()
        .map(|&d| {
            let c = colour(d);
            (d / 255.0, [c[0], c[1], c[2], opacity(d)])
        })
        .collect();
    TransferFunction { points, gradient_weight: 0.0, range: Some((0.0, 255.0)), threshold: 0.0 }
}

/// VTK's camera for an `n`³ volume at `size`×`size`, in voxsplat's centred coordinates.
pub fn camera(n: u32, size: u32) -> Camera {
    let n = n as f32;
    let eye = Vec3::new(1.2, 0.8, 1.6) * n;
    let dist = eye.length();
    let radius = 0.5 * 3f32.sqrt() * n;
    Camera {
        eye,
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 30.0 },
        near: (dist - radius * 1.1).max(dist * 0.01),
        far: dist + radius * 1.1,
        width: size,
        height: size,
        window: None,
    }
}

/// The side of a peer scene name (`peer128`, `peer256`, ...).
pub fn side_of(scene: &str) -> Option<u32> {
    scene.strip_prefix("peer").and_then(|s| s.parse().ok())
}
