//! The slice panes: the three planes of the store's voxels through the crosshair, windowed as the
//! transfer function's raw range, with the crosshair drawn in each. A click in a pane moves the
//! crosshair within its plane; a click on the volume moves it to the picked voxel.
use egui::{Color32, ColorImage, Pos2, Rect, Sense, Stroke, TextureHandle, TextureOptions, Vec2};
use voxsplat::bricks::BrickStore;

/// What one pane shows now: its plane's index and window (a new one uploads a new image).
struct Pane {
    texture: TextureHandle,
    index: u32,
    window: (f32, f32),
}

/// The crosshair and the three panes' images.
pub struct Slices {
    /// The voxel the three planes pass through.
    pub voxel: [u32; 3],
    panes: [Option<Pane>; 3],
    /// Where each pane was laid out last (points), for a script's clicks.
    pub rects: [Option<Rect>; 3],
}

/// The axes across and down a pane of the plane along `axis`, as `BrickStore::plane` lays it out.
fn axes(axis: usize) -> [usize; 2] {
    match axis {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

impl Slices {
    pub fn new(dims: [u32; 3]) -> Self {
        Self { voxel: dims.map(|d| d / 2), panes: [None, None, None], rects: [None; 3] }
    }

    /// The panes side by side; true when a click moved the crosshair.
    pub fn ui(&mut self, ui: &mut egui::Ui, store: &BrickStore, window: (f32, f32)) -> bool {
        let mut moved = false;
        let side = (ui.available_width() - 2.0 * ui.spacing().item_spacing.x) / 3.0;
        ui.horizontal(|ui| {
            for axis in [2, 1, 0] {
                moved |= self.pane(ui, store, axis, window, side);
            }
        });
        ui.label(format!("crosshair at voxel {} {} {} (planes z, y, x)", self.voxel[0], self.voxel[1], self.voxel[2]));
        moved
    }

    fn pane(&mut self, ui: &mut egui::Ui, store: &BrickStore, axis: usize, window: (f32, f32), side: f32) -> bool {
        let index = self.voxel[axis].min(store.dims[axis].saturating_sub(1));
        let stale = self.panes[axis].as_ref().is_none_or(|p| p.index != index || p.window != window);
        if stale {
            let Ok(plane) = store.plane(axis, index) else { return false };
            let (lo, hi) = window;
            let scale = if hi > lo { 255.0 / (hi - lo) } else { 0.0 };
            let (w, h) = (plane.width as usize, plane.height as usize);
            // Row 0 at the bottom: z (or y, for the z plane) up the pane.
            let grey: Vec<u8> = (0..h)
                .rev()
                .flat_map(|row| plane.values[row * w..(row + 1) * w].iter())
                .map(|&v| ((v - lo) * scale).clamp(0.0, 255.0) as u8)
                .collect();
            let image = ColorImage::from_gray([w, h], &grey);
            match &mut self.panes[axis] {
                Some(p) => {
                    p.texture.set(image, TextureOptions::NEAREST);
                    (p.index, p.window) = (index, window);
                }
                None => {
                    let texture = ui.ctx().load_texture(format!("plane {axis}"), image, TextureOptions::NEAREST);
                    self.panes[axis] = Some(Pane { texture, index, window });
                }
            }
        }
        let [u, v] = axes(axis);
        let (nu, nv) = (store.dims[u] as f32, store.dims[v] as f32);
        let size = if nu >= nv { Vec2::new(side, side * nv / nu) } else { Vec2::new(side * nu / nv, side) };
        let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
        self.rects[axis] = Some(rect);
        let pane = self.panes[axis].as_ref().expect("made above");
        let painter = ui.painter_at(rect);
        let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
        painter.image(pane.texture.id(), rect, uv, Color32::WHITE);
        let at = |i: u32, n: f32| (i as f32 + 0.5) / n;
        let x = rect.left() + at(self.voxel[u], nu) * rect.width();
        let y = rect.bottom() - at(self.voxel[v], nv) * rect.height();
        let stroke = Stroke::new(1.0, Color32::from_rgb(255, 200, 0));
        painter.line_segment([Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())], stroke);
        painter.line_segment([Pos2::new(rect.left(), y), Pos2::new(rect.right(), y)], stroke);
        let label = ["x", "y", "z"][axis];
        painter.text(
            rect.left_top() + Vec2::splat(2.0),
            egui::Align2::LEFT_TOP,
            format!("{label} {index}"),
            egui::FontId::monospace(10.0),
            Color32::LIGHT_GREEN,
        );
        if let Some(p) = response.interact_pointer_pos().filter(|_| response.clicked() || response.dragged()) {
            let fu = ((p.x - rect.left()) / rect.width()).clamp(0.0, 1.0);
            let fv = ((rect.bottom() - p.y) / rect.height()).clamp(0.0, 1.0);
            self.voxel[u] = ((fu * nu) as u32).min(store.dims[u] - 1);
            self.voxel[v] = ((fv * nv) as u32).min(store.dims[v] - 1);
            return true;
        }
        false
    }
}
