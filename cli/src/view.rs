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
use voxsplat::classify::{Shading, TransferFunction};
use voxsplat::vk::{OverlayFrame, PresentOptions, Presenter, Viewport};
use voxsplat::{Camera, Error, Mode, RenderOptions, Renderer, Result};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

mod orbit;
mod panel;
mod script;
mod tf_editor;

pub use orbit::Orbit;

/// The names the panel offers, as `render` takes them.
pub const ORDERS: &[&str] = &["pbtf", "wbtf", "btf", "pbtf-octant", "sorted"];
pub const COMPOSITES: &[&str] = &["splat", "sheet", "slab"];
pub const RASTERS: &[&str] = &["auto", "compute", "graphics", "points"];
pub const KERNELS: &[&str] = &["crawfis-max", "gaussian", "cubic", "narrow"];
/// The isosurface's first value (normalised).
const ISO_START: f32 = 0.3;
/// The window's least height in pixels: the panel's controls and editor fit.
const MIN_HEIGHT: u32 = 480;
/// Bins of the editor's histogram.
const HISTOGRAM_BINS: u32 = 256;

#[derive(Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The side panel's width in points.
    #[arg(long, default_value = "340")]
    pub panel: f32,
    /// While the pointer drags the view, draw at the render scale that keeps a frame within this
    /// many milliseconds (down to a quarter of the size); the full frame follows when it stops.
    #[arg(long, default_value = "100")]
    pub drag_ms: f32,
    /// Present without waiting for the display's refresh.
    #[arg(long)]
    pub no_vsync: bool,
    /// Run a script of synthetic pointer and key events, one line a frame, then exit (tests;
    /// docs/guide/cli.md lists its commands).
    #[arg(long)]
    pub script: Option<PathBuf>,
}

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
    /// The light the volume opened with (or a headlight made when shading is first turned on).
    pub light: Option<Shading>,
    pub shading_on: bool,
    pub series: Option<(crate::series::Series, u32)>,
    /// The pointer over the view, in points from its top left corner.
    pub pointer: Option<egui::Vec2>,
    pub hover: Option<String>,
    pub view_rect: Option<egui::Rect>,
    pub last_ms: f64,
    pub stats: String,
    pub message: String,
    /// The render scale a drag draws at (adapted to `drag_ms`).
    pub scale: f32,
    pub dragging: bool,
    pub help: bool,
    // What the window loop does after the panel ran.
    pub dirty: bool,
    pub tf_changed: bool,
    pub time_to: Option<u32>,
    pub save_now: bool,
    pub shot_now: Option<PathBuf>,
    pub quit: bool,
}

impl State {
    /// A mode, with the iso value it needs.
    pub fn set_mode(&mut self, mode: Mode) {
        self.options.mode = mode;
        self.options.iso = (mode == Mode::Iso).then_some(self.options.iso.unwrap_or(ISO_START));
        self.dirty = true;
    }

    pub fn home(&mut self) {
        self.orbit = Orbit::HOME;
        self.dirty = true;
    }

    /// The options the panel's names stand for.
    fn render_options(&self) -> Result<RenderOptions> {
        let mut o = self.options.clone();
        o.order = self.order.parse()?;
        o.composite = self.composite.parse()?;
        o.raster = self.raster.parse()?;
        o.kernel = self.kernel.parse()?;
        if o.mode != Mode::Composite {
            // As `render`: a projection draws in no visibility order and at full detail.
            (o.order, o.lod) = (voxsplat::OrderKind::Pbtf, voxsplat::Lod::Off);
        }
        o.validate()?;
        Ok(o)
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
            lod: if projection || o.lod == voxsplat::Lod::Off { "off".into() } else { "auto".into() },
            kernel: self.kernel.clone(),
            background: o.background.unwrap_or([0.0; 4]),
            camera: Session::view_of(cam),
            light: Session::light_of(self.shading()),
            tf,
        })
    }

    fn shading(&self) -> Option<Shading> {
        if self.shading_on {
            self.light
        } else {
            None
        }
    }
}

struct App {
    args: ViewArgs,
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
    times: Vec<f64>,
    failure: Option<Error>,
}

impl App {
    fn new(args: ViewArgs) -> Result<Self> {
        let script = args.script.as_deref().map(script::Script::load).transpose()?;
        if !(args.panel.is_finite() && (120.0..=2000.0).contains(&args.panel)) {
            return Err(Error::InvalidArgument(format!("--panel {}: 120 to 2000 points", args.panel)));
        }
        if !(args.drag_ms.is_finite() && args.drag_ms > 0.0) {
            return Err(Error::InvalidArgument(format!("--drag-ms {}: a positive time", args.drag_ms)));
        }
        let mut options = RenderOptions::default();
        options.order = args.scene.order.parse()?;
        // Opaque black behind the volume: the window shows no transparency.
        options.background = Some([0.0, 0.0, 0.0, 1.0]);
        let state = State {
            title: String::new(),
            panel_width: args.panel,
            base: None,
            radius: 1.0,
            orbit: Orbit::HOME,
            options,
            order: args.scene.order.clone(),
            composite: "splat".into(),
            raster: "auto".into(),
            kernel: "crawfis-max".into(),
            tf: None,
            histogram: None,
            tf_editor: Default::default(),
            light: None,
            shading_on: false,
            series: None,
            pointer: None,
            hover: None,
            view_rect: None,
            last_ms: 0.0,
            stats: String::new(),
            message: String::new(),
            scale: 1.0,
            dragging: false,
            help: false,
            dirty: true,
            tf_changed: false,
            time_to: None,
            save_now: false,
            shot_now: None,
            quit: false,
        };
        Ok(Self {
            args,
            window: None,
            egui: egui::Context::default(),
            input: None,
            renderer: None,
            presenter: None,
            state,
            script,
            drawn: None,
            times: Vec::new(),
            failure: None,
        })
    }

    /// The window (the view at --size, the panel beside it), the device, the scene.
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        // --size is the view's; the window is as tall as the panel needs at least.
        let (w, h) = self.args.scene.size;
        let (width, h) = (w + self.args.panel.ceil() as u32, h.max(MIN_HEIGHT));
        let attributes = Window::default_attributes()
            .with_title("voxsplat")
            .with_inner_size(winit::dpi::PhysicalSize::new(width, h));
        let window = Arc::new(event_loop.create_window(attributes).map_err(|e| Error::Unsupported(e.to_string()))?);
        let size = window.inner_size();
        let options = PresentOptions {
            context: voxsplat::vk::ContextOptions { validation: self.args.scene.validation, device_name: None },
            no_vsync: self.args.no_vsync,
        };
        let presenter = Presenter::new(window.clone(), (size.width, size.height), &options)?;
        let mut renderer = Renderer::with_context(presenter.context().clone())?;
        let a = &self.args.scene;
        let s = &mut self.state;
        let series = a.volume.as_ref().filter(|_| a.time.is_none()).map(|p| voxsplat::loaders::time_points(p));
        let (bricked, set, content) = if series.transpose()?.is_some_and(|t| t > 1) {
            let series = crate::series::Series::open(a)?;
            let scene = series.scene(a, 0)?;
            let content = crate::open::Content { orientation: series.orientation(), bounds: scene.visible_bounds() };
            let set = voxsplat::SplatSet::empty(scene.store.grid()?)?;
            s.series = Some((series, 0));
            (Some(scene), set, content)
        } else {
            crate::open::open(a, s.options.order != voxsplat::OrderKind::Pbtf)?
        };
        let grid = *set.grid();
        match bricked {
            Some(b) => {
                s.histogram = Some(b.store.histogram(HISTOGRAM_BINS)?);
                s.tf = Some(b.transfer_function().clone());
                s.light = b.shading();
                s.shading_on = s.light.is_some();
                let d = b.store.dims;
                s.title = format!("{} x {} x {} voxels on {}", d[0], d[1], d[2], renderer.device_name());
                renderer.set_bricks(b)?;
            }
            None => {
                s.title = format!("{} splats on {}", set.len(), renderer.device_name());
                renderer.set_scene(set)?;
            }
        }
        s.base = Some(crate::open::camera_of(a, &grid, &content)?);
        s.radius = 0.5 * grid.diagonal() + 4.0 * grid.kernel_spacing();
        let viewport_id = egui::ViewportId::ROOT;
        let input = egui_winit::State::new(
            self.egui.clone(),
            viewport_id,
            &window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        self.input = Some(input);
        self.renderer = Some(renderer);
        self.presenter = Some(presenter);
        self.window = Some(window);
        Ok(())
    }

    /// One frame: the panel, what it changed, the volume when something it shows changed, the
    /// overlay, the scripted steps.
    fn redraw(&mut self) -> Result<()> {
        let Some(window) = self.window.clone() else { return Ok(()) };
        let input = self.input.as_mut().expect("made with the window");
        let mut raw = input.take_egui_input(&window);
        let step = match &mut self.script {
            Some(script) => Some(script.step(&self.state, &mut raw)?),
            None => None,
        };
        let state = &mut self.state;
        let full = self.egui.run_ui(raw, |ui| panel::ui(ui, state));
        input.handle_platform_output(&window, full.platform_output);
        self.apply()?;
        let ppp = full.pixels_per_point;
        let primitives = self.egui.tessellate(full.shapes, ppp);
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
        let cam = s.orbit.camera(&base, s.radius, (viewport.width, viewport.height));
        let mut options = s.render_options()?;
        if s.dragging {
            options.render_scale = options.render_scale.min(s.scale);
        }
        let changed = s.dirty || self.drawn.as_ref().is_none_or(|d| d.0 != viewport || d.1 != cam || d.2 != options);
        let renderer = self.renderer.as_mut().expect("started");
        let mut ms = None;
        let mut timings = Vec::new();
        let mut draw = |t: &voxsplat::vk::HostTarget| {
            let start = Instant::now();
            let delivered = renderer.render_to(&cam, &options, t)?;
            ms = Some(start.elapsed().as_secs_f64() * 1e3);
            timings = delivered.timings;
            Ok(())
        };
        let overlay = OverlayFrame { primitives: &primitives, textures: &full.textures_delta, pixels_per_point: ppp };
        let read_back = s.shot_now.is_some();
        let clear = [0.0, 0.0, 0.0, 1.0];
        let draw: Option<voxsplat::vk::DrawView<'_>> = if changed { Some(&mut draw) } else { None };
        let presented = presenter.frame(viewport, clear, draw, &overlay, read_back)?;
        if !presented.shown {
            presenter.resize((window.inner_size().width, window.inner_size().height))?;
            self.drawn = None;
            return Ok(());
        }
        if let Some(ms) = ms {
            s.last_ms = ms;
            self.times.push(ms);
            s.stats = stage_summary(&timings);
            s.dirty = false;
            if s.dragging {
                // Hold the target: the cost goes roughly with the pixels drawn.
                let ratio = (self.args.drag_ms as f64 / ms).sqrt() as f32;
                s.scale = (options.render_scale * ratio).clamp(0.25, 1.0);
            }
            self.drawn = Some((viewport, cam, options.clone()));
        }
        if let (Some(path), Some(rgba)) = (s.shot_now.take(), presented.window_rgba) {
            save_png(&path, presenter.size(), rgba)?;
            s.message = format!("saved {}", path.display());
        }
        // The value under the pointer, for the next frame's panel.
        let hover = match s.pointer {
            Some(p) if !s.dragging => {
                let (px, py) = (p.x * ppp, p.y * ppp);
                match renderer.pick(&cam, &options, px.min(cam.width as f32), py.min(cam.height as f32)) {
                    Ok(Some(pick)) => Some(pick_text(&pick, s.histogram.as_ref(), s.tf.as_ref())),
                    Ok(None) => Some("(nothing under the pointer)".into()),
                    Err(e) => Some(e.to_string()),
                }
            }
            _ => None,
        };
        if hover != s.hover {
            s.hover = hover;
            window.request_redraw();
        }
        if let Some(step) = step {
            let view = presenter.read_view();
            step.after(s, &cam, view, (viewport.width, viewport.height))?;
        }
        let repaint = full.viewport_output.get(&egui::ViewportId::ROOT).is_some_and(|v| v.repaint_delay.is_zero());
        if s.dirty || repaint || self.script.as_ref().is_some_and(|s| !s.done()) {
            window.request_redraw();
        }
        if self.script.as_ref().is_some_and(|s| s.done()) {
            self.state.quit = true;
        }
        Ok(())
    }

    /// What the panel asked for that the renderer does: the transfer function and shading, a time
    /// point, saving.
    fn apply(&mut self) -> Result<()> {
        let s = &mut self.state;
        let renderer = self.renderer.as_mut().expect("started");
        if std::mem::take(&mut s.tf_changed) {
            if s.shading_on && s.light.is_none() {
                // A headlight along the current view.
                if let Some(base) = &s.base {
                    let cam = s.orbit.camera(base, s.radius, (base.width, base.height));
                    s.light = Some(Shading::headlight(cam.target - cam.eye));
                }
            }
            if let Some(tf) = &s.tf {
                renderer.set_transfer_function(tf, s.shading())?;
            }
            s.dirty = true;
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
                    "saved view-session.toml".into()
                }
                Some(Err(e)) => e.to_string(),
                None => "nothing drawn yet".into(),
            };
        }
        Ok(())
    }
}

/// The stages that took the most of the frame.
fn stage_summary(timings: &[voxsplat::StageTime]) -> String {
    let mut t: Vec<_> = timings.iter().filter(|s| s.ms > 0.0).collect();
    t.sort_by(|a, b| b.ms.total_cmp(&a.ms));
    t.iter().take(4).map(|s| format!("{} {:.1}", s.stage, s.ms)).collect::<Vec<_>>().join(", ")
}

/// The pick as the panel shows it: the raw value where the store's range is known.
fn pick_text(p: &voxsplat::Pick, h: Option<&Histogram>, _tf: Option<&TransferFunction>) -> String {
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

fn save_png(path: &std::path::Path, size: (u32, u32), rgba: Vec<u8>) -> Result<()> {
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
    let mut times = app.times.clone();
    if !times.is_empty() {
        times.sort_by(f64::total_cmp);
        println!("{} frames drawn, median {:.1} ms", times.len(), times[times.len() / 2]);
    }
    if let Some((n, messages)) = validation.filter(|v| v.0 > 0) {
        for m in messages {
            eprintln!("{m}");
        }
        return Err(Error::Unsupported(format!("{n} validation message(s)")));
    }
    Ok(())
}
