//! Volumes read a few z-slices at a time, so a bricked store is built without the volume in
//! memory (`BrickStore::from_slices`): NRRD (raw or gzip data, attached or detached), NIfTI-1
//! (`.nii`, `.nii.gz`) and raw files with their dims and type; gzip data is inflated as it is read. Every size comes
//! from a checked header and is checked against the file's length (a gzip stream's against what it
//! inflates to, as it is read) before a slice is read.
use super::{bad, decode, is_gzip, nifti_layout, nrrd_header, DType, VolumeHints};
use crate::error::{Error, Result};
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Most voxels of a volume streamed slice by slice into a bricked store (`SliceReader`): 2^34,
/// with the host's available memory checked against the store's worst case.
pub const MAX_STREAMED_VOXELS: u64 = 1 << 34;

/// Where the samples come from.
enum Source {
    File(std::fs::File),
    /// A multipage TIFF or a folder of numbered images, decoded a slice at a time.
    Stack(Box<super::stacks::Stack>),
    /// One level, time point and channel of an OME-Zarr image, decoded a row of chunks at a time.
    Zarr(Box<super::zarr::ZarrReader>),
    /// A gzip stream from byte `start` of `path`, inflated from its start again whenever a read
    /// goes back (a store's build reads the volume twice, front to back).
    Gzip {
        path: PathBuf,
        start: u64,
        stream: Box<dyn Read + Send>,
        at: u64,
    },
}

fn open_gzip(path: &Path, start: u64) -> std::io::Result<Box<dyn Read + Send>> {
    let mut file = std::fs::File::open(path)?;
    file.seek(SeekFrom::Start(start))?;
    Ok(Box::new(flate2::read::MultiGzDecoder::new(std::io::BufReader::with_capacity(1 << 16, file))))
}

impl Source {
    fn gzip(path: &Path, start: u64) -> Result<Self> {
        let stream = open_gzip(path, start).map_err(io_err(path))?;
        Ok(Source::Gzip { path: path.to_path_buf(), start, stream, at: 0 })
    }
}

impl Source {
    /// `buf.len()` bytes from byte `at` of the (inflated) data.
    fn read_at(&mut self, at: u64, buf: &mut [u8]) -> std::io::Result<()> {
        match self {
            Source::File(f) => {
                f.seek(SeekFrom::Start(at))?;
                f.read_exact(buf)
            }
            Source::Stack(_) | Source::Zarr(_) => Err(std::io::ErrorKind::Unsupported.into()),
            Source::Gzip { path, start, stream, at: pos } => {
                if at < *pos {
                    (*stream, *pos) = (open_gzip(path, *start)?, 0);
                }
                let skip = at - *pos;
                if std::io::copy(&mut stream.by_ref().take(skip), &mut std::io::sink())? < skip {
                    return Err(std::io::ErrorKind::UnexpectedEof.into());
                }
                stream.read_exact(buf)?;
                *pos = at + buf.len() as u64;
                Ok(())
            }
        }
    }
}

/// A volume file read z-slices at a time.
pub struct SliceReader {
    source: Source,
    offset: u64,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing.
    pub spacing: [f32; 3],
    /// Placement in patient space, when the header gives one; with `flip_x`, every read returns
    /// rows reversed.
    pub orientation: Option<crate::orient::Orientation>,
    dtype: DType,
    big_endian: bool,
    /// NIfTI value scaling.
    rescale: Option<super::NiftiLayout>,
    what: String,
    bytes: Vec<u8>,
}

/// Where a file's samples are and what they are.
struct Layout {
    offset: u64,
    dims: [u32; 3],
    spacing: [f32; 3],
    dtype: DType,
    big_endian: bool,
    orientation: Option<crate::orient::Orientation>,
}

fn io_err(p: &Path) -> impl FnOnce(std::io::Error) -> Error {
    let p = p.display().to_string();
    move |e| Error::Io { path: p, source: e }
}

impl SliceReader {
    /// `path` read slice by slice when its format allows (see the module), else `None` (load it
    /// whole with `load_volume`: NRRD in other encodings, `.npy`). `hints` as `load_volume` takes them
    /// (a raw file's dims and type); sizes are checked against `MAX_STREAMED_VOXELS` and the
    /// data's length before anything is read.
    pub fn open(path: &Path, hints: &VolumeHints) -> Result<Option<Self>> {
        if let Some((file, hints)) = super::sequence::member(path, hints)? {
            return Self::open(&file, &hints);
        }
        let name = super::lower_name(path);
        super::check_raw_hints(path, hints)?;
        let series = hints.series.as_deref();
        if path.is_dir() && super::zarr::is_ome_zarr(path) {
            let image = super::zarr::OmeZarr::open(path)?;
            zarr_time(path, &image, hints)?;
            if image.channels > 1 {
                return Err(super::several_channels(&path.display().to_string(), image.channels));
            }
            return Self::zarr(path, &image, hints, 0).map(Some);
        }
        let nifti = name.ends_with(".nii") || name.ends_with(".nii.gz");
        let nrrd = name.ends_with(".nrrd") || name.ends_with(".nhdr");
        let dicom = path.is_dir() && super::dicom::holds_dicom(path) || !path.is_dir() && super::dicom::is_dicom(path);
        if hints.level.is_some() || hints.time.is_some() && !(nifti || nrrd || dicom) {
            return Err(super::bad(
                &path.display().to_string(),
                if hints.level.is_some() {
                    "--level picks a level of an OME-Zarr image; this is none"
                } else {
                    "--time picks a time point of a 4-D NIfTI or NRRD, a DICOM series or an OME-Zarr image; this is none"
                },
            ));
        }
        if hints.series.is_some() && !(path.is_dir() || super::dicom::is_dicom(path)) {
            return Err(super::bad(&path.display().to_string(), "--series picks a DICOM series of a folder"));
        }
        if dicom {
            Ok(Some(Self::stack(super::stacks::Stack::dicom(path, series, hints.rectilinear, hints.time)?)))
        } else if path.is_dir() {
            if series.is_some() {
                return Err(super::bad(
                    &path.display().to_string(),
                    "--series picks a DICOM series; this folder holds none",
                ));
            }
            Ok(Some(Self::stack(super::stacks::Stack::folder(path)?)))
        } else if name.ends_with(".tif") || name.ends_with(".tiff") {
            Ok(Some(Self::stack(super::stacks::Stack::tiff(path)?)))
        } else if nrrd {
            Self::nrrd_at(path, hints.time)
        } else if nifti {
            Self::nifti_at(path, hints.time).map(Some)
        } else if name.ends_with(".npy") {
            Ok(None)
        } else {
            Self::raw(path, hints).map(Some)
        }
    }

    /// `path` when it is an NRRD with raw or gzip data, attached or detached; `None` for any other
    /// encoding.
    pub fn nrrd(path: &Path) -> Result<Option<Self>> {
        Self::nrrd_at(path, None)
    }

    /// An NRRD's header (its first MiB read) and the open file.
    fn nrrd_head(path: &Path) -> Result<(super::nrrd::NrrdHeader, std::fs::File)> {
        let mut file = std::fs::File::open(path).map_err(io_err(path))?;
        let mut head = Vec::new();
        (&mut file).take(1 << 20).read_to_end(&mut head).map_err(io_err(path))?;
        Ok((nrrd_header(&head, &path.display().to_string(), MAX_STREAMED_VOXELS)?, file))
    }

    /// The channels a NIfTI or an NRRD holds (`load_channels` reads them); 1 for any other file.
    pub fn channels(path: &Path) -> Result<u32> {
        let name = super::lower_name(path);
        if name.ends_with(".nii") || name.ends_with(".nii.gz") {
            return Self::nifti_channels(path);
        }
        if name.ends_with(".nrrd") || name.ends_with(".nhdr") {
            return Ok(Self::nrrd_head(path)?.0.channels);
        }
        Ok(1)
    }

    /// The time points an NRRD holds (1 unless it is a 4-D series).
    pub fn nrrd_times(path: &Path) -> Result<u32> {
        Ok(Self::nrrd_head(path)?.0.times)
    }

    /// `nrrd`, of time point `time` of a 4-D series (`None`: a file of one time point).
    pub fn nrrd_at(path: &Path, time: Option<u32>) -> Result<Option<Self>> {
        let what = path.display().to_string();
        let (h, file) = Self::nrrd_head(path)?;
        if h.channels > 1 {
            return Err(super::several_channels(&what, h.channels));
        }
        let t = super::time_point(&what, h.times, time)? as u64;
        // Time point t starts t volumes into the data.
        let skip = t * h.voxels * h.dtype.size() as u64;
        let gz = match h.encoding.as_str() {
            "raw" => false,
            "gzip" | "gz" => true,
            _ => return Ok(None),
        };
        let (file, offset, data_path) = match &h.data_file {
            Some(f) => {
                let p = path.parent().ok_or_else(|| bad(&what, "detached data file without a directory"))?.join(f);
                (std::fs::File::open(&p).map_err(io_err(&p))?, 0, p)
            }
            None => (file, h.data_start as u64, path.to_path_buf()),
        };
        let (dims, spacing, dtype, big_endian) = (h.dims.map(|d| d as u32), h.spacing, h.dtype, h.big_endian);
        let orientation = h.orientation;
        if gz {
            // The inflated data starts at its first byte.
            let layout = Layout { offset: skip, dims, spacing, dtype, big_endian, orientation };
            return Ok(Some(Self::new(Source::gzip(&data_path, offset)?, layout, what)));
        }
        let layout = Layout { offset: offset + skip, dims, spacing, dtype, big_endian, orientation };
        Self::from_file(file, &data_path, layout, what).map(Some)
    }

    /// A NIfTI-1 file, compressed or not (of one channel: `nifti_channel` reads one of several;
    /// of one time point: `nifti_at` reads one of several).
    pub fn nifti(path: &Path) -> Result<Self> {
        Self::nifti_at(path, None)
    }

    /// Time point `time` of a 4-D NIfTI-1 file of one channel (`None`: a file of one time point).
    pub fn nifti_at(path: &Path, time: Option<u32>) -> Result<Self> {
        let what = path.display().to_string();
        let l = nifti_layout(&Self::nifti_head(path)?.0, MAX_STREAMED_VOXELS, &what)?;
        if l.channels > 1 {
            return Err(super::several_channels(&what, l.channels));
        }
        Self::nifti_block(path, super::time_point(&what, l.times, time)?)
    }

    /// The channels a NIfTI-1 file holds (1 for a 3-D volume).
    pub fn nifti_channels(path: &Path) -> Result<u32> {
        let what = path.display().to_string();
        Ok(nifti_layout(&Self::nifti_head(path)?.0, MAX_STREAMED_VOXELS, &what)?.channels)
    }

    /// The time points a NIfTI-1 file holds (1 unless it is a 4-D series).
    pub fn nifti_times(path: &Path) -> Result<u32> {
        let what = path.display().to_string();
        Ok(nifti_layout(&Self::nifti_head(path)?.0, MAX_STREAMED_VOXELS, &what)?.times)
    }

    /// The first 348 bytes of a NIfTI-1 file, inflated if it is compressed, and whether it is.
    fn nifti_head(path: &Path) -> Result<(Vec<u8>, bool)> {
        let mut file = std::fs::File::open(path).map_err(io_err(path))?;
        let mut magic = [0u8; 2];
        let gz = file.read_exact(&mut magic).is_ok() && is_gzip(&magic);
        let mut head = Vec::new();
        if gz {
            open_gzip(path, 0).map_err(io_err(path))?.take(348).read_to_end(&mut head).map_err(io_err(path))?;
        } else {
            file.seek(SeekFrom::Start(0)).map_err(io_err(path))?;
            (&mut file).take(348).read_to_end(&mut head).map_err(io_err(path))?;
        }
        Ok((head, gz))
    }

    /// Channel `channel` of a NIfTI-1 file (the channels stored one after another).
    pub fn nifti_channel(path: &Path, channel: u32) -> Result<Self> {
        let what = path.display().to_string();
        let l = nifti_layout(&Self::nifti_head(path)?.0, MAX_STREAMED_VOXELS, &what)?;
        if channel >= l.channels {
            return Err(bad(&what, format!("no channel {channel}: the file holds {}", l.channels)));
        }
        Self::nifti_block(path, channel)
    }

    /// The `block`th volume of a NIfTI-1 file whose channels or time points lie one after another.
    fn nifti_block(path: &Path, block: u32) -> Result<Self> {
        let what = path.display().to_string();
        let (head, gz) = Self::nifti_head(path)?;
        let file = std::fs::File::open(path).map_err(io_err(path))?;
        let l = nifti_layout(&head, MAX_STREAMED_VOXELS, &what)?;
        let size = l.dims.iter().map(|&d| d as u64).product::<u64>() * l.dtype.size() as u64;
        let layout = Layout {
            offset: l.offset + block as u64 * size,
            dims: l.dims,
            spacing: l.spacing,
            dtype: l.dtype,
            big_endian: l.big_endian,
            orientation: l.orientation,
        };
        let mut reader = if gz {
            Self::new(Source::gzip(path, 0)?, layout, what)
        } else {
            Self::from_file(file, path, layout, what)?
        };
        reader.rescale = Some(l);
        Ok(reader)
    }

    /// A raw file of `hints.dims` samples of `hints.dtype` (or its `.toml` sidecar's).
    pub fn raw(path: &Path, hints: &VolumeHints) -> Result<Self> {
        let what = path.display().to_string();
        let (dims, dtype, big_endian, spacing) = super::raw_layout(path, hints, &what)?;
        super::check_spacing(spacing, &what)?;
        let need = super::voxel_count_within(&dims.map(u64::from), &what, MAX_STREAMED_VOXELS)? * dtype.size() as u64;
        let file = std::fs::File::open(path).map_err(io_err(path))?;
        let len = file.metadata().map_err(io_err(path))?.len();
        if len != need {
            return Err(bad(&what, format!("has {len} bytes; {dims:?} of {dtype:?} needs {need}")));
        }
        let layout = Layout { offset: 0, dims, spacing, dtype, big_endian, orientation: None };
        Ok(Self::new(Source::File(file), layout, what))
    }

    /// A file whose data (`layout`) it is checked to hold whole.
    fn from_file(file: std::fs::File, data_path: &Path, layout: Layout, what: String) -> Result<Self> {
        let len = file.metadata().map_err(io_err(data_path))?.len();
        let r = Self::new(Source::File(file), layout, what);
        let need = r.plane_bytes() * r.dims[2] as u64;
        if len < r.offset + need {
            return Err(bad(&r.what, format!("data is truncated: {} bytes for {need}", len.saturating_sub(r.offset))));
        }
        Ok(r)
    }

    fn new(source: Source, l: Layout, what: String) -> Self {
        let (offset, dims, spacing, dtype, big_endian) = (l.offset, l.dims, l.spacing, l.dtype, l.big_endian);
        let orientation = l.orientation;
        Self { source, offset, dims, spacing, orientation, dtype, big_endian, rescale: None, what, bytes: Vec::new() }
    }

    fn plane_bytes(&self) -> u64 {
        self.dims[0] as u64 * self.dims[1] as u64 * self.dtype.size() as u64
    }

    /// Channel `channel` of an OME-Zarr image, at `hints.level` (by default the finest the host
    /// budget holds: `OmeZarr::default_level`) and
    /// `hints.time` (needed when the image holds several time points).
    pub fn zarr(path: &Path, image: &super::zarr::OmeZarr, hints: &VolumeHints, channel: u32) -> Result<Self> {
        let what = path.display().to_string();
        if hints.series.is_some() {
            return Err(bad(&what, "--series picks a DICOM series; this is an OME-Zarr image"));
        }
        let time = zarr_time(path, image, hints)?;
        let mut reader = super::zarr::ZarrReader::open(
            path,
            image,
            hints.level.unwrap_or_else(|| image.default_level()),
            time,
            channel,
        )?;
        if let Some(cache) = &hints.chunk_cache {
            reader.use_cache(cache.clone());
        }
        Ok(SliceReader {
            dims: reader.dims,
            spacing: reader.spacing,
            orientation: None,
            source: Source::Zarr(Box::new(reader)),
            offset: 0,
            dtype: DType::F32,
            big_endian: false,
            rescale: None,
            what,
            bytes: Vec::new(),
        })
    }

    /// An image stack's reader (a DICOM series placed in patient space).
    fn stack(stack: super::stacks::Stack) -> Self {
        SliceReader {
            dims: stack.dims,
            spacing: stack.spacing,
            orientation: stack.orientation,
            source: Source::Stack(Box::new(stack)),
            offset: 0,
            dtype: DType::F32,
            big_endian: false,
            rescale: None,
            what: String::new(),
            bytes: Vec::new(),
        }
    }

    /// Slices `z0..z0 + count` (x fastest) into `out`.
    pub fn read(&mut self, z0: u32, count: u32, out: &mut Vec<f32>) -> Result<()> {
        if let Source::Zarr(zarr) = &mut self.source {
            return zarr.read(z0, count, out);
        }
        if let Source::Stack(stack) = &mut self.source {
            stack.read(z0, count, out)?;
            if self.flip_x() {
                super::nrrd::flip_rows(out, self.dims[0] as usize);
            }
            return Ok(());
        }
        let plane = self.dims[0] as u64 * self.dims[1] as u64;
        let n = plane * count as u64;
        self.bytes.resize((self.plane_bytes() * count as u64) as usize, 0);
        let at = self.offset + self.plane_bytes() * z0 as u64;
        let r = self.source.read_at(at, &mut self.bytes);
        r.map_err(|e| read_error(&self.what, z0 + count, e))?;
        self.decode(n, self.dims[0] as usize, out)
    }

    fn flip_x(&self) -> bool {
        self.orientation.is_some_and(|o| o.flip_x())
    }

    /// An OME-Zarr level reads only the chunks `camera` may see (`ZarrReader::only_in_view`);
    /// other files are read whole.
    pub fn only_in_view(&mut self, camera: crate::Camera, margin_px: f32) {
        if let Source::Zarr(zarr) = &mut self.source {
            zarr.only_in_view(camera, margin_px);
        }
    }

    /// The part `lo..hi` (x and y) of slices `z0..z0 + count` into `out`, x fastest over the
    /// part: a file is read row by row at its offsets, only the part's bytes; an OME-Zarr level
    /// reads only the chunks the part touches; a gzip stream is inflated through (the slices
    /// whole, the part kept). Sort-last rendering and a cropped OME-Zarr store read boxes this way.
    pub fn read_part(&mut self, z0: u32, count: u32, lo: [u32; 2], hi: [u32; 2], out: &mut Vec<f32>) -> Result<()> {
        let [nx, ny, _] = self.dims;
        if lo[0] > hi[0] || lo[1] > hi[1] || hi[0] > nx || hi[1] > ny || z0 + count > self.dims[2] {
            return Err(Error::InvalidArgument(format!(
                "the part {lo:?}..{hi:?} of slices {z0}..{} lies outside {}'s {:?} grid",
                z0 + count,
                self.what,
                self.dims
            )));
        }
        let (w, h) = ((hi[0] - lo[0]) as usize, (hi[1] - lo[1]) as usize);
        if let Source::Zarr(zarr) = &mut self.source {
            return zarr.read_part(z0, count, lo, hi, out);
        }
        if let Source::Gzip { .. } | Source::Stack(_) = self.source {
            let mut whole = Vec::new();
            self.read(z0, count, &mut whole)?;
            out.clear();
            for z in 0..count as usize {
                for y in lo[1] as usize..hi[1] as usize {
                    let row = (z * ny as usize + y) * nx as usize;
                    out.extend_from_slice(&whole[row + lo[0] as usize..row + hi[0] as usize]);
                }
            }
            return Ok(());
        }
        let size = self.dtype.size();
        let row_bytes = w * size;
        self.bytes.resize(count as usize * h * row_bytes, 0);
        // A reversed x reads the mirrored span of each file row, then reverses it.
        let x0 = if self.flip_x() { nx - hi[0] } else { lo[0] };
        for z in 0..count as usize {
            for y in 0..h {
                let voxel = ((z0 as u64 + z as u64) * ny as u64 + lo[1] as u64 + y as u64) * nx as u64 + x0 as u64;
                let at = self.offset + voxel * size as u64;
                let row = (z * h + y) * row_bytes;
                let r = self.source.read_at(at, &mut self.bytes[row..row + row_bytes]);
                r.map_err(|e| read_error(&self.what, z0 + z as u32 + 1, e))?;
            }
        }
        self.decode((count as usize * h * w) as u64, w, out)
    }

    /// With `hints.crop` on an OME-Zarr image, a reader of the part it needs and that part's
    /// voxels (`lo..hi`): at `hints.level`, else the finest level whose part fits the host budget,
    /// and with `hints.view` only the chunks the view may see (the others read as NaN, empty).
    /// `None` for other files, or with no crop.
    pub fn part(path: &Path, hints: &VolumeHints) -> Result<Option<(Self, [[u32; 3]; 2])>> {
        let Some(crop) = hints.crop.filter(|_| super::is_ome_zarr(path)) else {
            return Ok(None);
        };
        let image = super::OmeZarr::open(path)?;
        let misses =
            || Error::InvalidArgument(format!("{}: the crop box {crop:?} holds no voxel of the image", path.display()));
        let level = match hints.level {
            Some(l) => l,
            None => image.default_level_within(Some(crop), hints.view.as_ref()).ok_or_else(misses)?,
        };
        let whole = VolumeHints { level: Some(level), crop: None, ..hints.clone() };
        let not_read = || Error::InvalidArgument(format!("{}: not read as an OME-Zarr image", path.display()));
        let mut reader = Self::open(path, &whole)?.ok_or_else(not_read)?;
        if let Some(camera) = hints.view {
            reader.only_in_view(camera, super::VIEW_MARGIN_PX);
        }
        let region = image.region(level, crop).ok_or_else(misses)?;
        if let Source::Zarr(zarr) = &reader.source {
            zarr.pin(region)?;
        }
        Ok(Some((reader, region)))
    }

    /// `read_part` of slices `z0..z0 + count` over `region`'s x and y.
    pub fn read_region(&mut self, z0: u32, count: u32, region: [[u32; 3]; 2], out: &mut Vec<f32>) -> Result<()> {
        let [lo, hi] = region;
        self.read_part(z0, count, [lo[0], lo[1]], [hi[0], hi[1]], out)
    }

    /// `n` samples from the bytes read, in rows of `row` samples: rescaled, checked finite, and
    /// each row reversed for a left-handed file (`Orientation::flip_x`).
    fn decode(&self, n: u64, row: usize, out: &mut Vec<f32>) -> Result<()> {
        *out = decode(&self.bytes, n, self.dtype, self.big_endian, &self.what)?;
        if let Some(l) = &self.rescale {
            l.rescale(out);
        }
        super::check_finite(out, &self.what)?;
        if self.flip_x() {
            super::nrrd::flip_rows(out, row);
        }
        Ok(())
    }
}

/// The smallest and largest finite values of `path` (of the time point `hints.time` picks), read
/// a few slices at a time where the format streams; (inf, -inf) when it holds none. A series'
/// range is the union of its time points' (`bricks::store_range` of it normalises every store
/// alike: `BrickStore::load_in_range`).
pub fn value_range(path: &Path, hints: &VolumeHints) -> Result<(f32, f32)> {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    let mut take = |values: &[f32]| {
        for &v in values.iter().filter(|v| v.is_finite()) {
            (lo, hi) = (lo.min(v), hi.max(v));
        }
    };
    let (mut slab, step) = (Vec::new(), crate::constants::BRICK_SIDE);
    // An OME-Zarr image's part (`VolumeHints::crop`), or the whole.
    if let Some((mut reader, region @ [r0, r1])) = SliceReader::part(path, hints)? {
        for z0 in (r0[2]..r1[2]).step_by(step as usize) {
            reader.read_region(z0, step.min(r1[2] - z0), region, &mut slab)?;
            take(&slab);
        }
    } else {
        match SliceReader::open(path, hints)? {
            Some(mut reader) => {
                for z0 in (0..reader.dims[2]).step_by(step as usize) {
                    reader.read(z0, step.min(reader.dims[2] - z0), &mut slab)?;
                    take(&slab);
                }
            }
            None => take(&super::load_volume(path, hints)?.values),
        }
    }
    Ok((lo, hi))
}

/// The time point of `image` to read: `hints.time`, needed when it holds several.
fn zarr_time(path: &Path, image: &super::zarr::OmeZarr, hints: &VolumeHints) -> Result<u32> {
    match hints.time {
        Some(t) => Ok(t),
        None if image.times > 1 => {
            Err(bad(&path.display().to_string(), format!("holds {} time points: pick one with --time N", image.times)))
        }
        None => Ok(0),
    }
}

/// A failed read of the data up to slice `end` as a typed error.
fn read_error(what: &str, end: u32, e: std::io::Error) -> Error {
    match e.kind() {
        std::io::ErrorKind::UnexpectedEof => bad(what, format!("data is truncated before slice {end}")),
        std::io::ErrorKind::InvalidInput | std::io::ErrorKind::InvalidData => bad(what, format!("gzip: {e}")),
        _ => Error::Io { path: what.to_string(), source: e },
    }
}
