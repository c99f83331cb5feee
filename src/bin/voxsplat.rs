//! The voxsplat command line: list scenes, render a frame, dump or check a visibility order.
use clap::{Args, Parser, Subcommand};
use glam::Vec3;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use voxsplat::{
    order, scene, Backend, Camera, Composite, Direction, Error, Kernel, OrderKind, Projection, RenderOptions, Renderer,
    RendererOptions, Result,
};

#[derive(Parser)]
#[command(name = "voxsplat", version, about = "Splatting renderer for discrete objects (Swan 1997) on Vulkan")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenes.
    Scenes,
    /// Render a scene to a PNG (straight alpha) or EXR (premultiplied alpha).
    Render(RenderArgs),
    /// Write or check a visibility order (back to front).
    Order(OrderArgs),
    /// Time the benchmark cases (cube60 and the plane at 512x512): per-stage medians.
    Bench(BenchArgs),
}

#[derive(Args)]
struct BenchArgs {
    /// Measured frames per case (after 2 warm-up frames).
    #[arg(long, default_value_t = 9)]
    frames: usize,
    /// Time the CPU mirrors instead of the GPU.
    #[arg(long)]
    cpu: bool,
}

fn parse_vec3(s: &str) -> std::result::Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 3 {
        return Err(format!("expected X,Y,Z, got '{s}'"));
    }
    let mut v = [0.0f32; 3];
    for (o, p) in v.iter_mut().zip(parts) {
        *o = p.trim().parse::<f32>().map_err(|_| format!("'{p}' is not a number"))?;
        if !o.is_finite() {
            return Err(format!("'{p}' is not finite"));
        }
    }
    Ok(Vec3::from(v))
}

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width '{w}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height '{h}'"))?;
    if w == 0 || h == 0 {
        return Err("image size must be at least 1x1".into());
    }
    Ok((w, h))
}

fn parse_finite(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("'{s}' is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("'{s}' is not finite"))
    }
}

#[derive(Args)]
struct SceneArgs {
    /// Built-in scene name (see `voxsplat scenes`).
    #[arg(long, default_value = "cube60")]
    scene: String,
    /// Eye position (default: a three-quarter view framing the scene).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<Vec3>,
    /// Look-at point (default: the scene's centre).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    target: Option<Vec3>,
    /// Up vector.
    #[arg(long, value_parser = parse_vec3, default_value = "0,1,0", allow_hyphen_values = true)]
    up: Vec3,
    /// Vertical field of view in degrees (perspective).
    #[arg(long, value_parser = parse_finite, conflicts_with = "ortho", allow_hyphen_values = true)]
    fov: Option<f32>,
    /// Orthographic projection with this view height (world units).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    ortho: Option<f32>,
    /// Near plane distance (default: fitted to the scene).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    near: Option<f32>,
    /// Far plane distance (default: fitted to the scene).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    far: Option<f32>,
    /// Image size.
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    size: (u32, u32),
    /// Visibility order.
    #[arg(long, default_value = "pbtf", value_parser = ["btf", "wbtf", "pbtf", "sorted"])]
    order: String,
    /// Run every stage on the CPU mirrors instead of Vulkan.
    #[arg(long)]
    cpu: bool,
    /// Enable the Khronos validation layer and report its messages.
    #[arg(long)]
    validation: bool,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Per-splat compositing or Westover's sheet summation buffer.
    #[arg(long, default_value = "splat", value_parser = ["splat", "sheet"])]
    composite: String,
    /// Reconstruction kernel.
    #[arg(long, default_value = "gaussian", value_parser = ["gaussian", "cubic"])]
    kernel: String,
    /// Traversal direction (default: back to front for splats, front to back for sheets).
    #[arg(long, value_parser = ["ftb", "btf"])]
    direction: Option<String>,
    /// Memory budget for one batch of sheet summation layers, in MiB.
    #[arg(long, default_value_t = 256)]
    sheet_budget_mib: u64,
    /// Print per-stage times.
    #[arg(long)]
    timings: bool,
    /// Output file, .png or .exr.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args)]
struct OrderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Write the back-to-front sequence as `i,j,k,x,y,z` lines.
    #[arg(long)]
    dump: Option<PathBuf>,
    /// Count 6-neighbour pairs drawn in the wrong order; prints `violations: N` last.
    #[arg(long)]
    check: bool,
}

fn camera_of(a: &SceneArgs, grid: &voxsplat::Grid) -> Result<Camera> {
    let (w, h) = a.size;
    let mut cam = Camera::framing(grid, w, h);
    let fitted_eye = cam.eye;
    if let Some(t) = a.target {
        cam.target = t;
    }
    if let Some(e) = a.eye {
        cam.eye = e;
    } else if a.target.is_some() {
        cam.eye = cam.target + (fitted_eye - grid.center());
    }
    cam.up = a.up;
    if let Some(fov) = a.fov {
        cam.projection = Projection::Perspective { fov_y_deg: fov };
    }
    if let Some(hgt) = a.ortho {
        cam.projection = Projection::Orthographic { height: hgt };
    }
    // Fit near/far to the scene's bounding sphere seen from this eye unless given.
    let d = (grid.center() - cam.eye).length();
    let r = 0.5 * grid.diagonal() + 4.0 * grid.kernel_spacing();
    cam.near = a.near.unwrap_or(if cam.is_perspective() { (d - r).max(1e-3 * d.max(1.0)) } else { d - r - 1.0 });
    cam.far = a.far.unwrap_or(d + r + 1.0);
    cam.validate()?;
    Ok(cam)
}

fn renderer_of(a: &SceneArgs) -> Result<Renderer> {
    let mut opts = RendererOptions::default();
    opts.backend = if a.cpu { Backend::Cpu } else { Backend::Gpu };
    opts.validation = a.validation;
    Renderer::new(&opts)
}

fn report_validation(r: &Renderer) -> Result<()> {
    let n = r.validation_count();
    if n > 0 {
        for m in r.validation_messages() {
            eprintln!("validation: {m}");
        }
        return Err(Error::Unsupported(format!("{n} validation message(s)")));
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Scenes => {
            for (name, about) in scene::SCENES {
                println!("{name:<18} {about}");
            }
            Ok(())
        }
        Command::Render(a) => {
            let set = scene::build(&a.scene.scene)?;
            let cam = camera_of(&a.scene, set.grid())?;
            let mut opts = RenderOptions::default();
            opts.order = a.scene.order.parse::<OrderKind>()?;
            opts.composite = a.composite.parse::<Composite>()?;
            opts.kernel = a.kernel.parse::<Kernel>()?;
            opts.direction =
                a.direction
                    .as_deref()
                    .map(|d| if d == "ftb" { Direction::FrontToBack } else { Direction::BackToFront });
            if a.sheet_budget_mib == 0 {
                return Err(Error::InvalidArgument("--sheet-budget-mib must be positive".into()));
            }
            opts.sheet_budget_bytes = a.sheet_budget_mib << 20;
            let splats = set.len();
            let mut r = renderer_of(&a.scene)?;
            r.set_scene(set)?;
            let frame = r.render(&cam, &opts)?;
            voxsplat::output::write_image(&frame.image, &a.out)?;
            report_validation(&r)?;
            eprintln!("{} splats on {} -> {}", splats, r.device_name(), a.out.display());
            if a.timings {
                for t in &frame.timings {
                    println!("{:<14} {:>9.3} ms", t.stage, t.ms);
                }
            }
            Ok(())
        }
        Command::Bench(a) => {
            if a.frames == 0 {
                return Err(Error::InvalidArgument("--frames must be positive".into()));
            }
            let mut opts = RendererOptions::default();
            opts.backend = if a.cpu { Backend::Cpu } else { Backend::Gpu };
            let mut r = Renderer::new(&opts)?;
            println!("device: {}", r.device_name());
            let mut rows = Vec::new();
            let cases = voxsplat::bench::default_cases();
            for (i, case) in cases.iter().enumerate() {
                eprintln!("[{}/{}] {}", i + 1, cases.len(), case.label());
                rows.push(voxsplat::bench::measure(&mut r, case, 2, a.frames)?);
            }
            print!("{}", voxsplat::bench::table(&rows));
            Ok(())
        }
        Command::Order(a) => {
            let set = scene::build(&a.scene.scene)?;
            let cam = camera_of(&a.scene, set.grid())?;
            let kind = a.scene.order.parse::<OrderKind>()?;
            let seq = if kind == OrderKind::Pbtf && !a.scene.cpu {
                let mut r = renderer_of(&a.scene)?;
                r.set_scene(set.clone())?;
                let s = r.pbtf_order(&cam, Direction::BackToFront)?;
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
                let v = order::count_violations(&set, &cam, &seq, Direction::BackToFront)?;
                println!("violations: {v}");
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
