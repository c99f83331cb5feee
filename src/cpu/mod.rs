//! CPU mirrors of the GPU stages, one function per stage with the stage's name, written loop for
//! loop like the shaders and reading the same `#[repr(C)]` structs.
pub mod composite;
pub mod footprint;
pub mod order;
pub mod raycast;
pub mod sheet_tiles;
pub mod slab;
pub mod splat_params;
pub mod tile;

pub use composite::composite;
pub use footprint::{footprint, footprint_sum, sample_table};
pub use order::{order_count, order_scan, order_scatter};
pub use raycast::raycast;
pub use sheet_tiles::sheet_tiles;
pub use slab::{slab_count, slab_scan, slab_scatter};
pub use splat_params::splat_params;
pub use tile::{tile_composite, tile_count, tile_offsets, tile_scan, tile_scatter};

/// An RGBA32F image, row 0 at the top. Colour is premultiplied by alpha.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageF32 {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

impl ImageF32 {
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![[0.0; 4]; width as usize * height as usize] }
    }
}
