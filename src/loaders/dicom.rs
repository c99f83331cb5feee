//! DICOM series (issue 47): the images of one series in a folder (single-frame, enhanced
//! multi-frame placed by per-frame functional groups, or multi-frame with a Grid Frame Offset
//! Vector such as RT Dose), read with dicom-rs.
//! Slices are ordered by their position along the slice normal (DICOM C.7.6.2: Image Position and
//! Orientation (Patient), Pixel Spacing), not by file name or instance number; the grid is placed
//! in patient space (LPS turned RAS), a gantry tilt as a sheared grid; values are rescaled by the
//! series' Rescale Slope and Intercept. Pixel data is decoded by dicom-pixeldata (JPEG
//! baseline/extended/lossless, JPEG 2000 through OpenJPEG's pure-Rust port, and RLE) or by
//! `pure_jpegls` (JPEG-LS; dicom-rs has only the C++ CharLS for it); other transfer syntaxes are
//! refused by name; a deflated data set is inflated (`walk::checked_bytes`). A series is read a
//! few slices at a time, so it streams into the bricked store as NIfTI does.
use super::bad;
use crate::error::{Error, Result};
use dicom_dictionary_std::tags;
use dicom_object::file::ReadPreamble;
use dicom_object::OpenFileOptions;
use glam::{DMat4, DVec3, DVec4};
use std::path::{Path, PathBuf};

/// Most bytes the images decoded in parallel hold together (`Series::slices`).
const PARALLEL_BYTES: u64 = 256 << 20;

/// Most files a folder may hold to be scanned for series.
const MAX_FILES: usize = 1 << 16;

/// Whether `path` is a DICOM file: "DICM" after its 128-byte preamble.
pub fn is_dicom(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 132];
    std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut head)).is_ok() && &head[128..] == b"DICM"
}

mod apart;
mod jpegls;
mod pixels;
use pixels::decode;
mod resample;
use resample::Gaps;
mod walk;
pub use resample::even_slices;
use walk::checked_bytes;

/// One image of a series, from its header.
#[derive(Clone, Debug)]
struct Image {
    path: PathBuf,
    position: DVec3,
    row: DVec3,
    column: DVec3,
    /// Pixel Spacing: between rows, between columns.
    spacing: [f64; 2],
    rescale: [f64; 2],
    size: [u32; 2],
    /// The file's frame this slice is (0 for a single-frame image), of its `frames`.
    frame: u32,
    frames: u32,
    /// Its temporal position (an enhanced image's Temporal Position Index, else a classic
    /// image's Temporal Position Identifier; 0 without one).
    time: i64,
}

/// A series in a folder: what `voxsplat info DIR` lists.
#[derive(Clone, Debug)]
pub struct SeriesInfo {
    /// Series Instance UID.
    pub uid: String,
    /// Series Description (empty when absent).
    pub description: String,
    /// Modality (CT, MR, ...).
    pub modality: String,
    /// Columns, rows, images (of one time point).
    pub dims: [u32; 3],
    /// Its temporal positions, in order (one for a series without time).
    pub times: u32,
    images: Vec<Image>,
}

fn text(obj: &dicom_object::InMemDicomObject, tag: dicom_core::Tag) -> String {
    obj.element_opt(tag).ok().flatten().and_then(|e| e.to_str().ok()).map(|s| s.trim().to_string()).unwrap_or_default()
}

/// The numbers of element `tag` (`name` in messages), exactly `n` of them.
fn numbers(
    obj: &dicom_object::InMemDicomObject,
    tag: dicom_core::Tag,
    name: &str,
    n: usize,
    what: &str,
) -> Result<Vec<f64>> {
    let e = obj.element_opt(tag).ok().flatten().ok_or_else(|| bad(what, format!("no {name}")))?;
    let v = e.to_multi_float64().map_err(|e| bad(what, format!("{name}: {e}")))?;
    if v.len() != n || !v.iter().all(|x| x.is_finite()) {
        return Err(bad(what, format!("{name} holds {v:?}, not {n} finite numbers")));
    }
    Ok(v)
}

/// The data set that holds an enhanced image's attribute `tag` for a frame: the frame's item of
/// functional group `seq` (C.7.6.16), else the shared one, else the data set itself (a classic
/// image, or a group the file left out).
fn group<'a>(
    frame: Option<&'a dicom_object::InMemDicomObject>,
    shared: Option<&'a dicom_object::InMemDicomObject>,
    top: &'a dicom_object::InMemDicomObject,
    seq: dicom_core::Tag,
    tag: dicom_core::Tag,
) -> &'a dicom_object::InMemDicomObject {
    [frame, shared]
        .into_iter()
        .flatten()
        .filter_map(|g| g.element_opt(seq).ok().flatten()?.items()?.first())
        .find(|item| item.element_opt(tag).ok().flatten().is_some())
        .unwrap_or(top)
}

/// An image's plane and rescale, read from the data sets that hold Image Orientation (Patient),
/// Pixel Spacing, Rescale Slope (or RT Dose's Dose Grid Scaling) and Rescale Intercept; its
/// position, size and frame are left for the caller.
fn plane(
    orientation: &dicom_object::InMemDicomObject,
    measures: &dicom_object::InMemDicomObject,
    slope: &dicom_object::InMemDicomObject,
    intercept: &dicom_object::InMemDicomObject,
    what: &str,
) -> Result<Image> {
    let o = numbers(orientation, tags::IMAGE_ORIENTATION_PATIENT, "Image Orientation (Patient)", 6, what)?;
    let s = numbers(measures, tags::PIXEL_SPACING, "Pixel Spacing", 2, what)?;
    if !(s[0] > 0.0 && s[1] > 0.0) {
        return Err(bad(what, format!("Pixel Spacing {s:?}: spacings must be positive")));
    }
    let (row, column) = (DVec3::new(o[0], o[1], o[2]), DVec3::new(o[3], o[4], o[5]));
    if (row.length() - 1.0).abs() > 1e-3 || (column.length() - 1.0).abs() > 1e-3 || row.dot(column).abs() > 1e-3 {
        return Err(bad(what, format!("Image Orientation (Patient) {o:?} is not two unit, perpendicular directions")));
    }
    let scalar = |obj: &dicom_object::InMemDicomObject, tag, default: f64, name: &str| -> Result<f64> {
        match obj.element_opt(tag).ok().flatten() {
            Some(e) => e.to_float64().map_err(|e| bad(what, format!("{name}: {e}"))).and_then(|v| {
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(bad(what, format!("{name} is {v}")))
                }
            }),
            None => Ok(default),
        }
    };
    // RT Dose stores its values scaled: Dose Grid Scaling, where no Rescale Slope is given.
    let (slope, name) = match slope.element_opt(tags::RESCALE_SLOPE).ok().flatten() {
        Some(_) => (scalar(slope, tags::RESCALE_SLOPE, 1.0, "Rescale Slope")?, "Rescale Slope"),
        None => (scalar(slope, tags::DOSE_GRID_SCALING, 1.0, "Dose Grid Scaling")?, "Dose Grid Scaling"),
    };
    // A slope of 0 maps every stored value to the intercept: a constant volume, an empty frame.
    if slope == 0.0 {
        return Err(bad(what, format!("{name} is 0: every stored value would read as one value (a slope is not 0)")));
    }
    Ok(Image {
        path: PathBuf::new(),
        position: DVec3::ZERO,
        row: row.normalize(),
        column: column.normalize(),
        spacing: [s[0], s[1]],
        rescale: [slope, scalar(intercept, tags::RESCALE_INTERCEPT, 0.0, "Rescale Intercept")?],
        size: [0; 2],
        frame: 0,
        frames: 1,
        time: 0,
    })
}

/// A file's series UID, description, modality and slices.
type Header = (String, String, String, Vec<Image>);

/// An image's header (up to its pixel data), or `None` for an object that is not an image (no
/// Rows): a folder's other objects are left alone. A multi-frame image is one slice per frame,
/// placed by its own functional groups (an enhanced CT or MR image: Plane Position, Plane
/// Orientation, Pixel Measures and Pixel Value Transformation, per frame or shared; frames of
/// several temporal positions are time points), or by its Grid Frame Offset Vector (RT Dose: offsets
/// along the normal from Image Position (Patient) when the first is 0, else the frames' z
/// coordinates on an axial grid) and scaled by its Dose Grid Scaling.
fn header(path: &Path) -> Result<Option<Header>> {
    let what = path.display().to_string();
    let bytes = checked_bytes(path, &what)?;
    let obj = OpenFileOptions::new()
        .read_preamble(ReadPreamble::Always)
        .read_until(tags::PIXEL_DATA)
        .from_reader(bytes.as_slice())
        .map_err(|e| bad(&what, format!("DICOM: {e}")))?;
    if obj.element_opt(tags::ROWS).ok().flatten().is_none() {
        return Ok(None);
    }
    let count = |tag, name: &str| -> Result<u32> {
        let e = obj.element(tag).map_err(|_| bad(&what, format!("no {name}")))?;
        let v: u32 = e.to_int().map_err(|e| bad(&what, format!("{name}: {e}")))?;
        Ok(v)
    };
    let size = [count(tags::COLUMNS, "Columns")?, count(tags::ROWS, "Rows")?];
    if size.contains(&0) {
        return Err(bad(&what, format!("an image of {} x {} pixels", size[0], size[1])));
    }
    // A decoder sizes its frame by Rows x Columns x Samples per Pixel before it reads a byte.
    let samples = match obj.element_opt(tags::SAMPLES_PER_PIXEL).ok().flatten() {
        Some(e) => e.to_int::<u32>().map_err(|e| bad(&what, format!("Samples per Pixel: {e}")))?,
        None => 1,
    };
    if samples != 1 {
        return Err(Error::Unsupported(format!(
            "{what}: Samples per Pixel {samples}: only one sample per pixel (a grey-scale image) is read"
        )));
    }
    let frames = match obj.element_opt(tags::NUMBER_OF_FRAMES).ok().flatten() {
        Some(e) => e.to_int::<u32>().map_err(|e| bad(&what, format!("Number of Frames: {e}")))?,
        None => 1,
    };
    if frames == 0 || frames as u64 > MAX_FILES as u64 {
        return Err(bad(&what, format!("Number of Frames {frames}: 1 to {MAX_FILES}")));
    }
    let per_frame = obj.element_opt(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE).ok().flatten();
    let images = match per_frame {
        // An enhanced image: each frame placed by its own functional groups.
        Some(e) => {
            let items =
                e.items().ok_or_else(|| bad(&what, "Per-frame Functional Groups Sequence is not a sequence"))?;
            if items.len() != frames as usize {
                return Err(bad(
                    &what,
                    format!("Per-frame Functional Groups Sequence holds {} items for {frames} frames", items.len()),
                ));
            }
            let shared = obj
                .element_opt(tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE)
                .ok()
                .flatten()
                .and_then(|e| e.items())
                .and_then(|i| i.first());
            let mut images = Vec::with_capacity(items.len());
            for (k, item) in items.iter().enumerate() {
                let at = |seq, tag| group(Some(item), shared, &obj, seq, tag);
                let frame = format!("{what} frame {}", k + 1);
                let p = numbers(
                    at(tags::PLANE_POSITION_SEQUENCE, tags::IMAGE_POSITION_PATIENT),
                    tags::IMAGE_POSITION_PATIENT,
                    "Image Position (Patient)",
                    3,
                    &frame,
                )?;
                let plane = plane(
                    at(tags::PLANE_ORIENTATION_SEQUENCE, tags::IMAGE_ORIENTATION_PATIENT),
                    at(tags::PIXEL_MEASURES_SEQUENCE, tags::PIXEL_SPACING),
                    at(tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE, tags::RESCALE_SLOPE),
                    at(tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE, tags::RESCALE_INTERCEPT),
                    &frame,
                )?;
                let content = at(tags::FRAME_CONTENT_SEQUENCE, tags::TEMPORAL_POSITION_INDEX);
                let time = match content.element_opt(tags::TEMPORAL_POSITION_INDEX).ok().flatten() {
                    Some(t) => t.to_int::<i64>().map_err(|e| bad(&frame, format!("Temporal Position Index: {e}")))?,
                    None => 0,
                };
                images.push(Image {
                    path: path.to_path_buf(),
                    position: DVec3::new(p[0], p[1], p[2]),
                    size,
                    frame: k as u32,
                    frames,
                    time,
                    ..plane
                });
            }
            images
        }
        None => {
            let p = numbers(&obj, tags::IMAGE_POSITION_PATIENT, "Image Position (Patient)", 3, &what)?;
            let time = match obj.element_opt(tags::TEMPORAL_POSITION_IDENTIFIER).ok().flatten() {
                Some(t) => t.to_int::<i64>().map_err(|e| bad(&what, format!("Temporal Position Identifier: {e}")))?,
                None => 0,
            };
            let plane = Image { frames, time, ..plane(&obj, &obj, &obj, &obj, &what)? };
            let position = DVec3::new(p[0], p[1], p[2]);
            let offsets = if frames > 1 {
                numbers(&obj, tags::GRID_FRAME_OFFSET_VECTOR, "Grid Frame Offset Vector", frames as usize, &what)?
            } else {
                vec![0.0]
            };
            let normal = plane.row.cross(plane.column);
            // Offsets from the first frame, or (a first offset other than 0) the frames' z on an axial grid.
            let relative = offsets[0] == 0.0;
            if !relative && (normal.z.abs() - 1.0).abs() > 1e-6 {
                return Err(bad(&what, "Grid Frame Offset Vector of z coordinates on a grid that is not axial"));
            }
            offsets
                .iter()
                .enumerate()
                .map(|(k, &o)| Image {
                    path: path.to_path_buf(),
                    position: if relative { position + normal * o } else { DVec3::new(position.x, position.y, o) },
                    size,
                    frame: k as u32,
                    ..plane.clone()
                })
                .collect()
        }
    };
    let uid = text(&obj, tags::SERIES_INSTANCE_UID);
    Ok(Some((uid, text(&obj, tags::SERIES_DESCRIPTION), text(&obj, tags::MODALITY), images)))
}

/// The series of the DICOM images in folder `dir` (its files, not its subfolders), in order of
/// their UIDs; files that are not DICOM, and DICOM objects that are not images, are left alone.
/// A DICOM file whose header does not read (cut short, malformed) is left out too, so that one
/// bad file does not hide the folder's other series (`Scan::unread` names each); with no series
/// left, the first such file's error is the folder's.
pub fn series_in(dir: &Path) -> Result<Scan> {
    let what = dir.display().to_string();
    let io = |e| Error::Io { path: what.clone(), source: e };
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(dir).map_err(io)?.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.is_file()).collect();
    if files.len() > MAX_FILES {
        return Err(bad(&what, format!("{} files: at most {MAX_FILES} are scanned for DICOM series", files.len())));
    }
    files.sort();
    let mut series: Vec<SeriesInfo> = Vec::new();
    let mut unread = Vec::new();
    for path in files.into_iter().filter(|p| is_dicom(p)) {
        let (uid, description, modality, images) = match header(&path) {
            Ok(Some(h)) => h,
            Ok(None) => continue,
            Err(e) => {
                unread.push((path, e));
                continue;
            }
        };
        match series.iter_mut().find(|s| s.uid == uid) {
            Some(s) => s.images.extend(images),
            None => series.push(SeriesInfo { uid, description, modality, dims: [0; 3], times: 1, images }),
        }
    }
    series.sort_by(|a, b| a.uid.cmp(&b.uid));
    for s in &mut series {
        let times = s.temporal_positions().len();
        s.times = times as u32;
        s.dims = [s.images[0].size[0], s.images[0].size[1], (s.images.len() / times) as u32];
    }
    if series.is_empty() && !unread.is_empty() {
        return Err(unread.swap_remove(0).1);
    }
    Ok(Scan { series, unread })
}

/// A folder's DICOM series (`series_in`) and the DICOM files whose headers did not read.
pub struct Scan {
    /// Its series, in order of their UIDs.
    pub series: Vec<SeriesInfo>,
    /// Each file left out, and why.
    pub unread: Vec<(PathBuf, Error)>,
}

impl Scan {
    /// A note on the files left out (the first three named), or `None` when every file read.
    pub fn note(&self) -> Option<String> {
        let (first, n) = (self.unread.iter().take(3), self.unread.len());
        let said = |e: &Error| match e {
            Error::InvalidArgument(m) => m.clone(),
            e => e.to_string(),
        };
        let named: Vec<String> = first.map(|(_, why)| said(why)).collect();
        let more = if n > 3 { format!("; and {} more", n - 3) } else { String::new() };
        (n > 0).then(|| {
            format!("{n} DICOM file(s) of the folder left out, their headers unread: {}{more}", named.join("; "))
        })
    }
}

impl SeriesInfo {
    /// Its images' temporal positions, each once, in order.
    fn temporal_positions(&self) -> Vec<i64> {
        self.images.iter().map(|i| i.time).collect::<std::collections::BTreeSet<_>>().into_iter().collect()
    }
}

/// Whether folder `dir` holds a DICOM file (read as a series rather than a stack of images).
pub fn holds_dicom(dir: &Path) -> bool {
    std::fs::read_dir(dir).is_ok_and(|d| d.filter_map(|e| e.ok()).take(MAX_FILES).any(|e| is_dicom(&e.path())))
}

/// A series read a slice at a time.
pub struct Series {
    images: Vec<Image>,
    /// The last multi-frame file decoded: its path and every frame's raw samples (its slices are
    /// read in turn, and dicom-pixeldata decodes a file whole).
    frames: Option<(PathBuf, Vec<Vec<f64>>)>,
    /// Columns, rows, slices.
    pub dims: [u32; 3],
    /// Placement in patient space (RAS).
    pub orientation: crate::orient::Orientation,
    rescale: [f64; 2],
    /// How its slices are spaced.
    gaps: Gaps,
    /// The last image a resampled read decoded, and its index: the next read of the slices
    /// after it starts from it.
    kept: Option<(u32, Vec<f32>)>,
    /// The images of the series left out (a localizer, a slice far from the rest), a line each.
    pub left_out: Vec<String>,
}

/// The series `path` names: a folder holding one series (or `pick`, its index in `voxsplat info`'s
/// list or its UID), or one DICOM file of its series, at time point `time` (its images of one
/// temporal position, needed when it has several). Uneven slice gaps are resampled onto even
/// slices at the smallest gap (each linear between its two images; refused when that would take
/// more than `resample::MAX_GROWTH` slices per image), or with `rectilinear` read as they lie (the
/// caller places the slices at `Series::offsets`).
pub fn open(path: &Path, pick: Option<&str>, rectilinear: bool, time: Option<u32>) -> Result<Series> {
    open_at(path, pick, rectilinear, |times| super::time_point(&path.display().to_string(), times, time))
}

/// `open` at time point `time`, or the first when none is given: the placement all time points
/// share (their slices' gaps, the images left out).
pub fn open_placed(path: &Path, pick: Option<&str>, time: Option<u32>) -> Result<Series> {
    open_at(path, pick, true, |times| {
        super::time_point(&path.display().to_string(), times, time.or((times > 1).then_some(0)))
    })
}

fn open_at(path: &Path, pick: Option<&str>, rectilinear: bool, at: impl Fn(u32) -> Result<u32>) -> Result<Series> {
    let what = path.display().to_string();
    let (chosen, unread) = chosen(path, pick)?;
    let t = at(chosen.times)?;
    let at = chosen.temporal_positions()[t as usize];
    let images = chosen.images.iter().filter(|i| i.time == at).cloned().collect();
    let mut series = build(&SeriesInfo { images, ..chosen }, &what, rectilinear)?;
    series.left_out.extend(unread);
    Ok(series)
}

/// The temporal positions of the series `path` names (`open`'s), 1 when it names none alone (a
/// folder of several series without `pick`).
pub fn time_points(path: &Path, pick: Option<&str>) -> Result<u32> {
    Ok(chosen(path, pick).map_or(1, |(s, _)| s.times))
}

/// The series `path` and `pick` name (`open`), and a note on the folder's files left out.
fn chosen(path: &Path, pick: Option<&str>) -> Result<(SeriesInfo, Option<String>)> {
    let what = path.display().to_string();
    let (dir, own) = if path.is_dir() {
        (path.to_path_buf(), None)
    } else {
        (path.parent().unwrap_or(Path::new(".")).to_path_buf(), Some(path))
    };
    let mut scan = series_in(&dir)?;
    // A file named itself whose header does not read is refused for its own reason.
    if let Some(i) = own.and_then(|f| scan.unread.iter().position(|(p, _)| p == f)) {
        return Err(scan.unread.swap_remove(i).1);
    }
    let all = &scan.series;
    let list = || {
        all.iter()
            .enumerate()
            .map(|(i, s)| format!("{i}: {} {} '{}' {:?}", s.uid, s.modality, s.description, s.dims))
            .collect::<Vec<_>>()
            .join("; ")
    };
    let chosen = match (pick, own) {
        (Some(p), _) => all
            .iter()
            .enumerate()
            .find(|(i, s)| s.uid == p || p.parse::<usize>().is_ok_and(|n| n == *i))
            .map(|(_, s)| s)
            .ok_or_else(|| bad(&what, format!("no series {p} here ({})", list())))?,
        (None, Some(file)) => all
            .iter()
            .find(|s| s.images.iter().any(|i| i.path == file))
            .ok_or_else(|| bad(&what, "not an image of a DICOM series"))?,
        (None, None) => match all.len() {
            0 => return Err(bad(&what, "holds no DICOM image")),
            1 => &all[0],
            n => return Err(bad(&what, format!("holds {n} series: pick one with --series N or UID ({})", list()))),
        },
    };
    // A file left out may be an image of this series: refused unless its Series Instance UID,
    // found in its bytes, names another one.
    if let Some(i) = scan.unread.iter().position(|(p, _)| walk::series_uid(p).is_none_or(|u| u == chosen.uid)) {
        return Err(scan.unread.swap_remove(i).1);
    }
    Ok((chosen.clone(), scan.note()))
}

/// Checks a series' images agree and orders them along their normal.
fn build(s: &SeriesInfo, what: &str, rectilinear: bool) -> Result<Series> {
    // A file, or a frame of a multi-frame file.
    let name = |i: &Image| match s.images.iter().filter(|j| j.path == i.path).count() {
        1 => i.path.display().to_string(),
        _ => format!("{} frame {}", i.path.display(), i.frame + 1),
    };
    if s.images.len() > MAX_FILES {
        return Err(bad(what, format!("{} slices: a series holds at most {MAX_FILES}", s.images.len())));
    }
    let (images, mut notes) = apart::localizers(s.images.clone(), &name).unwrap_or((s.images.clone(), Vec::new()));
    apart::agree(&images, what, &name)?;
    let first = &images[0];
    let normal = first.row.cross(first.column);
    let mut images = images;
    images.sort_by(|a, b| a.position.dot(normal).total_cmp(&b.position.dot(normal)));
    let (images, far) = apart::far_slices(images, normal, &name);
    notes.extend(far);
    let first = &images[0].clone();
    let steps: Vec<f64> = images.windows(2).map(|w| (w[1].position - w[0].position).dot(normal)).collect();
    let least = first.spacing[0].min(first.spacing[1]) * 1e-3;
    if let Some(k) = steps.iter().position(|&d| d.abs() < least) {
        return Err(bad(what, format!("duplicate positions: {} and {}", name(&images[k]), name(&images[k + 1]))));
    }
    let mean = steps.iter().sum::<f64>() / steps.len().max(1) as f64;
    let n = images.len();
    let mut gaps = Gaps::Even;
    let mut slices = n;
    if let Some(k) = steps.iter().position(|d| (d - mean).abs() > 0.01 * mean) {
        let gap = format!(
            "uneven slice gaps ({:.4} between {} and {}, {mean:.4} on average)",
            steps[k],
            name(&images[k]),
            name(&images[k + 1])
        );
        // A tilted series' positions leave the normal: its grid would be sheared and uneven.
        let along = (images[n - 1].position - images[0].position).normalize_or_zero();
        if along.dot(normal).abs() < 1.0 - 1e-6 {
            return Err(Error::Unsupported(format!("{what}: {gap} with a gantry tilt: not read")));
        }
        let at: Vec<f64> = images.iter().map(|i| (i.position - images[0].position).dot(normal)).collect();
        if rectilinear {
            gaps = Gaps::At(at);
        } else {
            let m = resample::even_slices(&at).ok_or_else(|| {
                bad(
                    what,
                    format!(
                        "{gap}: resampled at its smallest gap it would take over {} slices per image; draw it as \
                         a rectilinear grid at its slices' positions, as voxsplat render does (the library: the \
                         rectilinear volume hint)",
                        resample::MAX_GROWTH
                    ),
                )
            })?;
            gaps = Gaps::Resampled(resample::weights(&at, m));
            slices = m as usize;
        }
    }
    // The slice step: the first to the last position, over the gaps (a gantry tilt leans it off the
    // normal, which places the grid sheared); one image steps one pixel spacing along the normal.
    let step = if n > 1 {
        (images[n - 1].position - images[0].position) / (slices - 1) as f64
    } else {
        normal * first.spacing[0]
    };
    let lps = DMat4::from_cols(
        (first.row * first.spacing[1]).extend(0.0),
        (first.column * first.spacing[0]).extend(0.0),
        step.extend(0.0),
        images[0].position.extend(1.0),
    );
    // LPS to RAS: x and y negated.
    let affine = DMat4::from_diagonal(DVec4::new(-1.0, -1.0, 1.0, 1.0)) * lps;
    let dims = [first.size[0], first.size[1], slices as u32];
    let orientation = crate::orient::Orientation::from_affine(affine, dims).map_err(|e| bad(what, e))?;
    Ok(Series { images, frames: None, dims, orientation, rescale: first.rescale, gaps, kept: None, left_out: notes })
}

impl Series {
    /// Unevenly spaced slices' positions along the normal, from the first (mm), when they are
    /// read as they lie; `None` when the gaps are even or the series is resampled.
    pub fn offsets(&self) -> Option<&[f64]> {
        match &self.gaps {
            Gaps::At(at) => Some(at),
            _ => None,
        }
    }

    /// Slice `z`'s rescaled values, x fastest.
    pub fn slice(&mut self, z: u32) -> Result<Vec<f32>> {
        if matches!(self.gaps, Gaps::Resampled(_)) {
            return Ok(self.slices(z, 1)?.swap_remove(0));
        }
        self.image(z)
    }

    /// Image `z`'s rescaled values (in order along the normal).
    fn image(&mut self, z: u32) -> Result<Vec<f32>> {
        let image = &self.images[z as usize];
        let raw = match &self.frames {
            Some((path, all)) if *path == image.path => all[image.frame as usize].clone(),
            _ if image.frames == 1 => frames_of(image)?.swap_remove(0),
            _ => {
                let all = frames_of(image)?;
                let raw = all[image.frame as usize].clone();
                self.frames = Some((image.path.clone(), all));
                raw
            }
        };
        self.rescaled(z, raw)
    }

    /// Slices `z0..z0 + count`, as `slice` reads them: single-frame images decoded in parallel,
    /// two per thread at a time within `PARALLEL_BYTES` (a compressed series' decoding is most of
    /// its reading).
    pub fn slices(&mut self, z0: u32, count: u32) -> Result<Vec<Vec<f32>>> {
        let Gaps::Resampled(weights) = &self.gaps else { return self.images_at(z0, count) };
        let Some(picked) = weights.get(z0 as usize..z0 as usize + count as usize).map(<[_]>::to_vec) else {
            return Err(bad(&self.images[0].path.display().to_string(), format!("no slices {z0}..{z0}+{count}")));
        };
        let (Some(first), Some(last)) = (picked.first(), picked.last()) else { return Ok(Vec::new()) };
        let below = first.0;
        let above = (last.0 + 1).min(self.images.len() as u32 - 1);
        // The image below the first slice is often the one above the last read's last slice.
        let mut images = match self.kept.take() {
            Some((k, image)) if k == below => vec![image],
            _ => Vec::new(),
        };
        let next = below + images.len() as u32;
        if next <= above {
            images.extend(self.images_at(next, above - next + 1)?);
        }
        self.kept = images.last().map(|image| (above, image.clone()));
        let blend = |&(k, t): &(u32, f32)| {
            let a = &images[(k - below) as usize];
            match images.get((k + 1 - below) as usize) {
                Some(b) if t > 0.0 => a.iter().zip(b).map(|(a, b)| a + t * (b - a)).collect(),
                _ => a.clone(),
            }
        };
        Ok(picked.iter().map(blend).collect())
    }

    /// Images `z0..z0 + count` (in order along the normal), as `image` reads them.
    fn images_at(&mut self, z0: u32, count: u32) -> Result<Vec<Vec<f32>>> {
        use rayon::prelude::*;
        // An image's file and its samples as f64 and f32, about.
        let per_image = self.dims[0] as u64 * self.dims[1] as u64 * 16;
        let at_once = (PARALLEL_BYTES / per_image.max(1)).clamp(1, 2 * rayon::current_num_threads() as u64);
        let zs: Vec<u32> = (z0..z0 + count).collect();
        let mut out = Vec::with_capacity(zs.len());
        for group in zs.chunks(at_once as usize) {
            if group.iter().all(|&z| self.images[z as usize].frames == 1) {
                let raws: Vec<Result<Vec<f64>>> = group
                    .par_iter()
                    .map(|&z| frames_of(&self.images[z as usize]).map(|mut f| f.swap_remove(0)))
                    .collect();
                for (&z, raw) in group.iter().zip(raws) {
                    out.push(self.rescaled(z, raw?)?);
                }
            } else {
                for &z in group {
                    out.push(self.image(z)?);
                }
            }
        }
        Ok(out)
    }

    /// Slice `z`'s raw samples checked against Rows x Columns and rescaled.
    fn rescaled(&self, z: u32, raw: Vec<f64>) -> Result<Vec<f32>> {
        let [w, h, _] = self.dims;
        if raw.len() as u64 != w as u64 * h as u64 {
            let what = self.images[z as usize].path.display().to_string();
            return Err(bad(&what, format!("pixel data holds {} samples, not Rows x Columns = {h} x {w}", raw.len())));
        }
        let [slope, intercept] = self.rescale;
        Ok(raw.into_iter().map(|v| (v * slope + intercept) as f32).collect())
    }
}

/// Every frame's raw samples of `image`'s file, read and decoded.
fn frames_of(image: &Image) -> Result<Vec<Vec<f64>>> {
    let what = image.path.display().to_string();
    let [w, h] = image.size.map(u64::from);
    crate::error::check_host_memory(image.frames as u64 * w * h * 8, &format!("{what}'s frames"))?;
    let bytes = checked_bytes(&image.path, &what)?;
    let obj = OpenFileOptions::new()
        .read_preamble(ReadPreamble::Always)
        .from_reader(bytes.as_slice())
        .map_err(|e| bad(&what, format!("DICOM: {e}")))?;
    let syntax = obj.meta().transfer_syntax().trim_end_matches('\0').to_string();
    decode(&obj, &syntax, image.size, image.frames, &what)
}
