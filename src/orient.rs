//! Where a file puts its grid in patient space, and the named anatomical views.
//!
//! World space for data with an anatomical frame is RAS+ in the file's units (NIfTI's convention:
//! +x toward the patient's right, +y anterior, +z superior); NRRD's LPS and LAS spaces are turned
//! into it. The renderer draws a grid in its own frame (`Grid::centered`: axis-aligned, centred on
//! the origin); the file's affine, split into spacing, a rotation and the centre's world position,
//! maps that frame into the world. A camera given in world space is mapped into the grid's frame by
//! the inverse (`Orientation::camera_to_grid`): a rigid map of scene and camera together leaves the
//! picture unchanged, and the visibility order is computed from the mapped eye (docs/MODEL.md).
//! A left-handed affine (a reflection) cannot be undone by moving a camera, so its grid's x axis is
//! stored reversed (`flip_x`): the loaders apply it, and the rotation left is proper. A sheared
//! (oblique) affine, such as a CT's tilted gantry gives, is split as rotation times an upper
//! triangular cell matrix (QR): the rotation moves the camera, the cell matrix places the voxels
//! (`Orientation::grid`, `Grid::shear`).
//!
//! ```
//! use voxsplat::orient::Orientation;
//! use voxsplat::glam::DMat4;
//! // A file's affine places its grid in patient space; a singular one is refused.
//! let placed = Orientation::from_affine(DMat4::from_scale([0.5, 0.5, 2.0].into()), [64, 64, 32])?;
//! assert!(Orientation::from_affine(DMat4::ZERO, [64, 64, 32]).is_err());
//! # let _ = placed;
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::camera::Camera;
use crate::error::{Error, Result};
use glam::{DMat3, DMat4, DVec3, Vec3};

/// Most an affine's axes may depart from perpendicular (cosine of the angle between two
/// directions) and still be taken as a rotation: files store their directions in f32, and scanners
/// round them. Beyond it the grid is sheared.
pub const MAX_SKEW: f64 = 1e-3;

/// Most a sheared grid's axes may depart from perpendicular (cosine 0.95, about 18 degrees from
/// parallel): a flatter cell is more likely a broken header than a scan, and its voxels' kernels,
/// round in the world, would overlap many neighbours.
pub const MAX_SHEAR: f64 = 0.95;

/// A grid's placement in patient space (RAS+), from its file's affine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orientation {
    affine: DMat4,
    /// Grid frame -> world rotation (proper: determinant +1).
    rotation: DMat3,
    /// World position of the grid's centre.
    center: DVec3,
    /// The cell matrix (upper triangular: the grid's spacing and shear): the affine's linear part
    /// is `rotation * cell` (x reversed first when `flip_x`).
    cell: DMat3,
    flip_x: bool,
    dims: [u32; 3],
}

impl Orientation {
    /// The placement of a `dims` grid whose file maps index (i, j, k) to world `affine` (RAS+).
    /// Refuses a singular or non-finite affine, and one whose axes meet at a grazing angle
    /// (`MAX_SHEAR`: Error::Unsupported names the angle).
    pub fn from_affine(affine: DMat4, dims: [u32; 3]) -> Result<Self> {
        let cols = [affine.x_axis.truncate(), affine.y_axis.truncate(), affine.z_axis.truncate()];
        if !affine.is_finite() || cols.iter().any(|c| c.length() <= 0.0) {
            return Err(Error::InvalidArgument(format!("index-to-world affine {affine:?} is singular or not finite")));
        }
        // Past these the camera cannot frame the grid ("eye, target and up must be finite").
        let far = crate::camera::MAX_WORLD as f64;
        if let Some(c) = cols.iter().find(|c| c.length() * dims.into_iter().max().unwrap_or(1) as f64 > far) {
            return Err(Error::InvalidArgument(format!(
                "index-to-world affine: a voxel step of {:.3e} units spans past the 1e15 units a camera resolves",
                c.length()
            )));
        }
        let origin = affine.w_axis.truncate();
        if origin.length() > far {
            return Err(Error::InvalidArgument(format!(
                "index-to-world affine: the grid's origin [{:.3e}, {:.3e}, {:.3e}] lies past the 1e15 units a camera \
                 resolves",
                origin.x, origin.y, origin.z
            )));
        }
        let dirs = cols.map(|c| c.normalize());
        let mut sheared = false;
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            let cos = dirs[a].dot(dirs[b]);
            if cos.abs() > MAX_SHEAR {
                return Err(Error::Unsupported(format!(
                    "the file's index axes {a} and {b} meet at {:.2} degrees: a grid sheared past {:.0} degrees \
                     from square is not placed (a broken header?); resample the volume first",
                    cos.clamp(-1.0, 1.0).acos().to_degrees(),
                    90.0 - MAX_SHEAR.acos().to_degrees()
                )));
            }
            sheared |= cos.abs() > MAX_SKEW;
        }
        let linear = DMat3::from_cols(cols[0], cols[1], cols[2]);
        let flip_x = linear.determinant() < 0.0;
        // x reversed: the grid's i runs along the file's -i.
        let proper = if flip_x { DMat3::from_cols(-cols[0], cols[1], cols[2]) } else { linear };
        let (rotation, cell) = if sheared {
            qr(proper)
        } else {
            // The nearest rotation to the directions; the cell is the columns' lengths.
            let x = if flip_x { -dirs[0] } else { dirs[0] };
            let m = orthonormalize(DMat3::from_cols(x, dirs[1], dirs[2]));
            (m, DMat3::from_diagonal(DVec3::new(cols[0].length(), cols[1].length(), cols[2].length())))
        };
        let mid = DVec3::new(dims[0] as f64 - 1.0, dims[1] as f64 - 1.0, dims[2] as f64 - 1.0) * 0.5;
        let center = affine.transform_point3(mid);
        Ok(Self { affine, rotation, center, cell, flip_x, dims })
    }

    /// The grid this placement draws, in its own frame (centred on the origin): the cell matrix's
    /// diagonal as spacing and what lies above it as shear (`Grid::shear`).
    pub fn grid(&self) -> Result<crate::volume::Grid> {
        let c = self.cell;
        let spacing = [c.x_axis.x, c.y_axis.y, c.z_axis.z].map(|v| v as f32);
        let shear = [c.y_axis.x, c.z_axis.x, c.z_axis.y].map(|v| v as f32);
        crate::volume::Grid::centered_sheared(self.dims, spacing, shear)
    }

    /// The angles in degrees at which the grid's axes i and j, i and k, j and k meet in the world.
    pub fn angles(&self) -> [f64; 3] {
        let c = [self.cell.x_axis, self.cell.y_axis, self.cell.z_axis].map(|v| v.normalize());
        [(0, 1), (0, 2), (1, 2)].map(|(a, b)| c[a].dot(c[b]).clamp(-1.0, 1.0).acos().to_degrees())
    }

    /// The grid is sheared: its axes are not perpendicular in the world.
    pub fn is_sheared(&self) -> bool {
        self.cell.y_axis.x != 0.0 || self.cell.z_axis.x != 0.0 || self.cell.z_axis.y != 0.0
    }

    /// Index -> world affine as the file gives it (columns i, j, k, then the translation).
    pub fn affine(&self) -> DMat4 {
        self.affine
    }

    /// The affine is left-handed: the grid's x axis is stored reversed (voxel i of the grid is the
    /// file's nx - 1 - i), which leaves the grid-to-world map a rotation.
    pub fn flip_x(&self) -> bool {
        self.flip_x
    }

    /// Voxel spacing along i, j, k: the lengths of the affine's columns.
    pub fn spacing(&self) -> [f32; 3] {
        [self.affine.x_axis, self.affine.y_axis, self.affine.z_axis].map(|c| c.truncate().length() as f32)
    }

    /// The same placement with the spacing replaced (`--spacing` overriding the file's).
    pub fn with_spacing(&self, spacing: [f32; 3]) -> Result<Self> {
        let s = self.spacing();
        let mut a = self.affine;
        a.x_axis *= DVec3::splat(spacing[0] as f64 / s[0] as f64).extend(1.0);
        a.y_axis *= DVec3::splat(spacing[1] as f64 / s[1] as f64).extend(1.0);
        a.z_axis *= DVec3::splat(spacing[2] as f64 / s[2] as f64).extend(1.0);
        // Keep the file's voxel (0, 0, 0) where it was.
        Self::from_affine(a, self.dims)
    }

    /// The anatomical direction each index axis points to, as in "RAS" (i toward the right, j
    /// anterior, k superior) or "LPS": the dominant world axis of each column of the file's affine.
    pub fn code(&self) -> String {
        [self.affine.x_axis, self.affine.y_axis, self.affine.z_axis]
            .iter()
            .map(|c| {
                let v = c.truncate();
                let a = (0..3).max_by(|&p, &q| v[p].abs().total_cmp(&v[q].abs())).unwrap_or(0);
                let positive = v[a] >= 0.0;
                [["L", "R"], ["P", "A"], ["I", "S"]][a][positive as usize]
            })
            .collect()
    }

    /// World position of a point given in the grid's frame.
    pub fn to_world(&self, p: Vec3) -> Vec3 {
        (self.rotation * p.as_dvec3() + self.center).as_vec3()
    }

    /// The grid-frame position of world point `p`.
    pub fn to_grid(&self, p: Vec3) -> Vec3 {
        (self.rotation.transpose() * (p.as_dvec3() - self.center)).as_vec3()
    }

    /// A world direction in the grid's frame.
    pub fn dir_to_grid(&self, v: Vec3) -> Vec3 {
        (self.rotation.transpose() * v.as_dvec3()).as_vec3()
    }

    /// A grid-frame direction in the world.
    pub fn dir_to_world(&self, v: Vec3) -> Vec3 {
        (self.rotation * v.as_dvec3()).as_vec3()
    }

    /// `camera` (world space) as the grid's frame sees it: the same picture of the grid.
    pub fn camera_to_grid(&self, camera: &Camera) -> Camera {
        Camera {
            eye: self.to_grid(camera.eye),
            target: self.to_grid(camera.target),
            up: self.dir_to_grid(camera.up),
            ..*camera
        }
    }

    /// `camera` (grid frame) in world space.
    pub fn camera_to_world(&self, camera: &Camera) -> Camera {
        Camera {
            eye: self.to_world(camera.eye),
            target: self.to_world(camera.target),
            up: self.dir_to_world(camera.up),
            ..*camera
        }
    }
}

/// `placement` with a voxel spacing given instead of the file's (`--spacing`,
/// `Orientation::with_spacing`), where there are both.
pub fn respaced(placement: Option<Orientation>, spacing: Option<[f32; 3]>) -> Result<Option<Orientation>> {
    match (placement, spacing) {
        (Some(o), Some(s)) => o.with_spacing(s).map(Some),
        (o, _) => Ok(o),
    }
}

/// The grid a `dims` volume of voxel `spacing` is drawn on: its placement's (sheared where the
/// file's affine is, `Orientation::grid`), else axis-aligned; centred on the origin either way.
pub fn placed_grid(dims: [u32; 3], spacing: [f32; 3], placement: Option<&Orientation>) -> Result<crate::volume::Grid> {
    match placement {
        Some(o) if o.dims == dims => o.grid(),
        Some(o) => Err(Error::InvalidArgument(format!("a placement of a {:?} grid for a {dims:?} volume", o.dims))),
        None => crate::volume::Grid::centered(dims, spacing),
    }
}

/// `m` = Q R with Q a rotation and R upper triangular with a positive diagonal (Gram-Schmidt on
/// the columns; `m` has a positive determinant).
fn qr(m: DMat3) -> (DMat3, DMat3) {
    let q0 = m.x_axis.normalize();
    let y = m.y_axis - q0 * q0.dot(m.y_axis);
    let q1 = y.normalize();
    let q2 = q0.cross(q1);
    let q = DMat3::from_cols(q0, q1, q2);
    (q, q.transpose() * m)
}

/// The orthogonal matrix nearest `m` (a few Newton steps of the polar decomposition: `m` is already
/// within MAX_SKEW of one).
fn orthonormalize(mut m: DMat3) -> DMat3 {
    for _ in 0..8 {
        m = (m + m.inverse().transpose()) * 0.5;
    }
    m
}

/// Anatomical views of data with a frame (3D Slicer's names): where the eye is. Superior is up in
/// the four side views; the superior and inferior views put anterior up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// From the front.
    Anterior,
    /// From behind.
    Posterior,
    /// From the patient's left.
    Left,
    /// From the patient's right.
    Right,
    /// From above.
    Superior,
    /// From below.
    Inferior,
    /// From the front, a little to the patient's right and above (the default).
    Oblique,
}

/// Every view's name, for help and errors.
pub const VIEWS: &[&str] = &["anterior", "posterior", "left", "right", "superior", "inferior", "oblique"];

impl std::str::FromStr for View {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s {
            "anterior" => View::Anterior,
            "posterior" => View::Posterior,
            "left" => View::Left,
            "right" => View::Right,
            "superior" => View::Superior,
            "inferior" => View::Inferior,
            "oblique" => View::Oblique,
            other => return Err(Error::InvalidArgument(format!("unknown view '{other}' ({})", VIEWS.join(", ")))),
        })
    }
}

impl View {
    /// World (RAS+) direction from the object to the eye, and the up direction.
    pub fn directions(self) -> (Vec3, Vec3) {
        let (r, a, s) = (Vec3::X, Vec3::Y, Vec3::Z);
        match self {
            View::Anterior => (a, s),
            View::Posterior => (-a, s),
            View::Left => (-r, s),
            View::Right => (r, s),
            View::Superior => (s, a),
            View::Inferior => (-s, a),
            View::Oblique => ((a + 0.55 * r + 0.45 * s).normalize(), s),
        }
    }
}
