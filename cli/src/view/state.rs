//! What the panel shows and edits (`State`), and what it derives from it: the render options,
//! the session, the clipping and its handles.
use super::{handles, slices, tf_editor, Orbit, ISO_START};
use crate::session::Session;
use std::path::PathBuf;
use voxsplat::bricks::Histogram;
use voxsplat::classify::{Shading, TransferFunction};
use voxsplat::glam::{Vec3, Vec4};
use voxsplat::{options::Mode, Camera, Error, RenderOptions, Result};

/// What the panel shows and edits; the window loop applies it.
pub struct State {
    pub title: String,
    pub panel_width: f32,
    pub base: Option<Camera>,
    pub radius: f32,
    pub orbit: Orbit,
    pub options: RenderOptions,
    pub order: String,
    pub composite: String,
    pub raster: String,
    pub kernel: String,
    pub tf: Option<TransferFunction>,
    pub histogram: Option<Histogram>,
    pub tf_editor: tf_editor::TfEditor,
    /// The transfer function's file (or a preset's name) to load or save, and which, this frame.
    pub tf_file: String,
    pub tf_io: Option<TfIo>,
    /// The light the volume opened with (or a headlight made when shading is first turned on).
    pub light: Option<Shading>,
    pub shading_on: bool,
    pub series: Option<(crate::series::Series, u32)>,
    /// Labels or channels, kept to classify them again (`reclassify`) when the panel changes one.
    pub parts: Option<crate::open::Parts>,
    pub reclassify: bool,
    /// The pointer over the view, in points from its top left corner.
    pub pointer: Option<egui::Vec2>,
    pub hover: Option<String>,
    /// The voxel under the pointer, and where the pointer and camera were when it was picked.
    pub hover_voxel: Option<[u32; 3]>,
    pub(super) picked_at: Option<(egui::Vec2, Camera)>,
    /// A click on the volume: the crosshair goes to the voxel under it.
    pub clicked: bool,
    pub slices: Option<slices::Slices>,
    pub grid: Option<voxsplat::Grid>,
    /// Clip planes in world space (a unit normal N and D: what lies where N . p + D < 0 is cut),
    /// as `render --clip` takes them, and a crop box's world corners, as `render --crop`: a session
    /// saves them as they are, so `render --session` cuts the same voxels.
    pub clip_planes: Vec<Vec4>,
    pub crop: Option<[Vec3; 2]>,
    /// Whether the clipping's handles show (and take drags).
    pub handles_shown: bool,
    /// The clipping's handle a drag moves, and the pixels the last still frame's handles covered.
    pub grip: Option<handles::Grip>,
    pub handle_pixels: usize,
    pub view_rect: Option<egui::Rect>,
    pub pixels_per_point: f32,
    pub last_ms: f64,
    pub stats: String,
    pub message: String,
    /// How much coarser a drag frame is than the still one (adapted to `drag_ms`): it draws at
    /// 1 / coarse of the render scale (a quarter at least) with levels of detail `coarse` times
    /// the pixel bound, the error bound set aside.
    pub coarse: f32,
    /// Whether a drag frame has set `coarse` (until then the first drag starts from the still
    /// frame's time).
    pub coarse_measured: bool,
    /// The last window frame's time beyond drawing the volume.
    pub overhead_ms: f64,
    pub dragging: bool,
    pub help: bool,
    /// `?` was pressed: the key help opens or closes to `help` on the next frame.
    pub help_pressed: bool,
    // What the window loop does after the panel ran.
    pub dirty: bool,
    pub tf_changed: bool,
    pub time_to: Option<u32>,
    pub save_now: bool,
    pub shot_now: Option<PathBuf>,
    pub quit: bool,
}

/// Loading or saving the transfer function (`State::tf_file`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TfIo {
    Load,
    Save,
}

impl State {
    /// The panel at `panel_width` points, drawing with `options` and the order, compositing,
    /// raster and kernel `names`, clipped by `clipping` (world planes, a crop box).
    pub fn new(
        panel_width: f32,
        options: RenderOptions,
        (order, composite, raster, kernel): (String, String, String, String),
        (clip_planes, crop): (Vec<Vec4>, Option<[Vec3; 2]>),
    ) -> Self {
        State {
            title: String::new(),
            panel_width,
            base: None,
            radius: 1.0,
            orbit: Orbit::HOME,
            options,
            order,
            composite,
            raster,
            kernel,
            tf: None,
            histogram: None,
            tf_editor: Default::default(),
            tf_file: "view-tf.toml".into(),
            tf_io: None,
            light: None,
            shading_on: false,
            series: None,
            parts: None,
            reclassify: false,
            pointer: None,
            hover: None,
            hover_voxel: None,
            picked_at: None,
            clicked: false,
            slices: None,
            grid: None,
            clip_planes,
            crop,
            handles_shown: true,
            grip: None,
            handle_pixels: 0,
            view_rect: None,
            pixels_per_point: 1.0,
            last_ms: 0.0,
            stats: String::new(),
            message: String::new(),
            coarse: 1.0,
            coarse_measured: false,
            overhead_ms: 0.0,
            dragging: false,
            help: false,
            help_pressed: false,
            dirty: true,
            tf_changed: false,
            time_to: None,
            save_now: false,
            shot_now: None,
            quit: false,
        }
    }

    /// A mode, with the iso value it needs.
    pub fn set_mode(&mut self, mode: Mode) {
        self.options.mode = mode;
        self.options.iso = (mode == Mode::Iso).then_some(self.options.iso.unwrap_or(ISO_START));
        self.dirty = true;
    }

    /// The camera of the view as last laid out (its size in pixels).
    pub fn view_camera(&self) -> Option<Camera> {
        let (base, rect) = (self.base.as_ref()?, self.view_rect?);
        let size = (
            (rect.width() * self.pixels_per_point).round() as u32,
            (rect.height() * self.pixels_per_point).round() as u32,
        );
        Some(self.orbit.camera(base, self.centre().unwrap_or(base.target), self.radius, size))
    }

    /// The direction the current view looks along.
    pub fn view_direction(&self) -> Option<Vec3> {
        let base = self.base.as_ref()?;
        let cam = self.orbit.camera(base, self.centre().unwrap_or(base.target), self.radius, (base.width, base.height));
        Some(cam.forward())
    }

    pub fn home(&mut self) {
        self.orbit = Orbit::HOME;
        self.dirty = true;
    }

    /// The options the panel's names stand for.
    pub(super) fn render_options(&self) -> Result<RenderOptions> {
        let mut o = self.options.clone();
        o.order = self.order.parse()?;
        o.composite = self.composite.parse()?;
        o.raster = self.raster.parse()?;
        o.kernel = self.kernel.parse()?;
        o.clip = voxsplat::options::Clip::new(&self.clip_planes, self.crop)?;
        if o.mode != Mode::Composite {
            // As `render`: a projection draws in no visibility order and at full detail.
            (o.order, o.lod) = (voxsplat::order::OrderKind::Pbtf, voxsplat::options::Lod::Off);
        }
        o.validate()?;
        Ok(o)
    }

    /// The grid's world box: the crop box's whole extent.
    fn bounds(&self) -> Option<[Vec3; 2]> {
        let g = self.grid.as_ref()?;
        Some(g.world_box(Vec3::ZERO, Vec3::from(g.dims.map(|d| d.saturating_sub(1) as f32))))
    }

    /// The grid's world box's centre, which the clip planes' offsets and the view's near plane count from.
    pub fn centre(&self) -> Option<Vec3> {
        self.bounds().map(|[lo, hi]| (lo + hi) * 0.5)
    }

    /// The clipping's handles, when a plane or a box clips and they are shown.
    pub fn handle_shapes(&self) -> Option<handles::Shapes> {
        let bounds = self.bounds()?;
        if !self.handles_shown || (self.clip_planes.is_empty() && self.crop.is_none()) {
            return None;
        }
        let c = self.centre()?;
        // Each plane's point nearest the box's centre.
        let planes: Vec<(Vec3, Vec3)> =
            self.clip_planes.iter().map(|p| (p.truncate(), c - p.truncate() * (p.truncate().dot(c) + p.w))).collect();
        Some(handles::Shapes::of(bounds, self.crop, &planes))
    }

    /// A clip plane through the grid's centre facing the view (it keeps what lies beyond the
    /// centre), up to the library's limit.
    pub fn add_plane(&mut self) {
        let (Some(n), Some(c)) = (self.view_direction(), self.centre()) else { return };
        if self.clip_planes.len() >= voxsplat::options::MAX_CLIP_PLANES {
            self.message = format!("at most {} clip planes", voxsplat::options::MAX_CLIP_PLANES);
            return;
        }
        let n = n.normalize();
        self.clip_planes.push(n.extend(-n.dot(c)));
        self.dirty = true;
    }

    /// Remove clip plane `i` (the last one when `i` is past the end).
    pub fn remove_plane(&mut self, i: usize) {
        if !self.clip_planes.is_empty() {
            self.clip_planes.remove(i.min(self.clip_planes.len() - 1));
            self.dirty = true;
        }
    }

    /// How far plane `i` lies beyond the grid's centre, along its normal (world units).
    pub fn plane_offset(&self, i: usize) -> Option<f32> {
        let (p, c) = (self.clip_planes.get(i)?, self.centre()?);
        Some(-(p.truncate().dot(c) + p.w))
    }

    /// Move plane `i` to `offset` beyond the grid's centre, within the view's radius of it.
    pub fn set_plane_offset(&mut self, i: usize, offset: f32) {
        let Some(c) = self.centre() else { return };
        let radius = self.radius;
        if let Some(p) = self.clip_planes.get_mut(i) {
            p.w = -(p.truncate().dot(c) + offset.clamp(-radius, radius));
            self.dirty = true;
        }
    }

    /// The crop box around the whole grid, or none.
    pub fn toggle_crop(&mut self) {
        self.crop = if self.crop.is_none() { self.bounds() } else { None };
        self.dirty = true;
    }

    /// The crop box as fractions of the grid's world box along each axis.
    pub fn crop_fractions(&self) -> Option<[[f32; 3]; 2]> {
        let ([lo, hi], [b0, b1]) = (self.crop?, self.bounds()?);
        let f = |w: Vec3| ((w - b0) / (b1 - b0).max(Vec3::splat(f32::MIN_POSITIVE))).to_array();
        Some([f(lo), f(hi)])
    }

    /// Move the crop box's face across `axis` (its high or low one) to `fraction` of the grid's
    /// box. The box keeps a hundredth of the grid at least.
    pub fn set_crop_face(&mut self, axis: usize, high: bool, fraction: f32) {
        let Some([b0, b1]) = self.bounds() else { return };
        let Some([lo, hi]) = &mut self.crop else { return };
        let (extent, keep) = ((b1 - b0)[axis], 0.01 * (b1 - b0)[axis]);
        let at = b0[axis] + fraction * extent;
        if high {
            hi[axis] = at.clamp(lo[axis] + keep, b1[axis]);
        } else {
            lo[axis] = at.clamp(b0[axis], hi[axis] - keep);
        }
        self.dirty = true;
    }

    /// Move `grip` by `amount` world units along its direction.
    pub fn move_grip(&mut self, grip: handles::Grip, amount: f32) {
        match grip {
            handles::Grip::Plane(i) => {
                if let Some(offset) = self.plane_offset(i) {
                    self.set_plane_offset(i, offset + amount);
                }
            }
            handles::Grip::Face { axis, high } => {
                let (Some([b0, b1]), Some([lo, hi])) = (self.bounds(), self.crop) else { return };
                let extent = (b1 - b0)[axis].max(f32::MIN_POSITIVE);
                let at = if high { hi[axis] } else { lo[axis] };
                self.set_crop_face(axis, high, (at + amount - b0[axis]) / extent);
            }
        }
    }

    /// The session of the frame drawn through `cam`: what `render --session` draws again.
    pub fn session(&self, cam: &Camera) -> Result<Session> {
        let tf = self.tf.clone().ok_or_else(|| Error::InvalidArgument("a session needs a --volume file".into()))?;
        let o = &self.options;
        let projection = o.mode != Mode::Composite;
        Ok(Session {
            mode: o.mode.to_string(),
            iso: o.iso,
            order: if projection { "pbtf".into() } else { self.order.clone() },
            composite: self.composite.clone(),
            raster: self.raster.clone(),
            lod: if projection || o.lod == voxsplat::options::Lod::Off { "off".into() } else { "auto".into() },
            kernel: self.kernel.clone(),
            background: o.background.unwrap_or([0.0; 4]),
            camera: Session::view_of(cam),
            light: Session::light_of(self.shading()),
            clip: self.clip_planes.iter().map(|p| p.to_array()).collect(),
            crop: self.crop.map(|[lo, hi]| [lo.to_array(), hi.to_array()]),
            tf,
        })
    }

    pub(super) fn shading(&self) -> Option<Shading> {
        if self.shading_on {
            self.light
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> State {
        let names = ["pbtf", "splat", "auto", "crawfis-max"].map(String::from);
        let mut s = State::new(300.0, RenderOptions::default(), names.into(), (Vec::new(), None));
        let grid = voxsplat::Grid::centered([33, 17, 9], [1.0, 2.0, 3.0]).unwrap();
        s.base = Some(Camera::framing(&grid, 64, 64));
        (s.grid, s.radius) = (Some(grid), 0.5 * grid.diagonal());
        s.tf = Some(TransferFunction::preset("ct").unwrap());
        s
    }

    /// Planes face the view through the centre, up to the library's limit; each moves along its
    /// normal by its offset, within the view's radius; the crop box's faces keep a hundredth of
    /// the grid between them; the options and the session carry the same world clipping.
    #[test]
    fn planes_add_up_to_the_limit_and_move_and_the_session_keeps_them() {
        let mut s = state();
        for _ in 0..voxsplat::options::MAX_CLIP_PLANES + 1 {
            s.add_plane();
        }
        assert_eq!(s.clip_planes.len(), voxsplat::options::MAX_CLIP_PLANES);
        assert!(s.message.contains("at most"), "{}", s.message);
        let forward = s.view_direction().unwrap();
        assert!(s.clip_planes[0].truncate().distance(forward) < 1e-6);
        assert!(s.plane_offset(0).unwrap().abs() < 1e-4);
        s.set_plane_offset(1, 2.5);
        assert!((s.plane_offset(1).unwrap() - 2.5).abs() < 1e-4);
        s.move_grip(handles::Grip::Plane(1), 1e9);
        assert!((s.plane_offset(1).unwrap() - s.radius).abs() < 1e-3, "held within the radius");
        s.remove_plane(0);
        s.remove_plane(usize::MAX);
        assert_eq!(s.clip_planes.len(), voxsplat::options::MAX_CLIP_PLANES - 2);
        assert!((s.plane_offset(0).unwrap() - s.radius).abs() < 1e-3, "the first removed, the second first now");

        s.toggle_crop();
        assert_eq!(s.crop_fractions(), Some([[0.0; 3], [1.0; 3]]));
        s.set_crop_face(2, true, 0.3);
        s.set_crop_face(2, false, 0.9);
        let [lo, hi] = s.crop_fractions().unwrap();
        assert!((hi[2] - 0.3).abs() < 1e-5 && (hi[2] - lo[2] - 0.01).abs() < 1e-5, "{lo:?} {hi:?}");
        s.move_grip(handles::Grip::Face { axis: 0, high: true }, -1e9);
        let [lo, hi] = s.crop_fractions().unwrap();
        assert!((hi[0] - lo[0] - 0.01).abs() < 1e-5, "{lo:?} {hi:?}");

        let cam = s.view_camera().unwrap_or_else(|| Camera::framing(s.grid.as_ref().unwrap(), 64, 64));
        let session = s.session(&cam).unwrap();
        assert_eq!(session.clipping(), (s.clip_planes.clone(), s.crop));
        assert_eq!(session.clip().unwrap(), s.render_options().unwrap().clip);
        let shapes = s.handle_shapes().unwrap();
        // A grip on each plane that cuts the grid's box: not on the first, pushed to the radius.
        let grips: Vec<_> = shapes.grips.iter().filter(|g| matches!(g.0, handles::Grip::Plane(_))).collect();
        assert_eq!(grips.iter().map(|g| g.0).collect::<Vec<_>>(), (1..4).map(handles::Grip::Plane).collect::<Vec<_>>());
        s.handles_shown = false;
        assert!(s.handle_shapes().is_none(), "hidden handles take no drags");
    }
}
