//! Long runs: render many frames with changing scenes, cameras and modes and watch host memory and
//! GPU allocations. The scene/mode sequence repeats every `CYCLE` frames, so after warm-up
//! the allocator's report at the start of each cycle must not grow.
use voxsplat::camera::Camera;
use voxsplat::kernel::KERNELS;
use voxsplat::options::{Antialias, Composite, RenderOptions};
use voxsplat::Result;
use voxsplat::{order::OrderKind, scene, Renderer};

/// Frames per repetition of the sequence.
pub const CYCLE: usize = 12;

/// What a soak run saw, sampled at the start of every cycle.
#[derive(Clone, Debug, Default)]
pub struct SoakReport {
    pub frames: usize,
    /// Host resident set size in bytes, per cycle.
    pub rss: Vec<u64>,
    /// (live allocations, bytes) from gpu-allocator, per cycle.
    pub gpu: Vec<(usize, u64)>,
    pub validation_messages: u64,
}

impl SoakReport {
    /// Host memory growth after warm-up: the peak RSS of the later half of the cycles minus the
    /// peak of the earlier half (the first cycle is warm-up). Peaks, not means, because the
    /// allocator returns memory to the system now and then: a leak raises the peak, a returned
    /// block only dips. Run with `MALLOC_MMAP_THRESHOLD_=131072 MALLOC_ARENA_MAX=1` (as `scripts/soak.sh` and the
    /// test do) so that large transient buffers are mapped and unmapped instead of fragmenting
    /// the heap, which otherwise adds steps of several MiB that are not leaks.
    pub fn rss_growth(&self) -> i64 {
        let after = self.rss.get(2..).unwrap_or(&[]);
        if after.len() < 2 {
            return 0;
        }
        let (a, b) = after.split_at(after.len() / 2);
        let peak = |x: &[u64]| x.iter().copied().max().unwrap_or(0) as i64;
        peak(b) - peak(a)
    }

    /// The median change of host RSS from one cycle to the next after warm-up, in bytes: a leak
    /// moves every cycle and shows here; a one-off step (a driver pool or allocator arena growing
    /// once, seen as +10-30 MiB in one cycle on loaded machines) moves only one and does not.
    pub fn rss_median_step(&self) -> i64 {
        let after = self.rss.get(2..).unwrap_or(&[]);
        let mut steps: Vec<i64> = after.windows(2).map(|w| w[1] as i64 - w[0] as i64).collect();
        if steps.is_empty() {
            return 0;
        }
        steps.sort_unstable();
        steps[steps.len() / 2]
    }

    /// Frames between the middles of the two halves that `rss_growth` compares.
    pub fn growth_span_frames(&self) -> usize {
        self.rss.len().saturating_sub(2) / 2 * CYCLE
    }
}

/// Resident set size of this process (Linux `/proc/self/statm`; 0 elsewhere).
pub fn rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1).and_then(|p| p.parse::<u64>().ok()))
        .map(|pages| pages * 4096)
        .unwrap_or(0)
}

/// Render `frames` frames of the repeating sequence at `size`×`size`.
pub fn soak(r: &mut Renderer, frames: usize, size: u32, mut progress: impl FnMut(usize)) -> Result<SoakReport> {
    let scenes = ["cube40", "plane", "cube40-attenuated"];
    let mut report = SoakReport { frames, ..Default::default() };
    let mut current = "";
    for f in 0..frames {
        if f % CYCLE == 0 {
            report.rss.push(rss_bytes());
            report.gpu.push(r.context().map(|c| c.allocation_report()).unwrap_or((0, 0)));
        }
        let step = f % CYCLE;
        let name = scenes[step / 4];
        if name != current {
            r.set_scene(scene::build(name)?)?;
            current = name;
        }
        let set = r.scene().expect("set above");
        let mut cam = Camera::framing(set.grid(), size, size);
        // Orbit the camera a little each frame; alternate the image size to exercise reallocation.
        let angle = step as f32 * 0.21;
        let off = cam.eye - cam.target;
        cam.eye = cam.target + glam::Quat::from_rotation_y(angle).mul_vec3(off);
        if step % 2 == 1 {
            cam.width = size + 8;
        }
        let opts = {
            let mut o = RenderOptions::default();
            o.order = [OrderKind::Pbtf, OrderKind::Wbtf][step % 2];
            o.composite = if step % 3 == 2 { Composite::Sheet } else { Composite::Splat };
            o.kernel = KERNELS[step / 2 % KERNELS.len()];
            o.antialias = [Antialias::None, Antialias::Swan, Antialias::Ewa][step % 3];
            o
        };
        r.render(&cam, &opts)?;
        progress(f);
    }
    report.validation_messages = r.validation_count();
    Ok(report)
}
