//! What the mirrors read and write: host copies of the resources the GPU binds, by name.
use crate::dispatch::{List, Res};
use crate::gpu_types::{Frame, Splat, SplatParams};
use crate::image::ImageF32;
use crate::plan::Prepared;
use std::collections::HashMap;

/// What a mirror reads and writes: the scene, the frame's uniforms and tables, and the frame's
/// resources by name (buffers as 32-bit words, images as `ImageF32`).
pub struct Bindings<'a> {
    /// The scene.
    pub prep: &'a Prepared,
    /// The frame's uniforms.
    pub frame: Frame,
    /// The radial footprint table and the kernel-slice table (`Kernel::radial_table`,
    /// `Kernel::slice_table`).
    pub table: Vec<f32>,
    /// See `table`.
    pub slice_table: Vec<f32>,
    /// The image's size.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    pub(crate) bufs: HashMap<Res, Vec<u32>>,
    /// The raster target (`Res::Color`).
    pub color: ImageF32,
    /// The accumulation image (`Res::Accum`).
    pub accum: ImageF32,
    /// The summation layers.
    pub sums: Vec<ImageF32>,
    /// The ray caster's brick occupancy (`Res::Bricks`; the field is `prep.dense_field()`).
    pub bricks: Vec<u32>,
}

impl<'a> Bindings<'a> {
    /// Empty bindings for a frame of `prep`.
    pub fn new(prep: &'a Prepared) -> Self {
        Self {
            prep,
            frame: Frame::default(),
            table: Vec::new(),
            slice_table: Vec::new(),
            width: 0,
            height: 0,
            bufs: HashMap::new(),
            color: ImageF32::new(0, 0),
            accum: ImageF32::new(0, 0),
            sums: Vec::new(),
            bricks: Vec::new(),
        }
    }

    /// A frame buffer as `T`s (empty when it does not exist): its whole `T`s, since a buffer
    /// handed over from the device may be longer than the records it holds (grown by powers of two).
    pub fn get<T: bytemuck::Pod>(&self, res: Res) -> &[T] {
        let Some(v) = self.bufs.get(&res) else { return &[] };
        let words = v.len() / (std::mem::size_of::<T>() / 4).max(1) * (std::mem::size_of::<T>() / 4).max(1);
        bytemuck::cast_slice(&v[..words])
    }

    /// Take a frame buffer out to write it (put it back with `put`).
    pub fn take(&mut self, res: Res) -> Vec<u32> {
        self.bufs.remove(&res).unwrap_or_default()
    }

    /// `res` now holds `words`.
    pub fn put(&mut self, res: Res, words: Vec<u32>) {
        self.bufs.insert(res, words);
    }

    /// The dispatch's draw list.
    pub fn list(&self, list: List) -> &[u32] {
        match list {
            List::Order => self.get(Res::Order),
            List::Slices(axis) => &self.prep.slices[axis as usize].1,
            List::SlabPairs => self.get(Res::SlabPairs),
        }
    }

    /// The footprint stages' inputs, as bound on the GPU.
    pub fn inputs(&self, list: List) -> FootprintInputs<'_> {
        FootprintInputs {
            frame: &self.frame,
            params: self.get(Res::Params),
            draw_list: self.list(list),
            splats: self.prep.set.splats(),
            sheet_rank: &self.prep.ranks,
            table: &self.table,
            slice_table: &self.slice_table,
            occlusion: self.get(Res::Occlusion),
            host_depth: self.get(Res::HostDepth),
        }
    }

    /// The image resource `res` (its layers for `Sums`).
    pub fn images(&self, res: Res) -> Vec<&ImageF32> {
        match res {
            Res::Accum => vec![&self.accum],
            Res::Color => vec![&self.color],
            _ => self.sums.iter().collect(),
        }
    }

    /// `images`, to write.
    pub fn image_mut(&mut self, res: Res) -> Vec<&mut ImageF32> {
        match res {
            Res::Accum => vec![&mut self.accum],
            Res::Color => vec![&mut self.color],
            _ => self.sums.iter_mut().collect(),
        }
    }
}

/// The footprint stages' inputs, as bound on the GPU (the draw call's and the tile stages').
#[derive(Clone, Copy)]
pub struct FootprintInputs<'a> {
    /// The frame's uniforms.
    pub frame: &'a Frame,
    /// Per splat its parameters.
    pub params: &'a [SplatParams],
    /// The dispatch's draw list.
    pub draw_list: &'a [u32],
    /// The scene's splats.
    pub splats: &'a [Splat],
    /// Each slice's rank among the non-empty slices.
    pub sheet_rank: &'a [u32],
    /// The radial footprint table (`Kernel::radial_table`).
    pub table: &'a [f32],
    /// The kernel-slice table (slab mode).
    pub slice_table: &'a [f32],
    /// Largest transmittance left per composite tile (early termination; empty when off).
    pub occlusion: &'a [f32],
    /// The host's eye-space depth per pixel (`Res::HostDepth`; read when `frame.rect[3]` is 1).
    pub host_depth: &'a [f32],
}
