//! `voxsplat slice`: one plane of a volume's voxels as a grey PNG, windowed (the axial, coronal
//! and sagittal views of the data that a viewer shows beside the frame).
use super::*;

#[derive(Args)]
pub(crate) struct SliceArgs {
    /// The volume file (any that `render --volume` reads).
    file: PathBuf,
    /// The axis the plane cuts across: z (rows along y), y (rows along z) or x (rows along z).
    #[arg(long, default_value = "z", value_parser = ["x", "y", "z"])]
    axis: String,
    /// The plane's voxel index along --axis, from 0 [default: the middle].
    #[arg(long)]
    index: Option<u32>,
    /// The values drawn black and white, LO,HI in the file's units [default: its value range].
    #[arg(long, value_parser = parse_floats::<2>, allow_hyphen_values = true)]
    window: Option<[f32; 2]>,
    /// A folder of several DICOM series: the one to cut (its number or UID in `info`'s list).
    #[arg(long)]
    series: Option<String>,
    /// The time point of a series (needed when it holds several).
    #[arg(long)]
    time: Option<u32>,
    /// An OME-Zarr image's pyramid level [default: as `render` picks it].
    #[arg(long)]
    level: Option<u32>,
    /// The PNG to write (8-bit grey, the plane's row 0 at the top).
    #[arg(long)]
    out: PathBuf,
}

/// Runs `voxsplat slice`.
pub(crate) fn slice(a: SliceArgs) -> Result<()> {
    if !a.out.to_string_lossy().to_ascii_lowercase().ends_with(".png") {
        return Err(Error::InvalidArgument(format!("slice writes PNG: name the output .png, not {}", a.out.display())));
    }
    if let Some([lo, hi]) = a.window.filter(|[lo, hi]| hi <= lo) {
        return Err(Error::InvalidArgument(format!("--window {lo},{hi}: HI must exceed LO")));
    }
    let axis = match a.axis.as_str() {
        "x" => 0,
        "y" => 1,
        _ => 2,
    };
    let (bar, progress) = voxsplat_cli::progress::load_bar(&a.file);
    let hints = voxsplat::loaders::VolumeHints {
        series: a.series,
        time: a.time,
        level: a.level,
        progress: Some(progress),
        ..Default::default()
    };
    let store = voxsplat::bricks::BrickStore::load(&a.file, &hints)?;
    bar.finish_and_clear();
    let index = a.index.unwrap_or(store.dims[axis] / 2);
    if index >= store.dims[axis] {
        return Err(Error::InvalidArgument(format!(
            "--index {index}: the {} axis has {} voxels (0 to {})",
            a.axis,
            store.dims[axis],
            store.dims[axis] - 1
        )));
    }
    let plane = store.plane(axis, index)?;
    let [lo, hi] = a.window.unwrap_or([store.range.0, store.range.1]);
    let span = if hi > lo { hi - lo } else { 1.0 };
    let grey: Vec<u8> =
        plane.values.iter().map(|&v| ((v - lo) / span * 255.0).round().clamp(0.0, 255.0) as u8).collect();
    image::save_buffer(&a.out, &grey, plane.width, plane.height, image::ExtendedColorType::L8)
        .map_err(|e| Error::InvalidArgument(format!("{}: {e}", a.out.display())))?;
    println!(
        "plane {} = {index} of the {:?} grid, {} x {} voxels, values {lo} .. {hi} drawn black to white -> {}",
        a.axis,
        store.dims,
        plane.width,
        plane.height,
        a.out.display()
    );
    Ok(())
}
