//! The transfer-function editor: the opacity curve over the data's histogram (log scale), its
//! points dragged, added (double-click) and deleted (right-click), a point's colour, presets and
//! the window of raw values the curve spans.
use egui::{Color32, Pos2, Rect, Sense, Shape, Stroke, Vec2};
use voxsplat::bricks::Histogram;
use voxsplat::classify::TransferFunction;

/// What the editor keeps between frames.
#[derive(Default)]
pub struct TfEditor {
    /// The point whose colour the picker edits.
    pub selected: Option<usize>,
    /// The curve's area on screen, in points (the scripted session aims at it).
    pub rect: Option<Rect>,
}

/// Raw values across the editor's width: the histogram's range.
fn raw_at(h: &Histogram, t: f32) -> f32 {
    h.range.0 + t * (h.range.1 - h.range.0)
}

fn t_of(h: &Histogram, raw: f32) -> f32 {
    let span = h.range.1 - h.range.0;
    if span > 0.0 {
        (raw - h.range.0) / span
    } else {
        0.0
    }
}

impl TfEditor {
    /// The point `i` of `tf` on screen, for the scripted session.
    pub fn point_pos(&self, tf: &TransferFunction, h: &Histogram, i: usize) -> Option<Pos2> {
        let rect = self.rect?;
        let (x, rgba) = *tf.points.get(i)?;
        let (lo, hi) = tf.range.unwrap_or(h.range);
        let t = t_of(h, lo + x * (hi - lo));
        Some(Pos2::new(rect.left() + t * rect.width(), rect.bottom() - rgba[3] * rect.height()))
    }

    /// Draw the editor; true when `tf` changed (and is valid).
    pub fn ui(&mut self, ui: &mut egui::Ui, tf: &mut TransferFunction, h: &Histogram) -> bool {
        let mut changed = false;
        let width = ui.available_width();
        let (rect, background) = ui.allocate_exact_size(Vec2::new(width, 140.0), Sense::click());
        self.rect = Some(rect);
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 2.0, Color32::from_gray(24));
        let heights = h.log_heights();
        let bar = rect.width() / heights.len().max(1) as f32;
        for (i, &v) in heights.iter().enumerate() {
            let x = rect.left() + i as f32 * bar;
            let top = rect.bottom() - v * rect.height();
            painter.rect_filled(
                Rect::from_min_max(Pos2::new(x, top), Pos2::new(x + bar, rect.bottom())),
                0.0,
                Color32::from_gray(70),
            );
        }
        let (lo, hi) = tf.range.unwrap_or(h.range);
        let to_screen = |x: f32, a: f32| {
            let t = t_of(h, lo + x * (hi - lo));
            Pos2::new(rect.left() + t * rect.width(), rect.bottom() - a * rect.height())
        };
        let from_screen = |p: Pos2| {
            let raw = raw_at(h, ((p.x - rect.left()) / rect.width()).clamp(0.0, 1.0));
            let x = if hi > lo { ((raw - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.0 };
            (x, ((rect.bottom() - p.y) / rect.height()).clamp(0.0, 1.0))
        };
        // The window's edges.
        for raw in [lo, hi] {
            let x = rect.left() + t_of(h, raw) * rect.width();
            painter.line_segment(
                [Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())],
                Stroke::new(1.0, Color32::from_rgb(90, 90, 140)),
            );
        }
        let line: Vec<Pos2> = tf.points.iter().map(|&(x, c)| to_screen(x, c[3])).collect();
        painter.add(Shape::line(line, Stroke::new(1.5, Color32::from_gray(220))));
        let mut edit = tf.clone();
        let mut remove = None;
        let n = tf.points.len();
        for (i, &(x, c)) in tf.points.iter().enumerate() {
            let at = to_screen(x, c[3]);
            let id = ui.id().with(("tf point", i));
            let handle = ui.interact(Rect::from_center_size(at, Vec2::splat(12.0)), id, Sense::click_and_drag());
            let colour = Color32::from_rgb((c[0] * 255.0) as u8, (c[1] * 255.0) as u8, (c[2] * 255.0) as u8);
            let ring = if self.selected == Some(i) || handle.hovered() { Color32::YELLOW } else { Color32::WHITE };
            painter.circle(at, 5.0, colour, Stroke::new(1.5, ring));
            if handle.clicked() || handle.drag_started() {
                self.selected = Some(i);
            }
            if handle.dragged() {
                if let Some(p) = handle.interact_pointer_pos() {
                    let (nx, na) = from_screen(p);
                    // A point stays between its neighbours: the curve is a function of density.
                    let left = if i > 0 { edit.points[i - 1].0 + 1e-4 } else { 0.0 };
                    let right = if i + 1 < n { edit.points[i + 1].0 - 1e-4 } else { 1.0 };
                    edit.points[i].0 = nx.clamp(left.min(right), right.max(left));
                    edit.points[i].1[3] = na;
                    changed = true;
                }
            }
            if handle.secondary_clicked() && n > 2 {
                remove = Some(i);
            }
        }
        if let Some(i) = remove {
            edit.points.remove(i);
            self.selected = None;
            changed = true;
        }
        if background.double_clicked() {
            if let Some(p) = background.interact_pointer_pos() {
                let (x, a) = from_screen(p);
                let at = edit.points.partition_point(|q| q.0 < x);
                let mut c = edit.eval(x);
                c[3] = a;
                edit.points.insert(at, (x, c));
                self.selected = Some(at);
                changed = true;
            }
        }
        if let Some(i) = self.selected.filter(|&i| i < edit.points.len()) {
            ui.horizontal(|ui| {
                ui.label(format!("point {i}: colour"));
                let mut rgb = [edit.points[i].1[0], edit.points[i].1[1], edit.points[i].1[2]];
                if ui.color_edit_button_rgb(&mut rgb).changed() {
                    edit.points[i].1[..3].copy_from_slice(&rgb);
                    changed = true;
                }
                ui.add(egui::DragValue::new(&mut edit.points[i].1[3]).range(0.0..=1.0).speed(0.01).prefix("opacity "))
                    .changed()
                    .then(|| changed = true);
            });
        }
        // Window and level over the raw values.
        let span = (h.range.1 - h.range.0).max(f32::MIN_POSITIVE);
        let (mut level, mut window) = (0.5 * (lo + hi), hi - lo);
        ui.horizontal(|ui| {
            let speed = span / 500.0;
            let a = ui.add(egui::DragValue::new(&mut level).speed(speed).prefix("level "));
            let b = ui
                .add(egui::DragValue::new(&mut window).speed(speed).range(span * 1e-3..=span * 4.0).prefix("window "));
            if a.changed() || b.changed() {
                edit.range = Some((level - 0.5 * window, level + 0.5 * window));
                changed = true;
            }
            if ui.button("full range").clicked() {
                edit.range = None;
                changed = true;
            }
        });
        ui.horizontal(|ui| {
            ui.label("preset");
            for (name, about) in voxsplat::classify::TF_PRESETS {
                if ui.small_button(*name).on_hover_text(*about).clicked() {
                    if let Ok(p) = TransferFunction::preset(name) {
                        edit.points = p.points;
                        self.selected = None;
                        changed = true;
                    }
                }
            }
        });
        if changed && edit.validate().is_ok() {
            *tf = edit;
            return true;
        }
        false
    }
}
