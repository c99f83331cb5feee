//! How a store's values are spread: the histogram a transfer-function editor draws its curve over,
//! on a log scale (the empty background and a few dense tissues outnumber the thin structures a
//! transfer function picks out by orders of magnitude), and what `voxsplat info --histogram` prints.
use super::{BrickStore, Q};
use crate::error::{Error, Result};

/// Most bins a histogram takes: one per quantised value a store holds.
pub const MAX_BINS: u32 = Q as u32 + 1;

/// A store's stored voxels counted in equal bins over its value range.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    /// The values the bins span, the store's range (`BrickStore::range`): bin `i` holds values from
    /// `edge(i)` up to `edge(i + 1)`, the last one its end too.
    pub range: (f32, f32),
    /// Stored voxels per bin.
    pub counts: Vec<u64>,
    /// Voxels of the grid the store keeps empty (at its smallest value, or outside the part read),
    /// counted apart: they would dwarf every bin.
    pub empty: u64,
}

impl Histogram {
    /// Where bin `i` begins (`i` = the bin count: where the last ends).
    pub fn edge(&self, i: usize) -> f32 {
        let (lo, hi) = self.range;
        (lo as f64 + (hi as f64 - lo as f64) * i as f64 / self.counts.len().max(1) as f64) as f32
    }

    /// Each bin's height on a log scale, from 0 (no voxel) to 1 (the fullest bin):
    /// ln(1 + count) / ln(1 + largest count).
    pub fn log_heights(&self) -> Vec<f32> {
        let top = (self.counts.iter().copied().max().unwrap_or(0) as f64).ln_1p();
        self.counts.iter().map(|&c| if top > 0.0 { ((c as f64).ln_1p() / top) as f32 } else { 0.0 }).collect()
    }
}

impl BrickStore {
    /// Its stored voxels in `bins` equal bins over its value range (1 to `MAX_BINS`). A voxel of
    /// value v lies in bin ⌊(v − lo) / (hi − lo) × bins⌋ (the last bin closed), v as stored: a
    /// quantised value is binned as the middle of its quantum, so that integer samples spanning
    /// fewer than 65,535 values land where their exact values would.
    pub fn histogram(&self, bins: u32) -> Result<Histogram> {
        if bins == 0 || bins > MAX_BINS {
            return Err(Error::InvalidArgument(format!("a histogram has 1 to {MAX_BINS} bins, not {bins}")));
        }
        let (q, n) = (Q as u64, bins as u64);
        // (q + 1/2) / Q × bins, in integers: exact at every bin edge.
        let bin = |v: u32| (((2 * v as u64 + 1) * n / (2 * q)) as usize).min(bins as usize - 1);
        let mut counts = vec![0u64; bins as usize];
        for h in &self.headers {
            if h.is_uniform() {
                counts[bin(h.range & 0xffff)] += h.count as u64;
                continue;
            }
            let records = &self.records[h.first as usize..(h.first + h.count) as usize];
            for r in records {
                counts[bin(r >> 16)] += 1;
            }
        }
        let voxels = self.dims.iter().map(|&d| d as u64).product::<u64>();
        Ok(Histogram { range: self.range, counts, empty: voxels - self.len() as u64 })
    }
}
