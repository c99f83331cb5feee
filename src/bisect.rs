//! Engines around engines: [`Split`] runs a frame's stages up to a named one on one engine and the
//! rest on the other (vello's `force_gpu_from`), to find the first stage whose GPU output departs
//! from its mirror; [`Stop`] ends a recording after a named stage, for probes.
use crate::error::{Error, Result};
use crate::gpu_types::Frame;
use crate::kernel::Kernel;
use crate::options::StageTime;
use crate::stages::{Dispatch, Engine, Limits, Res, StageId};

/// Which engine runs which stages of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bisect {
    /// The device runs every stage before this one; from its first dispatch on, the mirrors.
    GpuUntil(StageId),
    /// The mirrors run every stage before this one; from its first dispatch on, the device.
    CpuUntil(StageId),
}

impl std::str::FromStr for Bisect {
    type Err = Error;
    /// `gpu-until:STAGE` or `cpu-until:STAGE`.
    fn from_str(s: &str) -> Result<Self> {
        match s.split_once(':') {
            Some(("gpu-until", stage)) => Ok(Bisect::GpuUntil(StageId::named(stage)?)),
            Some(("cpu-until", stage)) => Ok(Bisect::CpuUntil(StageId::named(stage)?)),
            _ => Err(Error::InvalidArgument(format!("bisect '{s}' must be gpu-until:STAGE or cpu-until:STAGE"))),
        }
    }
}

/// Two engines, switched at a stage: everything a stage wrote on the first moves to the second.
pub struct Split<'a> {
    first: &'a mut dyn Engine,
    second: &'a mut dyn Engine,
    at: StageId,
    switched: bool,
}

impl<'a> Split<'a> {
    /// `first` runs the stages before `at`; `second` the rest.
    pub fn new(first: &'a mut dyn Engine, second: &'a mut dyn Engine, at: StageId) -> Self {
        Self { first, second, at, switched: false }
    }

    fn active(&mut self) -> &mut dyn Engine {
        if self.switched {
            &mut *self.second
        } else {
            &mut *self.first
        }
    }

    fn switch(&mut self) -> Result<()> {
        for res in self.first.live() {
            if res.is_constant() {
                continue;
            }
            let words = self.first.words(res);
            if words == 0 {
                // Bound by a stage but never filled this frame (a levels-of-detail buffer a
                // resident store does not use): nothing to move.
                continue;
            }
            let data = self.first.read(&[(res, words)]).map_err(|e| cannot(self.at, res, e))?;
            if !res.is_image() {
                self.second.ensure(res, words as u64 * 4)?;
            }
            self.second.upload(res, &data[0]).map_err(|e| cannot(self.at, res, e))?;
        }
        self.switched = true;
        Ok(())
    }
}

fn cannot(at: StageId, res: Res, e: Error) -> Error {
    Error::Unsupported(format!("switching engines at {}: {res:?} cannot move ({e})", at.desc().name))
}

impl Engine for Split<'_> {
    fn begin(&mut self, frame: &Frame, kernel: Kernel, width: u32, height: u32) -> Result<()> {
        self.first.begin(frame, kernel, width, height)?;
        self.second.begin(frame, kernel, width, height)
    }
    fn layers(&mut self, layers: u32) -> Result<()> {
        self.first.layers(layers)?;
        self.second.layers(layers)
    }
    fn ensure(&mut self, res: Res, bytes: u64) -> Result<()> {
        self.first.ensure(res, bytes)?;
        self.second.ensure(res, bytes)
    }
    fn fill(&mut self, res: Res, range: Option<(u64, u64)>, value: u32) -> Result<()> {
        self.active().fill(res, range, value)
    }
    fn upload(&mut self, res: Res, data: &[u32]) -> Result<()> {
        self.active().upload(res, data)
    }
    fn upload_regions(&mut self, res: Res, data: &[u32], regions: &[[u64; 3]]) -> Result<()> {
        self.active().upload_regions(res, data, regions)
    }
    fn run(&mut self, d: &Dispatch) -> Result<()> {
        if !self.switched && d.stage == self.at {
            self.switch()?;
        }
        self.active().run(d)
    }
    fn read(&mut self, what: &[(Res, usize)]) -> Result<Vec<Vec<u32>>> {
        self.active().read(what)
    }
    fn tag(&self, _: Res) -> u64 {
        // A split frame rebuilds every cache: which engine ends up holding it depends on the stage
        // the frame switches at.
        0
    }
    fn set_tag(&mut self, _: Res, _: u64) {}
    fn words(&self, res: Res) -> usize {
        if self.switched {
            self.second.words(res)
        } else {
            self.first.words(res)
        }
    }
    fn host_time(&mut self, stage: &'static str, ms: f64) {
        self.active().host_time(stage, ms)
    }
    fn finish(&mut self) -> Result<Vec<StageTime>> {
        let mut t = self.first.finish()?;
        t.extend(self.second.finish()?);
        Ok(t)
    }
    fn live(&self) -> Vec<Res> {
        let mut live = self.first.live();
        live.extend(self.second.live());
        live
    }
    fn limits(&self) -> Limits {
        let (a, b) = (self.first.limits(), self.second.limits());
        Limits {
            max_layers: a.max_layers.min(b.max_layers),
            max_storage_range: a.max_storage_range.min(b.max_storage_range),
            budget_bytes: a.budget_bytes.min(b.budget_bytes),
            target_depth: a.target_depth.or(b.target_depth),
        }
    }
    fn prepare_field(&mut self, brick: u32, mode: crate::options::Mode) -> Result<()> {
        self.first.prepare_field(brick, mode)?;
        self.second.prepare_field(brick, mode)
    }
    fn is_device(&self) -> bool {
        if self.switched {
            self.second.is_device()
        } else {
            self.first.is_device()
        }
    }
}

/// An engine that runs a recording until the stage after `after` begins, then does nothing (reads
/// give zeros), so the recording ends early with `after`'s outputs in place.
pub struct Stop<'a> {
    inner: &'a mut dyn Engine,
    after: StageId,
    seen: bool,
    done: bool,
}

impl<'a> Stop<'a> {
    /// Run `inner` until the stage after `after` begins.
    pub fn new(inner: &'a mut dyn Engine, after: StageId) -> Self {
        Self { inner, after, seen: false, done: false }
    }
}

impl Engine for Stop<'_> {
    fn begin(&mut self, frame: &Frame, kernel: Kernel, width: u32, height: u32) -> Result<()> {
        self.inner.begin(frame, kernel, width, height)
    }
    fn layers(&mut self, layers: u32) -> Result<()> {
        if self.done {
            return Ok(());
        }
        self.inner.layers(layers)
    }
    fn ensure(&mut self, res: Res, bytes: u64) -> Result<()> {
        if self.done {
            return Ok(());
        }
        self.inner.ensure(res, bytes)
    }
    fn fill(&mut self, res: Res, range: Option<(u64, u64)>, value: u32) -> Result<()> {
        if self.done {
            return Ok(());
        }
        self.inner.fill(res, range, value)
    }
    fn upload(&mut self, res: Res, data: &[u32]) -> Result<()> {
        if self.done {
            return Ok(());
        }
        self.inner.upload(res, data)
    }
    fn upload_regions(&mut self, res: Res, data: &[u32], regions: &[[u64; 3]]) -> Result<()> {
        if self.done {
            return Ok(());
        }
        self.inner.upload_regions(res, data, regions)
    }
    fn run(&mut self, d: &Dispatch) -> Result<()> {
        if d.stage == self.after {
            self.seen = true;
        } else if self.seen {
            self.done = true;
        }
        if self.done {
            return Ok(());
        }
        self.inner.run(d)
    }
    fn read(&mut self, what: &[(Res, usize)]) -> Result<Vec<Vec<u32>>> {
        if self.done {
            return Ok(what.iter().map(|&(_, words)| vec![0; words]).collect());
        }
        self.inner.read(what)
    }
    fn words(&self, res: Res) -> usize {
        self.inner.words(res)
    }
    fn tag(&self, res: Res) -> u64 {
        self.inner.tag(res)
    }
    fn set_tag(&mut self, res: Res, tag: u64) {
        if !self.done {
            self.inner.set_tag(res, tag)
        }
    }
    fn host_time(&mut self, stage: &'static str, ms: f64) {
        self.inner.host_time(stage, ms)
    }
    fn finish(&mut self) -> Result<Vec<StageTime>> {
        self.inner.finish()
    }
    fn live(&self) -> Vec<Res> {
        self.inner.live()
    }
    fn limits(&self) -> Limits {
        self.inner.limits()
    }
    fn prepare_field(&mut self, brick: u32, mode: crate::options::Mode) -> Result<()> {
        self.inner.prepare_field(brick, mode)
    }
    fn is_device(&self) -> bool {
        self.inner.is_device()
    }
}
