//! What `voxsplat render` opens and how: the scene flags shared by the commands and the viewer
//! example (`SceneArgs`, in `scene_args`), their parsers (`parse`), the camera they describe, and
//! loading the scene as host splats or a bricked store classified on the device.
mod parts;
use glam::Vec3;
pub use parts::Parts;
use voxsplat::orient::Orientation;
use voxsplat::{camera::Projection, scene, Backend, Camera, Error, Renderer, RendererOptions, Result};

pub use crate::parse::{parse_background, parse_dims, parse_finite, parse_floats, parse_level, parse_size, parse_vec3};
pub use crate::scene_args::SceneArgs;

/// What a camera frames beyond the grid: the file's placement in patient space, and the box of
/// voxels the transfer function shows (grid indices).
#[derive(Clone, Copy, Debug, Default)]
pub struct Content {
    /// The --volume file's placement (`None`: no anatomical frame; the grid's frame is the world).
    pub orientation: Option<Orientation>,
    /// Smallest and largest index of a visible voxel (`None`: frame the whole grid).
    pub bounds: Option<[[u32; 3]; 2]>,
}

/// The --volume file's placement in patient space, if its header gives one. With --positions the
/// positions file places the voxels instead (a left-handed file, stored x-reversed, is refused).
pub fn orientation_of(a: &SceneArgs) -> Result<Option<Orientation>> {
    match &a.volume {
        Some(path) if a.terrain.is_none() => {
            // No level is read for it (a pyramid's levels share their placement); a DICOM series
            // drawn at its slices' positions is placed by its first slice and mean gap.
            let hints =
                voxsplat::loaders::VolumeHints { rectilinear: at_positions(a, path)?, ..volume_hints_at(a, None)? };
            let o = voxsplat::loaders::load_orientation(path, &hints)?;
            if a.positions.is_some() {
                if o.is_some_and(|o| o.flip_x()) {
                    return Err(Error::Unsupported(
                        "--positions with a left-handed file (its x is stored reversed): give the positions in \
                         a right-handed file's order"
                            .into(),
                    ));
                }
                return Ok(None);
            }
            Ok(o)
        }
        _ => Ok(None),
    }
}

/// The camera `a` asks for, in the grid's frame (`Grid::centered`). With an anatomical frame,
/// --eye, --target and --up are world (patient) coordinates, mapped into the grid's frame.
pub fn camera_of(a: &SceneArgs, grid: &voxsplat::Grid, content: &Content) -> Result<Camera> {
    let (w, h) = a.size;
    if let Some(s) = &a.session {
        return s.camera(w, h);
    }
    let o = content.orientation;
    let view = match a.view.as_str() {
        "auto" if a.terrain.is_some() || a.scene == "rmnp" => "flyover",
        "auto" if voxsplat::scene::peer::side_of(&a.scene).is_some() && a.volume.is_none() => "peer",
        "auto" if o.is_some() => "oblique",
        "auto" => "framing",
        v => v,
    };
    let anatomical = voxsplat::orient::VIEWS.contains(&view);
    if anatomical && o.is_none() {
        return Err(Error::InvalidArgument(format!(
            "--view {view} names a side of the patient: it needs a volume whose file gives an anatomical frame \
             (NIfTI sform/qform, NRRD space); use --view framing"
        )));
    }
    let grazing = view == "grazing" || view == "flyover";
    let top = grid.dims.map(|d| d - 1);
    let [lo, hi] = content.bounds.unwrap_or([[0; 3], top]).map(|c| Vec3::from(c.map(|v| v as f32)));
    let [lo, hi] = grid.world_box(lo, hi);
    let ks = grid.kernel_spacing();
    let mut cam = match (view, o) {
        ("grazing", _) => Camera::grazing(grid, w, h),
        ("flyover", _) => Camera::flyover(grid, w, h),
        ("peer", _) => {
            if w != h {
                return Err(Error::InvalidArgument("the peer view is square: use --size NxN".into()));
            }
            voxsplat::scene::peer::camera(grid.dims[0], w)
        }
        (v, Some(o)) if anatomical => {
            let (dir, up) = v.parse::<voxsplat::orient::View>()?.directions();
            Camera::framing_box(lo, hi, ks, o.dir_to_grid(dir), o.dir_to_grid(up), w, h)
        }
        _ => Camera::framing_box(lo, hi, ks, Vec3::new(0.55, 0.45, 1.0), Vec3::Y, w, h),
    };
    let point = |p: Vec3| o.map_or(p, |o| o.to_grid(p));
    let dir = |v: Vec3| o.map_or(v, |o| o.dir_to_grid(v));
    let fitted_eye = cam.eye;
    let fitted_target = cam.target;
    if let Some(t) = a.target {
        cam.target = point(t);
    }
    if let Some(e) = a.eye {
        cam.eye = point(e);
    } else if a.target.is_some() {
        cam.eye = cam.target + (fitted_eye - fitted_target);
    }
    match a.up {
        Some(u) => cam.up = dir(u),
        None if o.is_none() && (!grazing || a.eye.is_some()) => cam.up = Vec3::Y,
        None => {}
    }
    // Looking along the up it was not told: another up, as a viewer would pick (the view was
    // refused as "up is parallel").
    let view = (cam.target - cam.eye).normalize_or_zero();
    if a.up.is_none() && view.cross(cam.up.normalize_or_zero()).length() < 1e-4 {
        cam.up = if view.cross(Vec3::Z).length() >= 1e-3 { Vec3::Z } else { Vec3::X };
    }
    if let Some(fov) = a.fov {
        cam.projection = Projection::Perspective { fov_y_deg: fov };
    }
    if let Some(hgt) = a.ortho {
        cam.projection = Projection::Orthographic { height: hgt };
    }
    // Fit near/far to the scene's bounding sphere seen from this eye unless given, widened by the
    // splats' cull margin (`Camera::cull_margin`; what anti-aliasing widens is never culled). The
    // near plane from the sphere's depth along the view, not its distance: a --target away from
    // the scene puts it off the axis, nearer in depth than in distance (it was clipped away).
    let d = (grid.center() - cam.eye).length();
    let depth = (grid.center() - cam.eye).dot(cam.forward());
    let r = 0.5 * grid.diagonal() + (4.0 * grid.kernel_spacing()).max(Camera::cull_margin(grid.kernel_spacing()));
    // Margins relative to the scene, not in units: spacings in metres (1e-4 and below) are common.
    // An eye at what the view looks at has no view: say which flag to add.
    if a.eye.is_some() && a.target.is_none() && (cam.eye - cam.target).length() <= 1e-6 * r {
        let e = a.eye.unwrap_or_default();
        return Err(Error::InvalidArgument(format!(
            "--eye {},{},{} is the point the view looks at (the centre of what it frames): give --target too",
            e.x, e.y, e.z
        )));
    }
    // An eye inside the scene sees from a near plane a small share of the scene's size ahead.
    let fit_near = if cam.is_perspective() { (depth - r).max(1e-3 * d).max(1e-4 * r) } else { depth - 1.5 * r };
    cam.near = a.near.unwrap_or(if grazing { cam.near } else { fit_near });
    cam.far = a.far.unwrap_or(if grazing { cam.far } else { d + 1.5 * r });
    cam.validate()?;
    Ok(cam)
}

pub type VolumeParts =
    (voxsplat::volume::ScalarVolume, voxsplat::classify::TransferFunction, Option<voxsplat::classify::Shading>);

/// The --tf preset or TOML file.
pub fn transfer_function(a: &SceneArgs) -> Result<voxsplat::classify::TransferFunction> {
    match &a.session {
        Some(s) => Ok(s.tf.clone()),
        None => load_tf(tf_spec(a)),
    }
}

/// What --tf names, `ramp` when it is not given.
fn tf_spec(a: &SceneArgs) -> &str {
    a.tf.as_deref().unwrap_or("ramp")
}

/// A transfer-function preset by name, or a TOML file.
pub fn load_tf(spec: &str) -> Result<voxsplat::classify::TransferFunction> {
    if spec.ends_with(".toml") {
        let text = voxsplat::loaders::read_text(std::path::Path::new(spec), spec)?;
        voxsplat::classify::TransferFunction::from_toml(&text)
    } else {
        voxsplat::classify::TransferFunction::preset(spec)
    }
}

/// The --dims, --dtype, --big-endian and --spacing hints for the --volume file.
pub fn volume_hints(a: &SceneArgs) -> Result<voxsplat::loaders::VolumeHints> {
    let level =
        match a.level.as_deref() {
            None => None,
            Some("auto") => return Err(Error::InvalidArgument(
                "--level auto picks a level of an OME-Zarr --volume drawn from its bricked store (not with --dense, \
                 --labels, --channel, --channel-tf or host splats); give --level N"
                    .into(),
            )),
            Some(n) => Some(n.parse().expect("checked by parse_level")),
        };
    volume_hints_at(a, level)
}

/// `volume_hints` with the pyramid level `level`.
fn volume_hints_at(a: &SceneArgs, level: Option<u32>) -> Result<voxsplat::loaders::VolumeHints> {
    Ok(voxsplat::loaders::VolumeHints {
        dims: a.dims,
        dtype: a.dtype.as_deref().map(str::parse).transpose()?,
        big_endian: a.big_endian,
        spacing: a.spacing.map(|v| v.to_array()),
        series: a.series.clone(),
        level,
        time: a.time,
        rectilinear: false,
        crop: a.crop,
        view: a.view_read,
        ..Default::default()
    })
}

/// With --shade, a headlight along the view of a grid of `dims` x `spacing` (placed by
/// `orientation`).
pub fn headlight(
    a: &SceneArgs,
    dims: [u32; 3],
    spacing: [f32; 3],
    orientation: Option<Orientation>,
) -> Option<voxsplat::classify::Shading> {
    if let Some(s) = &a.session {
        return s.shading();
    }
    let by_default = voxsplat::classify::SHADED_PRESETS.contains(&tf_spec(a));
    a.shading().unwrap_or(by_default).then(|| {
        let g = voxsplat::Grid::centered(dims, spacing).ok();
        let content = Content { orientation, bounds: None };
        let forward = g.and_then(|g| camera_of(a, &g, &content).ok()).map(|c| c.forward()).unwrap_or(Vec3::NEG_Z);
        voxsplat::classify::Shading::headlight(forward)
    })
}

/// The --volume file, its transfer function and shading (a headlight along the view of the file
/// placed by `orientation`, `orientation_of`'s).
pub fn load_volume_parts(
    a: &SceneArgs,
    path: &std::path::Path,
    orientation: Option<Orientation>,
) -> Result<VolumeParts> {
    // A DICOM series drawn at its slices' positions reads at its mean gap; `load_scene` places them.
    let hints = voxsplat::loaders::VolumeHints { rectilinear: at_positions(a, path)?, ..volume_hints(a)? };
    let vol = voxsplat::loaders::load_volume(path, &hints)?;
    let tf = transfer_function(a)?;
    let shading = headlight(a, vol.dims, vol.spacing, orientation);
    Ok((vol, tf, shading))
}

/// The --volume file as a bricked scene (shaded as `load_volume_parts` shades), with a one-line
/// report of the store.
pub fn load_bricked(
    a: &SceneArgs,
    path: &std::path::Path,
    orientation: Option<Orientation>,
) -> Result<voxsplat::bricks::BrickScene> {
    let auto = a.level.as_deref() == Some("auto");
    let mut hints = volume_hints_at(a, None)?;
    hints.level = if auto { None } else { volume_hints(a)?.level };
    if voxsplat::loaders::is_ome_zarr(path) && hints.level.is_none() {
        hints.level = Some(ome_zarr_level(a, path, &hints, auto)?);
    } else if auto {
        return Err(Error::InvalidArgument(format!(
            "{}: --level auto picks a level of an OME-Zarr image",
            path.display()
        )));
    }
    let chunks = voxsplat::loaders::zarr_chunks_read();
    let (bar, terminal) = crate::progress::load_bar(path);
    let progress = match a.progress.clone() {
        Some(window) => voxsplat::loaders::Progress::new(move |read, of| {
            terminal.report(read, of);
            window.report(read, of);
        }),
        None => terminal,
    };
    let mut store = voxsplat::bricks::BrickStore::load(
        path,
        &voxsplat::loaders::VolumeHints { progress: Some(progress), ..hints },
    )?;
    bar.finish_and_clear();
    if voxsplat::loaders::is_ome_zarr(path) {
        // The value range's pass (the bricks' takes what it kept, when that fits); before it, what
        // choosing the level read.
        let read = voxsplat::loaders::zarr_chunks_read() - chunks;
        eprintln!("OME-Zarr: the store read {read} chunks ({chunks} read before it to choose the level)");
    }
    if let Some(o) = &orientation {
        store.place(o)?;
    }
    let tf = transfer_function(a)?;
    let shading = headlight(a, store.dims, store.spacing, orientation);
    eprintln!(
        "{} stored voxels in {} bricks of {}^3, {:.2} bytes per stored voxel on the GPU ({} x {} x {} grid)",
        store.len(),
        store.headers.len(),
        voxsplat::bricks::BRICK,
        store.bytes() as f64 / store.len().max(1) as f64,
        store.dims[0],
        store.dims[1],
        store.dims[2]
    );
    voxsplat::bricks::BrickScene::new(store, tf, shading)
}

/// The level of an OME-Zarr --volume to draw, reported when it is not the finest: by default
/// `OmeZarr::default_level`; with `auto` the one --view needs (`OmeZarr::level_for`): the view
/// framed on what the coarsest level shows (the levels span one extent, and it reads fastest),
/// then the coarsest level whose voxels project to at most `LEVEL_PIXELS` there.
fn ome_zarr_level(
    a: &SceneArgs,
    path: &std::path::Path,
    hints: &voxsplat::loaders::VolumeHints,
    auto: bool,
) -> Result<u32> {
    let image = voxsplat::loaders::OmeZarr::open(path)?;
    let last = image.levels.len() as u32 - 1;
    if !auto || last == 0 {
        let level = image
            .default_level_within(hints.crop, hints.view.as_ref())
            .ok_or_else(|| Error::InvalidArgument(format!("{}: --crop holds no voxel of the image", path.display())))?;
        let within = if hints.crop.is_some() { " for the part read" } else { "" };
        if level > 0 {
            let l = &image.levels[level as usize];
            eprintln!(
                "OME-Zarr level {level} of 0..{last} drawn ({:?} voxels): the finer ones may not fit the host's memory{within} \
                 (--host-budget-mib, --level N)",
                l.dims
            );
        }
        return Ok(level);
    }
    let coarse = voxsplat::loaders::VolumeHints { level: Some(last), ..hints.clone() };
    let store = voxsplat::bricks::BrickStore::load(path, &coarse)?;
    let grid = store.grid()?;
    let scene = voxsplat::bricks::BrickScene::new(store, transfer_function(a)?, None)?;
    let camera = camera_of(a, &grid, &Content { orientation: None, bounds: scene.visible_bounds() })?;
    let level = image.level_for(&camera, voxsplat::loaders::LEVEL_PIXELS);
    let l = &image.levels[level as usize];
    eprintln!(
        "OME-Zarr level {level} of 0..{last} drawn ({:?} voxels, spacing {:?}): its voxels span at most {:.2} px in this \
         view (levels are picked at {} px; --level N draws another)",
        l.dims,
        l.spacing,
        image.voxel_pixels(&camera, level),
        voxsplat::loaders::LEVEL_PIXELS
    );
    Ok(level)
}

/// The splats named by --volume, --terrain or --scene, with a one-line report of what was loaded,
/// and what a camera frames of them: a volume's placement and the voxels its transfer function
/// shows (a rectilinear grid's voxels lie at its --positions: framed whole).
pub fn load_scene(a: &SceneArgs) -> Result<(voxsplat::SplatSet, Content)> {
    load_scene_parts(a).map(|(set, content, _)| (set, content))
}

/// `load_scene`, and for labels or channels what they were classified from (the viewer
/// classifies them again as its panel shows or hides one).
pub fn load_scene_parts(a: &SceneArgs) -> Result<(voxsplat::SplatSet, Content, Option<Parts>)> {
    let orientation = orientation_of(a)?;
    let parts = Parts::load(a, orientation)?;
    let set = if let (Some(parts), true) = (&parts, a.labels.is_some()) {
        parts.classify(true)?
    } else if let Some(path) = &a.volume {
        let set = match &parts {
            Some(channels) => channels.classify(true)?,
            None => {
                let (vol, tf, shading) = load_volume_parts(a, path, orientation)?;
                let grid = voxsplat::orient::placed_grid(vol.dims, vol.spacing, orientation.as_ref())?;
                voxsplat::classify::classify_on(grid, &vol, &tf, shading)?
            }
        };
        match &a.positions {
            Some(p) => {
                let coords = voxsplat::loaders::load_positions(p, set.grid())?;
                set.with_coordinates(coords)?
            }
            None if at_positions(a, path)? => match crate::uneven::positions(path, &volume_hints(a)?, set.grid())? {
                Some(coords) => set.with_coordinates(coords)?,
                None => set,
            },
            None => set,
        }
    } else if let Some(path) = &a.terrain {
        // (clap drops `requires = "volume"` when --terrain, which conflicts with it, is given.)
        if a.dims.is_some() || a.dtype.is_some() || a.big_endian || a.spacing.is_some() {
            return Err(Error::InvalidArgument(
                "--dims, --dtype, --big-endian and --spacing describe --volume files, not --terrain".into(),
            ));
        }
        if a.tf.is_some() {
            return Err(Error::InvalidArgument(
                "--tf colours a --volume; a --terrain is coloured by its height or by --color".into(),
            ));
        }
        let heights = voxsplat::loaders::load_heights(path)?;
        let color = match &a.color {
            Some(c) => Some(voxsplat::output::read_rgba8(c)?),
            None => None,
        };
        let opts = voxsplat::terrain::TerrainOptions { cell: a.cell, vscale: a.vscale, color, ..Default::default() };
        voxsplat::terrain::terrain_splats(&heights, &opts)?
    } else {
        refuse_volume_flags(a)?;
        scene::build(&a.scene)?
    };
    eprintln!(
        "{} splats, {:.0} bytes per splat on the GPU ({} x {} x {} grid)",
        set.len(),
        voxsplat::volume::gpu_bytes_per_splat(&set),
        set.grid().dims[0],
        set.grid().dims[1],
        set.grid().dims[2]
    );
    let bounds = if a.volume.is_some() && a.positions.is_none() { set.bounds() } else { None };
    Ok((set, Content { orientation, bounds }, parts))
}

/// `mib` MiB in bytes: positive, and without wrapping past u64.
pub fn mib_bytes(mib: u64, flag: &str) -> Result<u64> {
    match mib.checked_mul(1 << 20) {
        Some(b) if b > 0 => Ok(b),
        Some(_) => Err(Error::InvalidArgument(format!("{flag} must be positive"))),
        None => {
            Err(Error::InvalidArgument(format!("{flag} {mib} overflows a byte count (at most {} MiB)", u64::MAX >> 20)))
        }
    }
}

pub fn renderer_of(a: &SceneArgs) -> Result<Renderer> {
    let mut opts = RendererOptions::default();
    opts.backend = if a.cpu { Backend::Cpu } else { Backend::Gpu };
    opts.validation = a.validation;
    opts.gpu_budget_bytes = a.gpu_budget_mib.map(|m| mib_bytes(m, "--gpu-budget-mib")).transpose()?;
    let mut r = Renderer::new(&opts)?;
    r.set_bisect(a.research.bisect)?;
    Ok(r)
}

pub fn report_validation(r: &Renderer) -> Result<()> {
    let n = r.validation_count();
    if n > 0 {
        for m in r.validation_messages() {
            eprintln!("validation: {m}");
        }
        return Err(Error::Unsupported(format!("{n} validation message(s)")));
    }
    Ok(())
}

/// A built-in scene has its own colours and grid: what describes a --volume would be ignored.
fn refuse_volume_flags(a: &SceneArgs) -> Result<()> {
    let given = [
        (a.tf.is_some(), "--tf"),
        (a.spacing.is_some(), "--spacing"),
        (a.positions.is_some(), "--positions"),
        (a.dims.is_some(), "--dims"),
        (a.dtype.is_some(), "--dtype"),
        (a.big_endian, "--big-endian"),
    ];
    match given.iter().find(|g| g.0) {
        Some((_, flag)) => Err(Error::InvalidArgument(format!(
            "{flag} describes a --volume file; the built-in scene '{}' has its own colours and grid",
            a.scene
        ))),
        None => Ok(()),
    }
}

/// Whether --volume's file places its voxels and classifies them itself: no --positions file
/// places them, no --labels classify them.
fn file_places(a: &SceneArgs) -> bool {
    a.positions.is_none() && a.labels.is_none()
}

/// Whether --volume is a DICOM series drawn at its slices' own positions (`uneven::at_positions`).
fn at_positions(a: &SceneArgs, path: &std::path::Path) -> Result<bool> {
    Ok(file_places(a) && crate::uneven::at_positions(path, &volume_hints_at(a, None)?)?)
}

/// The scene `a` names: a --volume as a bricked store classified on the device unless
/// `host_splats` (a mode that needs host splats), else host splats; with the grid's splat set
/// (empty for a bricked store) for cameras and orders, and what a camera frames (`Content`).
pub fn open(
    a: &SceneArgs,
    host_splats: bool,
) -> Result<(Option<voxsplat::bricks::BrickScene>, voxsplat::SplatSet, Content)> {
    let peer = voxsplat::scene::peer::side_of(&a.scene).filter(|_| a.volume.is_none() && a.terrain.is_none());
    if a.research.dense && a.volume.is_none() && peer.is_none() {
        return Err(Error::InvalidArgument(
            "--dense classifies a --volume or the peers' scene (--scene peer128, peer256) on the host; this scene is \
             already a classified splat set"
                .into(),
        ));
    }
    // An unevenly spaced DICOM series is resampled evenly (said here), or when its gaps are too far
    // apart, drawn as a rectilinear grid: host splats.
    if let Some(path) = &a.volume {
        crate::uneven::say_left_out(path, &volume_hints_at(a, None)?)?;
    }
    let uneven = match &a.volume {
        Some(path) if file_places(a) => crate::uneven::report(path, &volume_hints_at(a, None)?)?,
        _ => false,
    };
    let (bricked, orientation) = match (&a.volume, peer) {
        (Some(path), _)
            if !host_splats
                && !a.research.dense
                && !uneven
                && file_places(a)
                && a.channels.is_empty()
                && a.channel_tfs.is_empty() =>
        {
            let orientation = orientation_of(a)?;
            (load_bricked(a, path, orientation)?, orientation)
        }
        (None, Some(n)) if !host_splats && !a.research.dense => {
            refuse_volume_flags(a)?;
            let store = voxsplat::bricks::BrickStore::build(&voxsplat::scene::peer::volume(n)?)?;
            eprintln!("{} stored voxels in {} bricks", store.len(), store.headers.len());
            (voxsplat::bricks::BrickScene::new(store, voxsplat::scene::peer::transfer_function(), None)?, None)
        }
        _ => return load_scene(a).map(|(set, content)| (None, set, content)),
    };
    let set = voxsplat::SplatSet::empty(bricked.store.grid()?)?;
    let content = Content { orientation, bounds: bricked.visible_bounds() };
    Ok((Some(bricked), set, content))
}

/// `--iso` (in the file's units) in the scene's normalised values: a bricked store's by its
/// values' range; a built-in scene's as given. A volume file on the host path is refused (its
/// classification normalises by the transfer function).
pub fn normalised_iso(
    bricked: Option<&voxsplat::bricks::BrickScene>,
    scene: &SceneArgs,
    iso: Option<f32>,
) -> Result<Option<f32>> {
    Ok(match (bricked, iso) {
        (Some(b), Some(v)) => {
            let (lo, hi) = b.store.range;
            Some(if hi > lo { (v - lo) / (hi - lo) } else { v - lo })
        }
        (None, Some(_)) if scene.volume.is_some() => {
            return Err(Error::InvalidArgument(
                "--mode iso reads a volume file's values from its bricked store: drop --dense, --labels, --channel \
                 and --positions"
                    .into(),
            ))
        }
        (_, v) => v,
    })
}
