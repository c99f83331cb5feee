//! Fits the Crawfis–Max kernel (`voxsplat::kernel::fit_crawfis_max`) and prints it beside the
//! other kernels' lattice RMS and sheet ripple.
use voxsplat::kernel::{fit_crawfis_max, lattice_rms, KERNELS};
fn main() {
    let t = std::time::Instant::now();
    let s = fit_crawfis_max();
    println!("fit in {:.1} s: {s:?}", t.elapsed().as_secs_f64());
    for k in KERNELS {
        let r = k.radius() as f64;
        println!(
            "{:<12} lattice rms {:.5}  sheet ripple {:.5}",
            k.name(),
            lattice_rms(|x| k.profile(x), r),
            k.sheet_ripple()
        );
    }
    let r = voxsplat::kernel::CRAWFIS_MAX_RADIUS;
    println!("fitted       lattice rms {:.6}", lattice_rms(|x| s.eval(x / r), r));
}
