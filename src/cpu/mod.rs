//! CPU mirrors of the GPU stages, one function per stage with the stage's name, written loop for
//! loop like the shaders and reading the same `#[repr(C)]` structs.
pub mod bindings;
pub mod brick;
pub mod brick_hidden;
pub mod brick_nodes;
pub mod brick_words;
pub mod composite;
pub mod footprint;
pub mod lod;
pub mod order;
pub mod present;
pub mod raycast;
pub mod sheet_tiles;
pub mod slab;
pub mod splat_params;
pub mod tile;
pub mod tile_occlusion;

pub use crate::image::ImageF32;
pub use brick::{brick_cull, brick_order, brick_params};
pub use brick_hidden::brick_hidden;
pub use composite::composite;
pub use footprint::{footprint, footprint_sum, sample_table};
pub use order::{order_count, order_scan, order_scatter};
pub use present::present;
pub use raycast::raycast;
pub use sheet_tiles::sheet_tiles;
pub use slab::{slab_count, slab_scan, slab_scatter};
pub use splat_params::splat_params;
pub use tile::{tile_composite, tile_count, tile_offsets, tile_scan, tile_scatter};
pub use tile_occlusion::tile_occlusion;
