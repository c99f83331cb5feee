//! What the panel shows and edits (`State`), and what it derives from it: the render options,
//! the session, the clipping and its handles.
use super::{handles, slices, tf_editor, Orbit, ISO_START};
use crate::session::Session;
use std::path::PathBuf;
use voxsplat::bricks::Histogram;
use voxsplat::classify::{Shading, TransferFunction};
use voxsplat::glam::{Vec3, Vec4};
use voxsplat::{Camera, Error, Mode, RenderOptions, Result};

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
    /// A clip plane through the grid's centre (its normal, the offset along it) keeping what lies
    /// beyond it, and a crop box as fractions of the grid along each axis.
    pub clip_plane: Option<(Vec3, f32)>,
    pub crop: Option<[[f32; 3]; 2]>,
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
        Some(self.orbit.camera(base, self.radius, size))
    }

    /// The direction the current view looks along.
    pub fn view_direction(&self) -> Option<Vec3> {
        let base = self.base.as_ref()?;
        let cam = self.orbit.camera(base, self.radius, (base.width, base.height));
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
        if let Some(g) = &self.grid {
            let planes: Vec<Vec4> = self
                .clip_plane
                .map(|(n, offset)| Vec4::new(n.x, n.y, n.z, -n.dot(g.center()) - offset))
                .into_iter()
                .collect();
            o.clip = voxsplat::Clip::new(&planes, self.crop_world(g))?;
        }
        if o.mode != Mode::Composite {
            // As `render`: a projection draws in no visibility order and at full detail.
            (o.order, o.lod) = (voxsplat::OrderKind::Pbtf, voxsplat::Lod::Off);
        }
        o.validate()?;
        Ok(o)
    }

    /// The crop box in world space: the world box of its fractions of the grid.
    fn crop_world(&self, g: &voxsplat::Grid) -> Option<[Vec3; 2]> {
        let last = Vec3::from(g.dims.map(|d| d.saturating_sub(1) as f32));
        self.crop.map(|[lo, hi]| g.world_box(Vec3::from(lo) * last, Vec3::from(hi) * last))
    }

    /// The clipping's handles, when a plane or a box clips.
    pub fn handle_shapes(&self) -> Option<handles::Shapes> {
        let g = self.grid.as_ref()?;
        if self.clip_plane.is_none() && self.crop.is_none() {
            return None;
        }
        let bounds = g.world_box(Vec3::ZERO, Vec3::from(g.dims.map(|d| d.saturating_sub(1) as f32)));
        let plane = self.clip_plane.map(|(n, offset)| (n, g.center() + n * offset));
        Some(handles::Shapes::of(bounds, self.crop_world(g), plane))
    }

    /// A clip plane through the centre facing the view, or none.
    pub fn toggle_plane(&mut self) {
        self.clip_plane = if self.clip_plane.is_none() { self.view_direction().map(|n| (n, 0.0)) } else { None };
        self.dirty = true;
    }

    /// The crop box around the whole grid, or none.
    pub fn toggle_crop(&mut self) {
        self.crop = if self.crop.is_none() { Some([[0.0; 3], [1.0; 3]]) } else { None };
        self.dirty = true;
    }

    /// Move `grip` by `amount` world units along its direction.
    pub fn move_grip(&mut self, grip: handles::Grip, amount: f32) {
        let Some(g) = &self.grid else { return };
        match grip {
            handles::Grip::Plane => {
                if let Some((_, offset)) = &mut self.clip_plane {
                    *offset = (*offset + amount).clamp(-self.radius, self.radius);
                }
            }
            handles::Grip::Face { axis, high } => {
                let last = Vec3::from(g.dims.map(|d| d.saturating_sub(1) as f32));
                let [lo, hi] = g.world_box(Vec3::ZERO, last);
                let extent = (hi - lo)[axis].max(f32::MIN_POSITIVE);
                if let Some([lo, hi]) = &mut self.crop {
                    // As the sliders: the box keeps a hundredth of the grid at least.
                    if high {
                        hi[axis] = (hi[axis] + amount / extent).clamp(lo[axis] + 0.01, 1.0);
                    } else {
                        lo[axis] = (lo[axis] + amount / extent).clamp(0.0, hi[axis] - 0.01);
                    }
                }
            }
        }
        self.dirty = true;
    }

    /// The session of the frame drawn through `cam`: what `render --session` draws again.
    pub fn session(&self, cam: &Camera) -> Result<Session> {
        let tf = self.tf.clone().ok_or_else(|| Error::InvalidArgument("a session needs a --volume file".into()))?;
        if self.clip_plane.is_some() || self.crop.is_some() {
            return Err(Error::InvalidArgument("a session holds no clipping: turn the plane and box off first".into()));
        }
        let o = &self.options;
        let projection = o.mode != Mode::Composite;
        Ok(Session {
            mode: o.mode.to_string(),
            iso: o.iso,
            order: if projection { "pbtf".into() } else { self.order.clone() },
            composite: self.composite.clone(),
            raster: self.raster.clone(),
            lod: if projection || o.lod == voxsplat::Lod::Off { "off".into() } else { "auto".into() },
            kernel: self.kernel.clone(),
            background: o.background.unwrap_or([0.0; 4]),
            camera: Session::view_of(cam),
            light: Session::light_of(self.shading()),
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
