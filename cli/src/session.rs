//! A session: what the viewer shows (its camera, transfer function, shading and the options its
//! keys change), saved as TOML so that `voxsplat render --session FILE` draws the same frame of
//! the same file.
use serde::{Deserialize, Serialize};
use voxsplat::classify::{Shading, TransferFunction};
use voxsplat::glam::{Vec3, Vec4};
use voxsplat::{camera::Projection, Camera, Error, Result};

/// The view, in the grid's frame (the one `render` prints as "camera (grid frame)").
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct View {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Perspective: the vertical field of view in degrees.
    pub fov: Option<f32>,
    /// Orthographic: the view's height in world units.
    pub height: Option<f32>,
    pub near: f32,
    pub far: f32,
}

/// The headlight the volume was classified with (`classify::Shading`).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    pub direction: [f32; 3],
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub shininess: f32,
}

/// A saved session.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Session {
    /// As `render --mode`.
    pub mode: String,
    /// --mode iso's value, normalised to 0..1 over the store's range (`RenderOptions::iso`).
    pub iso: Option<f32>,
    /// As `render --lod`, and `voxsplat-lab render`'s `--order`, `--accumulate`, `--raster` and `--kernel`.
    pub order: String,
    pub composite: String,
    pub raster: String,
    pub lod: String,
    pub kernel: String,
    /// The background the frame is composited over, R, G, B, A.
    pub background: [f32; 4],
    /// Clip planes NX, NY, NZ, D in world space, as `render --clip` (a unit normal: what lies
    /// where NX x + NY y + NZ z + D < 0 is cut).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clip: Vec<[f32; 4]>,
    /// A crop box's world corners (low, high), as `render --crop`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crop: Option<[[f32; 3]; 2]>,
    pub camera: View,
    /// None: unshaded.
    pub light: Option<Light>,
    pub tf: TransferFunction,
}

impl Session {
    /// The session in `path`, checked.
    pub fn load(path: &std::path::Path) -> Result<Self> {
        let text = voxsplat::loaders::read_text(path, &path.display().to_string())?;
        let s: Session = toml::from_str(&text)
            .map_err(|e| Error::InvalidArgument(format!("{}: not a session: {e}", path.display())))?;
        s.check().map_err(|e| Error::InvalidArgument(format!("{}: {e}", path.display())))?;
        Ok(s)
    }

    /// Refuse what would draw a wrong frame rather than fail: a value that is not finite, a
    /// background or iso value outside 0 to 1, a light with no direction, clipping `Clip` refuses.
    fn check(&self) -> Result<()> {
        self.tf.validate()?;
        self.clip()?;
        self.camera(1, 1)?;
        let bad = |m: &str| Err(Error::InvalidArgument(format!("a session's {m}")));
        if !self.background.iter().all(|c| (0.0..=1.0).contains(c)) {
            return bad("background is R, G, B, A in 0 to 1");
        }
        if self.iso.is_some_and(|v| !(0.0..=1.0).contains(&v)) {
            return bad("iso value is normalised: 0 to 1");
        }
        if let Some(l) = &self.light {
            let terms = [l.ambient, l.diffuse, l.specular, l.shininess];
            let direction = Vec3::from(l.direction);
            if !(direction.is_finite() && direction.length() > 0.0 && terms.iter().all(|t| t.is_finite() && *t >= 0.0))
            {
                return bad("light needs a direction and finite, non-negative terms");
            }
        }
        Ok(())
    }

    /// Written to `path` as TOML.
    pub fn save(&self, path: &std::path::Path) -> Result<()> {
        let text = toml::to_string(self).map_err(|e| Error::InvalidArgument(format!("session: {e}")))?;
        let head = "# A voxsplat session: `voxsplat render --volume FILE --session THIS --size WxH` draws it again.\n";
        std::fs::write(path, format!("{head}{text}"))
            .map_err(|e| Error::Io { path: path.display().to_string(), source: e })
    }

    /// The camera, at `width` x `height` pixels.
    pub fn camera(&self, width: u32, height: u32) -> Result<Camera> {
        let c = &self.camera;
        let projection = match (c.fov, c.height) {
            (Some(fov_y_deg), None) => Projection::Perspective { fov_y_deg },
            (None, Some(height)) => Projection::Orthographic { height },
            _ => return Err(Error::InvalidArgument("a session's camera has a fov or a height, one of them".into())),
        };
        let (eye, target, up) = (Vec3::from(c.eye), Vec3::from(c.target), Vec3::from(c.up));
        let cam = Camera { eye, target, up, projection, near: c.near, far: c.far, width, height, window: None };
        cam.validate()?;
        Ok(cam)
    }

    /// The view of `cam`.
    pub fn view_of(cam: &Camera) -> View {
        let (fov, height) = match cam.projection {
            Projection::Perspective { fov_y_deg } => (Some(fov_y_deg), None),
            Projection::Orthographic { height } => (None, Some(height)),
        };
        let (eye, target, up) = (cam.eye.to_array(), cam.target.to_array(), cam.up.to_array());
        View { eye, target, up, fov, height, near: cam.near, far: cam.far }
    }

    /// The clip planes and the crop box, as the viewer keeps them.
    pub fn clipping(&self) -> (Vec<Vec4>, Option<[Vec3; 2]>) {
        (self.clip.iter().map(|&p| Vec4::from(p)).collect(), self.crop.map(|[lo, hi]| [Vec3::from(lo), Vec3::from(hi)]))
    }

    /// The clipping as the renderer takes it.
    pub fn clip(&self) -> Result<voxsplat::options::Clip> {
        let (planes, crop) = self.clipping();
        voxsplat::options::Clip::new(&planes, crop)
            .map_err(|e| Error::InvalidArgument(format!("a session's clipping: {e}")))
    }

    /// The shading, if any.
    pub fn shading(&self) -> Option<Shading> {
        self.light.map(|l| Shading {
            light: Vec3::from(l.direction),
            ambient: l.ambient,
            diffuse: l.diffuse,
            specular: l.specular,
            shininess: l.shininess,
        })
    }

    /// The light of `shading`.
    pub fn light_of(shading: Option<Shading>) -> Option<Light> {
        shading.map(|s| Light {
            direction: s.light.to_array(),
            ambient: s.ambient,
            diffuse: s.diffuse,
            specular: s.specular,
            shininess: s.shininess,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn session() -> Session {
        let cam = Camera::framing(&voxsplat::Grid::centered([8; 3], [1.0; 3]).unwrap(), 4, 4);
        Session {
            mode: "composite".into(),
            iso: None,
            order: "pbtf".into(),
            composite: "splat".into(),
            raster: "auto".into(),
            lod: "auto".into(),
            kernel: "crawfis-max".into(),
            background: [0.0, 0.0, 0.0, 1.0],
            clip: vec![[0.0, 0.6, 0.8, -1.0]],
            crop: Some([[-2.0, -2.0, -2.0], [2.0, 2.5, 3.0]]),
            camera: Session::view_of(&cam),
            light: Session::light_of(Some(Shading::headlight(Vec3::NEG_Z))),
            tf: TransferFunction::preset("ct").unwrap(),
        }
    }

    /// A saved session reads back as it was; one that would draw a wrong frame is refused.
    #[test]
    fn a_session_reads_back_and_a_wrong_one_is_refused() {
        let dir = std::env::temp_dir().join(format!("voxsplat-session-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.toml");
        session().save(&path).unwrap();
        assert_eq!(Session::load(&path).unwrap(), session());
        type Spoil = fn(&mut Session);
        let broken: [(&str, Spoil); 8] = [
            ("background", |s| s.background[3] = 2.0),
            ("iso", |s| s.iso = Some(f32::NAN)),
            ("light", |s| s.light.as_mut().unwrap().direction = [0.0; 3]),
            ("light", |s| s.light.as_mut().unwrap().ambient = f32::INFINITY),
            ("fov", |s| s.camera.height = Some(3.0)),
            ("transfer function", |s| s.tf.points.clear()),
            ("clipping", |s| s.clip[0] = [0.0; 4]),
            ("clipping", |s| s.crop.as_mut().unwrap()[1][2] = -3.0),
        ];
        for (what, spoil) in broken {
            let mut s = session();
            spoil(&mut s);
            s.save(&path).unwrap();
            let e = Session::load(&path).unwrap_err().to_string();
            assert!(e.contains(what), "{what}: {e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
