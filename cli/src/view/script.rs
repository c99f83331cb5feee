//! `view --script FILE`: synthetic pointer and key events, one line a frame, fed to the panel as
//! the window's own events would be. The lines start once the first frame is shown. Positions are
//! resolved when a line runs, against the last frame's layout (the editor's points move as they
//! are dragged).
//!
//! ```text
//! move X Y            pointer to (X, Y) points from the window's top left
//! drag X0 Y0 X1 Y1    left-drag over a few frames (the view orbits)
//! drag-tf I X Y       drag the editor's point I to (X, Y): fractions of its width and height
//! add-tf X Y          double-click the editor there: a new point
//! delete-tf I         right-click the editor's point I
//! key K               press and release key K (a letter, comma, period; shift+K with shift)
//! pick X Y            click at (X, Y), fractions of the view; print the value under it and
//!                     the slices' crosshair
//! slice A X Y         click the slice pane across axis A (x, y or z) at (X, Y), fractions of
//!                     it from its top left; print the crosshair
//! grip G DX DY        drag the clipping's grip G (x+, x-, y+, y-, z+, z-: the crop box's
//!                     faces; plane or plane1 to plane6: the clip planes) by (DX, DY) points
//! state               print the clipping (crop box as fractions, each plane's offset beyond the
//!                     centre) and the handles' pixels
//! label V on|off      show or hide label V, as its checkbox in the panel does
//! channel I on|off    draw channel I (0 the first) or not, as its checkbox does
//! wait N              N frames
//! shot PATH           the window's pixels as a PNG
//! view PATH           the volume's image alone as a PNG
//! session PATH        save the session (render --session draws it again)
//! tf PATH             save the transfer function (render --tf reads it)
//! load-tf SPEC        load a transfer function (a TOML file or a preset), as the panel's load
//! ```
use super::State;
use crate::open::Parts;
use egui::{Event, Key, Modifiers, PointerButton, Pos2, RawInput};
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use voxsplat::{Camera, Error, Result};

#[derive(Clone, Debug)]
enum Line {
    Move(Pos2),
    Drag(Pos2, Pos2),
    DragTf(usize, Pos2),
    AddTf(Pos2),
    DeleteTf(usize),
    Key(Key, bool),
    Pick(Pos2),
    Slice(usize, Pos2),
    Grip(super::handles::Grip, egui::Vec2),
    State,
    Label(u32, bool),
    Channel(usize, bool),
    Wait(u32),
    Shot(PathBuf),
    View(PathBuf),
    Session(PathBuf),
    Tf(PathBuf),
    LoadTf(String),
}

/// One frame's events and what to do once it is drawn.
#[derive(Default)]
pub struct Step {
    events: Vec<Event>,
    after: Option<Line>,
}

/// A loaded script and where it is.
pub struct Script {
    lines: VecDeque<(usize, Line)>,
    /// Frames expanded from the running line.
    pending: VecDeque<Step>,
    /// The first frame lays out the panel; the script starts after it.
    started: bool,
}

fn parse_line(n: usize, text: &str) -> Result<Option<Line>> {
    let words: Vec<&str> = text.split_whitespace().collect();
    let Some((&cmd, rest)) = words.split_first() else { return Ok(None) };
    if cmd.starts_with('#') {
        return Ok(None);
    }
    let bad = |why: &str| Error::InvalidArgument(format!("script line {n}: {why}: {text}"));
    let num = |i: usize| -> Result<f32> {
        rest.get(i)
            .and_then(|w| w.parse::<f32>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad("expected a number"))
    };
    let index = |i: usize| -> Result<usize> {
        rest.get(i).and_then(|w| w.parse().ok()).ok_or_else(|| bad("expected an index"))
    };
    let path = || -> Result<PathBuf> { rest.first().map(PathBuf::from).ok_or_else(|| bad("expected a path")) };
    let pos = |i: usize| -> Result<Pos2> { Ok(Pos2::new(num(i)?, num(i + 1)?)) };
    let line = match cmd {
        "move" => Line::Move(pos(0)?),
        "drag" => Line::Drag(pos(0)?, pos(2)?),
        "drag-tf" => Line::DragTf(index(0)?, pos(1)?),
        "add-tf" => Line::AddTf(pos(0)?),
        "delete-tf" => Line::DeleteTf(index(0)?),
        "key" => {
            let name = rest.first().ok_or_else(|| bad("expected a key"))?;
            let (shift, name) = name.strip_prefix("shift+").map_or((false, *name), |k| (true, k));
            let key = match name {
                "," | "comma" => Some(Key::Comma),
                "." | "period" => Some(Key::Period),
                k => Key::from_name(&k.to_uppercase()),
            };
            Line::Key(key.ok_or_else(|| bad("unknown key"))?, shift)
        }
        "pick" => Line::Pick(pos(0)?),
        "slice" => {
            let axis = rest.first().and_then(|a| "xyz".find(*a).filter(|_| a.len() == 1));
            Line::Slice(axis.ok_or_else(|| bad("expected an axis: x, y or z"))?, pos(1)?)
        }
        "grip" => {
            let grip = rest.first().and_then(|g| super::handles::Grip::parse(g));
            Line::Grip(
                grip.ok_or_else(|| bad("expected a grip: x+, x-, y+, y-, z+, z-, plane or plane2 to plane6"))?,
                pos(1)? - Pos2::ZERO,
            )
        }
        "state" => Line::State,
        "label" | "channel" => {
            let on = match rest.get(1) {
                Some(&"on") => true,
                Some(&"off") => false,
                _ => return Err(bad("expected on or off")),
            };
            let i = index(0)?;
            if cmd == "label" {
                Line::Label(u32::try_from(i).map_err(|_| bad("a label past u32"))?, on)
            } else {
                Line::Channel(i, on)
            }
        }
        "wait" => Line::Wait(index(0)?.min(10_000) as u32),
        "shot" => Line::Shot(path()?),
        "view" => Line::View(path()?),
        "session" => Line::Session(path()?),
        "tf" => Line::Tf(path()?),
        "load-tf" if !rest.is_empty() => Line::LoadTf(rest.join(" ")),
        "load-tf" => return Err(bad("expected a TOML file or a preset's name")),
        _ => return Err(bad("unknown command")),
    };
    Ok(Some(line))
}

fn button(pos: Pos2, button: PointerButton, pressed: bool) -> Event {
    Event::PointerButton { pos, button, pressed, modifiers: Modifiers::NONE }
}

/// A left drag from `a` to `b`: press, four moves, release, one frame each.
fn drag(a: Pos2, b: Pos2) -> Vec<Step> {
    let mut steps =
        vec![Step { events: vec![Event::PointerMoved(a), button(a, PointerButton::Primary, true)], after: None }];
    for i in 1..=4 {
        let p = a + (b - a) * (i as f32 / 4.0);
        steps.push(Step { events: vec![Event::PointerMoved(p)], after: None });
    }
    steps.push(Step { events: vec![button(b, PointerButton::Primary, false)], after: None });
    steps
}

impl Script {
    pub fn load(path: &Path) -> Result<Self> {
        let text = voxsplat::loaders::read_text(path, &path.display().to_string())?;
        let mut lines = VecDeque::new();
        for (i, l) in text.lines().enumerate() {
            if let Some(line) = parse_line(i + 1, l)? {
                lines.push_back((i + 1, line));
            }
        }
        Ok(Self { lines, pending: VecDeque::new(), started: false })
    }

    pub fn done(&self) -> bool {
        self.started && self.lines.is_empty() && self.pending.is_empty()
    }

    /// This frame's events, added to `raw`; the step to finish once the frame is drawn.
    /// `shown`: a frame of the volume has reached the window. The lines wait for it, and then one
    /// frame more, so that they are resolved against the panel's settled layout (its statistics
    /// line appears with the first frame; a slow machine shows it later).
    pub fn step(&mut self, s: &mut State, raw: &mut RawInput, shown: bool) -> Result<Step> {
        if !self.started {
            self.started = shown;
            return Ok(Step::default());
        }
        if self.pending.is_empty() {
            if let Some((n, line)) = self.lines.pop_front() {
                self.pending = expand(n, line, s)?.into();
            }
        }
        let step = self.pending.pop_front().unwrap_or_default();
        raw.events.extend(step.events.iter().cloned());
        Ok(Step { events: Vec::new(), after: step.after })
    }
}

/// A line as frames, its positions resolved against the last frame's layout.
fn expand(n: usize, line: Line, s: &mut State) -> Result<Vec<Step>> {
    let missing = |what: &str| Error::InvalidArgument(format!("script line {n}: {what}"));
    let editor = || -> Result<(egui::Rect, &voxsplat::classify::TransferFunction, &voxsplat::bricks::Histogram)> {
        match (s.tf_editor.rect, &s.tf, &s.histogram) {
            (Some(r), Some(tf), Some(h)) => Ok((r, tf, h)),
            _ => Err(missing("no transfer-function editor (a --volume file opens one)")),
        }
    };
    let in_rect = |r: egui::Rect, f: Pos2| Pos2::new(r.left() + f.x * r.width(), r.top() + f.y * r.height());
    let point = |i: usize| -> Result<Pos2> {
        let (_, tf, h) = editor()?;
        s.tf_editor.point_pos(tf, h, i).ok_or_else(|| missing(&format!("the editor has no point {i}")))
    };
    Ok(match line {
        Line::Move(p) => vec![Step { events: vec![Event::PointerMoved(p)], after: None }],
        Line::Drag(a, b) => drag(a, b),
        Line::DragTf(i, to) => {
            let (rect, ..) = editor()?;
            // y: opacity, up the editor.
            drag(point(i)?, in_rect(rect, Pos2::new(to.x, 1.0 - to.y)))
        }
        Line::AddTf(at) => {
            let (rect, ..) = editor()?;
            let p = in_rect(rect, Pos2::new(at.x, 1.0 - at.y));
            let click = |pressed| button(p, PointerButton::Primary, pressed);
            vec![
                Step { events: vec![Event::PointerMoved(p)], after: None },
                Step { events: vec![click(true), click(false), click(true), click(false)], after: None },
            ]
        }
        Line::DeleteTf(i) => {
            let p = point(i)?;
            vec![
                Step { events: vec![Event::PointerMoved(p)], after: None },
                Step {
                    events: vec![button(p, PointerButton::Secondary, true), button(p, PointerButton::Secondary, false)],
                    after: None,
                },
            ]
        }
        Line::Key(key, shift) => {
            let modifiers = if shift { Modifiers::SHIFT } else { Modifiers::NONE };
            let k = |pressed| Event::Key { key, physical_key: None, pressed, repeat: false, modifiers };
            let (down, up) = (Event::ModifiersChanged(modifiers), Event::ModifiersChanged(Modifiers::NONE));
            vec![Step { events: vec![down, k(true)], after: None }, Step { events: vec![k(false), up], after: None }]
        }
        Line::Pick(f) => {
            let rect = s.view_rect.ok_or_else(|| missing("no view laid out"))?;
            let p = in_rect(rect, f);
            // One frame to move and pick, one to click (the crosshair follows) and report it.
            let click = |pressed| button(p, PointerButton::Primary, pressed);
            vec![
                Step { events: vec![Event::PointerMoved(p)], after: None },
                Step { events: vec![click(true), click(false)], after: Some(Line::Pick(f)) },
            ]
        }
        Line::Slice(axis, f) => {
            let rect =
                s.slices.as_ref().and_then(|c| c.rects[axis]).ok_or_else(|| missing("no slice pane laid out"))?;
            let p = in_rect(rect, f);
            let click = |pressed| button(p, PointerButton::Primary, pressed);
            vec![
                Step { events: vec![Event::PointerMoved(p)], after: None },
                Step { events: vec![click(true), click(false)], after: Some(Line::Slice(axis, f)) },
            ]
        }
        Line::Grip(grip, by) => {
            let (cam, rect) = (s.view_camera(), s.view_rect);
            let at = match (cam, rect, s.handle_shapes()) {
                (Some(cam), Some(rect), Some(h)) => {
                    h.grip_screen(&cam, grip).map(|p| rect.min + egui::vec2(p.x, p.y) / s.pixels_per_point)
                }
                _ => None,
            };
            let a = at.ok_or_else(|| missing(&format!("no grip {grip:?} in view (c: a plane, b: the crop box)")))?;
            drag(a, a + by)
        }
        Line::Label(value, on) => {
            match &mut s.parts {
                Some(Parts::Labels { table, .. }) => table.set_visible(value, on)?,
                _ => return Err(missing("no labels (--labels with --label-table)")),
            }
            s.reclassify = true;
            vec![Step::default()]
        }
        Line::Channel(i, on) => {
            match &mut s.parts {
                Some(Parts::Channels { channels, .. }) if i < channels.len() => channels[i].2 = on,
                _ => return Err(missing(&format!("no channel {i} (--channel files, a 4-D --volume)"))),
            }
            s.reclassify = true;
            vec![Step::default()]
        }
        Line::LoadTf(spec) => {
            s.tf_file = spec;
            s.tf_io = Some(super::state::TfIo::Load);
            vec![Step::default()]
        }
        Line::Wait(frames) => (0..frames).map(|_| Step::default()).collect(),
        // The next frame reads the window back.
        Line::Shot(path) => vec![Step { events: vec![], after: Some(Line::Shot(path)) }, Step::default()],
        other => vec![Step { events: vec![], after: Some(other) }],
    })
}

impl Step {
    /// After the frame: report a pick, save what was asked.
    /// `view` reads the volume's image back, when a line saves it.
    pub fn after(
        self,
        s: &mut State,
        cam: &Camera,
        view: impl FnOnce() -> Result<Vec<u8>>,
        size: (u32, u32),
    ) -> Result<()> {
        match self.after {
            Some(Line::Pick(_)) => {
                let crosshair = s.slices.as_ref().map(|c| format!("; crosshair {:?}", c.voxel)).unwrap_or_default();
                println!("pick: {}{crosshair}", s.hover.clone().unwrap_or_default().replace('\n', "; "));
            }
            Some(Line::Slice(..)) => {
                println!("slice: crosshair {:?}", s.slices.as_ref().map(|c| c.voxel));
            }
            Some(Line::State) => {
                let offsets: Vec<f32> = (0..s.clip_planes.len()).filter_map(|i| s.plane_offset(i)).collect();
                let crop = s.crop_fractions();
                println!("state: crop {crop:?}; plane offsets {offsets:?}; handle pixels {}", s.handle_pixels);
            }
            Some(Line::Shot(path)) => s.shot_now = Some(path),
            Some(Line::View(path)) => super::save_png(&path, size, view()?)?,
            Some(Line::Session(path)) => s.session(cam)?.save(&path)?,
            Some(Line::Tf(path)) => {
                super::save_tf(s, &path)?;
            }
            _ => {}
        }
        Ok(())
    }
}
