//! The CPU engine: runs a frame's recording (`crate::recording`) on the mirrors, each dispatch
//! through its stage's `mirror` entry in the stage table, over `cpu::bindings::Bindings`.
use crate::constants::DEFAULT_GPU_BUDGET;
use crate::cpu::bindings::Bindings;
use crate::dispatch::Res;
use crate::error::{Error, Result};
use crate::gpu_types::Frame;
use crate::image::ImageF32;
use crate::kernel::Kernel;
use crate::options::{add_time, StageTime};
use crate::plan::Prepared;
use crate::stages::{Dispatch, Engine, Limits};

use std::collections::BTreeSet;
use std::time::Instant;

/// The CPU engine of one frame.
pub struct CpuEngine<'a> {
    b: Bindings<'a>,
    budget_bytes: u64,
    timings: Vec<StageTime>,
    live: BTreeSet<Res>,
    tags: std::collections::HashMap<Res, u64>,
}

impl<'a> CpuEngine<'a> {
    /// An engine for one frame of `prep`.
    pub fn new(prep: &'a Prepared) -> Self {
        Self {
            b: Bindings::new(prep),
            budget_bytes: DEFAULT_GPU_BUDGET,
            timings: Vec::new(),
            live: BTreeSet::new(),
            tags: Default::default(),
        }
    }

    /// The same engine cutting a bricked volume's batches for a device budget of `bytes`.
    pub fn with_budget(mut self, bytes: u64) -> Self {
        self.budget_bytes = bytes;
        self
    }
}

impl Engine for CpuEngine<'_> {
    fn begin(&mut self, frame: &Frame, kernel: Kernel, width: u32, height: u32) -> Result<()> {
        let b = &mut self.b;
        b.frame = *frame;
        b.table = kernel.radial_table();
        b.slice_table = kernel.slice_table();
        (b.width, b.height) = (width, height);
        b.color = ImageF32::new(width, height);
        b.accum = ImageF32::new(width, height);
        b.sums.clear();
        Ok(())
    }

    fn layers(&mut self, layers: u32) -> Result<()> {
        self.b.sums = vec![ImageF32::new(self.b.width, self.b.height); layers as usize];
        Ok(())
    }

    fn ensure(&mut self, res: Res, bytes: u64) -> Result<()> {
        if res.is_image() || res.is_constant() {
            return Ok(());
        }
        let words = bytes.div_ceil(4);
        let words = usize::try_from(words).map_err(|_| Error::TooLarge(format!("{bytes} bytes of {res:?}")))?;
        let buf = self.b.bufs.entry(res).or_default();
        if buf.len() < words {
            buf.resize(words, 0);
            self.tags.remove(&res);
        }
        Ok(())
    }

    fn fill(&mut self, res: Res, range: Option<(u64, u64)>, value: u32) -> Result<()> {
        self.live.insert(res);
        if res.is_image() {
            for img in self.b.image_mut(res) {
                img.pixels.fill([f32::from_bits(value); 4]);
            }
            return Ok(());
        }
        let buf = self.b.bufs.entry(res).or_default();
        let len = buf.len();
        let (first, count) = range.map(|(f, c)| (f as usize, c as usize)).unwrap_or((0, len));
        buf[first.min(len)..(first + count).min(len)].fill(value);
        Ok(())
    }

    fn upload(&mut self, res: Res, data: &[u32]) -> Result<()> {
        self.live.insert(res);
        if res.is_image() {
            let mut words = data.chunks_exact(4);
            for img in self.b.image_mut(res) {
                for (px, w) in img.pixels.iter_mut().zip(&mut words) {
                    *px = [0, 1, 2, 3].map(|i| f32::from_bits(w[i]));
                }
            }
            return Ok(());
        }
        self.ensure(res, data.len() as u64 * 4)?;
        self.b.bufs.get_mut(&res).expect("ensured")[..data.len()].copy_from_slice(data);
        Ok(())
    }

    fn upload_regions(&mut self, res: Res, data: &[u32], regions: &[[u64; 3]]) -> Result<()> {
        self.live.insert(res);
        let buf = self.b.bufs.entry(res).or_default();
        for &[src, dst, words] in regions {
            let (src, dst, n) = (src as usize, dst as usize, words as usize);
            let (Some(from), Some(to)) = (data.get(src..src + n), buf.get_mut(dst..dst + n)) else {
                return Err(Error::InvalidArgument(format!("an upload region outside {res:?} or its data")));
            };
            to.copy_from_slice(from);
        }
        Ok(())
    }

    fn run(&mut self, d: &Dispatch) -> Result<()> {
        let t = Instant::now();
        let desc = d.stage.desc();
        (desc.mirror)(&mut self.b, &d.args, d.variant())?;
        self.live.extend(desc.writes.iter().copied());
        add_time(&mut self.timings, desc.timing, t.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    fn read(&mut self, what: &[(Res, usize)]) -> Result<Vec<Vec<u32>>> {
        Ok(what
            .iter()
            .map(|&(res, words)| {
                if res.is_image() {
                    let all =
                        self.b.images(res).into_iter().flat_map(|i| i.pixels.iter().flat_map(|p| p.map(f32::to_bits)));
                    all.take(words).collect()
                } else {
                    let buf = self.b.get::<u32>(res);
                    buf[..words.min(buf.len())].to_vec()
                }
            })
            .collect())
    }

    fn tag(&self, res: Res) -> u64 {
        self.tags.get(&res).copied().unwrap_or(0)
    }

    fn set_tag(&mut self, res: Res, tag: u64) {
        self.tags.insert(res, tag);
    }

    fn words(&self, res: Res) -> usize {
        let px = self.b.width as usize * self.b.height as usize * 4;
        match res {
            Res::Accum | Res::Color => px,
            Res::Sums => px * self.b.sums.len(),
            _ => self.b.get::<u32>(res).len(),
        }
    }

    fn host_time(&mut self, stage: &'static str, ms: f64) {
        add_time(&mut self.timings, stage, ms);
    }

    fn finish(&mut self) -> Result<Vec<StageTime>> {
        Ok(std::mem::take(&mut self.timings))
    }

    fn live(&self) -> Vec<Res> {
        self.live.iter().copied().collect()
    }

    fn limits(&self) -> Limits {
        Limits {
            max_layers: u32::MAX,
            max_storage_range: u64::MAX,
            budget_bytes: self.budget_bytes,
            target_depth: None,
        }
    }

    fn is_device(&self) -> bool {
        false
    }

    fn prepare_field(&mut self, brick: u32, mode: crate::options::Mode) -> Result<()> {
        let field = self.b.prep.field_for(mode)?;
        self.b.bricks = field.brick_occupancy(brick.max(1)).1;
        Ok(())
    }
}
