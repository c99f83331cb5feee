//! `voxsplat pick`: what one pixel of a view shows (the point, its voxel, value and depth).
use super::*;
use voxsplat_cli::println;

#[derive(Args)]
pub(crate) struct PickArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The pixel X,Y of the view (--size), from the top left corner.
    #[arg(long, value_parser = parse_floats::<2>)]
    at: [f32; 2],
    /// As `render --mode`: composite (the first point where the opacity passes one half), mip or
    /// minip (the point of the largest or smallest value), average or xray (as composite), iso
    /// (the first crossing of --iso).
    #[arg(long, default_value = "composite", value_parser = ["composite", "mip", "minip", "average", "xray", "iso"])]
    mode: String,
    /// As `render --iso`: --mode iso's value, in the volume file's units.
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    iso: Option<f32>,
}

/// Runs `voxsplat pick`.
pub(crate) fn pick(a: PickArgs) -> Result<()> {
    let mut opts = RenderOptions::default();
    opts.mode = a.mode.parse()?;
    // As render opens it: a volume as a bricked store, read where the ray passes.
    let (bricked, set, content) = open(&a.scene, false)?;
    opts.iso = normalised_iso(bricked.as_ref(), &a.scene, a.iso)?;
    let cam = camera_of(&a.scene, set.grid(), &content)?;
    let [x, y] = a.at;
    if !(x >= 0.0 && y >= 0.0 && x < cam.width as f32 && y < cam.height as f32) {
        return Err(Error::InvalidArgument(format!(
            "--at {x},{y}: outside the {} x {} view (--size)",
            cam.width, cam.height
        )));
    }
    let mut ro = RendererOptions::default();
    ro.backend = Backend::Cpu;
    let mut r = Renderer::new(&ro)?;
    match bricked {
        Some(b) => r.set_bricks(b)?,
        None => r.set_scene(set)?,
    }
    match r.pick(&cam, &opts, x.floor() + 0.5, y.floor() + 0.5)? {
        None => println!("pixel {x},{y}: nothing (its ray meets no drawn voxel)"),
        Some(p) => {
            println!("pixel      {x},{y}");
            println!("point      {:.4} {:.4} {:.4} (the grid's world frame)", p.world.x, p.world.y, p.world.z);
            println!("voxel      {} {} {}", p.voxel[0], p.voxel[1], p.voxel[2]);
            let over = if opts.mode == voxsplat::options::Mode::Iso {
                "the volume's values"
            } else {
                "the transfer function's range"
            };
            println!("value      {:.6} (0 to 1 over {over})", p.value);
            println!("depth      {:.4} (along the view, from the eye)", p.depth);
        }
    }
    Ok(())
}
