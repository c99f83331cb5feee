//! What one `over` of two premultiplied RGBA32F frames costs on this host (docs/SCALE.md's
//! compositing model): a 4K frame over another, median of nine, one core.
fn main() {
    let (w, h) = (3840usize, 2160usize);
    let front: Vec<f32> = (0..w * h * 4).map(|i| (i % 7) as f32 * 0.1).collect();
    let mut back: Vec<f32> = (0..w * h * 4).map(|i| (i % 5) as f32 * 0.2).collect();
    let mut ms: Vec<f64> = (0..9)
        .map(|_| {
            let t = std::time::Instant::now();
            voxsplat::distributed::over_into(&front, &mut back);
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    let px = (w * h) as f64;
    println!("{w}x{h} over: median {:.1} ms, {:.2} ns per pixel ({:.3})", ms[4], ms[4] * 1e6 / px, back[12345]);
}
