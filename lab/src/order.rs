//! `voxsplat-lab order`: write or check a visibility order (back to front) for a scene's view: the
//! device's PBTF order, or one of the host's orders (`--order`).
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use voxsplat::{order, order::Direction, order::OrderKind, Error, Result};
use voxsplat_cli::open::{camera_of, load_scene, renderer_of, report_validation, SceneArgs};
use voxsplat_cli::println;
use voxsplat_cli::scene_args::SceneResearch;

/// The scene, its view, and what to do with the order.
#[derive(Args)]
pub struct OrderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub research: SceneResearch,
    /// Write the back-to-front sequence as `i,j,k,x,y,z` lines.
    #[arg(long)]
    pub dump: Option<PathBuf>,
    /// Count pairs drawn in the wrong order: in image space (splats covering a pixel drawn against
    /// their depth along its ray, the default kernel's footprints; `pixel inversions: N`), then
    /// 6-neighbours (prints `violations: N` last).
    #[arg(long)]
    pub check: bool,
}

/// Runs `voxsplat-lab order`.
pub fn run(mut a: OrderArgs) -> Result<()> {
    a.scene.research = a.research.clone();
    let (set, content) = load_scene(&a.scene)?;
    let cam = camera_of(&a.scene, set.grid(), &content)?;
    let kind = a.research.order.parse::<OrderKind>()?;
    let seq = if kind == OrderKind::Pbtf && !a.scene.cpu {
        let mut r = renderer_of(&a.scene)?;
        r.set_scene(set.clone())?;
        let s = voxsplat::low_level::pbtf_order(&mut r, &cam, Direction::BackToFront)?;
        report_validation(&r)?;
        s
    } else {
        order::visibility_order(&set, &cam, kind, Direction::BackToFront)
    };
    if let Some(path) = &a.dump {
        let io = |e| Error::Io { path: path.display().to_string(), source: e };
        let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
        for &s in &seq {
            let ijk = set.splats()[s as usize].ijk;
            let p = set.grid().position([ijk[0], ijk[1], ijk[2]]);
            writeln!(f, "{},{},{},{},{},{}", ijk[0], ijk[1], ijk[2], p.x, p.y, p.z).map_err(io)?;
        }
        f.flush().map_err(io)?;
    }
    println!("splats: {}", seq.len());
    if a.check {
        let radius = voxsplat::kernel::Kernel::default().radius();
        let p = order::count_pixel_inversions(&set, &cam, &seq, Direction::BackToFront, radius)?;
        println!(
            "pixel inversions: {} in {} of {} covered pixels, {} of them between kernels apart along the ray",
            p.inversions, p.pixels, p.covered, p.separated
        );
        let v = order::count_violations(&set, &cam, &seq, Direction::BackToFront)?;
        println!("violations: {v}");
    }
    Ok(())
}
