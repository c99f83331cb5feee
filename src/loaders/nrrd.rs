//! NRRD headers, and the placement in patient space that NIfTI and NRRD headers give.
use super::{
    bad, check_finite, check_spacing, decode, gunzip, read_bounded, voxel_count_within, DType, ScalarVolume,
    MAX_INFLATED, MAX_TIME_POINTS, MAX_VOXELS,
};
use crate::error::{Error, Result};
use crate::orient::Orientation;
use glam::{DMat4, DVec3, DVec4};
use std::path::Path;

/// An NRRD header's fields.
pub(super) struct NrrdHeader {
    pub dtype: DType,
    pub dims: [u64; 3],
    pub voxels: u64,
    pub encoding: String,
    pub big_endian: bool,
    pub spacing: [f32; 3],
    pub data_file: Option<String>,
    /// Offset of attached data.
    pub data_start: usize,
    /// Placement from `space`, `space directions` and `space origin`, when the space is anatomical.
    pub orientation: Option<Orientation>,
    /// Samples per voxel: a 4-D file's channels (1 for a scalar volume).
    pub channels: u32,
    /// The channels are the fastest axis (interleaved per voxel), else the slowest (one volume
    /// after another).
    pub channel_first: bool,
    /// Time points, one volume after another (a 4-D file whose last axis `kinds` marks `time`): 1
    /// otherwise.
    pub times: u32,
}

/// The time axis of a 4-D NRRD: the one `kinds` marks `time` when the other three are spatial.
/// Only the last (slowest) may be: each time point is then one block of the data.
fn time_axis(kinds: Option<&[String]>, what: &str) -> Result<Option<usize>> {
    let Some(k) = kinds.filter(|k| k.len() == 4) else { return Ok(None) };
    let time: Vec<usize> = (0..4).filter(|&a| k[a] == "time").collect();
    if time.len() != 1 || k.iter().any(|s| !matches!(s.as_str(), "domain" | "space" | "time")) {
        return Ok(None);
    }
    if time[0] != 3 {
        return Err(Error::Unsupported(format!(
            "{what}: kinds '{}': time on axis {}; a series is read with time as its last (slowest) axis",
            k.join(" "),
            time[0]
        )));
    }
    Ok(Some(3))
}

/// Which axis of a 4-D NRRD holds its channels: the one its `kinds` marks as not spatial (neither
/// `domain`, `space` nor `time`), else the first axis if it has at most `MAX_CHANNELS` samples
/// (NRRD puts non-spatial axes first), else the last. Only the first or last may be.
fn channel_axis(sizes: &[u64], kinds: Option<&[String]>, what: &str) -> Result<usize> {
    let most = crate::classify::MAX_CHANNELS as u64;
    let axis = match kinds {
        Some(k) if k.len() == sizes.len() => {
            let spatial = |s: &str| matches!(s, "domain" | "space" | "time");
            let others: Vec<usize> = (0..k.len()).filter(|&a| !spatial(&k[a])).collect();
            match others.as_slice() {
                &[a] => a,
                _ => {
                    return Err(bad(
                        what,
                        format!("kinds '{}': a 4-D volume needs three spatial axes and one of channels", k.join(" ")),
                    ))
                }
            }
        }
        Some(k) => return Err(bad(what, format!("kinds has {} entries for {} axes", k.len(), sizes.len()))),
        None if sizes[0] <= most => 0,
        None if sizes[3] <= most => 3,
        None => {
            return Err(bad(
                what,
                format!("sizes {sizes:?}: a 4-D volume's channel axis (first or last, at most {most}) is not marked"),
            ))
        }
    };
    if axis != 0 && axis != 3 {
        return Err(Error::Unsupported(format!(
            "{what}: channels on axis {axis}; the first or last axis may hold them"
        )));
    }
    if !(1..=most).contains(&sizes[axis]) {
        return Err(Error::Unsupported(format!(
            "{what}: {} channels; a frame combines 1 to {most} (voxsplat render --channel)",
            sizes[axis]
        )));
    }
    Ok(axis)
}

/// Parse the header at the start of `bytes`, allowing at most `limit` voxels.
pub(super) fn nrrd_header(bytes: &[u8], what: &str, limit: u64) -> Result<NrrdHeader> {
    if !bytes.starts_with(b"NRRD000") {
        return Err(bad(what, "not an NRRD file (no NRRD000x magic)"));
    }
    // The header ends at the first blank line.
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .map(|p| (p + 1, p + 2))
        .or_else(|| bytes.windows(4).position(|w| w == b"\r\n\r\n").map(|p| (p + 2, p + 4)));
    let (hdr_end, data_start) = match end {
        Some(e) => e,
        // (A reader passes at most the first MiB: a longer header has no end in it.)
        None if bytes.len() >= 1 << 20 => return Err(bad(what, "header longer than 1 MiB (no blank line ends it)")),
        None => (bytes.len(), bytes.len()),
    };
    if hdr_end > 1 << 20 {
        return Err(bad(what, "header longer than 1 MiB"));
    }
    let header = std::str::from_utf8(&bytes[..hdr_end]).map_err(|_| bad(what, "header is not text"))?;
    let (mut dtype, mut dims, mut enc, mut endian_big, mut spacing, mut data_file) =
        (None, None, None, false, [1.0f32; 3], None::<String>);
    let mut dimension = None;
    let (mut space, mut directions, mut space_origin) = (None, None, None);
    let (mut kinds, mut spacings) = (None::<Vec<String>>, None::<Vec<String>>);
    for line in header.lines().skip(1) {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let Some((key, value)) = line.split_once(':') else { continue };
        let value = value.trim_start_matches('=').trim();
        match key.trim() {
            "type" => dtype = Some(value.parse::<DType>().map_err(|e| bad(what, e))?),
            "dimension" => dimension = Some(value.parse::<u32>().map_err(|_| bad(what, "bad dimension"))?),
            "sizes" => {
                let v: std::result::Result<Vec<u64>, _> = value.split_whitespace().map(|t| t.parse::<u64>()).collect();
                dims = Some(v.map_err(|_| bad(what, "bad sizes"))?);
            }
            "encoding" => enc = Some(value.to_string()),
            "endian" => {
                endian_big = match value {
                    "big" => true,
                    "little" => false,
                    other => return Err(bad(what, format!("endian '{other}': little or big expected"))),
                }
            }
            // Skipped lines or bytes before the data: not read (the data would shift and be read
            // wrong), so refused by name.
            "line skip" | "lineskip" | "byte skip" | "byteskip" if value != "0" => {
                return Err(Error::Unsupported(format!(
                    "{what}: NRRD '{}: {value}' (data after skipped lines or bytes) is not supported; \
                     write the data without the skip",
                    key.trim()
                )));
            }
            "spacings" => spacings = Some(value.split_whitespace().map(str::to_string).collect()),
            "kinds" => kinds = Some(value.split_whitespace().map(|k| k.to_ascii_lowercase()).collect()),
            "data file" | "datafile" => {
                // One detached file; a LIST or a numbered format names several.
                if value.starts_with("LIST") || value.split_whitespace().count() > 1 {
                    return Err(Error::Unsupported(format!(
                        "{what}: NRRD 'data file: {value}' names several data files; one is supported"
                    )));
                }
                data_file = Some(value.to_string())
            }
            "space" => space = Some(value.to_string()),
            "space directions" => directions = Some(value.to_string()),
            "space origin" => space_origin = Some(value.to_string()),
            _ => {}
        }
    }
    let dtype = dtype.ok_or_else(|| bad(what, "no type field"))?;
    let mut sizes = dims.ok_or_else(|| bad(what, "no sizes field"))?;
    if sizes.is_empty() || sizes.len() > 4 || dimension.map(|d| d as usize != sizes.len()).unwrap_or(false) {
        return Err(bad(what, "only 1 to 3 dimensional NRRD volumes, or 4 with a channel axis, are supported"));
    }
    // A 4-D file: its time or channel axis out of the sizes and the spacings.
    let (mut channels, mut channel_first, mut times) = (1u64, false, 1u64);
    let mut spacings = spacings.unwrap_or_default();
    if sizes.len() == 4 {
        if let Some(axis) = time_axis(kinds.as_deref(), what)? {
            times = sizes.remove(axis);
            if !(1..=MAX_TIME_POINTS).contains(&times) {
                return Err(bad(what, format!("{times} time points: a series holds 1 to {MAX_TIME_POINTS}")));
            }
            if spacings.len() == 4 {
                spacings.remove(axis);
            }
        } else {
            let axis = channel_axis(&sizes, kinds.as_deref(), what)?;
            (channels, channel_first) = (sizes.remove(axis), axis == 0);
            if spacings.len() == 4 {
                spacings.remove(axis);
            }
        }
    }
    // Plain numbers, one per axis: a unit ('2mm') or a comma ('2,3,4') read as spacing 1 before.
    if !spacings.is_empty() {
        let line = spacings.join(" ");
        if spacings.len() != sizes.len() {
            return Err(bad(
                what,
                format!(
                    "spacings '{line}' holds {} values for {} axes (numbers apart by spaces)",
                    spacings.len(),
                    sizes.len()
                ),
            ));
        }
        for (i, t) in spacings.iter().enumerate() {
            spacing[i] = t.parse::<f32>().map_err(|_| {
                bad(what, format!("spacings '{line}': '{t}' is not a number (units belong in 'space units')"))
            })?;
        }
    }
    // `space dimension` with `space directions` and no named space: no anatomical frame, but the
    // directions' lengths are the spacing (it was left at 1).
    if let (None, Some(d)) = (&space, &directions) {
        let vectors: Vec<&str> = d.split_whitespace().filter(|t| *t != "none").collect();
        if vectors.len() != sizes.len() {
            return Err(bad(what, format!("space directions '{d}': {} vectors expected", sizes.len())));
        }
        for (i, v) in vectors.iter().enumerate() {
            spacing[i] = nrrd_vector(v, what)?.length() as f32;
        }
    }
    let mut d3 = [1u64; 3];
    d3[..sizes.len()].copy_from_slice(&sizes);
    let n = voxel_count_within(&d3, what, limit)?;
    voxel_count_within(&[n, channels, 1], what, limit)?;
    if d3.iter().any(|&d| d > crate::volume::MAX_DIM as u64) {
        return Err(Error::TooLarge(format!("{what}: a dimension exceeds {}", crate::volume::MAX_DIM)));
    }
    let orientation = match space {
        Some(space) => nrrd_orientation(&space, directions.as_deref(), space_origin.as_deref(), d3, spacing, what)?,
        None => None,
    };
    let spacing = orientation.map(|o| o.spacing()).unwrap_or(spacing);
    check_spacing(spacing, what)?;
    Ok(NrrdHeader {
        dtype,
        dims: d3,
        voxels: n,
        encoding: enc.unwrap_or_else(|| "raw".into()),
        big_endian: endian_big,
        spacing,
        data_file,
        data_start,
        orientation,
        channels: channels as u32,
        channel_first,
        times: times as u32,
    })
}

/// A 4-D NRRD's channels (a 3-D file's one volume), each a dense volume.
pub fn nrrd_channels_from_bytes(bytes: &[u8], dir: Option<&Path>, what: &str) -> Result<Vec<ScalarVolume>> {
    let (h, values) = nrrd_samples(bytes, dir, what)?;
    let (n, c) = (h.voxels as usize, h.channels as usize);
    let dims = h.dims.map(|d| d as u32);
    Ok((0..c)
        .map(|k| {
            let values = if h.channel_first {
                values.iter().skip(k).step_by(c).copied().collect()
            } else {
                values[k * n..(k + 1) * n].to_vec()
            };
            ScalarVolume { dims, spacing: h.spacing, values }
        })
        .collect())
}

/// An NRRD's header and samples (every channel's, in the file's order), decoded and checked.
pub(super) fn nrrd_samples(bytes: &[u8], dir: Option<&Path>, what: &str) -> Result<(NrrdHeader, Vec<f32>)> {
    let h = nrrd_header(bytes, what, MAX_VOXELS)?;
    if h.times > 1 {
        // A series is read a time point at a time (`SliceReader::nrrd_at`).
        return Err(super::several_times(what, h.times));
    }
    let (dtype, n, endian_big, data_start) = (h.dtype, h.voxels * h.channels as u64, h.big_endian, h.data_start);
    let enc = Some(h.encoding.clone());
    let need = n * dtype.size() as u64;
    let payload: Vec<u8> = match &h.data_file {
        Some(f) => {
            let dir = dir.ok_or_else(|| bad(what, "detached data file without a directory"))?;
            let p = dir.join(f);
            let len = std::fs::metadata(&p).map_err(|e| Error::Io { path: p.display().to_string(), source: e })?.len();
            if !enc.as_deref().unwrap_or("raw").starts_with("gz") && len < need {
                return Err(bad(what, format!("data file {} has {len} bytes, needs {need}", p.display())));
            }
            read_bounded(&p, MAX_INFLATED, what)?
        }
        None => bytes[data_start.min(bytes.len())..].to_vec(),
    };
    let data = match enc.as_deref().unwrap_or("raw") {
        "raw" => payload,
        "gzip" | "gz" => gunzip(&payload, need, what)?,
        other => return Err(bad(what, format!("unsupported encoding '{other}' (raw, gzip)"))),
    };
    let mut values = decode(&data, n, dtype, endian_big, what)?;
    check_finite(&values, what)?;
    if h.orientation.is_some_and(|o| o.flip_x()) {
        // Rows of x samples (of every channel, when they are the fastest axis).
        let per = if h.channel_first { h.channels as usize } else { 1 };
        if per == 1 {
            flip_rows(&mut values, h.dims[0] as usize);
        } else {
            for row in values.chunks_exact_mut(h.dims[0] as usize * per) {
                let flipped: Vec<f32> = row.chunks_exact(per).rev().flatten().copied().collect();
                row.copy_from_slice(&flipped);
            }
        }
    }
    Ok((h, values))
}

/// The RAS+ placement an NRRD `space` (RAS, LAS or LPS, short or long names) with its directions
/// and origin gives a `dims` grid; `None` for other spaces (no anatomical frame).
fn nrrd_orientation(
    space: &str,
    directions: Option<&str>,
    origin: Option<&str>,
    dims: [u64; 3],
    spacing: [f32; 3],
    what: &str,
) -> Result<Option<Orientation>> {
    // World x and y signs turning the space into RAS+.
    let flip = match space.to_ascii_lowercase().as_str() {
        "ras" | "right-anterior-superior" => DVec3::new(1.0, 1.0, 1.0),
        "las" | "left-anterior-superior" => DVec3::new(-1.0, 1.0, 1.0),
        "lps" | "left-posterior-superior" => DVec3::new(-1.0, -1.0, 1.0),
        _ => return Ok(None),
    };
    let mut cols = [DVec3::X * spacing[0] as f64, DVec3::Y * spacing[1] as f64, DVec3::Z * spacing[2] as f64];
    if let Some(d) = directions {
        let vectors: Vec<&str> = d.split_whitespace().filter(|t| *t != "none").collect();
        if vectors.len() != 3 {
            return Err(bad(what, format!("space directions '{d}': three vectors expected")));
        }
        for (c, v) in cols.iter_mut().zip(vectors) {
            *c = nrrd_vector(v, what)?;
        }
    }
    let o = match origin {
        Some(o) => nrrd_vector(o, what)?,
        None => DVec3::ZERO,
    };
    let [x, y, z] = cols.map(|c| (c * flip).extend(0.0));
    let affine = DMat4::from_cols(x, y, z, (o * flip).extend(1.0));
    Orientation::from_affine(affine, dims.map(|d| d as u32)).map(Some).map_err(|e| place_error(e, what))
}

/// An NRRD vector `(a,b,c)`.
fn nrrd_vector(v: &str, what: &str) -> Result<DVec3> {
    let inner = v.trim().strip_prefix('(').and_then(|v| v.strip_suffix(')'));
    let parts: Option<Vec<f64>> = inner.and_then(|i| i.split(',').map(|t| t.trim().parse::<f64>().ok()).collect());
    match parts.as_deref() {
        Some(&[a, b, c]) if [a, b, c].iter().all(|x| x.is_finite()) => Ok(DVec3::new(a, b, c)),
        _ => Err(bad(what, format!("space vector '{v}' is not (x,y,z) of three finite numbers"))),
    }
}

/// The file's name on a placement error.
fn place_error(e: Error, what: &str) -> Error {
    match e {
        Error::InvalidArgument(m) => bad(what, m),
        Error::Unsupported(m) => Error::Unsupported(format!("{what}: {m}")),
        other => other,
    }
}

/// The RAS+ placement a NIfTI-1 header gives: its sform when `sform_code` > 0, else its qform
/// when `qform_code` > 0, else `None` (no frame: NIfTI's "method 1", spacing only).
pub(super) fn nifti_orientation(h: &nifti::NiftiHeader, dims: [u32; 3], what: &str) -> Result<Option<Orientation>> {
    let affine = if h.sform_code > 0 {
        let [x, y, z] = [h.srow_x, h.srow_y, h.srow_z].map(|r| DVec4::from_array(r.map(f64::from)));
        DMat4::from_cols(x, y, z, DVec4::W).transpose()
    } else if h.qform_code > 0 {
        let (mut b, mut c, mut d) = (h.quatern_b as f64, h.quatern_c as f64, h.quatern_d as f64);
        // A unit quaternion's b^2 + c^2 + d^2 is at most 1: past float32 rounding of 1 it is no
        // rotation (nibabel refuses it too); up to that, normalised as niftilib does (a = 0).
        let norm = b * b + c * c + d * d;
        if norm.is_nan() || norm > 1.0 + 1e-5 {
            return Err(bad(
                what,
                format!(
                    "qform quaternion (b, c, d) = ({b}, {c}, {d}) has b²+c²+d² = {norm}, more than 1: not a rotation"
                ),
            ));
        }
        if norm > 1.0 {
            (b, c, d) = (b / norm.sqrt(), c / norm.sqrt(), d / norm.sqrt());
        }
        let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let s = [h.pixdim[1] as f64, h.pixdim[2] as f64, qfac * h.pixdim[3] as f64];
        let r = [
            [a * a + b * b - c * c - d * d, 2.0 * (b * c - a * d), 2.0 * (b * d + a * c)],
            [2.0 * (b * c + a * d), a * a + c * c - b * b - d * d, 2.0 * (c * d - a * b)],
            [2.0 * (b * d - a * c), 2.0 * (c * d + a * b), a * a + d * d - c * c - b * b],
        ];
        let col = |j: usize| DVec4::new(r[0][j] * s[j], r[1][j] * s[j], r[2][j] * s[j], 0.0);
        let t = DVec4::new(h.quatern_x as f64, h.quatern_y as f64, h.quatern_z as f64, 1.0);
        DMat4::from_cols(col(0), col(1), col(2), t)
    } else {
        return Ok(None);
    };
    Orientation::from_affine(affine, dims).map(Some).map_err(|e| place_error(e, what))
}

/// Reverse each `nx`-sample row (a left-handed file's x, `Orientation::flip_x`).
pub(super) fn flip_rows(values: &mut [f32], nx: usize) {
    values.chunks_exact_mut(nx.max(1)).for_each(|r| r.reverse());
}
