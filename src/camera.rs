//! Perspective and orthographic cameras. World space is right-handed; eye space is the rigid
//! transform looking down -z (section 3.3.1); clip space follows Vulkan (y down, depth 0..1), so
//! image row 0 is the top of the picture.
//!
//! ```
//! use voxsplat::{camera::Projection, Camera, Grid};
//! // A camera that frames a 64^3 grid in a 256 x 256 image, then made orthographic.
//! let grid = Grid::centered([64; 3], [1.0; 3])?;
//! let mut camera = Camera::framing(&grid, 256, 256);
//! camera.projection = Projection::Orthographic { height: grid.diagonal() };
//! camera.validate()?;
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
use crate::volume::Grid;
use glam::{Mat4, Vec3, Vec4};

/// Largest image side accepted.
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Most pixels accepted (8192^2: 1 GiB per RGBA32F image).
pub const MAX_PIXELS: u64 = 8192 * 8192;
/// Largest eye or target coordinate: squared distances stay finite in f32.
pub const MAX_WORLD: f32 = 1e15;
/// Smallest pixel, relative to the view's coordinates (2^-18: 32 f32 steps).
const MIN_PIXEL_RELATIVE: f32 = 1.0 / (1u32 << 18) as f32;

#[derive(Clone, Copy, Debug, PartialEq)]
/// How the view volume maps to the image.
pub enum Projection {
    /// Vertical field of view in degrees, in (0, 180).
    /// A pinhole camera with this vertical field of view in degrees.
    Perspective {
        /// Vertical field of view in degrees.
        fov_y_deg: f32,
    },
    /// World-space height of the view.
    /// Parallel rays; the view is this many world units tall.
    Orthographic {
        /// Height of the view in world units.
        height: f32,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
/// A view of the scene: eye, target and up in world units, projection, clip planes and image size.
///
/// ```
/// use voxsplat::{glam::Vec3, Camera, Grid};
/// let grid = Grid::centered([64, 64, 32], [1.0, 1.0, 2.0])?;
/// // The default three-quarter view, then the same camera moved to look down the z axis.
/// let mut camera = Camera::framing(&grid, 512, 512);
/// let distance = camera.eye.distance(camera.target);
/// camera.eye = camera.target + Vec3::Z * distance;
/// camera.up = Vec3::Y;
/// camera.validate()?;
/// # Ok::<(), voxsplat::Error>(())
/// ```
pub struct Camera {
    /// Where the eye is.
    pub eye: Vec3,
    /// The point the eye looks at.
    pub target: Vec3,
    /// The up direction (need not be orthogonal to the view direction).
    pub up: Vec3,
    /// Perspective or orthographic.
    pub projection: Projection,
    /// Near clip distance along the view direction.
    pub near: f32,
    /// Far clip distance along the view direction.
    pub far: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// `Some`: this camera draws only a window of a larger frame, `width` x `height` pixels of it
    /// at the window's corner (a band of a frame drawn in parts). `None`: the whole frame.
    pub window: Option<Window>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
/// Where a camera's image lies in the whole frame it is part of: the frame's size and the image's
/// top-left pixel in it. The projection and the pixel size are the whole frame's, the window's
/// pixels stretched over the image.
pub struct Window {
    /// Column of the image's left edge in the frame.
    pub x: u32,
    /// Row of the image's top edge in the frame.
    pub y: u32,
    /// The whole frame's width in pixels.
    pub frame_width: u32,
    /// The whole frame's height in pixels.
    pub frame_height: u32,
}

impl Camera {
    /// A three-quarter perspective view that frames `grid` at the given image size.
    pub fn framing(grid: &Grid, width: u32, height: u32) -> Self {
        let [lo, hi] = grid.world_box(Vec3::ZERO, Vec3::from(grid.dims.map(|d| (d - 1) as f32)));
        let dir = Vec3::new(0.55, 0.45, 1.0);
        Self::framing_box(lo, hi, grid.kernel_spacing(), dir, Vec3::Y, width, height)
    }

    /// How far from the near and far planes a splat's centre must lie not to be culled, before
    /// anti-aliasing widens it: CULL_RADII of the widest kernel's radius, for a grid of
    /// `kernel_spacing`.
    pub fn cull_margin(kernel_spacing: f32) -> f32 {
        crate::constants::CULL_RADII
            * crate::kernel::KERNELS.iter().map(|k| k.radius()).fold(0.0, f32::max)
            * kernel_spacing
    }

    /// A perspective view along `-dir` with `up` that frames the box `lo..hi` (voxel centres) of a
    /// grid whose kernel spacing is `kernel_spacing`, at the given image size.
    pub fn framing_box(lo: Vec3, hi: Vec3, kernel_spacing: f32, dir: Vec3, up: Vec3, width: u32, height: u32) -> Self {
        let center = lo.lerp(hi, 0.5);
        // A floor of one kernel spacing (a one-voxel grid), not one unit: spacings in metres are common.
        let radius = 0.5 * (hi - lo).length().max(kernel_spacing);
        let fov = 35.0f32;
        // The nearest splats must clear the near plane by the cull margin, or a grid a few voxels
        // wide would frame its eye inside it and draw nothing.
        let reach = Self::cull_margin(kernel_spacing);
        let dist = (radius / (0.5 * fov.to_radians()).sin() * 1.05).max((radius + reach) / 0.98);
        Self {
            eye: center + dir.normalize() * dist,
            target: center,
            up,
            projection: Projection::Perspective { fov_y_deg: fov },
            near: (dist - radius * 1.5).min(dist - radius - reach).max(dist * 0.01),
            far: (dist + radius * 1.5).max(dist + radius + reach),
            width,
            height,
            window: None,
        }
    }

    /// Check every value; a camera that passes always yields finite matrices.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: &str| Err(Error::InvalidCamera(m.to_string()));
        if !(self.eye.is_finite() && self.target.is_finite() && self.up.is_finite()) {
            return bad("eye, target and up must be finite");
        }
        if self.width == 0 || self.height == 0 {
            return bad("image size must be at least 1x1");
        }
        if self.width > MAX_IMAGE_SIDE || self.height > MAX_IMAGE_SIDE {
            return Err(Error::InvalidCamera(format!("image sides must be at most {MAX_IMAGE_SIDE}")));
        }
        if self.width as u64 * self.height as u64 > MAX_PIXELS {
            return Err(Error::InvalidCamera(format!("image has more than {MAX_PIXELS} pixels")));
        }
        if let Some(w) = self.window {
            let (fw, fh) = (w.frame_width, w.frame_height);
            if fw > MAX_IMAGE_SIDE || fh > MAX_IMAGE_SIDE || fw as u64 * fh as u64 > MAX_PIXELS {
                return Err(Error::InvalidCamera(format!(
                    "the whole frame of a window ({fw}x{fh}) must have sides of at most {MAX_IMAGE_SIDE} and at most \
                     {MAX_PIXELS} pixels"
                )));
            }
            if w.x as u64 + self.width as u64 > fw as u64 || w.y as u64 + self.height as u64 > fh as u64 {
                return Err(Error::InvalidCamera(format!(
                    "a {}x{} window at ({}, {}) does not fit in its {fw}x{fh} frame",
                    self.width, self.height, w.x, w.y
                )));
            }
        }
        if self.eye.abs().max_element() > MAX_WORLD || self.target.abs().max_element() > MAX_WORLD {
            return Err(Error::InvalidCamera(format!(
                "eye and target must lie within {MAX_WORLD:e} world units of the origin on each axis"
            )));
        }
        let view = self.target - self.eye;
        // Relative to where they are, not in units: a scene in metres may be 1e-7 across.
        if view.length() <= 1e-6 * self.eye.length().max(self.target.length()) {
            return bad("eye and target coincide");
        }
        if self.up.length() < 1e-12 || view.normalize().cross(self.up.normalize()).length() < 1e-4 {
            return bad("up is zero or parallel to the view direction");
        }
        if !(self.near.is_finite() && self.far.is_finite()) || self.far <= self.near {
            return bad("near and far must be finite with far > near");
        }
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                if !(fov_y_deg.is_finite() && fov_y_deg > 0.0 && fov_y_deg < 180.0) {
                    return bad("field of view must be in (0, 180) degrees");
                }
                if self.near <= 0.0 {
                    return bad("perspective near distance must be positive");
                }
            }
            Projection::Orthographic { height } => {
                if !(height.is_finite() && height > 0.0) {
                    return bad("orthographic view height must be positive");
                }
            }
        }
        // A pixel must span enough f32 steps of the view's coordinates to be told from its
        // neighbours: below that the rasterizers fill parts of the frame or none of it.
        let scale = view.length().max(self.eye.abs().max_element()).max(self.target.abs().max_element());
        let pixel = self.pixel_size();
        if pixel.is_nan() || pixel < scale * MIN_PIXEL_RELATIVE {
            return Err(Error::InvalidCamera(format!(
                "a pixel spans {pixel:e} world units at the target, below 2^-18 of the view's coordinates ({scale:e}): \
                 f32 cannot resolve it; widen the view or move the scene nearer the origin"
            )));
        }
        Ok(())
    }

    /// World units a pixel spans at the target's distance.
    pub fn pixel_size(&self) -> f32 {
        let height = match self.projection {
            Projection::Perspective { fov_y_deg } => {
                2.0 * (self.target - self.eye).length() * (0.5 * fov_y_deg.to_radians()).tan()
            }
            Projection::Orthographic { height } => height,
        };
        height / self.frame_size().1 as f32
    }

    /// The whole frame's width and height: the image's own, or its window's frame's.
    pub fn frame_size(&self) -> (u32, u32) {
        self.window.map_or((self.width, self.height), |w| (w.frame_width, w.frame_height))
    }

    /// The same view on a pixel grid `k` times finer on each axis (its window's too).
    pub fn supersampled(&self, k: u32) -> Self {
        let window = self.window.map(|w| Window {
            x: w.x * k,
            y: w.y * k,
            frame_width: w.frame_width * k,
            frame_height: w.frame_height * k,
        });
        Self { width: self.width * k, height: self.height * k, window, ..*self }
    }

    /// The same view drawing only `width` x `height` pixels at column `x`, row `y` of this camera's
    /// image (of its window, for a window: the result is a window of the same frame).
    pub fn windowed(&self, x: u32, y: u32, width: u32, height: u32) -> Self {
        let (frame_width, frame_height) = self.frame_size();
        let (ox, oy) = self.window.map_or((0, 0), |w| (w.x, w.y));
        Self { width, height, window: Some(Window { x: ox + x, y: oy + y, frame_width, frame_height }), ..*self }
    }

    /// Whether the projection is a perspective one.
    pub fn is_perspective(&self) -> bool {
        matches!(self.projection, Projection::Perspective { .. })
    }

    /// Unit view direction (eye to target).
    pub fn forward(&self) -> Vec3 {
        (self.target - self.eye).normalize()
    }

    /// Unit right vector of the image plane.
    pub fn right(&self) -> Vec3 {
        self.forward().cross(self.up).normalize()
    }

    /// Unit up vector of the image plane (orthogonal to the view direction).
    pub fn true_up(&self) -> Vec3 {
        self.right().cross(self.forward())
    }

    /// Width over height, of the whole frame.
    pub fn aspect(&self) -> f32 {
        let (w, h) = self.frame_size();
        w as f32 / h as f32
    }

    /// World to eye space (right-handed, looking down -z).
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye, self.target, self.up)
    }

    /// Projection with Vulkan's downward y.
    pub fn proj(&self) -> Mat4 {
        let mut p = match self.projection {
            Projection::Perspective { fov_y_deg } => {
                Mat4::perspective_rh(fov_y_deg.to_radians(), self.aspect(), self.near, self.far)
            }
            Projection::Orthographic { height } => {
                let (h, w) = (0.5 * height, 0.5 * height * self.aspect());
                Mat4::orthographic_rh(-w, w, -h, h, self.near, self.far)
            }
        };
        p.y_axis = Vec4::new(p.y_axis.x, -p.y_axis.y, p.y_axis.z, p.y_axis.w);
        match self.window {
            None => p,
            // The window's pixels stretched over [-1, 1]: ndc' = ndc * F / n + (F - 2 o) / n - 1
            // per axis, for a frame of F pixels and a window of n at o.
            Some(w) => {
                let axis = |frame: u32, at: u32, n: u32| {
                    let (f, o, n) = (frame as f32, at as f32, n as f32);
                    (f / n, (f - 2.0 * o) / n - 1.0)
                };
                let (sx, ox) = axis(w.frame_width, w.x, self.width);
                let (sy, oy) = axis(w.frame_height, w.y, self.height);
                let t = Mat4::from_cols(
                    Vec4::new(sx, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, sy, 0.0, 0.0),
                    Vec4::Z,
                    Vec4::new(ox, oy, 0.0, 1.0),
                );
                t * p
            }
        }
    }

    /// World to clip space (Vulkan depth range, y down).
    pub fn view_proj(&self) -> Mat4 {
        self.proj() * self.view()
    }

    /// D/p of section 3.3.4: the eye-to-view-plane distance over a pixel's extent, i.e. pixels per
    /// world unit at unit depth. Orthographic: pixels per world unit everywhere.
    pub fn pixels_per_unit(&self) -> f32 {
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                0.5 * self.frame_size().1 as f32 / (0.5 * fov_y_deg.to_radians()).tan()
            }
            Projection::Orthographic { height } => self.frame_size().1 as f32 / height,
        }
    }

    /// k = s·D/p of Eq. 3.8: the eye distance beyond which a voxel spacing `s` covers less than a
    /// pixel. Orthographic views have no k: every splat lies before or beyond it at once, according
    /// to `s * pixels_per_unit()` (pixels per voxel) being above or below 1.
    pub fn k(&self, voxel_spacing: f32) -> Option<f32> {
        self.is_perspective().then(|| voxel_spacing * self.pixels_per_unit())
    }

    /// A grazing perspective view across a single-sheet grid such as the checkerboard plane
    /// (Fig. 3.6): the eye low above the near edge, the far part of the sheet beyond k.
    pub fn grazing(grid: &Grid, width: u32, height: u32) -> Self {
        let c = grid.center();
        let half_y = 0.5 * (grid.dims[1].max(2) - 1) as f32 * grid.spacing[1];
        // 12 voxels above the sheet, 5 before its near edge, pitched 25 degrees down with an 80
        // degree field: the sheet fills the frame below a horizon in its upper part.
        let eye = c + Vec3::new(0.0, -half_y - 5.0, 12.0);
        let target = eye + Vec3::new(0.0, 100.0, -46.6);
        Self {
            eye,
            target,
            up: Vec3::Z,
            projection: Projection::Perspective { fov_y_deg: 80.0 },
            near: 1.0,
            far: 4.0 * (half_y + 100.0),
            width,
            height,
            window: None,
        }
    }

    /// A perspective fly-over of a terrain grid (z up): the eye beyond the southern (low y) edge,
    /// above the highest level, looking north and down across the terrain (Figs 5.1-5.3).
    pub fn flyover(grid: &Grid, width: u32, height: u32) -> Self {
        let c = grid.center();
        let ext = Vec3::new(
            grid.dims[0] as f32 * grid.spacing[0],
            grid.dims[1] as f32 * grid.spacing[1],
            grid.dims[2] as f32 * grid.spacing[2],
        );
        let eye = c + Vec3::new(0.1 * ext.x, -0.75 * ext.y, 0.5 * ext.z + 0.25 * ext.y);
        // A grid a few cells wide would put the eye within its splats' cull margin and draw
        // nothing: the eye stays outside the bounding sphere widened by it.
        let least = 0.5 * ext.length() + 2.0 * Self::cull_margin(grid.kernel_spacing());
        let eye = if (eye - c).length() < least { c + (eye - c).normalize() * least } else { eye };
        let target = c + Vec3::new(0.0, 0.15 * ext.y, -0.2 * ext.z);
        let d = (target - eye).length();
        Self {
            eye,
            target,
            up: Vec3::Z,
            projection: Projection::Perspective { fov_y_deg: 55.0 },
            near: 0.01 * d,
            far: 4.0 * (d + ext.length()),
            width,
            height,
            window: None,
        }
    }

    /// World to eye space as in section 3.3.1: a rigid transform with the eye at the origin looking
    /// down +z (x right, y up).
    pub fn world_to_eye(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right()), d.dot(self.true_up()), d.dot(self.forward()))
    }

    /// Eye to perspective space, Eqs 3.3-3.5 with D = near, F = far and h = half the view-plane
    /// height at the near plane: x_p, y_p in [-1, 1] across the view (x scaled by the aspect),
    /// z_p in [0, 1] from near to far (Vulkan depth). Orthographic views map linearly. The whole
    /// frame's, whatever the window.
    pub fn eye_to_perspective(&self, e: Vec3) -> Vec3 {
        let (d, f) = (self.near, self.far);
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                let h = d * (0.5 * fov_y_deg.to_radians()).tan();
                Vec3::new(d / (h * self.aspect()) * e.x / e.z, d / h * e.y / e.z, f * (1.0 - d / e.z) / (f - d))
            }
            Projection::Orthographic { height } => {
                let h = 0.5 * height;
                Vec3::new(e.x / (h * self.aspect()), e.y / h, (e.z - d) / (f - d))
            }
        }
    }

    /// The view's side planes, `margin` pixels past the image's edges, as (inward normal n, d):
    /// a point p is in view when n . p >= d for each (near and far aside).
    pub fn side_planes(&self, margin: f32) -> [(Vec3, f32); 4] {
        let (f, r, u) = (self.forward(), self.right(), self.true_up());
        let (sx, sy) = self.half_view(margin);
        let e = self.eye;
        match self.projection {
            Projection::Perspective { .. } => [f * sx + r, f * sx - r, f * sy + u, f * sy - u].map(|n| (n, n.dot(e))),
            Projection::Orthographic { .. } => {
                [(r, r.dot(e) - sx), (-r, -r.dot(e) - sx), (u, u.dot(e) - sy), (-u, -u.dot(e) - sy)]
            }
        }
    }

    /// Whether box `lo..hi` may hold something in view (`side_planes(margin)`): false only when
    /// all its corners lie outside one side plane.
    pub fn may_see_box(&self, lo: Vec3, hi: Vec3, margin: f32) -> bool {
        self.side_planes(margin).iter().all(|&(n, d)| (0..8).any(|i| n.dot(box_corner(lo, hi, i)) >= d))
    }

    /// Half the view's width and height, `margin` pixels past the image's edges: at unit depth
    /// (perspective) or in world units (orthographic). A window's are its whole frame's: a reader
    /// reads what the frame shows (the engine culls each window by its own projection).
    fn half_view(&self, margin: f32) -> (f32, f32) {
        let per = self.pixels_per_unit();
        let (w, h) = self.frame_size();
        ((0.5 * w as f32 + margin) / per, (0.5 * h as f32 + margin) / per)
    }

    /// The bounds of the part of box `lo..hi` this view can see, `margin` pixels past the image's
    /// edges (its side planes only: near and far aside), or `None` when it sees none of it. A
    /// reader that needs only what the frame shows reads these bounds.
    pub fn box_in_view(&self, lo: Vec3, hi: Vec3, margin: f32) -> Option<[Vec3; 2]> {
        let (f, r, u) = (self.forward(), self.right(), self.true_up());
        let (sx, sy) = self.half_view(margin);
        let planes = self.side_planes(margin);
        // The view's edges: a point, a direction, and whether it is a ray from the eye.
        let corners = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)];
        let edges: Vec<(Vec3, Vec3, bool)> = match self.projection {
            Projection::Perspective { .. } => {
                corners.iter().map(|&(a, b)| (self.eye, f + r * (a * sx) + u * (b * sy), true)).collect()
            }
            Projection::Orthographic { .. } => {
                corners.iter().map(|&(a, b)| (self.eye + r * (a * sx) + u * (b * sy), f, false)).collect()
            }
        };
        let slack = 1e-4 * (hi - lo).max_element().max(1.0);
        let in_view = |p: Vec3| planes.iter().all(|&(n, d)| n.dot(p) >= d - slack * n.length());
        let in_box = |p: Vec3| (p - lo).min_element() >= -slack && (hi - p).min_element() >= -slack;
        let mut points = Vec::new();
        // The box's corners in view, and where its edges cross the side planes.
        let corner = |i: usize| box_corner(lo, hi, i);
        for i in 0..8 {
            points.push(corner(i));
            for bit in [1, 2, 4] {
                if i & bit == 0 {
                    let (a, b) = (corner(i), corner(i | bit));
                    for &(n, d) in &planes {
                        let (da, db) = (n.dot(a) - d, n.dot(b) - d);
                        if (da < 0.0) != (db < 0.0) {
                            points.push(a + (b - a) * (da / (da - db)));
                        }
                    }
                }
            }
        }
        // The view's apex and edges where they cross the box's faces.
        if self.is_perspective() {
            points.push(self.eye);
        }
        for &(p, dir, ray) in &edges {
            for a in 0..3 {
                if dir[a].abs() > 1e-12 {
                    for face in [lo[a], hi[a]] {
                        let t = (face - p[a]) / dir[a];
                        if t >= 0.0 || !ray {
                            points.push(p + dir * t);
                        }
                    }
                }
            }
        }
        let inside: Vec<Vec3> = points.into_iter().filter(|&p| in_view(p) && in_box(p)).collect();
        let first = *inside.first()?;
        let bounds = inside.iter().fold([first, first], |[a, b], &p| [a.min(p), b.max(p)]);
        Some([bounds[0].max(lo), bounds[1].min(hi)])
    }
}

/// Corner `i` (0 to 7: bit 0 high x, bit 1 high y, bit 2 high z) of box `lo..hi`.
fn box_corner(lo: Vec3, hi: Vec3, i: usize) -> Vec3 {
    Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2])
}
