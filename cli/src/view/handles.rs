//! The clip planes' and crop box's handles in the view: the box's edges, each plane's outline where
//! it cuts the grid's box, and a grip on each face of the box and on each plane. On a still frame
//! they are drawn under the volume with their depth (the host-depth path: `Presenter::underlay`
//! and `RenderOptions::depth`), so the volume hides the handles behind it and the handles hide
//! the volume behind them. A drag frame (a lower render scale, which the host's depth does not
//! take) gets them over the volume as the panel's lines. Dragging a grip moves its face or the
//! plane.
use voxsplat::glam::{Mat4, Vec2, Vec3, Vec3Swizzles, Vec4Swizzles};
use voxsplat::{options::DepthBuffer, options::DepthFormat, Camera};

/// What a grip moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Grip {
    /// The crop box's face across `axis`, its high or low one.
    Face { axis: usize, high: bool },
    /// Clip plane `i` (0 the first), along its normal.
    Plane(usize),
}

impl Grip {
    /// The name a script gives it: `x+`, `z-`, `plane` (the first plane), `plane2`.
    pub fn parse(name: &str) -> Option<Self> {
        if let Some(n) = name.strip_prefix("plane") {
            return match n {
                "" => Some(Grip::Plane(0)),
                n => n.parse::<usize>().ok().filter(|&i| i >= 1).map(|i| Grip::Plane(i - 1)),
            };
        }
        let mut c = name.chars();
        let axis = "xyz".find(c.next()?)?;
        let high = match (c.next()?, c.next()) {
            ('+', None) => true,
            ('-', None) => false,
            _ => return None,
        };
        Some(Grip::Face { axis, high })
    }
}

pub const BOX_COLOR: [u8; 4] = [255, 170, 0, 255];
pub const PLANE_COLOR: [u8; 4] = [0, 200, 255, 255];
/// Lines' width and grips' half side, in pixels.
const LINE_PX: i32 = 2;
const GRIP_PX: i32 = 5;
/// How near (pixels) a press must come to a grip to take it.
const GRIP_REACH: f32 = 12.0;

/// The handles in world space.
#[derive(Default)]
pub struct Shapes {
    pub lines: Vec<(Vec3, Vec3, [u8; 4])>,
    /// Each grip, where it sits and the world direction it moves along.
    pub grips: Vec<(Grip, Vec3, Vec3)>,
}

impl Shapes {
    /// The crop box `crop` (world corners) and each plane, (its normal, a point on it), cut by the
    /// grid's world box `bounds`.
    pub fn of(bounds: [Vec3; 2], crop: Option<[Vec3; 2]>, planes: &[(Vec3, Vec3)]) -> Self {
        let mut s = Shapes::default();
        if let Some([lo, hi]) = crop {
            for (a, b) in box_edges(lo, hi) {
                s.lines.push((a, b, BOX_COLOR));
            }
            let mid = (lo + hi) * 0.5;
            for axis in 0..3 {
                for high in [false, true] {
                    let mut at = mid;
                    at[axis] = if high { hi[axis] } else { lo[axis] };
                    s.grips.push((Grip::Face { axis, high }, at, Vec3::AXES[axis]));
                }
            }
        }
        for (i, &(n, point)) in planes.iter().enumerate() {
            let outline = plane_outline(bounds, n, point);
            for i in 0..outline.len() {
                s.lines.push((outline[i], outline[(i + 1) % outline.len()], PLANE_COLOR));
            }
            if !outline.is_empty() {
                let centre = outline.iter().copied().sum::<Vec3>() / outline.len() as f32;
                s.grips.push((Grip::Plane(i), centre, n));
            }
        }
        s
    }

    /// The grip nearest `p` (pixels from the view's top left) within reach, if any.
    pub fn grip_at(&self, cam: &Camera, p: Vec2) -> Option<Grip> {
        self.grips
            .iter()
            .filter_map(|&(g, at, _)| Some((g, (to_screen(cam, at)?.xy() - p).length())))
            .filter(|&(_, d)| d <= GRIP_REACH)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(g, _)| g)
    }

    /// Where `grip` sits on the screen (pixels), if in front of the eye.
    pub fn grip_screen(&self, cam: &Camera, grip: Grip) -> Option<Vec2> {
        let &(_, at, _) = self.grips.iter().find(|g| g.0 == grip)?;
        Some(to_screen(cam, at)?.xy())
    }

    /// How far (world units, along the grip's direction) a pointer moved by `delta` pixels
    /// carries `grip`: the motion's part along the direction's image on the screen.
    pub fn drag(&self, cam: &Camera, grip: Grip, delta: Vec2) -> f32 {
        let Some(&(_, at, dir)) = self.grips.iter().find(|g| g.0 == grip) else { return 0.0 };
        // A step a hundredth of the view's height at the grip's depth, and its image.
        let step = 0.01 * cam.width.max(cam.height) as f32 / cam.pixels_per_unit()
            * if cam.is_perspective() { (at - cam.eye).dot(cam.forward()).max(cam.near) } else { 1.0 };
        let (Some(a), Some(b)) = (to_screen(cam, at), to_screen(cam, at + dir * step)) else { return 0.0 };
        let d = b.xy() - a.xy();
        let across = 0.01 * cam.width.max(cam.height) as f32;
        if d.length() < 0.25 * across {
            // Along the view's axis (a plane facing the view) the direction has hardly an image to
            // follow: the pointer up carries the grip away from the eye, at a sideways move's rate.
            let away = if dir.dot(cam.forward()) >= 0.0 { 1.0 } else { -1.0 };
            return -delta.y / across * step * away;
        }
        delta.dot(d) / d.length_squared() * step
    }

    /// The lines and grips as the screen shows them (pixels), for the overlay of a drag frame.
    pub fn screen_lines(&self, cam: &Camera) -> Vec<([Vec2; 2], [u8; 4])> {
        let mut out: Vec<_> = self
            .lines
            .iter()
            .filter_map(|&(a, b, c)| clip_segment(cam, a, b).map(|(a, b)| ([a.xy(), b.xy()], c)))
            .collect();
        for &(g, at, _) in &self.grips {
            if let Some(p) = to_screen(cam, at) {
                let r = GRIP_PX as f32;
                let c = grip_color(g);
                let corners = [Vec2::new(-r, -r), Vec2::new(r, -r), Vec2::new(r, r), Vec2::new(-r, r)];
                for i in 0..4 {
                    out.push(([p.xy() + corners[i], p.xy() + corners[(i + 1) % 4]], c));
                }
            }
        }
        out
    }
}

fn grip_color(g: Grip) -> [u8; 4] {
    match g {
        Grip::Plane(_) => PLANE_COLOR,
        Grip::Face { .. } => [255, 255, 255, 255],
    }
}

/// The twelve edges of the box `lo..hi`.
fn box_edges(lo: Vec3, hi: Vec3) -> Vec<(Vec3, Vec3)> {
    let corner = |c: usize| Vec3::new([lo.x, hi.x][c & 1], [lo.y, hi.y][(c >> 1) & 1], [lo.z, hi.z][(c >> 2) & 1]);
    (0..8)
        .flat_map(|c| (0..3).filter(move |a| c & (1 << a) == 0).map(move |a| (corner(c), corner(c | 1 << a))))
        .collect()
}

/// Where the plane through `point` with normal `n` cuts the box: a convex polygon, in order.
fn plane_outline([lo, hi]: [Vec3; 2], n: Vec3, point: Vec3) -> Vec<Vec3> {
    let mut pts: Vec<Vec3> = Vec::new();
    for (a, b) in box_edges(lo, hi) {
        let (sa, sb) = (n.dot(a - point), n.dot(b - point));
        if sa * sb <= 0.0 && sa != sb {
            let p = a + (b - a) * (sa / (sa - sb));
            if pts.iter().all(|q| q.distance(p) > 1e-4 * (hi - lo).length()) {
                pts.push(p);
            }
        }
    }
    if pts.len() < 3 {
        return Vec::new();
    }
    let centre = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    pts.sort_by(|p, q| {
        let angle = |p: &Vec3| (*p - centre).dot(v).atan2((*p - centre).dot(u));
        angle(p).total_cmp(&angle(q))
    });
    pts
}

/// A world point on the screen: pixels from the top left, and its depth (Vulkan's 0 to 1 of the
/// camera's projection); None behind the near plane.
fn to_screen(cam: &Camera, p: Vec3) -> Option<Vec3> {
    screen_of(cam, cam.view_proj() * p.extend(1.0))
}

fn screen_of(cam: &Camera, c: voxsplat::glam::Vec4) -> Option<Vec3> {
    if c.w <= 0.0 || c.z < 0.0 {
        return None;
    }
    let ndc = c.xyz() / c.w;
    Some(Vec3::new((ndc.x * 0.5 + 0.5) * cam.width as f32, (ndc.y * 0.5 + 0.5) * cam.height as f32, ndc.z))
}

/// A world segment on the screen, cut at the near plane.
fn clip_segment(cam: &Camera, a: Vec3, b: Vec3) -> Option<(Vec3, Vec3)> {
    let vp: Mat4 = cam.view_proj();
    let (mut ca, mut cb) = (vp * a.extend(1.0), vp * b.extend(1.0));
    if ca.z < 0.0 && cb.z < 0.0 {
        return None;
    }
    // Vulkan's near plane is z = 0 in clip space.
    if ca.z < 0.0 {
        ca = ca + (cb - ca) * (ca.z / (ca.z - cb.z));
    } else if cb.z < 0.0 {
        cb = cb + (ca - cb) * (cb.z / (cb.z - ca.z));
    }
    Some((screen_of(cam, ca)?, screen_of(cam, cb)?))
}

/// The handles drawn for the host-depth path: display colours (RGBA8, premultiplied, opaque) and
/// depths, row by row from the top.
pub struct Layer {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub depth: Vec<f32>,
    /// Pixels the handles cover.
    pub drawn: usize,
}

impl Layer {
    /// The handles of `shapes` as `cam` sees them, over `background` (display bytes).
    pub fn draw(cam: &Camera, shapes: &Shapes, background: [u8; 4]) -> Self {
        let (w, h) = (cam.width, cam.height);
        let n = w as usize * h as usize;
        let mut layer = Layer {
            width: w,
            height: h,
            rgba: background.iter().copied().cycle().take(n * 4).collect(),
            depth: vec![1.0; n],
            drawn: 0,
        };
        for &(a, b, c) in &shapes.lines {
            if let Some((a, b)) = clip_segment(cam, a, b) {
                layer.line(a, b, c);
            }
        }
        for &(g, at, _) in &shapes.grips {
            if let Some(p) = to_screen(cam, at) {
                for dy in -GRIP_PX..=GRIP_PX {
                    for dx in -GRIP_PX..=GRIP_PX {
                        layer.plot(p.x as i32 + dx, p.y as i32 + dy, p.z, grip_color(g));
                    }
                }
            }
        }
        layer.drawn = (0..n).filter(|&i| layer.depth[i] < 1.0).count();
        layer
    }

    /// A pixel nearer than what it holds takes `color`.
    fn plot(&mut self, x: i32, y: i32, z: f32, color: [u8; 4]) {
        if x < 0 || y < 0 || x >= self.width as i32 || y >= self.height as i32 || !(0.0..1.0).contains(&z) {
            return;
        }
        let i = y as usize * self.width as usize + x as usize;
        if z < self.depth[i] {
            self.depth[i] = z;
            self.rgba[i * 4..i * 4 + 4].copy_from_slice(&color);
        }
    }

    /// A line `LINE_PX` wide; the depth is affine in the screen's x and y, so it interpolates
    /// linearly along the line.
    fn line(&mut self, a: Vec3, b: Vec3, color: [u8; 4]) {
        let steps = (b.xy() - a.xy()).abs().max_element().ceil().clamp(1.0, 1e5) as usize;
        for i in 0..=steps {
            let p = a.lerp(b, i as f32 / steps as f32);
            for dy in 0..LINE_PX {
                for dx in 0..LINE_PX {
                    self.plot(p.x as i32 + dx - LINE_PX / 2, p.y as i32 + dy - LINE_PX / 2, p.z, color);
                }
            }
        }
    }

    /// The depths as the renderer reads them, drawn with `projection` (the camera's).
    pub fn depth_buffer(&self, projection: Mat4) -> DepthBuffer {
        DepthBuffer {
            width: self.width,
            height: self.height,
            format: DepthFormat::D32,
            texels: self.depth.iter().map(|d| d.to_bits()).collect(),
            projection,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grips_parse_and_outlines_close() {
        assert_eq!(Grip::parse("x+"), Some(Grip::Face { axis: 0, high: true }));
        assert_eq!(Grip::parse("z-"), Some(Grip::Face { axis: 2, high: false }));
        assert_eq!(Grip::parse("plane"), Some(Grip::Plane(0)));
        assert_eq!(Grip::parse("plane3"), Some(Grip::Plane(2)));
        assert_eq!(Grip::parse("plane0"), None);
        assert_eq!(Grip::parse("planes"), None);
        assert_eq!(Grip::parse("w+"), None);
        assert_eq!(Grip::parse("x+-"), None);
        assert_eq!(box_edges(Vec3::ZERO, Vec3::ONE).len(), 12);
        // A plane across x through the middle of the unit box: a square.
        let square = plane_outline([Vec3::ZERO, Vec3::ONE], Vec3::X, Vec3::splat(0.5));
        assert_eq!(square.len(), 4);
        assert!(square.iter().all(|p| (p.x - 0.5).abs() < 1e-6));
        // A diagonal plane through the centre: a hexagon.
        assert_eq!(plane_outline([Vec3::ZERO, Vec3::ONE], Vec3::ONE.normalize(), Vec3::splat(0.5)).len(), 6);
        // Outside the box: nothing.
        assert!(plane_outline([Vec3::ZERO, Vec3::ONE], Vec3::X, Vec3::splat(2.0)).is_empty());
    }

    #[test]
    fn the_layer_keeps_the_nearest_handle_and_a_drag_follows_the_pointer() {
        let grid = voxsplat::Grid::centered([32, 32, 32], [1.0; 3]).unwrap();
        let cam = Camera::framing(&grid, 96, 96);
        let bounds = grid.world_box(Vec3::ZERO, Vec3::splat(31.0));
        let shapes = Shapes::of(bounds, Some(bounds), &[]);
        let layer = Layer::draw(&cam, &shapes, [0, 0, 0, 255]);
        assert!(layer.drawn > 0);
        // Every covered pixel holds a handle's colour and a depth in front of the far plane.
        for i in 0..layer.depth.len() {
            let c = &layer.rgba[i * 4..i * 4 + 4];
            assert_eq!(layer.depth[i] < 1.0, c != [0, 0, 0, 255], "pixel {i}");
        }
        // The grip of the face nearest the eye is nearer than the one across the box.
        let near = shapes.grips.iter().min_by(|a, b| a.1.distance(cam.eye).total_cmp(&b.1.distance(cam.eye))).unwrap();
        let z = |p: Vec3| to_screen(&cam, p).unwrap().z;
        let far = shapes.grips.iter().find(|g| g.1 == 2.0 * grid.center() - near.1).unwrap();
        assert!(z(near.1) < z(far.1));
        // Dragged by its own image on the screen, a grip moves by the step that makes it.
        let g = Grip::Face { axis: 0, high: true };
        let at = shapes.grip_screen(&cam, g).unwrap();
        let moved = to_screen(&cam, shapes.grips.iter().find(|x| x.0 == g).unwrap().1 + Vec3::X * 2.0).unwrap().xy();
        let d = shapes.drag(&cam, g, moved - at);
        assert!((d - 2.0).abs() < 0.1, "{d}");
        assert_eq!(shapes.grip_at(&cam, at + Vec2::new(1.0, 1.0)), Some(g));
        // A plane facing the view: the pointer up pushes it away from the eye.
        let plane = Shapes::of(bounds, None, &[(cam.forward(), grid.center())]);
        assert!(plane.drag(&cam, Grip::Plane(0), Vec2::new(0.0, -10.0)) > 0.0);
        assert!(plane.drag(&cam, Grip::Plane(0), Vec2::new(0.0, 10.0)) < 0.0);
        // Two planes: a grip each, the second's named by its index.
        let two = Shapes::of(bounds, None, &[(cam.forward(), grid.center()), (Vec3::X, grid.center())]);
        let named: Vec<Grip> = two.grips.iter().map(|g| g.0).collect();
        assert_eq!(named, [Grip::Plane(0), Grip::Plane(1)]);
    }
}
