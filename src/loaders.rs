//! Volume and height-grid loaders. Every size that comes from a header is checked against
//! `MAX_VOXELS` and against the bytes actually present before anything is allocated from it, and
//! files are read only as far as their header (or `--dims`) says the data goes; malformed input
//! gives typed errors (`Error::InvalidArgument` with the file's name, `Error::TooLarge`), never a
//! panic. One rule for values in every format: samples must be finite (NaN, infinities, and a
//! NIfTI `scl_slope` that overflows are errors), spacings finite and non-zero.
//!
//! ```,no_run
//! use voxsplat::loaders::{load_volume, VolumeHints};
//! // Any format by its name: raw (with hints), NRRD, NIfTI, npy, TIFF stacks, DICOM, OME-Zarr.
//! let volume = load_volume("head.nii.gz".as_ref(), &VolumeHints::default())?;
//! println!("{:?} voxels", volume.dims);
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
pub use crate::volume::{HeightGrid, ScalarVolume};
use std::io::Read;
use std::path::{Path, PathBuf};

mod bounded;
mod dicom;
mod endian;
mod held;
mod nifti1;
mod npy;
mod nrrd;
mod positions;
mod progress;
mod pyramid;
mod sequence;
mod slices;
mod stacks;
mod zarr;
mod zarr_axes;
mod zarr_chunks;
use bounded::read_bounded;
pub use bounded::{read_text, MAX_TEXT_BYTES};
pub use dicom::{even_slices, is_dicom, series_in as dicom_series, Scan as DicomScan, SeriesInfo};
use nifti1::nifti_size;
pub(crate) use nifti1::{nifti_layout, NiftiLayout};
use npy::read_npy;
pub use npy::{npy_from_bytes, npy_shape};
pub use nrrd::nrrd_channels_from_bytes;
use nrrd::{nrrd_header, nrrd_samples};
pub use positions::{load_positions, positions_from_text, MAX_POSITIONS_BYTES};
pub use progress::Progress;
pub use pyramid::{LEVEL_PIXELS, VIEW_MARGIN_PX};
pub use sequence::{files as series_files, is_pattern};
pub use slices::{value_range, SliceReader, MAX_STREAMED_VOXELS};
pub use stacks::{is_stack, tiff_heights};
pub use zarr::{
    chunks_read as zarr_chunks_read, is_ome_zarr, Axis as ZarrAxis, Level as ZarrLevel, OmeZarr, MAX_CHUNK_BYTES,
};
pub use zarr_chunks::{ChunkCache, ChunkCacheStats};

/// Most voxels (or height cells) a loader accepts: 2^28 (1 GiB as f32).
pub const MAX_VOXELS: u64 = 1 << 28;
/// Most bytes a compressed stream may inflate to.
pub const MAX_INFLATED: u64 = MAX_VOXELS * 8 + (1 << 20);

/// Sample types of raw and NRRD data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DType {
    /// Unsigned 8-bit samples.
    U8,
    /// Signed 8-bit samples.
    I8,
    /// Unsigned 16-bit samples.
    U16,
    /// Signed 16-bit samples.
    I16,
    /// Unsigned 32-bit samples (label volumes; held as f32, exact up to 2^24).
    U32,
    /// Signed 32-bit samples (label volumes; held as f32, exact within ±2^24).
    I32,
    /// 32-bit float samples.
    F32,
    /// 64-bit float samples (held as f32: rounded, and those past f32's range non-finite, which
    /// the loaders treat as they treat NaN).
    F64,
}

impl DType {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            DType::U8 | DType::I8 => 1,
            DType::U16 | DType::I16 => 2,
            DType::F32 | DType::U32 | DType::I32 => 4,
            DType::F64 => 8,
        }
    }
}

impl std::str::FromStr for DType {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "u8" | "uint8" | "uchar" | "unsigned char" | "uint8_t" => Ok(DType::U8),
            "i8" | "int8" | "signed char" | "int8_t" => Ok(DType::I8),
            "u16" | "uint16" | "ushort" | "unsigned short" | "uint16_t" => Ok(DType::U16),
            "i16" | "int16" | "short" | "signed short" | "int16_t" => Ok(DType::I16),
            "u32" | "uint32" | "uint" | "unsigned int" | "uint32_t" => Ok(DType::U32),
            "i32" | "int32" | "int" | "signed int" | "int32_t" => Ok(DType::I32),
            "f32" | "float" | "float32" => Ok(DType::F32),
            "f64" | "double" | "float64" => Ok(DType::F64),
            other => Err(Error::InvalidArgument(format!(
                "unsupported sample type '{other}' (u8, i8, u16, i16, u32, i32, f32, f64)"
            ))),
        }
    }
}

fn bad(path: &str, msg: impl std::fmt::Display) -> Error {
    Error::InvalidArgument(format!("{path}: {}", crate::error::clip_message(msg)))
}

/// Checked voxel count of `dims`.
pub fn voxel_count(dims: &[u64], what: &str) -> Result<u64> {
    voxel_count_within(dims, what, MAX_VOXELS)
}

/// Checked voxel count of `dims`, at most `limit`.
fn voxel_count_within(dims: &[u64], what: &str, limit: u64) -> Result<u64> {
    let mut n: u64 = 1;
    for &d in dims {
        if d == 0 {
            return Err(bad(what, "a dimension is zero"));
        }
        n = n.checked_mul(d).ok_or_else(|| bad(what, "dimensions overflow"))?;
        if n > limit {
            return Err(Error::TooLarge(format!("{what}: more than {limit} voxels")));
        }
    }
    Ok(n)
}

/// Decode `n` samples of `dtype` from `bytes` (which must hold exactly enough).
pub fn decode(bytes: &[u8], n: u64, dtype: DType, big_endian: bool, what: &str) -> Result<Vec<f32>> {
    let need = n.checked_mul(dtype.size() as u64).ok_or_else(|| bad(what, "size overflows"))?;
    if (bytes.len() as u64) < need {
        return Err(bad(what, format!("data is truncated: {} bytes for {need}", bytes.len())));
    }
    crate::error::check_host_memory(n * 4, &format!("{what}'s {n} samples"))?;
    let b = &bytes[..need as usize];
    let w2 = |c: &[u8]| endian::word::<2>(c, big_endian) as u16;
    let w4 = |c: &[u8]| endian::word::<4>(c, big_endian) as u32;
    let v = match dtype {
        DType::U8 => b.iter().map(|&x| x as f32).collect(),
        DType::I8 => b.iter().map(|&x| x as i8 as f32).collect(),
        DType::U16 => b.chunks_exact(2).map(|c| w2(c) as f32).collect(),
        DType::I16 => b.chunks_exact(2).map(|c| w2(c) as i16 as f32).collect(),
        // Wider than f32 holds exactly: kept within their type, refused where f32 would flatten them.
        DType::U32 => held::held(b.chunks_exact(4).map(|c| w4(c) as f64), held::U32, what)?,
        DType::I32 => held::held(b.chunks_exact(4).map(|c| w4(c) as i32 as f64), held::I32, what)?,
        DType::F64 => {
            held::held(b.chunks_exact(8).map(|c| f64::from_bits(endian::word::<8>(c, big_endian))), None, what)?
        }
        DType::F32 => b.chunks_exact(4).map(|c| f32::from_bits(w4(c))).collect(),
    };
    Ok(v)
}

/// Inflate gzip data, refusing to produce more than `limit` bytes.
pub fn gunzip(bytes: &[u8], limit: u64, what: &str) -> Result<Vec<u8>> {
    // `limit` is what the header says the data takes: a small file may inflate to all of it.
    crate::error::check_host_memory(limit, &format!("{what} inflated"))?;
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(bytes)
        .take(limit + 1)
        .read_to_end(&mut out)
        .map_err(|e| bad(what, format!("gzip: {e}")))?;
    if out.len() as u64 > limit {
        return Err(Error::TooLarge(format!("{what}: inflates beyond {limit} bytes")));
    }
    Ok(out)
}

fn is_gzip(bytes: &[u8]) -> bool {
    bytes.len() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b
}

/// A raw volume: `dims`, `dtype`, byte order and spacing given by the caller.
pub fn raw_from_bytes(
    bytes: &[u8],
    dims: [u32; 3],
    dtype: DType,
    big_endian: bool,
    spacing: [f32; 3],
    what: &str,
) -> Result<ScalarVolume> {
    let n = voxel_count(&dims.map(u64::from), what)?;
    let need = n * dtype.size() as u64;
    if bytes.len() as u64 != need {
        return Err(bad(what, format!("has {} bytes; {dims:?} of {dtype:?} needs {need}", bytes.len())));
    }
    check_spacing(spacing, what)?;
    let values = decode(bytes, n, dtype, big_endian, what)?;
    check_finite(&values, what)?;
    Ok(ScalarVolume { dims, spacing, values })
}

pub(crate) fn check_spacing(s: [f32; 3], what: &str) -> Result<()> {
    if !s.iter().all(|v| v.is_finite() && *v > 0.0) {
        return Err(bad(what, format!("spacing {s:?} must be finite and positive")));
    }
    // A grid of MAX_DIM voxels must stay within the 1e15 units a camera resolves.
    if s.iter().any(|&v| v > MAX_SPACING) {
        return Err(bad(what, format!("spacing {s:?} is past {MAX_SPACING:e} units a voxel: the grid would pass the 1e15 units a camera resolves")));
    }
    // Below it the camera's distances square to nothing in f32 ("eye and target coincide").
    if s.iter().any(|&v| v < MIN_SPACING) {
        return Err(bad(
            what,
            format!("spacing {s:?} is below {MIN_SPACING:e} units a voxel, closer than a camera resolves: give it in larger units"),
        ));
    }
    Ok(())
}

/// The smallest voxel spacing a file or `--spacing` may give (1e-20 drew; 1e-30 was "eye and
/// target coincide").
const MIN_SPACING: f32 = 1e-15;

/// The largest voxel spacing a file may give: 2^16 voxels of it span 1e15 units, the most a camera
/// resolves.
const MAX_SPACING: f32 = 1e10;

/// NRRD (attached or detached data, raw or gzip) as a dense volume.
pub fn nrrd_from_bytes(bytes: &[u8], dir: Option<&Path>, what: &str) -> Result<ScalarVolume> {
    let (h, values) = nrrd_samples(bytes, dir, what)?;
    if h.channels > 1 {
        return Err(several_channels(what, h.channels));
    }
    Ok(ScalarVolume { dims: h.dims.map(|d| d as u32), spacing: h.spacing, values })
}

/// NIfTI-1 (`.nii` or `.nii.gz`), through the `nifti` crate's header parser; the data is read
/// from the checked byte range.
pub fn nifti_from_bytes(bytes: &[u8], what: &str) -> Result<ScalarVolume> {
    // Compressed files are inflated in two steps: the header alone first, then exactly as much as
    // the checked header says the data needs.
    let head = if is_gzip(bytes) { gunzip_prefix(bytes, 348, what)? } else { bytes.to_vec() };
    let need_total = nifti_size(&head, what)?;
    let data = if is_gzip(bytes) { gunzip(bytes, need_total, what)? } else { head };
    let l = nifti_layout(&data, MAX_VOXELS, what)?;
    if l.channels > 1 {
        return Err(several_channels(what, l.channels));
    }
    if l.times > 1 {
        return Err(several_times(what, l.times));
    }
    if l.offset > data.len() as u64 {
        return Err(bad(what, format!("voxel offset {} outside the file", l.offset)));
    }
    let n = l.dims.iter().map(|&d| d as u64).product();
    let mut values = decode(&data[l.offset as usize..], n, l.dtype, l.big_endian, what)?;
    l.rescale(&mut values);
    check_finite(&values, what)?;
    if l.orientation.is_some_and(|o| o.flip_x()) {
        nrrd::flip_rows(&mut values, l.dims[0] as usize);
    }
    Ok(ScalarVolume { dims: l.dims, spacing: l.spacing, values })
}

/// The error for a series of several time points read as one volume.
pub(crate) fn several_times(what: &str, times: u32) -> Error {
    Error::InvalidArgument(format!(
        "{what} holds {times} time points: pick one with --time N, or play them all with \
         voxsplat animate --volume"
    ))
}

/// The time point `time` asks for of a file of `times` (0 when it holds one and none is asked
/// for): a series needs one, and one past it, or one of a file without a time axis, is refused.
pub(crate) fn time_point(what: &str, times: u32, time: Option<u32>) -> Result<u32> {
    match time {
        None if times > 1 => Err(several_times(what, times)),
        Some(t) if times == 1 => Err(bad(what, format!("--time {t}: it holds one volume, no time axis"))),
        Some(t) if t >= times => Err(bad(what, format!("--time {t}: it holds time points 0 to {}", times - 1))),
        t => Ok(t.unwrap_or(0)),
    }
}

/// The error for a file of several channels read as one volume.
pub(crate) fn several_channels(what: &str, channels: u32) -> Error {
    Error::InvalidArgument(format!(
        "{what} holds {channels} channels: draw them together with voxsplat render and one --channel-tf for \
         each channel after the first (the library: load_channels)"
    ))
}

/// Most channels a file may hold (`load_channels`; `classify::MAX_CHANNELS`).
pub const MAX_FILE_CHANNELS: u64 = 4;

/// Most time points a 4-D file may hold (one is read at a time: `VolumeHints::time`).
pub const MAX_TIME_POINTS: u64 = 1 << 16;

/// Every channel of a volume file: a 4-D NIfTI's 2 to 4 channels (its fourth axis, or a 5-D
/// file's fifth), or a 4-D NRRD's (the axis its `kinds` marks as not spatial, else a first or last
/// axis of at most 4 samples; interleaved per voxel or one volume after another), each as the
/// volume `load_volume` reads; any other file is one channel.
pub fn load_channels(path: &Path, hints: &VolumeHints) -> Result<Vec<ScalarVolume>> {
    if let Some((file, hints)) = sequence::member(path, hints)? {
        return load_channels(&file, &hints);
    }
    let name = lower_name(path);
    let what = path.display().to_string();
    if (name.ends_with(".nrrd") || name.ends_with(".nhdr")) && SliceReader::nrrd_times(path)? > 1 {
        // One time point of a series.
        return Ok(vec![load_volume(path, hints)?]);
    }
    if name.ends_with(".nrrd") || name.ends_with(".nhdr") {
        let mut channels = nrrd_channels_from_bytes(&read_bounded(path, MAX_INFLATED, &what)?, path.parent(), &what)?;
        if let Some(s) = hints.spacing {
            check_spacing(s, &what)?;
            channels.iter_mut().for_each(|v| v.spacing = s);
        }
        return Ok(channels);
    }
    if is_ome_zarr(path) {
        return zarr::channels(path, hints);
    }
    if !(name.ends_with(".nii") || name.ends_with(".nii.gz")) {
        return Ok(vec![load_volume(path, hints)?]);
    }
    let channels = SliceReader::nifti_channels(path)?;
    if channels == 1 {
        return Ok(vec![read_whole(SliceReader::nifti_at(path, hints.time)?, hints, &what)?]);
    }
    (0..channels).map(|k| read_whole(SliceReader::nifti_channel(path, k)?, hints, &what)).collect()
}

/// Every slice `reader` reads, as one volume (its samples finite), with `hints.spacing` over the
/// file's: a channel of a file of several.
fn read_whole(mut reader: SliceReader, hints: &VolumeHints, what: &str) -> Result<ScalarVolume> {
    let mut values = Vec::new();
    reader.read(0, reader.dims[2], &mut values)?;
    check_finite(&values, what)?;
    let mut v = ScalarVolume { dims: reader.dims, spacing: reader.spacing, values };
    if let Some(s) = hints.spacing {
        check_spacing(s, what)?;
        v.spacing = s;
    }
    Ok(v)
}

/// The first `n` inflated bytes of a gzip stream (fewer if it is shorter).
fn gunzip_prefix(bytes: &[u8], n: u64, what: &str) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(bytes)
        .take(n)
        .read_to_end(&mut out)
        .map_err(|e| bad(what, format!("gzip: {e}")))?;
    Ok(out)
}

/// A raw volume described by a TOML sidecar next to it (`FILE.toml`, e.g. `head.raw.toml`):
/// `dims = [x, y, z]`, `dtype = "u16"`, optional `endian = "big"` and `spacing = [sx, sy, sz]`.
pub fn raw_sidecar(path: &Path) -> Option<PathBuf> {
    let mut s = path.as_os_str().to_owned();
    s.push(".toml");
    let p = PathBuf::from(s);
    p.exists().then_some(p)
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Sidecar {
    dims: [u32; 3],
    dtype: String,
    #[serde(default)]
    endian: Option<String>,
    #[serde(default)]
    spacing: Option<[f32; 3]>,
}

/// Parse a raw sidecar into hints.
pub fn sidecar_hints(text: &str, what: &str) -> Result<VolumeHints> {
    let s: Sidecar = toml::from_str(text).map_err(|e| bad(what, format!("sidecar: {e}")))?;
    let big_endian = match s.endian.as_deref() {
        None | Some("little") => false,
        Some("big") => true,
        Some(o) => return Err(bad(what, format!("endian '{o}' (little, big)"))),
    };
    Ok(VolumeHints {
        dims: Some(s.dims),
        dtype: Some(s.dtype.parse()?),
        big_endian,
        spacing: s.spacing,
        ..Default::default()
    })
}

/// Options for volumes whose files do not say everything (raw data).
#[derive(Clone, Debug, Default)]
pub struct VolumeHints {
    /// Grid size of a raw file (required for raw without a sidecar).
    pub dims: Option<[u32; 3]>,
    /// Sample type of a raw file.
    pub dtype: Option<DType>,
    /// Whether raw samples are big-endian.
    pub big_endian: bool,
    /// Voxel spacing, overriding the file's.
    pub spacing: Option<[f32; 3]>,
    /// A folder of several DICOM series: the one to read, by its index in `dicom_series`' list or
    /// its Series Instance UID.
    pub series: Option<String>,
    /// An OME-Zarr image's pyramid level to read (by default the finest the host budget holds:
    /// `OmeZarr::default_level`).
    pub level: Option<u32>,
    /// The time point of a 4-D NIfTI or an OME-Zarr image to read (needed when it holds several:
    /// `time_points`).
    pub time: Option<u32>,
    /// The caller places the voxels at `file_positions`: a DICOM series with uneven slice gaps is
    /// read as its images lie (its grid spaced by the mean gap) instead of resampled onto even
    /// slices (`even_slices`) or, when that would take too many, refused.
    pub rectilinear: bool,
    /// Only what lies in this box (lo, hi; in the grid's frame, centred on the origin) will be
    /// drawn: a bricked store of an OME-Zarr image reads only the chunks of the voxels it needs
    /// there (`OmeZarr::region`), normalised by their own range, and its default level is the
    /// finest whose region fits the host budget. Other files are read whole.
    pub crop: Option<[[f32; 3]; 2]>,
    /// With `crop`: the one view (in the grid's centred frame) a store will be drawn from. An
    /// OME-Zarr image then reads only the chunks it may see (within `VIEW_MARGIN_PX` of the
    /// image's edges and one brick around), the others' voxels empty, and its default level
    /// counts only those. A view that moves must read again: through `chunk_cache`, only the
    /// chunks it did not read before.
    pub view: Option<crate::Camera>,
    /// OME-Zarr chunks are read through this cache: those it holds are not read from the file
    /// again, and those read are held for later loads given the same cache.
    pub chunk_cache: Option<ChunkCache>,
    /// Told how far `BrickStore::load` has read a file it streams, for a progress bar.
    pub progress: Option<Progress>,
}

/// The positions of an unevenly spaced DICOM series' slices along their normal, from the first
/// (mm); `None` for evenly spaced slices and any other file.
pub fn slice_offsets(path: &Path, hints: &VolumeHints) -> Result<Option<Vec<f64>>> {
    Ok(series_of(path, hints)?.and_then(|s| s.offsets().map(<[f64]>::to_vec)))
}

/// What reading DICOM series `path` leaves out (a localizer, a far slice), a line each; else none.
pub fn left_out(path: &Path, hints: &VolumeHints) -> Result<Vec<String>> {
    Ok(series_of(path, hints)?.map(|s| s.left_out).unwrap_or_default())
}

fn series_of(path: &Path, hints: &VolumeHints) -> Result<Option<dicom::Series>> {
    let dir = path.is_dir() && !is_ome_zarr(path);
    if !(dir && dicom::holds_dicom(path) || !path.is_dir() && is_dicom(path)) {
        return Ok(None);
    }
    dicom::open_placed(path, hints.series.as_deref(), hints.time).map(Some)
}

/// The voxel positions of a file whose slices are not evenly spaced (a DICOM series with uneven
/// gaps), per axis for `SplatSet::with_coordinates` on `grid` (its grid, placed: x and y its own,
/// z from the slices' positions along their normal, centred as the grid is); `None` for any
/// other file.
pub fn file_positions(path: &Path, hints: &VolumeHints, grid: &crate::volume::Grid) -> Result<Option<[Vec<f32>; 3]>> {
    let Some(offsets) = slice_offsets(path, hints)? else { return Ok(None) };
    if offsets.len() != grid.dims[2] as usize {
        return Err(bad(&path.display().to_string(), "its slices do not match the grid given"));
    }
    let own = |a: usize| (0..grid.dims[a]).map(|i| grid.origin[a] + i as f32 * grid.spacing[a]).collect::<Vec<_>>();
    let last = offsets.last().copied().unwrap_or(0.0);
    let z = offsets.iter().map(|o| (o - last / 2.0) as f32).collect();
    Ok(Some([own(0), own(1), z]))
}

/// The time points `path` holds: a 4-D NIfTI's fourth axis when it is time (`NiftiLayout`), a 4-D
/// NRRD's last axis when its `kinds` says `time`, an OME-Zarr image's time axis, a DICOM series'
/// temporal positions (of the folder's one series), the files a pattern matches (`is_pattern`: `scan_*.nii.gz`, one time point each); 1 for any other file. Each is read as a volume with
/// `VolumeHints::time` (`animate` plays them; `Renderer::update_volume` swaps them in).
pub fn time_points(path: &Path) -> Result<u32> {
    if is_pattern(path) {
        return Ok(sequence::files(path)?.len() as u32);
    }
    let name = lower_name(path);
    if name.ends_with(".nii") || name.ends_with(".nii.gz") {
        return SliceReader::nifti_times(path);
    }
    if name.ends_with(".nrrd") || name.ends_with(".nhdr") {
        return SliceReader::nrrd_times(path);
    }
    if is_ome_zarr(path) {
        return Ok(OmeZarr::open(path)?.times);
    }
    if path.is_dir() && dicom::holds_dicom(path) || !path.is_dir() && is_dicom(path) {
        return dicom::time_points(path, None);
    }
    Ok(1)
}

/// A raw file's dims, sample type, byte order and spacing: `hints` first, then its `.toml`
/// sidecar (`raw_sidecar`); dims and type are required.
pub(crate) fn raw_layout(path: &Path, hints: &VolumeHints, what: &str) -> Result<([u32; 3], DType, bool, [f32; 3])> {
    let side = match raw_sidecar(path) {
        Some(p) => {
            let text =
                std::fs::read_to_string(&p).map_err(|e| Error::Io { path: p.display().to_string(), source: e })?;
            sidecar_hints(&text, what)?
        }
        None => VolumeHints::default(),
    };
    let dims = hints.dims.or(side.dims).ok_or_else(|| bad(what, "raw data needs --dims X,Y,Z or a .toml sidecar"))?;
    let dtype = hints.dtype.or(side.dtype).ok_or_else(|| bad(what, "raw data needs --dtype or a .toml sidecar"))?;
    let spacing = hints.spacing.or(side.spacing).unwrap_or([1.0; 3]);
    Ok((dims, dtype, hints.big_endian || side.big_endian, spacing))
}

/// The placement in patient space (RAS+) a NIfTI sform/qform or an NRRD anatomical `space` gives
/// `path`, with `hints.spacing` applied; `None` for files without one (raw, npy, NRRD without a
/// space, NIfTI with both codes 0). An affine whose axes meet within `orient::MAX_SHEAR` of
/// parallel is `Error::Unsupported`; a less sheared one is placed (`Orientation::grid`).
pub fn load_orientation(path: &Path, hints: &VolumeHints) -> Result<Option<crate::orient::Orientation>> {
    // A series' time points share the header's placement.
    let first = VolumeHints { time: Some(0), ..hints.clone() };
    let hints = if hints.time.is_none() && time_points(path)? > 1 { &first } else { hints };
    if let Some((file, hints)) = sequence::member(path, hints)? {
        return load_orientation(&file, &hints);
    }
    let what = path.display().to_string();
    let name = lower_name(path);
    // A NIfTI of several channels places them all as its first.
    if name.ends_with(".nii") || name.ends_with(".nii.gz") {
        check_raw_hints(path, hints)?;
        return crate::orient::respaced(SliceReader::nifti_channel(path, 0)?.orientation, hints.spacing);
    }
    if is_ome_zarr(path) {
        // No anatomical frame: NGFF 0.4 and 0.5 give none.
        OmeZarr::open(path)?;
        return Ok(None);
    }
    let nrrd = name.ends_with(".nrrd") || name.ends_with(".nhdr");
    let o = match if nrrd { None } else { SliceReader::open(path, hints)? } {
        Some(reader) => reader.orientation,
        None if name.ends_with(".npy") => None,
        // An NRRD: its header places all its channels and time points, however it is read.
        None => {
            let mut head = Vec::new();
            let file = std::fs::File::open(path).map_err(|e| Error::Io { path: what.clone(), source: e })?;
            file.take(1 << 20).read_to_end(&mut head).map_err(|e| Error::Io { path: what.clone(), source: e })?;
            nrrd_header(&head, &what, MAX_STREAMED_VOXELS)?.orientation
        }
    };
    crate::orient::respaced(o, hints.spacing)
}

/// Load a volume by its extension: `.nrrd`/`.nhdr`, `.nii`/`.nii.gz`, `.npy`, a multipage `.tif`/`.tiff`
/// or a folder of numbered PNG or TIFF slices (`SliceReader`'s stacks), anything else raw.
/// A file whose affine is left-handed comes back with its x axis reversed, so that its placement
/// is a rotation (`Orientation::flip_x`, `load_orientation`); the `*_from_bytes` readers do the same.
/// Only the bytes its header (or `hints`) says the data needs are read, slice by slice where the
/// format allows (`SliceReader`), after the file is checked to hold them: a device or a file far
/// larger than its header says is never read whole.
///
/// ```no_run
/// use voxsplat::loaders::{load_volume, VolumeHints};
/// let ct = load_volume("scan.nii.gz".as_ref(), &VolumeHints::default())?;
/// // A raw file needs its grid size (and its sample type, unless u8).
/// let mut hints = VolumeHints::default();
/// hints.dims = Some([256, 256, 256]);
/// let raw = load_volume("bonsai.raw".as_ref(), &hints)?;
/// println!("{:?} and {:?}", ct.dims, raw.dims);
/// # Ok::<(), voxsplat::Error>(())
/// ```
pub fn load_volume(path: &Path, hints: &VolumeHints) -> Result<ScalarVolume> {
    if let Some((file, hints)) = sequence::member(path, hints)? {
        return load_volume(&file, &hints);
    }
    let what = path.display().to_string();
    let name = lower_name(path);
    let mut v = if let Some(mut reader) = SliceReader::open(path, hints)? {
        voxel_count(&reader.dims.map(u64::from), &what)?;
        let mut values = Vec::new();
        reader.read(0, reader.dims[2], &mut values)?;
        ScalarVolume { dims: reader.dims, spacing: reader.spacing, values }
    } else if name.ends_with(".npy") {
        let (shape, values) = npy_from_bytes(&read_npy(path, &what)?, &what)?;
        if shape.len() != 3 {
            return Err(bad(&what, "a volume .npy must be 3D (z, y, x)"));
        }
        ScalarVolume { dims: [shape[2] as u32, shape[1] as u32, shape[0] as u32], spacing: [1.0; 3], values }
    } else {
        // NRRD in an encoding the slice reader does not take: nrrd_from_bytes refuses it by name.
        nrrd_from_bytes(&read_bounded(path, MAX_INFLATED, &what)?, path.parent(), &what)?
    };
    check_finite(&v.values, &what)?;
    if let Some(s) = hints.spacing {
        check_spacing(s, &what)?;
        v.spacing = s;
    }
    Ok(v)
}

/// `path`'s file name in ASCII lower case, read lossily: a name that is not UTF-8 keeps its
/// extension (it was taken for raw data).
pub(crate) fn lower_name(path: &Path) -> String {
    path.file_name().map(|n| n.to_string_lossy().to_ascii_lowercase()).unwrap_or_default()
}

/// Whether `path` is raw data by its name (anything but NRRD, NIfTI, npy, a TIFF, a folder of
/// slices) and content (not a DICOM file).
pub fn is_raw(path: &Path) -> bool {
    let name = lower_name(path);
    !path.is_dir()
        && ![".nrrd", ".nhdr", ".nii", ".nii.gz", ".npy", ".tif", ".tiff"].iter().any(|e| name.ends_with(e))
        && !dicom::is_dicom(path)
}

/// Dims, sample type and byte order describe raw files only: given for a file whose header says
/// them, they would be ignored, so they are refused.
pub(crate) fn check_raw_hints(path: &Path, hints: &VolumeHints) -> Result<()> {
    if !is_raw(path) && (hints.dims.is_some() || hints.dtype.is_some() || hints.big_endian) {
        return Err(bad(
            &path.display().to_string(),
            "dims, sample type and byte order (--dims, --dtype, --big-endian) describe raw files; this file's header gives its own",
        ));
    }
    Ok(())
}

/// Every loader's rule for samples: NaN and infinities (in the file, or made by a NIfTI
/// `scl_slope`) are refused, since classification would silently drop or saturate them.
pub(crate) fn check_finite(values: &[f32], what: &str) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(bad(what, format!("sample {i} is {} (samples must be finite)", values[i]))),
    }
}

/// Load heights from a 16-bit (or 8-bit) PNG, a GeoTIFF / TIFF, or a 2D `.npy` (finite values,
/// as `check_finite` requires of volumes).
pub fn load_heights(path: &Path) -> Result<HeightGrid> {
    let grid = load_height_file(path)?;
    // NaN is a GeoTIFF's no-data cell (a hole in the terrain); infinities are refused.
    if let Some(v) = grid.heights.iter().find(|v| v.is_infinite()) {
        return Err(bad(&path.display().to_string(), format!("a height of {v}: heights are finite")));
    }
    if grid.heights.iter().all(|v| v.is_nan()) {
        return Err(bad(&path.display().to_string(), "no cell has a height (every one is no-data or NaN)"));
    }
    Ok(grid)
}

fn load_height_file(path: &Path) -> Result<HeightGrid> {
    let what = path.display().to_string();
    let name = lower_name(path);
    if name.ends_with(".npy") {
        let (shape, heights) = npy_from_bytes(&read_npy(path, &what)?, &what)?;
        if shape.len() != 2 {
            return Err(bad(&what, "a height .npy must be 2D (rows, columns)"));
        }
        return Ok(HeightGrid { width: shape[1] as u32, rows: shape[0] as u32, heights });
    }
    if name.ends_with(".tif") || name.ends_with(".tiff") {
        return tiff_heights(&read_bounded(path, MAX_INFLATED, &what)?, &what);
    }
    let mut reader = image::ImageReader::open(path)
        .map_err(|e| Error::Io { path: what.clone(), source: e })?
        .with_guessed_format()
        .map_err(|e| Error::Io { path: what.clone(), source: e })?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(MAX_VOXELS * 4);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| bad(&what, e))?.to_luma16();
    let (w, h) = img.dimensions();
    Ok(HeightGrid { width: w, rows: h, heights: img.pixels().map(|p| p[0] as f32).collect() })
}

/// Where the shared real datasets live: `$VOXSPLAT_DATA`, else `../shared/data` beside the crate.
pub fn data_dir() -> PathBuf {
    std::env::var_os("VOXSPLAT_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"))
}
