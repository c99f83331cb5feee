//! The studies that measure the voxsplat renderer, for its developers: the benchmark matrix and its
//! charts (`bench`), anti-aliasing on the seed's terrain and orthographic figures (`antialias`),
//! where methods fail (`stability`), the raster-rate sweep (`rates`), the peers' comparison
//! (`peer`), the reconstruction kernels (`kernels`), the rendering modes (`modes`), orders under
//! motion (`motion_orders`), a view's visibility order (`order`), bricked volumes (`bricked`) and long runs (`soak`). The
//! `voxsplat-lab` binary runs them; it builds on the user's command line (`voxsplat_cli`), and
//! neither the `voxsplat` binary nor the library needs any of this.
pub mod antialias;
pub mod bench;
pub mod bricked;
pub mod kernels;
pub mod modes;
pub mod motion_orders;
pub mod order;
pub mod peer;
pub mod rates;
pub mod soak;
pub mod stability;

/// The options the labs measure with: the library's defaults with the Gaussian kernel, the
/// dissertation's. Their figures in docs/RESULTS.md and the tests' ceilings were measured with it
/// (it was `RenderOptions::default()`'s kernel until Crawfis-Max, `render`'s default, became the
/// library's too).
pub fn lab_options() -> voxsplat::RenderOptions {
    let mut o = voxsplat::RenderOptions::default();
    o.kernel = voxsplat::kernel::Kernel::Gaussian;
    o
}
