//! The research harness around the voxsplat renderer: the benchmark matrix and its charts
//! (`bench`), anti-aliasing on the seed's terrain and orthographic figures (`antialias`), where methods fail (`stability`), the raster-rate sweep (`rates`), the peers'
//! comparison (`peer`), the reconstruction kernels (`kernels`) and long runs (`soak`). The `voxsplat` command-line tool is this crate's
//! binary; the renderer itself is the `voxsplat` library, which needs none of this.
pub mod antialias;
pub mod bench;
pub mod bricked;
pub mod devices;
pub use devices::{describe_device, device_toml};
pub mod kernels;
pub mod modes;
pub mod motion_orders;
pub mod open;
pub mod parse;
pub mod peer;
pub mod progress;
pub mod pyramid;
pub mod rates;
pub mod scene_args;
pub mod series;
pub mod session;
pub mod soak;
pub mod stability;
pub mod suite;
pub mod uneven;
pub mod view;
pub mod volumes;

/// The options the labs measure with: the library's defaults with the Gaussian kernel, the
/// dissertation's. Their figures in docs/RESULTS.md and the tests' ceilings were measured with it
/// (it was `RenderOptions::default()`'s kernel until Crawfis-Max, `render`'s default, became the
/// library's too).
pub fn lab_options() -> voxsplat::RenderOptions {
    let mut o = voxsplat::RenderOptions::default();
    o.kernel = voxsplat::Kernel::Gaussian;
    o
}
