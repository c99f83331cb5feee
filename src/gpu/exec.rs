//! The Vulkan engine: runs a frame's recording (`crate::stages`). Commands queue up until the
//! recording reads something back, then go in one submission; each stage is timed.
use super::resources::Target;
use super::Gpu;
use crate::dispatch::{Kind, Pass, Res};
use crate::error::{Error, Result};
use crate::gpu_types::Frame;
use crate::kernel::Kernel;
use crate::options::add_time;
use crate::options::StageTime;
use crate::plan::Prepared;
use crate::stages::{Dispatch, Engine, Limits};
use crate::vk::{Buffer, BufferUsageFlags as BU, HostTarget, Image, ImageLayout as IL, Recorder, Stage, Timer};
use std::collections::BTreeSet;
use std::time::Instant;

enum Cmd {
    Run(Dispatch),
    Fill(Res, Option<(u64, u64)>, u32),
    Upload(Res, Buffer),
    /// Copy regions (source, destination, size in bytes) of a staging buffer into a resource.
    UploadRegions(Res, Buffer, Vec<[u64; 3]>),
    /// Copy the first bytes of a resource to its readback buffer.
    Copy(Res, u64),
    /// Blit the accumulation image into the host's image (`GpuEngine::target`).
    Blit,
    /// Copy the host's depth image into a resource.
    CopyDepth(Res),
    /// Copy the host's image, as the frame finds it, into a resource (`HostTarget::over`).
    CopyColor(Res),
}

/// The Vulkan engine of one frame.
pub struct GpuEngine<'a> {
    gpu: &'a mut Gpu,
    prep: &'a Prepared,
    /// Commands and the timing they count towards ("" for transfers, which join the next stage).
    pending: Vec<(&'static str, Cmd)>,
    timings: Vec<StageTime>,
    live: BTreeSet<Res>,
    width: u32,
    height: u32,
    layers: u32,
    /// Where the accumulation image, the summation layers and the raster target stand.
    layouts: [IL; 3],
    /// The host's image the frame goes to (`Renderer::render_to`), if any.
    target: Option<&'a HostTarget>,
    /// The host's hook told how far a long build has got (`Engine::progress`).
    progress: Option<&'a mut dyn FnMut(u64, u64) -> Result<()>>,
}

impl<'a> GpuEngine<'a> {
    /// An engine for a frame of `prep` on `gpu`.
    pub fn new(gpu: &'a mut Gpu, prep: &'a Prepared) -> Self {
        Self {
            gpu,
            prep,
            pending: Vec::new(),
            timings: Vec::new(),
            live: BTreeSet::new(),
            width: 0,
            height: 0,
            layers: 1,
            layouts: [IL::UNDEFINED; 3],
            target: None,
            progress: None,
        }
    }

    /// An engine whose frame goes into the host's image `target` instead of being read back.
    pub fn to_target(gpu: &'a mut Gpu, prep: &'a Prepared, target: &'a HostTarget) -> Self {
        Self { target: Some(target), ..Self::new(gpu, prep) }
    }

    /// The same engine, telling `progress` how far a long build has got.
    pub fn with_progress(self, progress: &'a mut dyn FnMut(u64, u64) -> Result<()>) -> Self {
        Self { progress: Some(progress), ..self }
    }

    /// Submit the queued commands. On a GPU: one submission with a timestamp after each run of
    /// same-named stages. On a CPU device (lavapipe) timestamps are taken when the rasterizer next
    /// flushes, not when compute work ends, so there each run is its own submission timed on the
    /// host (fence to fence, submission overhead included).
    fn flush(&mut self) -> Result<()> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let pending = std::mem::take(&mut self.pending);
        let gpu = &mut *self.gpu;
        for (_, cmd) in &pending {
            if let Cmd::Run(d) = cmd {
                gpu.res.ensure_set(&gpu.pipes, d.stage, d.args.list)?;
            }
        }
        // Runs of commands with one timing; transfers join the stage after them.
        let mut runs: Vec<(&'static str, Vec<&Cmd>)> = Vec::new();
        let mut waiting: Vec<&Cmd> = Vec::new();
        for (name, cmd) in &pending {
            waiting.push(cmd);
            if name.is_empty() {
                continue;
            }
            match runs.last_mut() {
                Some((last, cmds)) if last == name => cmds.append(&mut waiting),
                _ => runs.push((name, std::mem::take(&mut waiting))),
            }
        }
        if !waiting.is_empty() {
            runs.push(("", waiting));
        }
        let ctx = gpu.ctx.clone();
        let host_timed = ctx.choices().timing == crate::device::Timing::Host;
        let needed = runs.len() as u32 + 1;
        if !host_timed && gpu.timer.capacity < needed {
            gpu.timer = Timer::new(&ctx, needed.next_power_of_two())?;
        }
        let mut layouts = self.layouts;
        let gpu = &*self.gpu;
        let target = gpu.res.current_target()?;
        let mut per_run = vec![0.0f64; runs.len()];
        // The submission holding the blit into the host's image (and the copy of what it held,
        // queued with the blit's run) carries the host's semaphores.
        let synced =
            |cmds: &[&Cmd]| self.target.filter(|_| cmds.iter().any(|c| matches!(c, Cmd::Blit | Cmd::CopyColor(_))));
        if host_timed {
            for (i, (_, cmds)) in runs.iter().enumerate() {
                let t = Instant::now();
                ctx.submit_synced(synced(cmds), |rec| {
                    for cmd in cmds {
                        record(rec, gpu, target, &mut layouts, cmd, self.target)?;
                    }
                    Ok(())
                })?;
                per_run[i] = t.elapsed().as_secs_f64() * 1e3;
            }
        } else {
            let timer = &gpu.timer;
            let all: Vec<&Cmd> = runs.iter().flat_map(|(_, cmds)| cmds.iter().copied()).collect();
            ctx.submit_synced(synced(&all), |rec| {
                rec.reset_timer(timer);
                rec.timestamp(timer, 0);
                for (i, (_, cmds)) in runs.iter().enumerate() {
                    for cmd in cmds {
                        record(rec, gpu, target, &mut layouts, cmd, self.target)?;
                    }
                    rec.timestamp(timer, i as u32 + 1);
                }
                Ok(())
            })?;
            if let Some(ms) = timer.read_ms(needed)? {
                per_run.copy_from_slice(&ms);
            }
        }
        self.layouts = layouts;
        for ((name, _), ms) in runs.iter().zip(per_run) {
            if !name.is_empty() {
                add_time(&mut self.timings, name, ms);
            }
        }
        Ok(())
    }
}

/// Move `image` (tracked in `layout`) to `to`.
fn to_layout(rec: &Recorder<'_>, image: &Image, layout: &mut IL, to: IL) {
    if *layout != to {
        rec.transition(image, *layout, to, Stage::All, Stage::All);
        *layout = to;
    }
}

fn image_of(target: &Target, res: Res) -> (&Image, usize) {
    match res {
        Res::Accum => (&target.accum, 0),
        Res::Sums => (&target.sums, 1),
        _ => (&target.color, 2),
    }
}

fn record(
    rec: &Recorder<'_>,
    gpu: &Gpu,
    target: &Target,
    layouts: &mut [IL; 3],
    cmd: &Cmd,
    host: Option<&HostTarget>,
) -> Result<()> {
    let res = &gpu.res;
    match cmd {
        Cmd::Run(d) => {
            let desc = d.stage.desc();
            let stage = &gpu.pipes.stages[d.stage as usize];
            let (pipe, set) = (&stage.variants[d.variant], res.set(d.stage, d.args.list)?);
            match desc.kind {
                Kind::Compute => {
                    for &r in desc.bindings.iter().filter(|r| r.is_image()) {
                        let (image, i) = image_of(target, r);
                        to_layout(rec, image, &mut layouts[i], IL::GENERAL);
                    }
                    rec.dispatch(pipe, &stage.layout, set, &d.args.push, d.args.groups);
                    rec.barrier(Stage::Compute, Stage::All);
                }
                Kind::Draw => {
                    let state = d.variant().draw.expect("draw variants carry raster state");
                    let (first, count) = (d.args.groups[0], d.args.groups[1]);
                    let carry = d.args.push_as::<crate::gpu_types::FootprintPush>().carry != 0;
                    match state.pass {
                        // A later part of a bricked frame (push carry 1) draws on what the earlier left.
                        Pass::Target => {
                            let pass = if carry { &gpu.pipes.target_load_pass } else { &gpu.pipes.target_pass };
                            rec.begin_pass(pass, &target.color_fb);
                            layouts[2] = IL::TRANSFER_SRC_OPTIMAL;
                        }
                        Pass::Sheet => {
                            let pass = if carry { &gpu.pipes.sheet_load_pass } else { &gpu.pipes.sheet_pass };
                            rec.begin_pass(pass, &target.sums_fb);
                            layouts[1] = IL::GENERAL;
                        }
                        Pass::Slots => {
                            rec.begin_pass(&gpu.pipes.slots_pass, &target.slots_fb);
                            (layouts[0], layouts[2]) = (IL::TRANSFER_SRC_OPTIMAL, IL::TRANSFER_SRC_OPTIMAL);
                        }
                    }
                    if count > 0 {
                        if state.points {
                            rec.draw_points(pipe, &stage.layout, set, &d.args.push, first, count);
                        } else {
                            rec.draw_quads(pipe, &stage.layout, set, &d.args.push, first, count);
                        }
                    }
                    rec.end_pass();
                    rec.barrier(Stage::All, Stage::All);
                }
            }
        }
        Cmd::Fill(r, range, value) => {
            if r.is_image() {
                let (image, i) = image_of(target, *r);
                to_layout(rec, image, &mut layouts[i], IL::GENERAL);
                rec.clear_image(image, IL::GENERAL, [f32::from_bits(*value); 4]);
            } else {
                let buf = res.buffer(*r)?;
                match range {
                    Some((first, count)) => rec.fill_buffer_range(buf, first * 4, count * 4, *value),
                    None => rec.fill_buffer(buf, *value),
                }
            }
            rec.barrier(Stage::Transfer, Stage::All);
        }
        Cmd::Upload(r, staging) => {
            if r.is_image() {
                let (image, i) = image_of(target, *r);
                to_layout(rec, image, &mut layouts[i], IL::TRANSFER_DST_OPTIMAL);
                rec.copy_buffer_to_image(staging, image);
            } else {
                rec.copy_buffer(staging, res.buffer(*r)?, staging.size());
            }
            rec.barrier(Stage::Transfer, Stage::All);
        }
        Cmd::UploadRegions(r, staging, regions) => {
            rec.copy_buffer_regions(staging, res.buffer(*r)?, regions);
            rec.barrier(Stage::Transfer, Stage::All);
        }
        Cmd::Copy(r, bytes) => {
            let back = res.readback(*r)?;
            rec.barrier(Stage::All, Stage::Transfer);
            if r.is_image() {
                let (image, i) = image_of(target, *r);
                to_layout(rec, image, &mut layouts[i], IL::TRANSFER_SRC_OPTIMAL);
                rec.copy_image_to_buffer(image, IL::TRANSFER_SRC_OPTIMAL, back);
            } else {
                rec.copy_buffer(res.buffer(*r)?, back, *bytes);
            }
            rec.barrier(Stage::Transfer, Stage::Host);
        }
        Cmd::CopyDepth(r) => {
            let host = host.ok_or_else(|| Error::InvalidArgument("a depth copy without a host target".into()))?;
            rec.barrier(Stage::All, Stage::Transfer);
            rec.copy_host_depth(host, res.buffer(*r)?);
            rec.barrier(Stage::Transfer, Stage::All);
        }
        Cmd::CopyColor(r) => {
            let host = host.ok_or_else(|| Error::InvalidArgument("a colour copy without a host target".into()))?;
            rec.barrier(Stage::All, Stage::Transfer);
            rec.copy_host_color(host, res.buffer(*r)?);
            rec.barrier(Stage::Transfer, Stage::All);
        }
        Cmd::Blit => {
            let host = host.ok_or_else(|| Error::InvalidArgument("a blit without a host target".into()))?;
            rec.barrier(Stage::All, Stage::Transfer);
            to_layout(rec, &target.accum, &mut layouts[0], IL::TRANSFER_SRC_OPTIMAL);
            rec.blit_to_host(&target.accum, host);
        }
    }
    Ok(())
}

impl Engine for GpuEngine<'_> {
    fn begin(&mut self, frame: &Frame, kernel: Kernel, width: u32, height: u32) -> Result<()> {
        let (max_side, _) = self.gpu.ctx.image_limits();
        if width > max_side || height > max_side {
            return Err(Error::InvalidArgument(format!(
                "image {width}x{height} exceeds the device's limit of {max_side} per side"
            )));
        }
        self.gpu.res.scene()?;
        self.gpu.res.set_kernel(kernel)?;
        self.gpu.res.frame.write(bytemuck::bytes_of(frame))?;
        let layers = match self.gpu.res.current_target() {
            Ok(t) if (t.width, t.height) == (width, height) => t.layers,
            _ => 1,
        };
        (self.width, self.height, self.layers) = (width, height, layers);
        self.gpu.res.target(&self.gpu.pipes, width, height, layers)?;
        self.layouts = [IL::UNDEFINED; 3];
        Ok(())
    }

    fn layers(&mut self, layers: u32) -> Result<()> {
        if layers != self.layers {
            self.flush()?;
            self.gpu.res.target(&self.gpu.pipes, self.width, self.height, layers)?;
            self.layers = layers;
            self.layouts = [IL::UNDEFINED; 3];
        }
        Ok(())
    }

    fn ensure(&mut self, res: Res, bytes: u64) -> Result<()> {
        if self.gpu.res.must_grow(res, bytes) {
            self.flush()?;
            self.gpu.res.ensure(res, bytes)?;
        }
        Ok(())
    }

    fn fill(&mut self, res: Res, range: Option<(u64, u64)>, value: u32) -> Result<()> {
        self.live.insert(res);
        self.pending.push(("", Cmd::Fill(res, range, value)));
        Ok(())
    }

    fn upload(&mut self, res: Res, data: &[u32]) -> Result<()> {
        if res == Res::Sums || res == Res::Color {
            return Err(Error::Unsupported(format!("uploading {res:?} to the device")));
        }
        if !res.is_image() {
            self.ensure(res, data.len() as u64 * 4)?;
        }
        self.live.insert(res);
        if data.is_empty() {
            return Ok(());
        }
        let staging =
            Buffer::with_data(&self.gpu.ctx, &format!("{res:?} upload"), bytemuck::cast_slice(data), BU::TRANSFER_SRC)?;
        self.pending.push(("", Cmd::Upload(res, staging)));
        Ok(())
    }

    fn upload_regions(&mut self, res: Res, data: &[u32], regions: &[[u64; 3]]) -> Result<()> {
        self.live.insert(res);
        let size = self.gpu.res.buffer(res)?.size();
        let bytes: Vec<[u64; 3]> = regions.iter().map(|r| r.map(|w| w * 4)).collect();
        if bytes.iter().any(|&[src, dst, n]| src + n > data.len() as u64 * 4 || dst + n > size) {
            return Err(Error::InvalidArgument(format!("an upload region outside {res:?} or its data")));
        }
        if bytes.iter().all(|r| r[2] == 0) {
            return Ok(());
        }
        let staging =
            Buffer::with_data(&self.gpu.ctx, &format!("{res:?} upload"), bytemuck::cast_slice(data), BU::TRANSFER_SRC)?;
        self.pending.push(("", Cmd::UploadRegions(res, staging, bytes)));
        Ok(())
    }

    fn progress(&mut self, done: u64, of: u64) -> Result<()> {
        if self.progress.is_none() {
            return Ok(());
        }
        // What was queued runs first: the host hears of work done, not recorded.
        self.flush()?;
        match &mut self.progress {
            Some(p) => p(done, of),
            None => Ok(()),
        }
    }

    fn run(&mut self, d: &Dispatch) -> Result<()> {
        let desc = d.stage.desc();
        self.live.extend(desc.writes.iter().copied());
        self.pending.push((desc.timing, Cmd::Run(d.clone())));
        Ok(())
    }

    fn read(&mut self, what: &[(Res, usize)]) -> Result<Vec<Vec<u32>>> {
        for &(res, words) in what {
            if res == Res::Sums {
                return Err(Error::Unsupported("reading the summation layers back".into()));
            }
            let bytes = words as u64 * 4;
            self.gpu.res.ensure_readback(res, bytes)?;
            self.pending.push(("", Cmd::Copy(res, bytes)));
        }
        self.flush()?;
        what.iter()
            .map(|&(res, words)| {
                let bytes = self.gpu.res.readback(res)?.read()?;
                let n = (words * 4).min(bytes.len());
                Ok(bytemuck::cast_slice::<u8, u32>(&bytes[..n & !3]).to_vec())
            })
            .collect()
    }

    fn words(&self, res: Res) -> usize {
        match res {
            Res::Accum | Res::Color => self.width as usize * self.height as usize * 4,
            Res::Sums => self.width as usize * self.height as usize * 4 * self.layers as usize,
            _ => (self.gpu.res.size(res) / 4) as usize,
        }
    }

    fn host_time(&mut self, stage: &'static str, ms: f64) {
        add_time(&mut self.timings, stage, ms);
    }

    fn tag(&self, res: Res) -> u64 {
        self.gpu.res.tags.get(&res).copied().unwrap_or(0)
    }

    fn set_tag(&mut self, res: Res, tag: u64) {
        self.gpu.res.tags.insert(res, tag);
    }

    fn finish(&mut self) -> Result<Vec<StageTime>> {
        self.flush()?;
        Ok(std::mem::take(&mut self.timings))
    }

    fn target_linear(&self) -> Option<bool> {
        self.target.map(|t| t.format().linear())
    }

    fn copy_target_depth(&mut self, res: Res) -> Result<()> {
        if self.target.and_then(|t| t.depth()).is_none() {
            return Err(Error::InvalidArgument("this frame's target has no depth image".into()));
        }
        self.live.insert(res);
        self.pending.push(("", Cmd::CopyDepth(res)));
        Ok(())
    }

    fn target_over(&self) -> Option<crate::image::TargetFormat> {
        self.target.filter(|t| t.is_over()).map(|t| t.format())
    }

    fn copy_target_color(&mut self, res: Res) -> Result<()> {
        if self.target_over().is_none() {
            return Err(Error::InvalidArgument("this frame's target is not drawn over".into()));
        }
        self.live.insert(res);
        // Named as the present stage: the copy runs in the blit's submission, after its waits.
        self.pending.push(("present", Cmd::CopyColor(res)));
        Ok(())
    }

    fn deliver(&mut self) -> Result<()> {
        if self.target.is_none() {
            return Err(Error::InvalidArgument("this frame has no host target".into()));
        }
        self.pending.push(("present", Cmd::Blit));
        Ok(())
    }

    fn live(&self) -> Vec<Res> {
        self.live.iter().copied().collect()
    }

    fn limits(&self) -> Limits {
        let ctx = &self.gpu.ctx;
        Limits {
            max_layers: ctx.image_limits().1,
            max_storage_range: ctx.max_storage_range(),
            budget_bytes: self.gpu.budget_bytes,
            target_depth: self.target.and_then(|t| t.depth()),
        }
    }

    fn is_device(&self) -> bool {
        true
    }

    fn prepare_field(&mut self, brick: u32, mode: crate::options::Mode) -> Result<()> {
        self.flush()?;
        self.gpu.upload_field(self.prep, brick, mode)
    }
}
