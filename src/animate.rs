//! Animations (chapter 4): a scene, a camera, and object-transform keyframes, from a small TOML
//! file or built in; frames rendered still, with motion-blurred splats, or with an accumulation
//! buffer of N sub-frames over the shutter interval.
//!
//! ```
//! use voxsplat::animate::Animation;
//! // A built-in animation (`voxsplat animate --list` names them): its camera half way through.
//! let a = Animation::builtin("rotating-box")?;
//! let camera = a.camera_at(0.5);
//! assert!(camera.width > 0);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::camera::{Camera, Projection};
use crate::error::{Error, Result};
use crate::image::ImageF32;
use crate::options::{BlurProfile, Motion, RenderOptions};
use crate::volume::Grid;
use crate::Renderer;
use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;

/// Largest frame count and accumulation sub-frame count accepted.
pub const MAX_FRAMES: u32 = 100_000;
/// Most sub-frames an accumulation-buffer frame may average.
pub const MAX_SUBFRAMES: u32 = 1024;
/// Default delta of chapter 4: paths shorter than this many pixels are not blurred.
pub const DEFAULT_DELTA_PX: f32 = 0.5;

/// One keyframe of the object's rigid transform: a rotation about the grid's centre, then a
/// translation.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// The frame this keyframe holds at.
    pub frame: f32,
    /// Axis (x, y, z) and angle in degrees.
    #[serde(default = "no_rotation")]
    pub rotate: [f32; 4],
    #[serde(default)]
    /// Translation of the object, in world units.
    pub translate: [f32; 3],
    /// Camera path: the eye and look-at point at this keyframe (both or neither); frames between
    /// camera keyframes interpolate linearly, and frames outside them hold the nearest.
    #[serde(default)]
    pub eye: Option<[f32; 3]>,
    #[serde(default)]
    /// Where the camera looks at this keyframe (optional camera path).
    pub target: Option<[f32; 3]>,
}

fn no_rotation() -> [f32; 4] {
    [0.0, 1.0, 0.0, 0.0]
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraFile {
    eye: [f32; 3],
    target: [f32; 3],
    #[serde(default = "default_up")]
    up: [f32; 3],
    fov: Option<f32>,
    ortho: Option<f32>,
    near: Option<f32>,
    far: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct AnimationFile {
    scene: String,
    frames: u32,
    #[serde(default = "one")]
    shutter: f32,
    #[serde(default = "default_size")]
    size: [u32; 2],
    camera: CameraFile,
    keyframe: Vec<Keyframe>,
}

fn one() -> f32 {
    1.0
}

fn default_size() -> [u32; 2] {
    [256, 256]
}

/// A rigid-body animation of one scene seen by a fixed camera.
#[derive(Clone, Debug)]
pub struct Animation {
    /// The built-in scene animated.
    pub scene: String,
    /// Frames rendered.
    pub frames: u32,
    /// Fraction of the frame interval the shutter is open (the blur covers [t - shutter, t]).
    pub shutter: f32,
    /// The world camera.
    pub camera: Camera,
    /// The object (and camera) path, interpolated linearly between keyframes.
    pub keyframes: Vec<Keyframe>,
}

/// Built-in animations: (name, description).
pub const ANIMATIONS: &[(&str, &str)] = &[
    ("rotating-box", "the 60^3 hollow cube turning 6 degrees a frame about y, orthographic (Fig. 4.5)"),
    (
        "spinning-box",
        "the same cube turning 30 degrees a frame: paths whose arcs a straight blur misses (--blur splat:arc)",
    ),
    (
        "rotating-terrain",
        "the rmnp terrain turning 3 degrees a frame about its vertical axis, perspective (a perspective companion of Figs 5.4-5.6)",
    ),
    (
        "rotating-terrain-ortho",
        "the same turn seen orthographically, as Figs 5.4-5.6 are (the seed draws them with --order wbtf)",
    ),
];

impl Animation {
    /// A built-in animation by name (`ANIMATIONS`).
    pub fn builtin(name: &str) -> Result<Self> {
        match name {
            "rotating-box" => Self::from_toml(
                r#"
                scene = "cube60"
                frames = 24
                size = [256, 256]
                [camera]
                eye = [0.0, 45.0, 120.0]
                target = [0.0, 0.0, 0.0]
                ortho = 110.0
                [[keyframe]]
                frame = 0
                rotate = [0.0, 1.0, 0.0, 0.0]
                [[keyframe]]
                frame = 24
                rotate = [0.0, 1.0, 0.0, 144.0]
                "#,
            ),
            "spinning-box" => {
                // Keyframes 150 degrees apart: the turn between two keyframes is taken about the
                // axis, not slerped the short way.
                let mut toml = String::from(
                    "scene = \"cube60\"\nframes = 24\nsize = [256, 256]\n[camera]\neye = [0.0, 45.0, 120.0]\n\
                     target = [0.0, 0.0, 0.0]\northo = 110.0\n",
                );
                for k in 0..=5 {
                    let frame = (5 * k).min(24);
                    toml += &format!("[[keyframe]]\nframe = {frame}\nrotate = [0.0, 1.0, 0.0, {}]\n", 30 * frame);
                }
                Self::from_toml(&toml)
            }
            "rotating-terrain" => Self::from_toml(
                r#"
                scene = "rmnp"
                frames = 40
                size = [256, 192]
                [camera]
                eye = [0.0, -190.0, 120.0]
                target = [0.0, 0.0, 0.0]
                up = [0.0, 0.0, 1.0]
                fov = 45.0
                [[keyframe]]
                frame = 0
                rotate = [0.0, 0.0, 1.0, 0.0]
                [[keyframe]]
                frame = 40
                rotate = [0.0, 0.0, 1.0, 120.0]
                "#,
            ),
            "rotating-terrain-ortho" => {
                // The same turn seen orthographically (near and far as an orthographic file gets them).
                let mut a = Self::builtin("rotating-terrain")?;
                let dist = (a.camera.target - a.camera.eye).length();
                (a.camera.projection, a.camera.near) = (Projection::Orthographic { height: 150.0 }, -4.0 * dist);
                a.camera.validate()?;
                Ok(a)
            }
            other => Err(Error::InvalidArgument(format!(
                "unknown animation '{other}'; built in: {}",
                ANIMATIONS.iter().map(|a| a.0).collect::<Vec<_>>().join(", ")
            ))),
        }
    }

    /// Parse and check an animation file.
    pub fn from_toml(text: &str) -> Result<Self> {
        let f: AnimationFile =
            toml::from_str(text).map_err(|e| Error::InvalidArgument(format!("animation file: {e}")))?;
        if f.frames == 0 || f.frames > MAX_FRAMES {
            return Err(Error::InvalidArgument(format!("frames must be in 1..={MAX_FRAMES}")));
        }
        if !(f.shutter.is_finite() && f.shutter > 0.0 && f.shutter <= 1.0) {
            return Err(Error::InvalidArgument("shutter must be in (0, 1]".into()));
        }
        if f.keyframe.is_empty() {
            return Err(Error::InvalidArgument("an animation needs at least one [[keyframe]]".into()));
        }
        for k in &f.keyframe {
            if k.eye.is_some() != k.target.is_some() {
                return Err(Error::InvalidArgument("a camera keyframe needs both eye and target".into()));
            }
            let cam_finite = k.eye.iter().chain(k.target.iter()).flatten().all(|v| v.is_finite());
            let finite = cam_finite
                && k.frame.is_finite()
                && k.rotate.iter().all(|v| v.is_finite())
                && k.translate.iter().all(|v| v.is_finite());
            if !finite {
                return Err(Error::InvalidArgument("keyframe values must be finite".into()));
            }
            if k.rotate[3] != 0.0 && unit_axis(&k.rotate).is_none() {
                return Err(Error::InvalidArgument("a keyframe rotates about a zero axis".into()));
            }
        }
        let mut keyframes = f.keyframe;
        keyframes.sort_by(|a, b| a.frame.partial_cmp(&b.frame).unwrap_or(std::cmp::Ordering::Equal));
        let c = f.camera;
        let projection = match (c.fov, c.ortho) {
            (Some(_), Some(_)) => return Err(Error::InvalidArgument("camera: give fov or ortho, not both".into())),
            (_, Some(h)) => Projection::Orthographic { height: h },
            (fov, None) => Projection::Perspective { fov_y_deg: fov.unwrap_or(40.0) },
        };
        let eye = Vec3::from(c.eye);
        let dist = (Vec3::from(c.target) - eye).length();
        let ortho = matches!(projection, Projection::Orthographic { .. });
        let camera = Camera {
            eye,
            target: Vec3::from(c.target),
            up: Vec3::from(c.up),
            projection,
            near: c.near.unwrap_or(if ortho { -4.0 * dist } else { 0.05 * dist }),
            far: c.far.unwrap_or(4.0 * dist.max(1.0)),
            width: f.size[0],
            height: f.size[1],
            window: None,
        };
        camera.validate()?;
        let anim = Self { scene: f.scene, frames: f.frames, shutter: f.shutter, camera, keyframes };
        for k in anim.keyframes.iter().filter(|k| k.eye.is_some()) {
            anim.camera_at(k.frame).validate()?;
        }
        Ok(anim)
    }

    /// The world camera at time `t`: the `[camera]` table, moved along the keyframes' camera path.
    pub fn camera_at(&self, t: f32) -> Camera {
        let path: Vec<(f32, Vec3, Vec3)> =
            self.keyframes.iter().filter_map(|k| Some((k.frame, Vec3::from(k.eye?), Vec3::from(k.target?)))).collect();
        let (eye, target) = match path.iter().position(|p| p.0 > t) {
            _ if path.is_empty() => (self.camera.eye, self.camera.target),
            Some(0) => (path[0].1, path[0].2),
            None => (path[path.len() - 1].1, path[path.len() - 1].2),
            Some(i) => {
                let (a, b) = (&path[i - 1], &path[i]);
                let s = ((t - a.0) / (b.0 - a.0).max(1e-9)).clamp(0.0, 1.0);
                (a.1.lerp(b.1, s), a.2.lerp(b.2, s))
            }
        };
        Camera { eye, target, ..self.camera }
    }

    /// Check the camera at every time `blur` renders, before any frame is drawn (a path through
    /// eye == target would otherwise fail after earlier frames were written); the error names the
    /// frame.
    pub fn check_path(&self, grid: &Grid, blur: Blur) -> Result<()> {
        for i in 0..self.frames {
            let t = i as f32;
            let times: Vec<f32> = match blur {
                Blur::None => vec![t],
                Blur::Splat(_) => vec![t - self.shutter, t - 0.5 * self.shutter, t],
                Blur::Accum(n) => (0..n).map(|k| t - self.shutter + (k + 1) as f32 / n as f32 * self.shutter).collect(),
            };
            for tk in times {
                let checked = self.camera_at(tk).validate().and_then(|_| self.object_camera(grid, tk).validate());
                checked.map_err(|e| match e {
                    Error::InvalidCamera(m) => Error::InvalidCamera(format!("frame {i} (time {tk}): {m}")),
                    other => other,
                })?;
            }
        }
        Ok(())
    }

    /// The object's transform at time `t` (in frames): rotation about the grid centre, slerped
    /// between keyframes, and linearly interpolated translation.
    pub fn model(&self, grid: &Grid, t: f32) -> Mat4 {
        let rot = |k: &Keyframe| match unit_axis(&k.rotate) {
            Some(axis) if k.rotate[3] != 0.0 => Quat::from_axis_angle(axis, k.rotate[3].to_radians()),
            _ => Quat::IDENTITY,
        };
        let ks = &self.keyframes;
        let (q, tr) = match ks.iter().position(|k| k.frame > t) {
            Some(0) => (rot(&ks[0]), Vec3::from(ks[0].translate)),
            None => (rot(&ks[ks.len() - 1]), Vec3::from(ks[ks.len() - 1].translate)),
            Some(i) => {
                let (a, b) = (&ks[i - 1], &ks[i]);
                let s = ((t - a.frame) / (b.frame - a.frame).max(1e-9)).clamp(0.0, 1.0);
                // Angles up to 180 degrees apart slerp the short way, which is the intended path
                // between keyframes given that far apart.
                let qa = rot(a);
                let qb = rot(b);
                let q = if (b.rotate[3] - a.rotate[3]).abs() < 180.0 && a.rotate[..3] == b.rotate[..3] {
                    Quat::from_axis_angle(
                        unit_axis(&a.rotate).unwrap_or(Vec3::Y),
                        (a.rotate[3] + (b.rotate[3] - a.rotate[3]) * s).to_radians(),
                    )
                } else {
                    qa.slerp(qb, s)
                };
                (q, Vec3::from(a.translate).lerp(Vec3::from(b.translate), s))
            }
        };
        let c = grid.center();
        Mat4::from_translation(tr + c) * Mat4::from_quat(q) * Mat4::from_translation(-c)
    }

    /// The camera expressed in the grid's own coordinates at time `t`: drawing the still grid with
    /// it gives the picture of the moving grid seen by the world camera.
    pub fn object_camera(&self, grid: &Grid, t: f32) -> Camera {
        let inv = self.model(grid, t).inverse();
        let c = &self.camera_at(t);
        Camera {
            eye: inv.transform_point3(c.eye),
            target: inv.transform_point3(c.target),
            up: inv.transform_vector3(c.up),
            ..*c
        }
    }

    /// Chapter 4's motion from `t0` to `t1`: grid point -> its position at `t0` relative to the
    /// eye at `t1`, in the object coordinates of `t1`.
    pub fn motion(&self, grid: &Grid, t0: f32, t1: f32) -> Mat4 {
        let (v0, v1) = (self.camera_at(t0).view(), self.camera_at(t1).view());
        (v1 * self.model(grid, t1)).inverse() * (v0 * self.model(grid, t0))
    }
}

/// How a frame's motion is rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blur {
    /// Each frame drawn still.
    None,
    /// Motion-blurred splats, of this shape.
    Splat(SplatBlur),
    /// N sub-frames over the shutter interval, averaged.
    Accum(u32),
}

/// The shape of motion-blurred splats: `splat` is the seed's (straight, uniform); `splat:arc`,
/// `splat:tapered`, `splat:arc+teardrop` and so on choose the path and the profile.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SplatBlur {
    /// Bend each path through where its point was halfway through the shutter.
    pub arc: bool,
    /// How the weight spreads along the path.
    pub profile: BlurProfile,
}

impl SplatBlur {
    /// The `--blur` spelling.
    pub fn name(self) -> String {
        let profile = match self.profile {
            BlurProfile::Uniform => None,
            BlurProfile::Tapered => Some("tapered"),
            BlurProfile::Teardrop => Some("teardrop"),
            BlurProfile::Slotted => Some("slotted"),
        };
        match (self.arc, profile) {
            (false, None) => "splat".into(),
            (true, None) => "splat:arc".into(),
            (false, Some(p)) => format!("splat:{p}"),
            (true, Some(p)) => format!("splat:arc+{p}"),
        }
    }
}

impl std::str::FromStr for Blur {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        if let Some(rest) = s.strip_prefix("splat").filter(|r| r.is_empty() || r.starts_with(':')) {
            let mut shape = SplatBlur::default();
            let (mut path, mut profile) = (None, None);
            for part in rest.strip_prefix(':').into_iter().flat_map(|r| r.split('+')) {
                // One path and one profile: a second would silently replace the first.
                let slot = if matches!(part, "arc" | "line") { &mut path } else { &mut profile };
                if let Some(first) = slot.replace(part) {
                    return Err(Error::InvalidArgument(format!(
                        "blur '{s}': '{first}' and '{part}' both given; a splat blur takes one path (line, arc) \
                         and one profile (uniform, tapered, teardrop, slotted)"
                    )));
                }
                match part {
                    "arc" => shape.arc = true,
                    "line" => shape.arc = false,
                    p => {
                        shape.profile = p.parse().map_err(|_| {
                            Error::InvalidArgument(format!(
                                "blur '{s}': splat takes ':' and a '+'-joined path (line, arc) and profile \
                                 (uniform, tapered, teardrop, slotted), e.g. splat:arc+tapered"
                            ))
                        })?
                    }
                }
            }
            return Ok(Blur::Splat(shape));
        }
        match s {
            "none" => Ok(Blur::None),
            _ => {
                let n = s
                    .strip_prefix("accum:")
                    .and_then(|n| n.parse::<u32>().ok())
                    .filter(|n| (1..=MAX_SUBFRAMES).contains(n))
                    .ok_or_else(|| {
                        Error::InvalidArgument(format!(
                            "blur '{s}': use none, splat[:arc+tapered...] or accum:N with N in 1..={MAX_SUBFRAMES}"
                        ))
                    })?;
                Ok(Blur::Accum(n))
            }
        }
    }
}

/// Render frame `i` (the renderer must hold the animation's scene).
pub fn render_frame(
    r: &mut Renderer,
    anim: &Animation,
    grid: &Grid,
    i: u32,
    blur: Blur,
    base: &RenderOptions,
) -> Result<ImageF32> {
    Ok(render_frame_timed(r, anim, grid, i, blur, base)?.0)
}

/// [`render_frame`] and the summed stage time of every render it took, in milliseconds.
pub fn render_frame_timed(
    r: &mut Renderer,
    anim: &Animation,
    grid: &Grid,
    i: u32,
    blur: Blur,
    base: &RenderOptions,
) -> Result<(ImageF32, f64)> {
    let t = i as f32;
    let ms = |f: &crate::Rendered| f.timings.iter().map(|s| s.ms).sum::<f64>();
    match blur {
        Blur::None => {
            let f = r.render(&anim.object_camera(grid, t), base)?;
            let m = ms(&f);
            Ok((f.image, m))
        }
        Blur::Splat(shape) => {
            let mut o = base.clone();
            o.motion = Some(Motion {
                previous: anim.motion(grid, t - anim.shutter, t),
                middle: shape.arc.then(|| anim.motion(grid, t - 0.5 * anim.shutter, t)),
                delta_px: DEFAULT_DELTA_PX,
                profile: shape.profile,
            });
            let f = r.render(&anim.object_camera(grid, t), &o)?;
            let m = ms(&f);
            Ok((f.image, m))
        }
        Blur::Accum(n) => {
            let mut acc: Option<ImageF32> = None;
            let mut total = 0.0;
            for k in 0..n {
                // The last sub-frame is exactly t_i, so N = 1 is the still frame.
                let tk = if k + 1 == n { t } else { t - anim.shutter + (k + 1) as f32 / n as f32 * anim.shutter };
                let f = r.render(&anim.object_camera(grid, tk), base)?;
                total += ms(&f);
                let img = f.image;
                match &mut acc {
                    None => acc = Some(img),
                    Some(a) => {
                        for (p, q) in a.pixels.iter_mut().zip(&img.pixels) {
                            for c in 0..4 {
                                p[c] += q[c];
                            }
                        }
                    }
                }
            }
            let mut a = acc.expect("n >= 1");
            let inv = 1.0 / n as f32;
            for p in &mut a.pixels {
                *p = p.map(|v| v * inv);
            }
            Ok((a, total))
        }
    }
}

/// A keyframe's rotation axis (`rotate[..3]`) as a unit vector, its length taken in f64 so that a
/// huge axis (1e30: its f32 length overflows) keeps its direction; `None` for an axis shorter than
/// 1e-6.
fn unit_axis(rotate: &[f32; 4]) -> Option<Vec3> {
    let axis = Vec3::from_slice(&rotate[..3]).as_dvec3();
    let len = axis.length();
    (len >= 1e-6 && len.is_finite()).then(|| (axis / len).as_vec3())
}
