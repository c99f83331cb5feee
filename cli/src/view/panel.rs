//! The side panel and the view's own input: what the user sees and edits each frame. It reads and
//! writes `State`; the window loop applies what changed to the renderer.
use super::state::TfIo;
use super::{State, COMPOSITES, KERNELS, ORDERS, RASTERS};
use crate::open::Parts;
use egui::{Key, PointerButton, Rect, Sense};
use voxsplat::bricks::BrickStore;

/// Labels listed in the panel, at most.
const LABELS_SHOWN: usize = 64;
use voxsplat::{options::Lod, options::Mode};

/// The key help the panel shows (and `?` opens).
pub const KEYS: &[(&str, &str)] = &[
    ("left drag", "orbit"),
    ("middle drag, ctrl + left drag", "pan"),
    ("wheel", "zoom"),
    ("pointer over the volume", "the value, voxel and position under it"),
    ("click on the volume", "the slices' crosshair to the voxel under the pointer"),
    ("click in a slice", "the crosshair within that plane"),
    ("c C", "add a clip plane facing the view (up to 6), remove the last"),
    ("b", "a crop box: on or off"),
    ("g", "the clipping's handles: shown or hidden"),
    ("drag a grip", "move the crop box's face or a clip plane (white and cyan squares)"),
    ("m", "next mode (composite, MIP, MinIP, average, X-ray, iso)"),
    (", .", "iso value down, up"),
    ("l", "levels of detail on or off"),
    ("t T", "next, previous time point of a series"),
    ("h", "home: the start camera"),
    ("s", "save the session (view-session.toml) and the transfer function (view-tf.toml)"),
    ("p", "save a screenshot of the window (view.png)"),
    ("tf editor", "drag a point; double-click adds one; right-click deletes one"),
    ("q, Esc", "quit"),
];

/// Draw the panel and the central view; record what changed in `state`.
pub fn ui(ui: &mut egui::Ui, s: &mut State, store: Option<&BrickStore>) {
    egui::Panel::left("controls").exact_size(s.panel_width).resizable(false).show(ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| controls(ui, s, store));
    });
    egui::CentralPanel::no_frame().show(ui, |ui| {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        s.view_rect = Some(rect);
        s.pixels_per_point = ui.ctx().pixels_per_point();
        view_input(ui, s, rect, &response);
    });
    keys(ui, s);
}

/// `text` in exactly `n` rows, each cut to the panel's width (the whole row shows on hover), so
/// that the controls below stay where they are as the text changes.
fn rows(ui: &mut egui::Ui, n: usize, text: &str) {
    let mut lines = text.lines();
    for _ in 0..n {
        ui.add(egui::Label::new(lines.next().unwrap_or(" ")).truncate());
    }
}

fn controls(ui: &mut egui::Ui, s: &mut State, store: Option<&BrickStore>) {
    ui.heading("voxsplat");
    ui.label(&s.title);
    // The rows above the transfer-function editor keep their number whatever they show: a row
    // that came and went would move the editor under a dragged point.
    let drag = if s.dragging { format!(", a drag frame {:.1}x coarser", s.coarse) } else { String::new() };
    rows(ui, 1, &format!("{:.1} ms a frame ({:.1} fps){drag}", s.last_ms, 1e3 / s.last_ms.max(1e-3)));
    rows(ui, 2, if s.stats.is_empty() { "(drawing the first frame)" } else { &s.stats });
    rows(ui, 2, s.hover.as_deref().unwrap_or("(point at the volume for its value)"));
    if s.message.is_empty() {
        rows(ui, 1, " ");
    } else {
        ui.add(egui::Label::new(egui::RichText::new(&s.message).color(egui::Color32::LIGHT_YELLOW)).truncate());
    }
    ui.separator();
    let mut mode = s.options.mode;
    egui::ComboBox::from_label("mode").selected_text(mode.name()).show_ui(ui, |ui| {
        for m in Mode::ALL {
            ui.selectable_value(&mut mode, m, m.name());
        }
    });
    if mode != s.options.mode {
        s.set_mode(mode);
    }
    if let Some(mut iso) = s.options.iso {
        if ui.add(egui::Slider::new(&mut iso, 0.0..=1.0).text("iso value")).changed() {
            s.options.iso = Some(iso);
            s.dirty = true;
        }
    }
    ui.separator();
    match (&mut s.tf, &s.histogram) {
        (Some(tf), Some(h)) => {
            ui.label("transfer function (opacity over the histogram, log)");
            if s.tf_editor.ui(ui, tf, h) {
                s.tf_changed = true;
            }
        }
        _ => {
            ui.label("transfer-function editing needs a --volume file");
        }
    }
    if let Some(parts) = &s.parts {
        let title = if matches!(parts, Parts::Labels { .. }) { "labels" } else { "channels" };
        egui::CollapsingHeader::new(title).default_open(true).show(ui, |ui| parts_ui(ui, s));
    }
    if let (Some(slices), Some(store), Some(h)) = (&mut s.slices, store, &s.histogram) {
        let window = s.tf.as_ref().and_then(|t| t.range).unwrap_or(h.range);
        egui::CollapsingHeader::new("slices").default_open(true).show(ui, |ui| {
            slices.ui(ui, store, window);
        });
    }
    ui.separator();
    if s.tf.is_some() {
        let mut shaded = s.shading_on;
        if ui.checkbox(&mut shaded, "shading (headlight)").changed() {
            s.shading_on = shaded;
            s.tf_changed = true;
        }
    }
    choice(ui, "order", ORDERS, &mut s.order, &mut s.dirty);
    choice(ui, "accumulate", COMPOSITES, &mut s.composite, &mut s.dirty);
    choice(ui, "raster", RASTERS, &mut s.raster, &mut s.dirty);
    choice(ui, "kernel", KERNELS, &mut s.kernel, &mut s.dirty);
    ui.horizontal(|ui| {
        let mut lod = s.options.lod != Lod::Off;
        if ui.checkbox(&mut lod, "levels of detail").changed() {
            s.options.lod = if lod { Lod::Auto } else { Lod::Off };
            s.dirty = true;
        }
        if lod && ui.add(egui::Slider::new(&mut s.options.lod_pixels, 0.25..=8.0).text("px")).changed() {
            s.dirty = true;
        }
    });
    if let Some((series, at)) = &s.series {
        let mut t = *at;
        let last = series.times - 1;
        if ui.add(egui::Slider::new(&mut t, 0..=last).text("time point")).changed() {
            s.time_to = Some(t);
        }
    }
    egui::CollapsingHeader::new("clipping").show(ui, |ui| clipping(ui, s));
    ui.separator();
    if s.tf.is_some() {
        // Below the slices: it moves none of the controls above.
        ui.horizontal(|ui| {
            ui.label("transfer function");
            ui.add(egui::TextEdit::singleline(&mut s.tf_file).desired_width(110.0));
            if ui.button("load").on_hover_text("a TOML file render --tf reads, or a preset's name").clicked() {
                s.tf_io = Some(TfIo::Load);
            }
            if ui.button("save").clicked() {
                s.tf_io = Some(TfIo::Save);
            }
        });
    }
    ui.horizontal(|ui| {
        if ui.button("save session").clicked() {
            s.save_now = true;
        }
        if ui.button("screenshot").clicked() {
            s.shot_now = Some("view.png".into());
        }
        if ui.button("home").clicked() {
            s.home();
        }
    });
    // `?` opens or closes it (`open` forces the state for that frame only); a click on the
    // header does too, and `help` follows it.
    let forced = std::mem::take(&mut s.help_pressed).then_some(s.help);
    let header = egui::CollapsingHeader::new("keys and mouse").open(forced).show(ui, |ui| {
        egui::Grid::new("keys").striped(true).show(ui, |ui| {
            for (key, what) in KEYS {
                ui.label(*key);
                ui.label(*what);
                ui.end_row();
            }
        });
    });
    if header.header_response.clicked() {
        s.help = !s.help;
    }
}

/// Labels shown or hidden, with their colours and opacities; channels drawn or not. A change
/// classifies the scene again (once a slider is let go).
fn parts_ui(ui: &mut egui::Ui, s: &mut State) {
    let mut changed = false;
    match &mut s.parts {
        Some(Parts::Labels { table, .. }) => {
            let n = table.labels.len();
            for l in table.labels.iter_mut().take(LABELS_SHOWN) {
                ui.horizontal(|ui| {
                    changed |= ui.checkbox(&mut l.visible, format!("label {}", l.value)).changed();
                    changed |= ui.color_edit_button_rgb(&mut l.color).changed();
                    let r = ui.add(egui::Slider::new(&mut l.opacity, 0.0..=1.0).text("opacity"));
                    changed |= r.drag_stopped() || (r.changed() && !r.dragged());
                });
            }
            if n > LABELS_SHOWN {
                ui.label(format!("(the first {LABELS_SHOWN} of {n} labels; the table sets the others)"));
            }
        }
        Some(Parts::Channels { channels, .. }) => {
            for (i, c) in channels.iter_mut().enumerate() {
                changed |= ui.checkbox(&mut c.2, format!("channel {i} (its --tf or --channel-tf)")).changed();
            }
        }
        None => {}
    }
    s.reclassify |= changed;
}

/// Clip planes (each added facing the view) and a crop box.
fn clipping(ui: &mut egui::Ui, s: &mut State) {
    let mut remove = None;
    for i in 0..s.clip_planes.len() {
        let (n, Some(mut offset)) = (s.clip_planes[i].truncate(), s.plane_offset(i)) else { continue };
        ui.horizontal(|ui| {
            ui.label(format!("plane {}: normal {:.2}, {:.2}, {:.2}", i + 1, n.x, n.y, n.z));
            if ui.small_button("flip").on_hover_text("keep the other side").clicked() {
                s.clip_planes[i] = -s.clip_planes[i];
                s.dirty = true;
            }
            if ui.small_button("remove").clicked() {
                remove = Some(i);
            }
        });
        let radius = s.radius;
        let slider = egui::Slider::new(&mut offset, -radius..=radius).text("beyond the centre");
        if ui.add(slider).changed() {
            s.set_plane_offset(i, offset);
        }
    }
    if let Some(i) = remove {
        s.remove_plane(i);
    }
    let room = s.clip_planes.len() < voxsplat::options::MAX_CLIP_PLANES;
    if ui.add_enabled(room, egui::Button::new("add a plane facing the view")).clicked() {
        s.add_plane();
    }
    if ui.checkbox(&mut s.handles_shown, "handles (g)").changed() {
        s.dirty = true;
    }
    let mut crop = s.crop.is_some();
    if ui.checkbox(&mut crop, "crop box (fractions of the grid)").changed() {
        s.toggle_crop();
    }
    if let Some([mut lo, mut hi]) = s.crop_fractions() {
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            ui.horizontal(|ui| {
                if ui.add(egui::Slider::new(&mut lo[axis], 0.0..=1.0).text(name)).changed() {
                    s.set_crop_face(axis, false, lo[axis]);
                }
                if ui.add(egui::Slider::new(&mut hi[axis], 0.0..=1.0)).changed() {
                    s.set_crop_face(axis, true, hi[axis]);
                }
            });
        }
    }
}

fn choice(ui: &mut egui::Ui, label: &str, names: &[&str], value: &mut String, dirty: &mut bool) {
    egui::ComboBox::from_label(label).selected_text(value.as_str()).show_ui(ui, |ui| {
        for name in names {
            if ui.selectable_label(value == name, *name).clicked() && value != name {
                *value = name.to_string();
                *dirty = true;
            }
        }
    });
}

/// Orbit, pan and zoom on the view; the pointer's position for the pick.
fn view_input(ui: &egui::Ui, s: &mut State, rect: Rect, r: &egui::Response) {
    let ctrl = ui.input(|i| i.modifiers.ctrl);
    let delta = r.drag_delta();
    s.dragging = r.dragged();
    let ppp = ui.ctx().pixels_per_point();
    let (w, h) = (rect.width() * ppp, rect.height() * ppp);
    let (cam, shapes) = (s.view_camera(), s.handle_shapes());
    // A press on a clipping handle's grip drags the grip, not the view.
    if r.drag_started_by(PointerButton::Primary) && !ctrl {
        let origin = ui.input(|i| i.pointer.press_origin());
        s.grip = match (&cam, &shapes, origin) {
            (Some(cam), Some(shapes), Some(p)) => {
                let p = (p - rect.min) * ppp;
                shapes.grip_at(cam, voxsplat::glam::Vec2::new(p.x, p.y))
            }
            _ => None,
        };
    }
    if !r.dragged() {
        s.grip = None;
    }
    if let (Some(grip), Some(cam), Some(shapes)) = (s.grip, &cam, &shapes) {
        if delta != egui::Vec2::ZERO {
            let amount = shapes.drag(cam, grip, voxsplat::glam::Vec2::new(delta.x * ppp, delta.y * ppp));
            s.move_grip(grip, amount);
        }
    } else if delta != egui::Vec2::ZERO {
        let (dx, dy) = (delta.x * ppp, delta.y * ppp);
        if r.dragged_by(PointerButton::Middle) || (r.dragged_by(PointerButton::Primary) && ctrl) {
            if let Some(base) = &s.base {
                s.orbit.slide(base, s.radius, dx, dy, h);
            }
        } else if r.dragged_by(PointerButton::Primary) {
            s.orbit.turn(dx, dy, w, h);
        }
        s.dirty = true;
    }
    if r.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            s.orbit.wheel(scroll / 40.0);
            s.dirty = true;
        }
    }
    s.pointer = r.hover_pos().filter(|_| !r.dragged()).map(|p| p - rect.min);
    if r.clicked() {
        s.clicked = true;
    }
}

/// The keyboard, when no text field holds it.
fn keys(ui: &egui::Ui, s: &mut State) {
    if ui.ctx().egui_wants_keyboard_input() {
        return;
    }
    let pressed = |k: Key| ui.input(|i| i.key_pressed(k));
    if pressed(Key::M) {
        let at = Mode::ALL.iter().position(|&m| m == s.options.mode).unwrap_or(0);
        s.set_mode(Mode::ALL[(at + 1) % Mode::ALL.len()]);
    }
    for (key, step) in [(Key::Comma, -0.02), (Key::Period, 0.02)] {
        if pressed(key) {
            match s.options.iso {
                Some(v) => {
                    s.options.iso = Some((v + step).clamp(0.0, 1.0));
                    s.dirty = true;
                }
                None => s.message = "the iso value: m to the iso mode first".into(),
            }
        }
    }
    if pressed(Key::L) {
        s.options.lod = if s.options.lod == Lod::Off { Lod::Auto } else { Lod::Off };
        s.dirty = true;
    }
    if pressed(Key::T) {
        let back = ui.input(|i| i.modifiers.shift);
        if let Some((series, at)) = &s.series {
            let n = series.times;
            s.time_to = Some(if back { (*at + n - 1) % n } else { (*at + 1) % n });
        } else {
            s.message = "time points: open a 4-D NIfTI or an OME-Zarr image with a time axis".into();
        }
    }
    if pressed(Key::C) {
        if ui.input(|i| i.modifiers.shift) {
            s.remove_plane(usize::MAX);
        } else {
            s.add_plane();
        }
    }
    if pressed(Key::B) {
        s.toggle_crop();
    }
    if pressed(Key::G) {
        s.handles_shown = !s.handles_shown;
        s.dirty = true;
    }
    if pressed(Key::H) {
        s.home();
    }
    if pressed(Key::S) {
        s.save_now = true;
    }
    if pressed(Key::P) {
        s.shot_now = Some("view.png".into());
    }
    if pressed(Key::Questionmark) {
        s.help = !s.help;
        s.help_pressed = true;
    }
    if pressed(Key::Q) || pressed(Key::Escape) {
        s.quit = true;
    }
}
