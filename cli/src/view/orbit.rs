//! The camera the mouse moves: yaw and pitch about the start camera's target, zoom and pan.
use voxsplat::glam::{Quat, Vec3};
use voxsplat::Camera;

/// The view the mouse edits, around a base camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Turn about the vertical axis, radians.
    pub yaw: f32,
    /// Turn about the base camera's right axis, radians.
    pub pitch: f32,
    /// The eye's distance as a multiple of the base camera's.
    pub zoom: f32,
    /// The target's offset, world units.
    pub pan: Vec3,
}

impl Orbit {
    /// The base camera unchanged.
    pub const HOME: Orbit = Orbit { yaw: 0.0, pitch: 0.0, zoom: 1.0, pan: Vec3::ZERO };

    /// The camera at `size`: `base` turned, zoomed and panned, its near and far planes around a
    /// scene of `radius` about `centre` (by its depth along the view: a target away from the
    /// scene, given or panned to, puts the scene off the axis, nearer in depth than in distance).
    pub fn camera(&self, base: &Camera, centre: Vec3, radius: f32, size: (u32, u32)) -> Camera {
        let mut cam = *base;
        (cam.width, cam.height) = size;
        if *self == Self::HOME {
            return cam; // the command line's camera, bit for bit
        }
        let right = base.right();
        let turn = Quat::from_axis_angle(Vec3::Y, self.yaw) * Quat::from_axis_angle(right, self.pitch);
        let offset = turn * (base.eye - base.target) * self.zoom;
        cam.target = base.target + self.pan;
        cam.eye = cam.target + offset;
        let d = (centre - cam.eye).length();
        let depth = (centre - cam.eye).dot(cam.forward());
        cam.near = if cam.is_perspective() { (depth - radius).max(1e-3 * d.max(1.0)) } else { depth - radius - 1.0 };
        cam.far = d + radius + 1.0;
        cam
    }

    /// A drag of (`dx`, `dy`) pixels across a view `width` x `height`: half a turn per view width.
    pub fn turn(&mut self, dx: f32, dy: f32, width: f32, height: f32) {
        self.yaw -= dx / width.max(1.0) * std::f32::consts::PI;
        self.pitch = (self.pitch - dy / height.max(1.0) * std::f32::consts::PI).clamp(-1.5, 1.5);
    }

    /// A pan drag: the target follows the pointer in the base camera's image plane.
    pub fn slide(&mut self, base: &Camera, radius: f32, dx: f32, dy: f32, height: f32) {
        let scale = 2.0 * radius * self.zoom / height.max(1.0);
        self.pan += (-base.right() * dx + base.up.normalize() * dy) * scale;
    }

    /// Wheel `lines` (positive: closer).
    pub fn wheel(&mut self, lines: f32) {
        self.zoom = (self.zoom * 0.9f32.powf(lines)).clamp(0.05, 20.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxsplat::camera::Projection;

    /// Turned a little from a command-line camera whose target lies 20 degrees off the scene, the
    /// scene still lies past the near plane (the plane followed the target's distance and cut it).
    #[test]
    fn an_off_axis_scene_stays_past_the_near_plane() {
        let base = Camera {
            eye: Vec3::new(0.0, 0.0, 1000.0),
            target: Vec3::new(364.0, 0.0, 0.0),
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y_deg: 35.0 },
            near: 1.0,
            far: 2000.0,
            width: 96,
            height: 64,
            window: None,
        };
        let orbit = Orbit { yaw: 0.01, ..Orbit::HOME };
        let (centre, radius) = (Vec3::ZERO, 40.0);
        let cam = orbit.camera(&base, centre, radius, (96, 64));
        let depth = (centre - cam.eye).dot(cam.forward());
        assert!(cam.near <= depth - radius, "near {} cuts the scene at depth {depth} ± {radius}", cam.near);
        assert!(cam.far >= depth + radius);
    }
}
