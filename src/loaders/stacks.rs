//! Image stacks read a slice at a time (`SliceReader`): a multipage TIFF, each page a z slice (its
//! spacing from ImageJ's or OME-TIFF's metadata where present), and a folder of numbered 2-D images
//! (PNG or TIFF), ordered by the number in each name. Every page or image must be one channel of
//! one size; the stack's size is checked against `MAX_STREAMED_VOXELS` before any slice is decoded.
use super::MAX_STREAMED_VOXELS;
use super::{bad, MAX_VOXELS};
use crate::error::{Error, Result};
use std::io::BufReader;
use std::path::{Path, PathBuf};
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;

/// Most pages of a multipage TIFF (each read as a slice).
const MAX_PAGES: u32 = 1 << 16;

/// Where a stack's slices are.
enum Slices {
    /// A multipage TIFF and the decoder at its current page (opened again to go back).
    Pages { path: PathBuf, at: Option<(Decoder<BufReader<std::fs::File>>, u32)> },
    /// One image a slice, in order.
    /// The files, and the first one's sample type (`read_image`), which every slice shares.
    Files(Vec<PathBuf>, &'static str),
    /// A DICOM series, its images in order along their normal.
    Dicom(super::dicom::Series),
}

/// A stack of 2-D images read as z slices.
pub struct Stack {
    slices: Slices,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing (1 where the files give none).
    pub spacing: [f32; 3],
    /// A DICOM series' placement in patient space.
    pub orientation: Option<crate::orient::Orientation>,
    what: String,
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::Io { path: path.display().to_string(), source: e }
}

/// Bytes of one value of TIFF field type `t` (an unknown type: 1).
fn type_size(t: u16) -> u64 {
    match t {
        3 | 8 => 2,
        4 | 9 | 11 | 13 => 4,
        5 | 10 | 12 | 16 | 17 | 18 => 8,
        _ => 1,
    }
}

/// Walks a TIFF's IFDs (classic or BigTIFF) before the tiff crate reads them, which sizes its
/// buffers by each entry's count: every entry's values must lie within the file, at most
/// `MAX_PAGES` IFDs, none visited twice.
fn check_ifds(path: &Path, what: &str) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(path).map_err(io(path))?;
    let len = f.metadata().map_err(io(path))?.len();
    let short = || bad(what, "tiff: truncated IFD");
    let mut head = [0u8; 16];
    let n = f.read(&mut head).map_err(io(path))?;
    if n < 8 {
        return Err(short());
    }
    let big_endian = match &head[..2] {
        b"II" => false,
        b"MM" => true,
        _ => return Err(bad(what, "not a TIFF file (no II or MM byte order)")),
    };
    let u16_at = |b: &[u8]| super::endian::word::<2>(b, big_endian) as u16;
    let u32_at = |b: &[u8]| super::endian::word::<4>(b, big_endian) as u32;
    let u64_at = |b: &[u8]| super::endian::word::<8>(b, big_endian);
    let bigtiff = match u16_at(&head[2..]) {
        42 => false,
        43 if n >= 16 => true,
        _ => return Err(bad(what, "not a TIFF file (no 42 or 43 after the byte order)")),
    };
    let (count_bytes, entry_bytes, field) = if bigtiff { (8u64, 20u64, 8u64) } else { (2, 12, 4) };
    let mut at = if bigtiff { u64_at(&head[8..]) } else { u32_at(&head[4..]) as u64 };
    let mut seen = std::collections::HashSet::new();
    let mut buf = Vec::new();
    while at != 0 {
        if seen.len() as u32 > MAX_PAGES || !seen.insert(at) {
            return Err(bad(what, "tiff: more IFDs than pages are read, or a loop of IFDs"));
        }
        if at.checked_add(count_bytes).is_none_or(|e| e > len) {
            return Err(short());
        }
        f.seek(SeekFrom::Start(at)).map_err(io(path))?;
        buf.resize(count_bytes as usize, 0);
        f.read_exact(&mut buf).map_err(|_| short())?;
        let entries = if bigtiff { u64_at(&buf) } else { u16_at(&buf) as u64 };
        let size = entries.checked_mul(entry_bytes).and_then(|b| b.checked_add(field));
        if size.and_then(|s| s.checked_add(at + count_bytes)).is_none_or(|e| e > len) {
            return Err(short());
        }
        buf.resize(size.unwrap_or(0) as usize, 0);
        f.read_exact(&mut buf).map_err(|_| short())?;
        for e in buf[..(entries * entry_bytes) as usize].chunks(entry_bytes as usize) {
            let count = if bigtiff { u64_at(&e[4..]) } else { u32_at(&e[4..]) as u64 };
            let bytes = count.checked_mul(type_size(u16_at(&e[2..]))).ok_or_else(short)?;
            if bytes > field {
                let offset = if bigtiff { u64_at(&e[12..]) } else { u32_at(&e[8..]) as u64 };
                if offset.checked_add(bytes).is_none_or(|end| end > len) {
                    return Err(bad(what, format!("tiff: tag {} holds {count} values past the file's end", u16_at(e))));
                }
            }
        }
        let next = &buf[(entries * entry_bytes) as usize..];
        at = if bigtiff { u64_at(next) } else { u32_at(next) as u64 };
    }
    Ok(())
}

fn decoder(path: &Path, what: &str) -> Result<Decoder<BufReader<std::fs::File>>> {
    check_ifds(path, what)?;
    let file = std::fs::File::open(path).map_err(io(path))?;
    let mut limits = Limits::default();
    // A page's samples, within the host budget (the page's size is checked before it decodes).
    let most = crate::error::host_budget().unwrap_or(u64::MAX).min(MAX_VOXELS * 8) as usize;
    limits.decoding_buffer_size = most;
    limits.intermediate_buffer_size = most;
    Ok(Decoder::new(BufReader::new(file)).map_err(|e| bad(what, format!("tiff: {e}")))?.with_limits(limits))
}

/// A page's size, refused unless it is one channel.
fn page_size(dec: &mut Decoder<BufReader<std::fs::File>>, page: u32, what: &str) -> Result<(u32, u32)> {
    let size = dec.dimensions().map_err(|e| bad(what, format!("tiff page {page}: {e}")))?;
    match dec.colortype().map_err(|e| bad(what, format!("tiff page {page}: {e}")))? {
        tiff::ColorType::Gray(8 | 16 | 32 | 64) => Ok(size),
        // The tiff crate reads packed samples a byte each, past the strip: garbage before.
        tiff::ColorType::Gray(bits) => Err(bad(
            what,
            format!("tiff page {page} holds {bits}-bit samples: 8, 16, 32 and 64-bit samples are read (save the mask as 8-bit)"),
        )),
        other => Err(bad(what, format!("tiff page {page} is {other:?}: a volume's slices are single-channel images"))),
    }
}

/// Refuses a TIFF whose pages interleave several channels or time points (ImageJ's `channels=` or
/// `frames=`, OME-TIFF's `SizeC` or `SizeT` above 1): its pages are not one volume's slices.
fn one_volume(dec: &mut Decoder<BufReader<std::fs::File>>, what: &str) -> Result<()> {
    let description = dec.get_tag_ascii_string(Tag::ImageDescription).unwrap_or_default();
    let count = |key: &str| -> u64 {
        description.find(key).map_or(1, |at| {
            let rest = description[at + key.len()..].trim_start_matches('"');
            rest[..rest.find(|c: char| !c.is_ascii_digit()).unwrap_or(rest.len())].parse().unwrap_or(1)
        })
    };
    let keys: &[(&str, &str)] = if description.starts_with("ImageJ=") {
        &[("channels=", "channels"), ("frames=", "time points")]
    } else if description.contains("<OME") {
        &[("SizeC=", "channels"), ("SizeT=", "time points")]
    } else {
        &[]
    };
    for (key, name) in keys {
        let n = count(key);
        if n > 1 {
            return Err(bad(what, format!("its pages interleave {n} {name}: a TIFF stack read as a volume holds one")));
        }
    }
    Ok(())
}

/// Spacing from a TIFF's description: ImageJ's `spacing=` (z; x and y from the resolution tags,
/// pixels per unit) or OME-TIFF's `PhysicalSizeX/Y/Z`.
fn tiff_spacing(dec: &mut Decoder<BufReader<std::fs::File>>) -> std::result::Result<[f32; 3], String> {
    let mut s = [1.0f32; 3];
    let description = dec.get_tag_ascii_string(Tag::ImageDescription).unwrap_or_default();
    let number = |key: &str| -> Option<f32> {
        let at = description.find(key)? + key.len();
        let rest = description[at..].trim_start_matches('"');
        let end = rest.find(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c))).unwrap_or(rest.len());
        let v: f32 = rest[..end].parse().ok()?;
        (v.is_finite() && v > 0.0).then_some(v)
    };
    if description.starts_with("ImageJ=") {
        if let Some(z) = number("spacing=") {
            s[2] = z;
        }
        for (axis, tag) in [(0, Tag::XResolution), (1, Tag::YResolution)] {
            if let Ok(r) = dec.get_tag_u32_vec(tag) {
                if r.len() == 2 && r[0] > 0 && r[1] > 0 {
                    s[axis] = r[1] as f32 / r[0] as f32;
                }
            }
        }
    } else if description.contains("<OME") {
        // Each size in its own unit (µm when none is named), turned into X's: a z in nm beside an
        // x in mm drew 10^6 times too long.
        let unit = |key: &str| -> std::result::Result<f64, String> {
            let Some(at) = description.find(key) else { return Ok(1e-6) };
            let rest = description[at + key.len()..].trim_start_matches('"');
            let name = &rest[..rest.find('"').unwrap_or(rest.len())];
            metres(name).ok_or_else(|| {
                format!("{}{name}: the units read are m, cm, mm, µm, nm, pm and Å", &key[..key.len() - 1])
            })
        };
        let mut first = None;
        for (axis, key) in ["PhysicalSizeX", "PhysicalSizeY", "PhysicalSizeZ"].iter().enumerate() {
            if let Some(v) = number(&format!("{key}=")) {
                let u = unit(&format!("{key}Unit="))?;
                let base = *first.get_or_insert(u);
                s[axis] = (v as f64 * u / base) as f32;
            }
        }
    }
    Ok(s)
}

/// Metres in one of OME's length units.
fn metres(unit: &str) -> Option<f64> {
    Some(match unit {
        "m" => 1.0,
        "cm" => 1e-2,
        "mm" => 1e-3,
        "\u{b5}m" | "\u{3bc}m" | "um" => 1e-6,
        "nm" => 1e-9,
        "pm" => 1e-12,
        "Å" | "A" => 1e-10,
        _ => return None,
    })
}

/// A decoded image's samples as f32, refused unless it is one channel of `w` x `h`.
fn samples(image: DecodingResult, w: u32, h: u32, what: &str) -> Result<Vec<f32>> {
    use DecodingResult as D;
    let v: Vec<f32> = match image {
        D::U8(v) => v.into_iter().map(f32::from).collect(),
        D::U16(v) => v.into_iter().map(f32::from).collect(),
        D::I16(v) => v.into_iter().map(f32::from).collect(),
        D::I8(v) => v.into_iter().map(f32::from).collect(),
        D::U32(v) => super::held::held(v.into_iter().map(f64::from), super::held::U32, what)?,
        D::I32(v) => super::held::held(v.into_iter().map(f64::from), super::held::I32, what)?,
        D::F32(v) => v,
        D::F64(v) => super::held::held(v.into_iter(), None, what)?,
        _ => {
            return Err(bad(what, "64-bit integer samples are not read (8, 16 and 32-bit integers, float32, float64)"))
        }
    };
    if v.len() as u64 != w as u64 * h as u64 {
        return Err(bad(what, format!("{} samples, not one channel of {w} x {h}", v.len())));
    }
    Ok(v)
}

/// The number in a file name's stem (its last run of digits), which orders a folder's slices.
pub(super) fn slice_number(path: &Path) -> Option<u64> {
    let stem = path.file_stem()?.to_string_lossy().into_owned();
    // Byte offsets only at ASCII digits: a name that is not UTF-8 reads with U+FFFD, three bytes.
    let end = stem.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = stem[..end].trim_end_matches(|c: char| c.is_ascii_digit()).len();
    stem[start..end].parse().ok()
}

/// Whether `path` is an image stack that reads as a volume: a folder, or a TIFF of more than one
/// page (a one-page TIFF is a height grid to `info`).
pub fn is_stack(path: &Path) -> Result<bool> {
    let name = super::lower_name(path);
    if path.is_dir() {
        return Ok(true);
    }
    if !(name.ends_with(".tif") || name.ends_with(".tiff")) {
        return Ok(false);
    }
    Ok(decoder(path, &path.display().to_string())?.more_images())
}

impl Stack {
    /// A multipage TIFF: every page a slice of the first page's size.
    pub fn tiff(path: &Path) -> Result<Stack> {
        let what = path.display().to_string();
        let mut dec = decoder(path, &what)?;
        let (w, h) = page_size(&mut dec, 0, &what)?;
        one_volume(&mut dec, &what)?;
        let spacing = tiff_spacing(&mut dec).map_err(|why| bad(&what, why))?;
        let mut pages = 1u32;
        while dec.more_images() {
            if pages == MAX_PAGES {
                return Err(bad(&what, format!("more than {MAX_PAGES} pages")));
            }
            dec.next_image().map_err(|e| bad(&what, format!("tiff page {pages}: {e}")))?;
            let size = page_size(&mut dec, pages, &what)?;
            if size != (w, h) {
                return Err(bad(&what, format!("tiff page {pages} is {} x {}, page 0 {w} x {h}", size.0, size.1)));
            }
            pages += 1;
        }
        Self::sized(Slices::Pages { path: path.to_path_buf(), at: None }, [w, h, pages], spacing, what)
    }

    /// A folder of numbered 2-D images (`.png`, `.tif`, `.tiff`), one slice each, ordered by the
    /// number in each name; the other files are left alone.
    pub fn folder(dir: &Path) -> Result<Stack> {
        let what = dir.display().to_string();
        let mut files = Vec::new();
        for entry in std::fs::read_dir(dir).map_err(io(dir))? {
            let path = entry.map_err(io(dir))?.path();
            let name = super::lower_name(&path);
            if [".png", ".tif", ".tiff"].iter().any(|e| name.ends_with(e)) {
                let n = slice_number(&path).ok_or_else(|| {
                    bad(&what, format!("{} has no number in its name to order the slices by", path.display()))
                })?;
                files.push((n, path));
            }
        }
        if files.is_empty() {
            return Err(bad(&what, "a folder read as a volume holds numbered PNG or TIFF slices; this one holds none"));
        }
        files.sort();
        if let Some(w) = files.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(bad(
                &what,
                format!("{} and {} share slice number {}", w[0].1.display(), w[1].1.display(), w[0].0),
            ));
        }
        let files: Vec<PathBuf> = files.into_iter().map(|(_, p)| p).collect();
        let first = read_image(&files[0])?;
        let (w, h) = (first.1, first.2);
        let depth = u32::try_from(files.len()).map_err(|_| bad(&what, "too many slices"))?;
        Self::sized(Slices::Files(files, first.3), [w, h, depth], [1.0; 3], what)
    }

    /// A DICOM series: a folder of one (or `pick`: its index or UID), or one file of its series,
    /// at time point `time` (`dicom::open`).
    pub fn dicom(path: &Path, pick: Option<&str>, rectilinear: bool, time: Option<u32>) -> Result<Stack> {
        let series = super::dicom::open(path, pick, rectilinear, time)?;
        let (dims, orientation) = (series.dims, series.orientation);
        let mut stack = Self::sized(Slices::Dicom(series), dims, orientation.spacing(), path.display().to_string())?;
        stack.orientation = Some(orientation);
        Ok(stack)
    }

    fn sized(slices: Slices, dims: [u32; 3], spacing: [f32; 3], what: String) -> Result<Stack> {
        super::voxel_count_within(&dims.map(u64::from), &what, MAX_STREAMED_VOXELS)?;
        Ok(Stack { slices, dims, spacing, orientation: None, what })
    }

    /// Slices `z0..z0 + count` (x fastest) into `out`.
    pub fn read(&mut self, z0: u32, count: u32, out: &mut Vec<f32>) -> Result<()> {
        out.clear();
        if let Slices::Dicom(series) = &mut self.slices {
            for slice in series.slices(z0, count)? {
                out.extend_from_slice(&slice);
            }
            return super::check_finite(out, &self.what);
        }
        let [w, h, _] = self.dims;
        for z in z0..z0 + count {
            let slice = match &mut self.slices {
                Slices::Pages { path, at } => {
                    if at.as_ref().is_none_or(|(_, page)| *page > z) {
                        *at = Some((decoder(path, &self.what)?, 0));
                    }
                    let (dec, page) = at.as_mut().expect("opened above");
                    while *page < z {
                        dec.next_image().map_err(|e| bad(&self.what, format!("tiff page {}: {e}", *page + 1)))?;
                        *page += 1;
                    }
                    let image = dec.read_image().map_err(|e| bad(&self.what, format!("tiff page {z}: {e}")))?;
                    samples(image, w, h, &format!("{} page {z}", self.what))?
                }
                Slices::Dicom(series) => series.slice(z)?,
                Slices::Files(files, kind) => {
                    let (values, fw, fh, k) = read_image(&files[z as usize])?;
                    let first = files[0].display();
                    if (fw, fh) != (w, h) {
                        return Err(bad(
                            &files[z as usize].display().to_string(),
                            format!("{fw} x {fh}, {first} {w} x {h}"),
                        ));
                    }
                    // 8-bit slices beside 16-bit ones sat at 0.4 % of the range: one volume's
                    // slices share a sample type.
                    if k != *kind {
                        return Err(bad(
                            &files[z as usize].display().to_string(),
                            format!("{k} samples, {first} {kind}: a folder's slices share one sample type"),
                        ));
                    }
                    values
                }
            };
            out.extend_from_slice(&slice);
        }
        super::check_finite(out, &self.what)
    }
}

/// One single-channel 2-D image (PNG, or a TIFF's first page): its samples, size and sample type.
fn read_image(path: &Path) -> Result<(Vec<f32>, u32, u32, &'static str)> {
    let what = path.display().to_string();
    let name = super::lower_name(path);
    if name.ends_with(".tif") || name.ends_with(".tiff") {
        let mut dec = decoder(path, &what)?;
        let (w, h) = page_size(&mut dec, 0, &what)?;
        let image = dec.read_image().map_err(|e| bad(&what, format!("tiff: {e}")))?;
        use DecodingResult as D;
        let kind = match &image {
            D::U8(_) => "8-bit",
            D::U16(_) => "16-bit",
            D::I8(_) => "signed 8-bit",
            D::I16(_) => "signed 16-bit",
            D::U32(_) => "32-bit",
            D::I32(_) => "signed 32-bit",
            D::F32(_) => "float32",
            D::F64(_) => "float64",
            _ => "64-bit integer",
        };
        return Ok((samples(image, w, h, &what)?, w, h, kind));
    }
    let mut reader = image::ImageReader::open(path).map_err(io(path))?.with_guessed_format().map_err(io(path))?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(MAX_VOXELS * 4);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| bad(&what, e))?;
    let (w, h) = (img.width(), img.height());
    let (values, kind): (Vec<f32>, _) = match img {
        image::DynamicImage::ImageLuma8(i) => (i.pixels().map(|p| p[0] as f32).collect(), "8-bit"),
        image::DynamicImage::ImageLuma16(i) => (i.pixels().map(|p| p[0] as f32).collect(), "16-bit"),
        other => {
            return Err(bad(&what, format!("{:?}: a volume's slices are single-channel (grey) images", other.color())))
        }
    };
    Ok((values, w, h, kind))
}

/// The first image of a TIFF as heights (u8, u16, i16, u32, f32), within `MAX_VOXELS`.
pub fn tiff_heights(bytes: &[u8], what: &str) -> Result<super::HeightGrid> {
    let mut limits = tiff::decoder::Limits::default();
    limits.decoding_buffer_size = (MAX_VOXELS * 4) as usize;
    limits.intermediate_buffer_size = (MAX_VOXELS * 4) as usize;
    let mut dec = tiff::decoder::Decoder::new(std::io::Cursor::new(bytes))
        .map_err(|e| bad(what, format!("tiff: {e}")))?
        .with_limits(limits);
    let (w, h) = dec.dimensions().map_err(|e| bad(what, format!("tiff: {e}")))?;
    super::voxel_count(&[w as u64, h as u64], what)?;
    // GDAL's no-data value (tag 42113, text): those cells have no height (holes), where they were
    // drawn at it (-9999 flattened a hill into a slab).
    let no_data = match dec.get_tag_ascii_string(Tag::GdalNodata) {
        Ok(text) => {
            let t = text.trim_end_matches('\0').trim();
            Some(t.parse::<f64>().map_err(|_| bad(what, format!("GDAL_NODATA '{t}' is not a number")))?)
        }
        Err(_) => None,
    };
    use tiff::decoder::DecodingResult as D;
    const READ: &str = "uint8, uint16, int16, uint32, float32 and float64 single-channel heights are read";
    let heights: Vec<f32> = match dec.read_image().map_err(|e| bad(what, format!("tiff: {e} ({READ})")))? {
        D::U8(v) => v.into_iter().map(f32::from).collect(),
        D::U16(v) => v.into_iter().map(f32::from).collect(),
        D::I16(v) => v.into_iter().map(f32::from).collect(),
        D::U32(v) => super::held::held(v.into_iter().map(f64::from), super::held::U32, what)?,
        D::F32(v) => v,
        D::F64(v) => super::held::held(v.into_iter(), None, what)?,
        other => {
            let kind = match other {
                D::I8(_) => "int8",
                D::I32(_) => "int32",
                D::U64(_) => "uint64",
                D::I64(_) => "int64",
                _ => "this sample type",
            };
            return Err(bad(what, format!("TIFF samples of {kind} are not read ({READ})")));
        }
    };
    if heights.len() as u64 != w as u64 * h as u64 {
        return Err(bad(what, "TIFF is not a single-channel height grid"));
    }
    let mut heights = heights;
    if let Some(nd) = no_data {
        // Compared as the samples are held (f32): -9999 is exact, 3.4e38 rounds alike.
        heights.iter_mut().filter(|v| **v == nd as f32 || nd.is_nan() && v.is_nan()).for_each(|v| *v = f32::NAN);
    }
    Ok(super::HeightGrid { width: w, rows: h, heights })
}
