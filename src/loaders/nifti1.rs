//! NIfTI-1 headers: checked, and read as where the voxels are (`NiftiLayout`), with a 4-D file's
//! fourth axis as time points or channels.
use super::{bad, nrrd, voxel_count, voxel_count_within, DType, MAX_FILE_CHANNELS, MAX_TIME_POINTS};
use crate::error::{Error, Result};

/// A NIfTI header's `dim[1..=dim[0]]` as the signed values the format stores (the parser reads
/// them unsigned, so -256 would read as 65280), each checked to be positive.
pub(super) fn nifti_dims(header: &nifti::NiftiHeader, what: &str) -> Result<Vec<u64>> {
    // The parser blames dim[0] for a zero or negative axis after it (dim[1] = 0 read as "dim[0]
    // = 3 must be positive"): the axes are checked here first.
    let n = header.dim[0] as i16;
    if (1..=7).contains(&n) {
        if let Some(i) = (1..=n as usize).find(|&i| header.dim[i] as i16 <= 0) {
            let d = header.dim[i] as i16;
            return Err(bad(what, format!("NIfTI dim[{i}] = {d}: dimensions must be positive")));
        }
    }
    let dim = header.dim().map_err(|e| bad(what, format!("NIfTI dim: {e}")))?;
    dim.iter()
        .enumerate()
        .map(|(i, &d)| match d as i16 {
            d if d > 0 => Ok(d as u64),
            d => Err(bad(what, format!("NIfTI dim[{}] = {d}: dimensions must be positive", i + 1))),
        })
        .collect()
}

/// Where a NIfTI-1 file's voxels are and how to read them, from its checked header.
pub(crate) struct NiftiLayout {
    pub dims: [u32; 3],
    pub dtype: DType,
    /// Byte offset of the voxels.
    pub offset: u64,
    pub big_endian: bool,
    pub spacing: [f32; 3],
    /// Placement from the sform or qform.
    pub orientation: Option<crate::orient::Orientation>,
    /// `scl_slope`, `scl_inter` when they change the values.
    scale: Option<(f32, f32)>,
    /// Channels stored one after another (a 4-D file's fourth axis, or a 5-D file's fifth with
    /// one frame): 1 for a 3-D volume.
    pub channels: u32,
    /// Time points stored one after another (a 4-D file's fourth axis when its units say time or
    /// it holds more than `MAX_FILE_CHANNELS`): 1 otherwise.
    pub times: u32,
}

impl NiftiLayout {
    /// Apply the header's value scaling.
    pub fn rescale(&self, values: &mut [f32]) {
        if let Some((slope, inter)) = self.scale {
            for v in values {
                *v = *v * slope + inter;
            }
        }
    }
}

/// The layout of the NIfTI-1 file whose first bytes are `head` (at least the 348-byte header),
/// its voxel count checked against `limit`.
pub(crate) fn nifti_layout(head: &[u8], limit: u64, what: &str) -> Result<NiftiLayout> {
    let header = nifti1_header(head, what)?;
    let dim = nifti_dims(&header, what)?;
    // 3-D; 4-D over time (its units say so, or it holds more frames than a file holds
    // channels: the standard's fourth axis is time); 4-D of 2 to 4 channels; 5-D with one frame
    // and 2 to 4 channels (the vector axis).
    let time_units = header.xyzt_units & 0o70 != 0;
    let (channels, times) = match dim.len() {
        1..=3 => (1, 1),
        4 if dim[3] > 1 && (time_units || dim[3] > MAX_FILE_CHANNELS) && dim[3] <= MAX_TIME_POINTS => (1, dim[3]),
        4 if dim[3] <= MAX_FILE_CHANNELS => (dim[3], 1),
        5 if dim[3] == 1 && dim[4] <= MAX_FILE_CHANNELS => (dim[4], 1),
        _ => {
            return Err(bad(
                what,
                format!(
                "NIfTI dims {dim:?}: a 3-D volume is read, a 4-D series of at most {MAX_TIME_POINTS} time points, or \
                     a volume of 2 to {MAX_FILE_CHANNELS} channels (4-D, or 5-D with one frame)"
            ),
            ))
        }
    };
    let mut d3 = [1u64; 3];
    for (i, d) in dim.iter().take(3).enumerate() {
        d3[i] = *d;
    }
    voxel_count_within(&d3, what, limit)?;
    voxel_count_within(&[d3[0], d3[1], d3[2], channels], what, limit.saturating_mul(MAX_FILE_CHANNELS))?;
    let dtype = match header.data_type().map_err(|e| bad(what, format!("NIfTI type: {e}")))? {
        nifti::NiftiType::Uint8 => DType::U8,
        nifti::NiftiType::Int8 => DType::I8,
        nifti::NiftiType::Int32 => DType::I32,
        nifti::NiftiType::Float64 => DType::F64,
        nifti::NiftiType::Uint16 => DType::U16,
        nifti::NiftiType::Int16 => DType::I16,
        nifti::NiftiType::Uint32 => DType::U32,
        nifti::NiftiType::Float32 => DType::F32,
        other => return Err(bad(what, format!("unsupported NIfTI type {other:?}"))),
    };
    let off = header.vox_offset;
    if !(off.is_finite() && (348.0..=1e7).contains(&off)) {
        return Err(bad(what, format!("voxel offset {off} outside the file")));
    }
    let (slope, inter) = (header.scl_slope, header.scl_inter);
    let scale = (slope.is_finite() && slope != 0.0 && (slope != 1.0 || inter != 0.0) && inter.is_finite())
        .then_some((slope, inter));
    // pixdim must be finite and non-zero, as NRRD's spacings must be (its sign is the qform's).
    let mut spacing = [1.0f32; 3];
    for (i, (s, p)) in spacing.iter_mut().zip(&header.pixdim[1..4]).enumerate() {
        if !(p.is_finite() && p.abs() > 0.0) {
            return Err(bad(what, format!("pixdim[{}] = {p}: voxel spacings must be finite and non-zero", i + 1)));
        }
        *s = p.abs();
    }
    let orientation = nrrd::nifti_orientation(&header, d3.map(|d| d as u32), what)?;
    let spacing = orientation.map(|o| o.spacing()).unwrap_or(spacing);
    super::check_spacing(spacing, what)?;
    Ok(NiftiLayout {
        orientation,
        dims: d3.map(|d| d as u32),
        dtype,
        offset: off as u64,
        big_endian: header.endianness == nifti::Endianness::Big,
        spacing,
        scale,
        channels: channels as u32,
        times: times as u32,
    })
}

/// A NIfTI-1 header from the first 348 bytes of `head`; a NIfTI-2 file (540-byte header) is
/// refused by name.
pub(super) fn nifti1_header(head: &[u8], what: &str) -> Result<nifti::NiftiHeader> {
    let sizeof_hdr =
        head.get(..4).map(|b| [u32::from_le_bytes(b.try_into().unwrap()), u32::from_be_bytes(b.try_into().unwrap())]);
    if sizeof_hdr.is_some_and(|s| s.contains(&540)) {
        return Err(Error::Unsupported(format!(
            "{what}: a NIfTI-2 file (540-byte header); NIfTI-1 is read (nibabel: nib.Nifti1Image(img.dataobj, img.affine, img.header))"
        )));
    }
    if head.len() < 348 {
        return Err(bad(what, "shorter than a NIfTI-1 header"));
    }
    nifti::NiftiHeader::from_reader(std::io::Cursor::new(&head[..348]))
        .map_err(|e| bad(what, format!("NIfTI header: {e}")))
}

/// Bytes a NIfTI-1 file needs (offset + data), from its checked header.
pub(super) fn nifti_size(head: &[u8], what: &str) -> Result<u64> {
    let header = nifti1_header(head, what)?;
    let n = voxel_count(&nifti_dims(&header, what)?, what)?;
    let size = (header.bitpix.max(8) as u64) / 8;
    let off = header.vox_offset;
    if !(off.is_finite() && (348.0..=1e7).contains(&off)) {
        return Err(bad(what, format!("voxel offset {off} is not valid")));
    }
    Ok(off as u64 + n * size)
}
