//! The kernel study (the seed's section 1.2.3): every reconstruction kernel's ripple on
//! a flat sheet, its support, and its error and time on the peers' scene against one truth that
//! no kernel shapes (scalars integrated along the rays), charted error against ripple.
use crate::bricked::frame_ms;
use std::fmt::Write as _;
use std::path::Path;
use voxsplat::kernel::{lattice_rms, KERNELS};
use voxsplat::{kernel::Kernel, options::Raster, Error, RenderOptions, Renderer, RendererOptions, Result};

/// One kernel's row.
pub struct KernelRow {
    pub kernel: Kernel,
    /// Peak-to-peak ripple of a flat sheet's summed footprints (`Kernel::sheet_ripple`).
    pub ripple: f64,
    /// Their RMS deviation (`kernel::lattice_rms`, Crawfis and Max's criterion).
    pub rms: f64,
    pub psnr: f64,
    pub median_ms: f64,
}

/// The peers' `n`³ scene at `size`², the tile compositor, every kernel alternating frame by frame
/// for `rounds` rounds after a warm-up.
pub fn study(n: u32, size: u32, rounds: usize) -> Result<Vec<KernelRow>> {
    let vol = voxsplat::scene::peer::volume(n)?;
    let tf = voxsplat::scene::peer::transfer_function();
    let camera = voxsplat::scene::peer::camera(n, size);
    let truth = voxsplat::truth::ray_integrate_scalars(&vol, &tf, &camera, 0.25)?;
    let mut r = Renderer::new(&RendererOptions::default())?;
    r.set_scene(voxsplat::classify::classify(&vol, &tf, None)?)?;
    let options = |kernel: Kernel| {
        let mut o = RenderOptions::default();
        (o.kernel, o.raster) = (kernel, Raster::Compute);
        o
    };
    let mut psnr = Vec::new();
    for k in KERNELS {
        psnr.push(voxsplat::metrics::compare(&r.render(&camera, &options(k))?.image, &truth)?.psnr);
    }
    let medians = crate::bench::alternating_medians(KERNELS.len(), 0, rounds, |k| {
        frame_ms(&mut r, &camera, &options(KERNELS[k]))
    })?;
    Ok(KERNELS
        .iter()
        .zip(psnr)
        .zip(medians)
        .map(|((&kernel, psnr), median_ms)| KernelRow {
            kernel,
            ripple: kernel.sheet_ripple(),
            rms: lattice_rms(|r| kernel.profile(r), kernel.radius() as f64),
            psnr,
            median_ms,
        })
        .collect())
}

/// The study's section of RESULTS.md; `chart` is linked as `bench/FILE`.
pub fn markdown(rows: &[KernelRow], n: u32, size: u32, chart: Option<&Path>) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Reconstruction kernels (section 1.2.3)\n\n`voxsplat-lab kernels`: ripple = peak to peak of a flat unit-spaced \
         sheet's summed footprints seen head-on, over their mean; lattice RMS = their RMS deviation (Crawfis and Max's \
         criterion, which `crawfis-max` is fitted to minimise with their support); error on the peers' {n}³ scene at \
         {size}², tile compositor, against the scalar ray integration (step 0.25), a truth no kernel shapes; median of \
         alternating frames.\n\n| kernel | radius | footprint area vs gaussian | sheet ripple | lattice RMS | PSNR dB | \
         median ms |\n|---|---:|---:|---:|---:|---:|---:|"
    );
    let area = |k: Kernel| (k.radius() / Kernel::Gaussian.radius()).powi(2);
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.2} % | {:.3} % | {:.2} | {:.1} |",
            r.kernel.name(),
            r.kernel.radius(),
            area(r.kernel),
            r.ripple * 100.0,
            r.rms * 100.0,
            r.psnr,
            r.median_ms
        );
    }
    if let Some(c) = chart.and_then(|c| c.file_name()) {
        let _ = writeln!(s, "\n![error against ripple per kernel](bench/{})", c.to_string_lossy());
    }
    s
}

/// PSNR against sheet ripple, one labelled point per kernel.
pub fn chart(rows: &[KernelRow], path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| Error::Io {
        path: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    };
    let root = SVGBackend::new(path, (640, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (x0, x1) = rows.iter().fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(r.ripple), b.max(r.ripple)));
    let (y0, y1) = rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| (a.min(r.psnr), b.max(r.psnr)));
    if !(x0 > 0.0 && y0.is_finite()) {
        return Err(Error::InvalidArgument("no kernel rows to chart".into()));
    }
    let mut chart = ChartBuilder::on(&root)
        .caption("reconstruction kernels: error against sheet ripple", ("sans-serif", 18))
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0 * 100.0 * 0.6..x1 * 100.0 * 1.6).log_scale(), y0 - 0.5..y1 + 0.5)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("sheet ripple, peak to peak (%)")
        .y_desc("PSNR against the truth (dB)")
        .draw()
        .map_err(|e| err(&e))?;
    for r in rows {
        let p = (r.ripple * 100.0, r.psnr);
        chart.draw_series([Circle::new(p, 4, BLUE.filled())]).map_err(|e| err(&e))?;
        chart.draw_series([Text::new(r.kernel.name().to_string(), p, ("sans-serif", 14))]).map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))
}
