//! Opening the file on a thread while the window shows how far the read has got; then handing
//! the scene to the renderer and the panel.
use super::{slices, State, HISTOGRAM_BINS};
use crate::open::Content;
use crate::scene_args::SceneArgs;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError};
use std::sync::Arc;
use voxsplat::bricks::{BrickScene, Histogram};
use voxsplat::{Error, Renderer, Result, SplatSet};

/// What the thread opened.
struct Opened {
    bricked: Option<(BrickScene, Histogram)>,
    set: SplatSet,
    content: Content,
    series: Option<crate::series::Series>,
    parts: Option<crate::open::Parts>,
}

/// A file being opened: the bytes read so far, of how many, and the thread's answer (with the
/// scene flags, which it borrowed).
pub struct Loading {
    pub what: String,
    read: Arc<(AtomicU64, AtomicU64)>,
    answer: Receiver<(SceneArgs, Result<Opened>)>,
}

fn open(a: &SceneArgs, host_splats: bool) -> Result<Opened> {
    let series = a.volume.as_ref().filter(|_| a.time.is_none()).map(|p| voxsplat::loaders::time_points(p));
    if series.transpose()?.is_some_and(|t| t > 1) {
        let series = crate::series::Series::open(a)?;
        let scene = series.scene(a, 0)?;
        let content = Content { orientation: series.orientation(), bounds: scene.visible_bounds() };
        let set = SplatSet::empty(scene.store.grid()?)?;
        let histogram = scene.store.histogram(HISTOGRAM_BINS)?;
        return Ok(Opened { bricked: Some((scene, histogram)), set, content, series: Some(series), parts: None });
    }
    if a.labels.is_some() || !a.channels.is_empty() || !a.channel_tfs.is_empty() {
        // Kept whole, for the panel to show or hide a label or a channel.
        let (set, content, parts) = crate::open::load_scene_parts(a)?;
        return Ok(Opened { bricked: None, set, content, series: None, parts });
    }
    let (bricked, set, content) = crate::open::open(a, host_splats)?;
    let bricked = bricked.map(|b| b.store.histogram(HISTOGRAM_BINS).map(|h| (b, h))).transpose()?;
    Ok(Opened { bricked, set, content, series: None, parts: None })
}

impl Loading {
    /// Open what `a` names on a thread.
    pub fn start(mut a: SceneArgs, host_splats: bool) -> Self {
        let what = a
            .volume
            .as_ref()
            .or(a.terrain.as_ref())
            .map(|p| p.display().to_string())
            .unwrap_or_else(|| format!("the {} scene", a.scene));
        let read = Arc::new((AtomicU64::new(0), AtomicU64::new(0)));
        let moved = read.clone();
        a.progress = Some(voxsplat::loaders::Progress::new(move |done, of| {
            moved.0.store(done, Ordering::Relaxed);
            moved.1.store(of, Ordering::Relaxed);
        }));
        let (tx, answer) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let opened = open(&a, host_splats);
            let _ = tx.send((a, opened));
        });
        Self { what, read, answer }
    }

    /// The fraction read (None: not known yet).
    pub fn fraction(&self) -> Option<f32> {
        let (done, of) = (self.read.0.load(Ordering::Relaxed), self.read.1.load(Ordering::Relaxed));
        (of > 0).then(|| (done as f64 / of as f64).min(1.0) as f32)
    }

    /// The scene once the thread is done: handed to `renderer` and the panel; the scene flags back.
    pub fn poll(&self, s: &mut State, renderer: &mut Renderer) -> Result<Option<SceneArgs>> {
        let (mut a, opened) = match self.answer.try_recv() {
            Ok(answer) => answer,
            Err(TryRecvError::Empty) => return Ok(None),
            Err(TryRecvError::Disconnected) => {
                return Err(Error::Unsupported(format!("opening {} stopped without an answer", self.what)))
            }
        };
        a.progress = None;
        let Opened { bricked, set, content, series, parts } = opened?;
        s.parts = parts;
        let grid = *set.grid();
        match bricked {
            Some((b, histogram)) => {
                s.histogram = Some(histogram);
                s.slices = Some(slices::Slices::new(b.store.dims));
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
        s.series = series.map(|x| (x, 0));
        s.base = Some(crate::open::camera_of(&a, &grid, &content)?);
        s.grid = Some(grid);
        s.radius = 0.5 * grid.diagonal() + 4.0 * grid.kernel_spacing();
        s.dirty = true;
        Ok(Some(a))
    }
}
