//! `voxsplat slice`: one plane of a volume's voxels as a grey PNG, windowed (the views of the data
//! that a viewer shows beside the frame).
use super::*;
use voxsplat_cli::println;

#[derive(Args)]
pub(crate) struct SliceArgs {
    /// The volume file (any that `render --volume` reads).
    file: PathBuf,
    /// The grid axis the plane cuts across, as the file stores it: z (the image's x across, y
    /// down), y (x across, z down) or x (y across, z down).
    #[arg(long, default_value = "z", value_parser = ["x", "y", "z"])]
    axis: String,
    /// The plane's voxel index along --axis, from 0 [default: the middle].
    #[arg(long)]
    index: Option<u32>,
    /// The values drawn black and white, LO,HI in the file's units [default: the plane's own
    /// smallest and largest].
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
    /// The channel to cut, from 0, of a file of several (a NIfTI's or NRRD's vector axis).
    #[arg(long)]
    channel: Option<u32>,
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
    let mut hints =
        voxsplat::loaders::VolumeHints { series: a.series, time: a.time, level: a.level, ..Default::default() };
    voxsplat_cli::uneven::say_left_out(&a.file, &hints)?;
    // A series too unevenly spaced to resample is cut as it is stored: one plane per image.
    if voxsplat_cli::uneven::at_positions(&a.file, &hints)? {
        hints.rectilinear = true;
        eprintln!("note: uneven slice gaps, too far apart to resample evenly: cut as stored, one plane per image");
    }
    let (dims, index, plane) = read_plane(&a.file, &hints, axis, a.index, &a.axis, a.channel)?;
    let [lo, hi] = a.window.unwrap_or_else(|| voxsplat::volume::value_span(&plane.values).into());
    let span = if hi > lo { hi - lo } else { 1.0 };
    let grey: Vec<u8> =
        plane.values.iter().map(|&v| ((v - lo) / span * 255.0).round().clamp(0.0, 255.0) as u8).collect();
    image::save_buffer(&a.out, &grey, plane.width, plane.height, image::ExtendedColorType::L8)
        .map_err(|e| Error::InvalidArgument(format!("{}: {e}", a.out.display())))?;
    println!(
        "plane {} = {index} of the {:?} grid, {} x {} voxels, values {lo} .. {hi} drawn black to white -> {}",
        a.axis,
        dims,
        plane.width,
        plane.height,
        a.out.display()
    );
    Ok(())
}

/// The grid's dims, the index and the plane `index` (the middle by default) across `axis` (`name`) of the
/// file's values as stored: a z plane reads its one slice, an x or y plane a row of each slice,
/// slab by slab with a progress bar; a file that does not stream (`.npy`) is loaded whole.
fn read_plane(
    path: &std::path::Path,
    hints: &voxsplat::loaders::VolumeHints,
    axis: usize,
    index: Option<u32>,
    name: &str,
    channel: Option<u32>,
) -> Result<([u32; 3], u32, voxsplat::bricks::Plane)> {
    let whole = match picked_channel(path, hints, channel)? {
        Some(v) => Ok(v),
        None => match voxsplat::loaders::SliceReader::open(path, hints)? {
            Some(reader) => Err(reader),
            None => Ok(voxsplat::loaders::load_volume(path, hints)?),
        },
    };
    let dims = match &whole {
        Ok(v) => v.dims,
        Err(r) => r.dims,
    };
    let index = index.unwrap_or(dims[axis] / 2);
    if index >= dims[axis] {
        return Err(Error::InvalidArgument(format!(
            "--index {index}: the {name} axis has {} voxels (0 to {})",
            dims[axis],
            dims[axis] - 1
        )));
    }
    let [nx, ny, nz] = dims;
    // In usize: a plane of two large sides passes u32.
    let plane = nx as usize * ny as usize;
    // Slice z's part of the plane: all of it across z, row y = index across y, column x = index across x.
    let take = |slice: &[f32], out: &mut Vec<f32>| match axis {
        2 => out.extend_from_slice(slice),
        1 => out.extend_from_slice(&slice[(index * nx) as usize..((index + 1) * nx) as usize]),
        _ => out.extend((0..ny).map(|y| slice[(index + y * nx) as usize])),
    };
    let mut values = Vec::new();
    match whole {
        Ok(v) if axis == 2 => take(&v.values[index as usize * plane..(index as usize + 1) * plane], &mut values),
        Ok(v) => v.values.chunks(plane).for_each(|s| take(s, &mut values)),
        Err(mut reader) if axis == 2 => {
            let mut slab = Vec::new();
            reader.read(index, 1, &mut slab)?;
            take(&slab, &mut values);
        }
        Err(mut reader) => {
            let (bar, _) = voxsplat_cli::progress::load_bar(path);
            bar.set_length(u64::from(nz));
            let mut slab = Vec::new();
            let step = voxsplat::bricks::BRICK;
            for z0 in (0..nz).step_by(step as usize) {
                let count = step.min(nz - z0);
                reader.read(z0, count, &mut slab)?;
                slab.chunks(plane).for_each(|s| take(s, &mut values));
                bar.set_position(u64::from(z0 + count));
            }
            bar.finish_and_clear();
        }
    }
    let (width, height) = [(ny, nz), (nx, nz), (nx, ny)][axis];
    Ok((dims, index, voxsplat::bricks::Plane { width, height, values }))
}

/// Channel `channel` of `path`, read whole, when the file holds several (refused without
/// `--channel`), or `None` for a file of one (refused with `--channel` past 0).
pub(crate) fn picked_channel(
    path: &std::path::Path,
    hints: &voxsplat::loaders::VolumeHints,
    channel: Option<u32>,
) -> Result<Option<voxsplat::loaders::ScalarVolume>> {
    let n = voxsplat::loaders::SliceReader::channels(path)?;
    match channel {
        None if n > 1 => Err(Error::InvalidArgument(format!(
            "{} holds {n} channels: pick one with --channel N (0 to {})",
            path.display(),
            n - 1
        ))),
        Some(c) if c >= n => Err(Error::InvalidArgument(format!(
            "--channel {c}: {} holds {n} channel{} (0 to {})",
            path.display(),
            if n == 1 { "" } else { "s" },
            n - 1
        ))),
        Some(c) if n > 1 => Ok(Some(voxsplat::loaders::load_channels(path, hints)?.swap_remove(c as usize))),
        _ => Ok(None),
    }
}
