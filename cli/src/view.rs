//! `voxsplat view`: a window with the volume and a side panel (egui, drawn on voxsplat's own
//! device by `vk::Presenter`): modes and options, the transfer function over the data's
//! histogram, the value under the pointer, frame times, sessions and screenshots. A drag draws at
//! the render scale that holds the frame-time target; the full frame follows when it stops.
//! `--script` drives it headless (tests, under Xvfb) with synthetic pointer and key events.
use crate::scene_args::SceneArgs;
use crate::session::Session;
use clap::Args;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use voxsplat::bricks::Histogram;
use voxsplat::classify::Shading;
use voxsplat::vk::{OverlayFrame, PresentOptions, Presenter, Viewport};
use voxsplat::{options::Mode, Camera, Error, RenderOptions, Renderer, Result};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

mod handles;
mod load;
mod orbit;
mod pace;
mod panel;
mod script;
mod slices;
mod state;
mod tf_editor;

pub use orbit::Orbit;
pub use state::State;

/// The names the panel offers, as `render` takes them.
pub const ORDERS: &[&str] = &["pbtf", "wbtf", "btf", "pbtf-octant", "sorted"];
pub const COMPOSITES: &[&str] = &["splat", "sheet", "slab"];
pub const RASTERS: &[&str] = &["auto", "compute", "graphics", "points"];
pub const KERNELS: &[&str] = &["crawfis-max", "gaussian", "cubic", "narrow"];
/// A drag frame's bound on a coarse level's error (`RenderOptions::lod_error`): none that matters.
const DRAG_LOD_ERROR: f32 = voxsplat::options::MAX_LOD_ERROR;
/// The isosurface's first value (normalised).
const ISO_START: f32 = 0.3;
/// The window's least height in pixels: the panel's controls and editor fit.
const MIN_HEIGHT: u32 = 480;
/// A frame's long build (the levels of detail) shows its progress in the window once it has
/// taken this long (a short one would only flash past the panel).
const BUSY_AFTER_S: f64 = 1.0;
/// Bins of the editor's histogram.
const HISTOGRAM_BINS: u32 = 256;

#[derive(Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The side panel's width in points.
    #[arg(long, default_value = "340")]
    pub panel: f32,
    /// While the pointer drags the view, draw coarser frames (a lower render scale, coarser levels
    /// of detail) that keep the window's frame within this many milliseconds; the full frame
    /// follows when the drag stops.
    #[arg(long, default_value = "100")]
    pub drag_ms: f32,
    /// Present without waiting for the display's refresh.
    #[arg(long)]
    pub no_vsync: bool,
    /// Open a saved session (`s`, or a script's `session`) of the same --volume: its camera,
    /// transfer function, shading, mode and options.
    #[arg(long, requires = "volume", conflicts_with_all = ["eye", "target", "up", "fov", "ortho", "near", "far",
        "view", "tf", "shade"])]
    pub session: Option<PathBuf>,
    /// Run a script of synthetic pointer and key events, one line a frame, then exit (tests;
    /// docs/guide/cli.md lists its commands).
    #[arg(long)]
    pub script: Option<PathBuf>,
}

/// The flags the window loop reads.
struct Settings {
    panel: f32,
    drag_ms: f32,
    no_vsync: bool,
}

struct App {
    args: Settings,
    /// The scene flags: lent to the loading thread, then back.
    scene: Option<SceneArgs>,
    loading: Option<load::Loading>,
    window: Option<Arc<Window>>,
    egui: egui::Context,
    input: Option<egui_winit::State>,
    // The renderer goes before the presenter (whose device it uses).
    renderer: Option<Renderer>,
    presenter: Option<Presenter>,
    state: State,
    script: Option<script::Script>,
    /// The viewport of the last frame drawn, in pixels.
    drawn: Option<(Viewport, Camera, RenderOptions)>,
    /// Whether the view's image holds the clipping's handles (drawn under a still frame).
    view_has_handles: bool,
    /// Each frame drawn (`pace::FrameTime`).
    times: Vec<pace::FrameTime>,
    /// From the command's start to the first frame presented.
    started: Instant,
    first_frame: Option<f64>,
    failure: Option<Error>,
}

impl App {
    fn new(args: ViewArgs) -> Result<Self> {
        let ViewArgs { mut scene, panel, drag_ms, no_vsync, session, script } = args;
        let args = Settings { panel, drag_ms, no_vsync };
        let script = script.as_deref().map(script::Script::load).transpose()?;
        if !(args.panel.is_finite() && (120.0..=2000.0).contains(&args.panel)) {
            return Err(Error::InvalidArgument(format!("--panel {}: 120 to 2000 points", args.panel)));
        }
        if !(args.drag_ms.is_finite() && args.drag_ms > 0.0) {
            return Err(Error::InvalidArgument(format!("--drag-ms {}: a positive time", args.drag_ms)));
        }
        let mut options = RenderOptions::default();
        // Opaque black behind the volume: the window shows no transparency.
        options.background = Some([0.0, 0.0, 0.0, 1.0]);
        let kernel = options.kernel.name().to_string();
        let mut names = (scene.research.order.clone(), "splat".to_string(), "auto".to_string(), kernel);
        let (mut clip_planes, mut crop) = (Vec::new(), None);
        if let Some(path) = &session {
            if scene.volume.is_none() {
                return Err(Error::InvalidArgument("--session draws the --volume it was saved from: give it".into()));
            }
            let saved = Session::load(path)?;
            (options.mode, options.iso, options.lod) = (saved.mode.parse()?, saved.iso, saved.lod.parse()?);
            if saved.background[3] == 1.0 {
                options.background = Some(saved.background);
            }
            names = (saved.order.clone(), saved.composite.clone(), saved.raster.clone(), saved.kernel.clone());
            (clip_planes, crop) = saved.clipping();
            scene.session = Some(saved);
        }
        options.order = names.0.parse()?;
        let state = State::new(args.panel, options, names, (clip_planes, crop));
        Ok(Self {
            args,
            scene: Some(scene),
            loading: None,
            window: None,
            egui: egui::Context::default(),
            input: None,
            renderer: None,
            presenter: None,
            state,
            script,
            drawn: None,
            view_has_handles: false,
            times: Vec::new(),
            started: Instant::now(),
            first_frame: None,
            failure: None,
        })
    }

    /// The window (the view at --size, the panel beside it) and the device; the scene opens on a
    /// thread.
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let a = self.scene.take().expect("the scene flags until the start");
        // --size is the view's; the window is as tall as the panel needs at least.
        let (w, h) = a.size;
        let (width, h) = (w + self.args.panel.ceil() as u32, h.max(MIN_HEIGHT));
        let attributes = Window::default_attributes()
            .with_title("voxsplat")
            .with_inner_size(winit::dpi::PhysicalSize::new(width, h));
        let window = Arc::new(event_loop.create_window(attributes).map_err(|e| Error::Unsupported(e.to_string()))?);
        let size = window.inner_size();
        let options = PresentOptions {
            context: voxsplat::vk::ContextOptions { validation: a.validation, device_name: None },
            no_vsync: self.args.no_vsync,
        };
        let presenter = Presenter::new(window.clone(), (size.width, size.height), &options)?;
        self.renderer = Some(Renderer::with_context(presenter.context().clone())?);
        self.loading = Some(load::Loading::start(a, self.state.options.order != voxsplat::order::OrderKind::Pbtf));
        let input = egui_winit::State::new(
            self.egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        self.input = Some(input);
        self.presenter = Some(presenter);
        self.window = Some(window);
        Ok(())
    }

    /// While the file opens: its progress, until the thread hands the scene over.
    fn wait_for_load(&mut self, window: &Window) -> Result<bool> {
        let Some(loading) = &self.loading else { return Ok(true) };
        let renderer = self.renderer.as_mut().expect("made with the window");
        if let Some(a) = loading.poll(&mut self.state, renderer)? {
            self.scene = Some(a);
            self.loading = None;
            return Ok(true);
        }
        let input = self.input.as_mut().expect("made with the window");
        let presenter = self.presenter.as_mut().expect("made with the window");
        busy_frame(window, input, &self.egui, presenter, &format!("opening {}", loading.what), loading.fraction())?;
        std::thread::sleep(std::time::Duration::from_millis(30));
        window.request_redraw();
        Ok(false)
    }

    /// One frame: the panel, what it changed, the volume when something it shows changed, the
    /// overlay, the scripted steps.
    fn redraw(&mut self) -> Result<()> {
        let Some(window) = self.window.clone() else { return Ok(()) };
        if !self.wait_for_load(&window)? {
            return Ok(());
        }
        let frame_start = Instant::now();
        let input = self.input.as_mut().expect("made with the window");
        let mut raw = input.take_egui_input(&window);
        let shown = self.first_frame.is_some();
        let step = match &mut self.script {
            Some(script) => Some(script.step(&mut self.state, &mut raw, shown)?),
            None => None,
        };
        let state = &mut self.state;
        let store = self.renderer.as_ref().and_then(|r| r.volume()).map(|v| &v.store);
        let full = self.egui.run_ui(raw, |ui| panel::ui(ui, state, store));
        input.handle_platform_output(&window, full.platform_output);
        self.apply()?;
        let ppp = full.pixels_per_point;
        let mut painted = full.shapes;
        let presenter = self.presenter.as_mut().expect("started");
        let (ww, wh) = presenter.size();
        let Some(rect) = self.state.view_rect else { return Ok(()) };
        let x = ((rect.left() * ppp).round().max(0.0) as u32).min(ww.saturating_sub(1));
        let y = ((rect.top() * ppp).round().max(0.0) as u32).min(wh.saturating_sub(1));
        let viewport = Viewport {
            x,
            y,
            width: ((rect.width() * ppp).round() as u32).clamp(1, ww.saturating_sub(x).max(1)),
            height: ((rect.height() * ppp).round() as u32).clamp(1, wh.saturating_sub(y).max(1)),
        };
        if ww == 0 || wh == 0 {
            return Ok(());
        }
        let s = &mut self.state;
        let base = s.base.expect("started");
        let cam = s.orbit.camera(&base, s.centre().unwrap_or(base.target), s.radius, (viewport.width, viewport.height));
        let mut options = s.render_options()?;
        if s.dragging && !s.coarse_measured {
            // The first drag frame: as coarse as the last full frame's time says.
            s.coarse = pace::next_coarse(1.0, s.last_ms + s.overhead_ms, self.args.drag_ms as f64);
        }
        if s.dragging {
            // A drag frame: fewer pixels and fewer splats. The splats set the cost, and they come
            // in levels (each a quarter of the last), so the pixel bound moves with the scale.
            options.render_scale = (options.render_scale / s.coarse).max(0.25);
            options.lod_pixels = (options.lod_pixels * s.coarse).min(voxsplat::options::MAX_LOD_PIXELS);
            options.lod_error = options.lod_error.max(DRAG_LOD_ERROR);
        }
        let changed = s.dirty || self.drawn.as_ref().is_none_or(|d| d.0 != viewport || d.1 != cam || d.2 != options);
        let handles = s.handle_shapes();
        // The handles go under a still frame with their depth; the host's depth takes no lower
        // render scale (a drag frame's) and no sheets or slabs, which get them over the volume.
        let depth_path = handles.is_some()
            && options.render_scale == 1.0
            && options.composite == voxsplat::options::Composite::Splat
            && matches!(options.mode, Mode::Composite | Mode::Iso);
        let mut frame_options = options.clone();
        if let (true, true, Some(shapes)) = (changed, depth_path, &handles) {
            let layer = handles::Layer::draw(&cam, shapes, display_bytes(options.background.unwrap_or([0.0; 4])));
            frame_options.depth = Some(Arc::new(layer.depth_buffer(cam.proj())));
            frame_options.background = None;
            s.handle_pixels = layer.drawn;
            presenter.underlay((viewport.width, viewport.height), layer.rgba)?;
        }
        if changed {
            self.view_has_handles = depth_path;
        }
        if let (false, Some(h)) = (self.view_has_handles, &handles) {
            // Over the volume: in points, from the view's corner.
            let at = |p: voxsplat::glam::Vec2| rect.min + egui::vec2(p.x, p.y) / ppp;
            for ([a, b], c) in h.screen_lines(&cam) {
                let stroke =
                    egui::Stroke::new(2.0 / ppp, egui::Color32::from_rgba_premultiplied(c[0], c[1], c[2], c[3]));
                painted.push(egui::epaint::ClippedShape {
                    clip_rect: rect,
                    shape: egui::Shape::line_segment([at(a), at(b)], stroke),
                });
            }
        }
        let primitives = self.egui.tessellate(painted, ppp);
        let renderer = self.renderer.as_mut().expect("started");
        let input = self.input.as_mut().expect("made with the window");
        let mut ms = None;
        let mut delivered = None;
        if changed {
            // Drawn outside the window's frame: a long build of the levels of detail presents
            // frames of its own, with its progress.
            let target = presenter.view_target((viewport.width, viewport.height))?;
            let start = Instant::now();
            let mut busy = 0.0;
            let mut progress = |done: u64, of: u64| -> Result<()> {
                if start.elapsed().as_secs_f64() < BUSY_AFTER_S || done >= of {
                    return Ok(());
                }
                let t = Instant::now();
                let what = format!("building the levels of detail: {done} of {of} bricks");
                busy_frame(&window, input, &self.egui, presenter, &what, Some(done as f32 / of as f32))?;
                busy += t.elapsed().as_secs_f64() * 1e3;
                Ok(())
            };
            delivered = Some(renderer.render_to_with_progress(&cam, &frame_options, &target, &mut progress)?);
            ms = Some(start.elapsed().as_secs_f64() * 1e3 - busy);
        }
        let overlay = OverlayFrame { primitives: &primitives, textures: &full.textures_delta, pixels_per_point: ppp };
        let read_back = s.shot_now.is_some();
        let clear = [0.0, 0.0, 0.0, 1.0];
        let presented = presenter.frame(Some(viewport), clear, None, &overlay, read_back)?;
        if !presented.shown {
            presenter.resize((window.inner_size().width, window.inner_size().height))?;
            self.drawn = None;
            return Ok(());
        }
        if let Some(ms) = ms {
            s.last_ms = ms;
            self.times.push((ms, s.dragging.then_some(options.render_scale), ms));
            if self.first_frame.is_none() {
                self.first_frame = Some(self.started.elapsed().as_secs_f64());
            }
            s.stats = delivered.as_ref().map(frame_summary).unwrap_or_default();
            s.dirty = false;
            if s.dragging {
                // Hold the target: coarser when over it, finer when well under.
                // The window's own share (the panel, the overlay, the present) counts too.
                s.coarse = pace::next_coarse(s.coarse, ms + s.overhead_ms, self.args.drag_ms as f64);
                s.coarse_measured = true;
            }
            self.drawn = Some((viewport, cam, options.clone()));
        }
        if let (Some(path), Some(rgba)) = (s.shot_now.take(), presented.window_rgba) {
            save_png(&path, presenter.size(), rgba)?;
            s.message = format!("saved {}", path.display());
        }
        // The value under the pointer, for the next frame's panel (picked again only when the
        // pointer or the camera moved).
        let at = s.pointer.filter(|_| !s.dragging).map(|p| (p, cam));
        if at != s.picked_at {
            s.picked_at = at;
            let pick = at.map(|(p, _)| {
                let (px, py) = (p.x * ppp, p.y * ppp);
                renderer.pick(&cam, &options, px.min(cam.width as f32), py.min(cam.height as f32))
            });
            s.hover_voxel = match &pick {
                Some(Ok(Some(p))) => Some(p.voxel),
                _ => None,
            };
            let hover = pick.map(|p| match p {
                Ok(Some(pick)) => pick_text(&pick, s.histogram.as_ref()),
                Ok(None) => "(nothing under the pointer)".into(),
                Err(e) => e.to_string(),
            });
            if hover != s.hover {
                s.hover = hover;
                window.request_redraw();
            }
        }
        if std::mem::take(&mut s.clicked) {
            if let (Some(v), Some(slices)) = (s.hover_voxel, &mut s.slices) {
                slices.voxel = v;
                window.request_redraw();
            }
        }
        if let Some(step) = step {
            step.after(s, &cam, || presenter.read_view(), (viewport.width, viewport.height))?;
        }
        let repaint = full.viewport_output.get(&egui::ViewportId::ROOT).is_some_and(|v| v.repaint_delay.is_zero());
        if s.dirty || repaint || self.script.as_ref().is_some_and(|s| !s.done()) {
            window.request_redraw();
        }
        if self.script.as_ref().is_some_and(|s| s.done()) {
            self.state.quit = true;
        }
        if ms.is_some() {
            // The whole window frame: the panel, the volume, the overlay, the present.
            if let Some(last) = self.times.last_mut() {
                last.2 = frame_start.elapsed().as_secs_f64() * 1e3;
                self.state.overhead_ms = (last.2 - last.0).max(0.0);
            }
        }
        Ok(())
    }

    /// What the panel asked for that the renderer does: the transfer function and shading, a time
    /// point, saving.
    fn apply(&mut self) -> Result<()> {
        let s = &mut self.state;
        let renderer = self.renderer.as_mut().expect("started");
        match s.tf_io.take() {
            Some(state::TfIo::Load) => match crate::open::load_tf(s.tf_file.trim()) {
                Ok(tf) => {
                    s.message = format!("loaded {}", s.tf_file.trim());
                    s.tf = Some(tf);
                    s.tf_editor.selected = None;
                    s.tf_changed = true;
                }
                Err(e) => s.message = e.to_string(),
            },
            Some(state::TfIo::Save) => {
                let file = PathBuf::from(s.tf_file.trim());
                s.message = save_tf(s, &file).unwrap_or_else(|e| e.to_string());
            }
            None => {}
        }
        if std::mem::take(&mut s.tf_changed) {
            if s.shading_on && s.light.is_none() {
                // A headlight along the current view.
                if let Some(base) = &s.base {
                    let cam =
                        s.orbit.camera(base, s.centre().unwrap_or(base.target), s.radius, (base.width, base.height));
                    s.light = Some(Shading::headlight(cam.target - cam.eye));
                }
            }
            if let Some(tf) = &s.tf {
                renderer.set_transfer_function(tf, s.shading())?;
            }
            s.dirty = true;
        }
        if std::mem::take(&mut s.reclassify) {
            if let Some(parts) = &s.parts {
                let set = parts.classify(false)?;
                s.message = format!("classified again: {} splats", set.len());
                renderer.set_scene(set)?;
                s.dirty = true;
            }
        }
        if let (Some(t), Some((series, at))) = (s.time_to.take(), &mut s.series) {
            let u = renderer.update_volume(series.store(t)?)?;
            *at = t;
            s.message = format!("time point {t}: {} bricks changed", u.changed);
            s.dirty = true;
        }
        if std::mem::take(&mut s.save_now) {
            s.message = match self.drawn.as_ref().map(|d| s.session(&d.1)) {
                Some(Ok(session)) => {
                    session.save(std::path::Path::new("view-session.toml"))?;
                    save_tf(s, std::path::Path::new("view-tf.toml"))
                        .map_or_else(|e| e.to_string(), |m| format!("saved view-session.toml, {m}"))
                }
                Some(Err(e)) => e.to_string(),
                None => "nothing drawn yet".into(),
            };
        }
        Ok(())
    }
}

/// Save the transfer function as the TOML `render --tf` reads; what the panel says of it.
pub(super) fn save_tf(s: &State, file: &std::path::Path) -> Result<String> {
    let tf = s.tf.as_ref().ok_or_else(|| Error::InvalidArgument("no transfer function to save".into()))?;
    std::fs::write(file, tf.to_toml()?).map_err(|e| Error::Io { path: file.display().to_string(), source: e })?;
    Ok(format!("saved {}", file.display()))
}

/// A window frame while the window waits: what for and how far it has got, nothing else.
fn busy_frame(
    window: &Window,
    input: &mut egui_winit::State,
    egui: &egui::Context,
    presenter: &mut Presenter,
    what: &str,
    fraction: Option<f32>,
) -> Result<()> {
    let raw = input.take_egui_input(window);
    let full = egui.run_ui(raw, |ui| {
        egui::CentralPanel::default().show(ui, |ui| {
            ui.heading(what);
            match fraction {
                Some(f) => ui.add(egui::ProgressBar::new(f).show_percentage()),
                None => ui.spinner(),
            };
        });
    });
    input.handle_platform_output(window, full.platform_output);
    let primitives = egui.tessellate(full.shapes, full.pixels_per_point);
    let overlay = OverlayFrame {
        primitives: &primitives,
        textures: &full.textures_delta,
        pixels_per_point: full.pixels_per_point,
    };
    presenter.frame(None, [0.0, 0.0, 0.0, 1.0], None, &overlay, false)?;
    Ok(())
}

/// The stages that took the most of the frame (ms), and what a bricked volume's frame drew.
fn frame_summary(d: &voxsplat::options::Delivered) -> String {
    let mut t: Vec<_> = d.timings.iter().filter(|s| s.ms > 0.0).collect();
    t.sort_by(|a, b| b.ms.total_cmp(&a.ms));
    let stages = t.iter().take(4).map(|s| format!("{} {:.1}", s.stage, s.ms)).collect::<Vec<_>>().join(", ");
    let st = &d.stats;
    if st.bricks == 0 {
        return stages;
    }
    format!(
        "{stages}\n{} splats from {} of {} bricks ({} coarser, {} hidden by nearer ones)",
        st.splats, st.bricks_visible, st.bricks, st.bricks_coarse, st.bricks_hidden
    )
}

/// The pick as the panel shows it: the raw value where the store's range is known.
fn pick_text(p: &voxsplat::Pick, h: Option<&Histogram>) -> String {
    let raw = h.map(|h| h.range.0 + p.value * (h.range.1 - h.range.0));
    let value = match raw {
        Some(r) => format!("value {r:.4} ({:.3} of the range)", p.value),
        None => format!("value {:.3}", p.value),
    };
    format!(
        "{value}\nvoxel {} {} {}, at {:.2} {:.2} {:.2}",
        p.voxel[0], p.voxel[1], p.voxel[2], p.world.x, p.world.y, p.world.z
    )
}

/// A premultiplied linear colour as the display's bytes (sRGB-encoded, premultiplied).
fn display_bytes(c: [f32; 4]) -> [u8; 4] {
    let a = c[3].clamp(0.0, 1.0);
    let encode = |v: f32| {
        let l = if a > 0.0 { (v / a).clamp(0.0, 1.0) } else { 0.0 };
        (voxsplat::low_level::to_srgb(l) * a * 255.0).round() as u8
    };
    [encode(c[0]), encode(c[1]), encode(c[2]), (a * 255.0).round() as u8]
}

pub(super) fn save_png(path: &std::path::Path, size: (u32, u32), rgba: Vec<u8>) -> Result<()> {
    let img = image::RgbaImage::from_raw(size.0, size.1, rgba)
        .ok_or_else(|| Error::InvalidArgument("a screenshot of the wrong size".into()))?;
    img.save(path).map_err(|e| Error::Image { path: path.display().to_string(), message: e.to_string() })
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() {
            if let Err(e) = self.start(event_loop) {
                self.failure = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let (Some(window), Some(input)) = (&self.window, &mut self.input) else { return };
        let response = input.on_window_event(window, &event);
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                self.drawn = None;
                self.presenter.as_mut().map_or(Ok(()), |p| p.resize((size.width, size.height)))
            }
            WindowEvent::RedrawRequested => self.redraw(),
            _ => Ok(()),
        };
        if response.repaint {
            if let Some(w) = &self.window {
                w.request_redraw();
            }
        }
        if let Err(e) = result {
            self.failure = Some(e);
            event_loop.exit();
        }
        if self.state.quit {
            event_loop.exit();
        }
    }
}

/// `voxsplat view`.
pub fn view(args: ViewArgs) -> Result<()> {
    if args.scene.cpu {
        return Err(Error::InvalidArgument("view draws on a Vulkan device: --cpu does not apply".into()));
    }
    let mut app = App::new(args)?;
    let event_loop = EventLoop::new().map_err(|e| Error::Unsupported(format!("no window system: {e}")))?;
    event_loop.run_app(&mut app).map_err(|e| Error::Unsupported(e.to_string()))?;
    let validation =
        app.renderer.as_ref().and_then(|r| r.context()).map(|c| (c.validation_count(), c.validation_messages()));
    app.renderer = None;
    app.presenter = None;
    if let Some(e) = app.failure.take() {
        return Err(e);
    }
    if let Some(first) = app.first_frame {
        println!("first frame {first:.2} s after the start (the file read, the device made, the frame drawn)");
    }
    for line in pace::summary(&app.times, app.args.drag_ms as f64) {
        println!("{line}");
    }
    if let Some((n, messages)) = validation.filter(|v| v.0 > 0) {
        for m in messages {
            eprintln!("{m}");
        }
        return Err(Error::Unsupported(format!("{n} validation message(s)")));
    }
    Ok(())
}
