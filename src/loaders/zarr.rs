//! OME-Zarr multiscale images (OME-NGFF 0.4 on Zarr v2, 0.5 on Zarr v3) from a local folder, read a
//! slab of z slices at a time (`SliceReader`) through zarrs: only the chunks a slab touches are read
//! and decoded, and a row of chunks is decoded once for the slabs it holds. Every level's metadata is
//! read and checked as JSON before zarrs opens it (a decoded chunk against `MAX_CHUNK_BYTES`, the
//! level read against `MAX_STREAMED_VOXELS`, the pyramid's levels against each other), so nothing is sized by
//! a header that has not been checked.
use super::zarr_axes::AxisText;
use super::zarr_chunks::{copy_part, may_see_block, spatial, ChunkKey, Samples};
use super::{bad, DType, MAX_STREAMED_VOXELS};
use crate::error::{Error, Result};
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;
use zarrs::array::{data_type as dt, Array, ArraySubset};
use zarrs::filesystem::FilesystemStore;

/// Most bytes one decoded chunk (a shard's inner chunk) may take: zarrs decodes a chunk whole.
pub const MAX_CHUNK_BYTES: u64 = 256 << 20;
/// Most bytes of decoded chunks kept between slab reads (a row of chunks along z).
const MAX_ROW_BYTES: u64 = 512 << 20;
/// Most levels of a pyramid.
const MAX_LEVELS: usize = 32;
/// Most inner chunks in one shard (each costs 16 bytes of the shard's index).
const MAX_SHARD_CHUNKS: u64 = 1 << 20;

/// Chunks (shards, when sharded) this process has asked zarrs to read, every image and level.
static CHUNKS_READ: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// How many chunks (shards, when sharded) of OME-Zarr images this process has read so far: the
/// difference across a load or a frame is what it read (`voxsplat render` reports it).
pub fn chunks_read() -> u64 {
    CHUNKS_READ.load(std::sync::atomic::Ordering::Relaxed)
}

/// One axis of an image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Axis {
    /// Its name (`x`, `y`, `z`, `c`, `t` by convention).
    pub name: String,
    /// `space`, `time`, `channel`, or empty where the file gives none.
    pub kind: String,
    /// Its unit, where the file gives one (`micrometer`, `second`).
    pub unit: Option<String>,
}

/// One level of a pyramid (level 0 the finest).
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    /// Its array's path inside the image.
    pub path: String,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing along x, y, z: the level's scale (times the image's own, where it has one).
    pub spacing: [f32; 3],
    /// Where voxel 0 lies along x, y, z (the translations), in the spacing's units.
    pub origin: [f64; 3],
    /// The chunk (a shard's inner chunk, when sharded) in array order, as decoded.
    pub chunk: Vec<u64>,
    /// The sample type, as the file names it.
    pub dtype: String,
    /// The codecs (Zarr v2: the filters and compressor), as the file names them.
    pub codecs: Vec<String>,
}

/// An OME-Zarr image's checked multiscale metadata.
#[derive(Clone, Debug, PartialEq)]
pub struct OmeZarr {
    /// The OME-NGFF version (`0.4` or `0.5`).
    pub version: String,
    /// The image's name, where it has one.
    pub name: Option<String>,
    /// Its axes, in array order (time and channel before the three spatial axes).
    pub axes: Vec<Axis>,
    /// Its levels, finest first.
    pub levels: Vec<Level>,
    /// Time points (1 without a time axis).
    pub times: u32,
    /// Channels (1 without a channel axis).
    pub channels: u32,
    /// Where the time and channel axes are, when present.
    time_axis: Option<usize>,
    channel_axis: Option<usize>,
}

/// Whether `path` is a folder holding an OME-Zarr image (multiscales in its `.zattrs` or in its
/// `zarr.json`'s `ome` attributes), or metadata that does not parse (read as an image, its
/// reader names the fault; it was taken for a folder of slices).
pub fn is_ome_zarr(path: &Path) -> bool {
    path.is_dir() && !matches!(root_multiscales(path), Ok(None))
}

/// The group's metadata JSON, when the folder has one: `zarr.json` (v3) or `.zattrs` (v2).
fn read_json(path: &Path, what: &str) -> Result<Option<Value>> {
    if !path.is_file() {
        return Ok(None);
    }
    let text = super::read_text(path, what)?;
    serde_json::from_str(&text).map(Some).map_err(|e| bad(what, format!("JSON: {e}")))
}

/// The image's first multiscales entry, its NGFF version and whether it is Zarr v3; `None` when
/// the folder is no OME-Zarr image.
fn root_multiscales(dir: &Path) -> Result<Option<(Value, String, bool)>> {
    let v3 = dir.join("zarr.json");
    if let Some(root) = read_json(&v3, &v3.display().to_string())? {
        let ome = &root["attributes"]["ome"];
        return Ok(ome["multiscales"].get(0).map(|m| (m.clone(), version_of(&ome["version"]), true)));
    }
    let v2 = dir.join(".zattrs");
    let Some(root) = read_json(&v2, &v2.display().to_string())? else { return Ok(None) };
    Ok(root["multiscales"].get(0).map(|m| (m.clone(), version_of(&m["version"]), false)))
}

fn version_of(v: &Value) -> String {
    v.as_str().unwrap_or("").to_string()
}

/// An array of `n` numbers at `v` (a transformation's scale or translation).
fn numbers(v: &Value, n: usize, what: &str, field: &str) -> Result<Vec<f64>> {
    let a = v.as_array().ok_or_else(|| bad(what, format!("{field} is not a list of numbers")))?;
    if a.len() != n {
        return Err(bad(what, format!("{field} has {} values for {n} axes", a.len())));
    }
    a.iter()
        .map(|x| x.as_f64().ok_or_else(|| bad(what, format!("{field} holds a value that is not a number"))))
        .collect()
}

/// A list of coordinate transformations (a scale, then optionally a translation) as the scale
/// and translation they make.
fn transforms(v: &Value, n: usize, what: &str) -> Result<(Vec<f64>, Vec<f64>)> {
    let (mut scale, mut shift) = (vec![1.0; n], vec![0.0; n]);
    let Some(list) = v.as_array() else { return Ok((scale, shift)) };
    for t in list {
        match t["type"].as_str() {
            Some("scale") if t.get("path").is_some() => {
                return Err(bad(what, "a scale stored in a file (\"path\") is not read; give it inline"))
            }
            Some("scale") => {
                let s = numbers(&t["scale"], n, what, "scale")?;
                // A translation before the scale is scaled by it: the spec orders scale first.
                scale.iter_mut().zip(&s).for_each(|(a, b)| *a *= b);
                shift.iter_mut().zip(&s).for_each(|(a, b)| *a *= b);
            }
            Some("translation") if t.get("path").is_some() => {
                return Err(bad(what, "a translation stored in a file (\"path\") is not read; give it inline"))
            }
            Some("translation") => {
                let s = numbers(&t["translation"], n, what, "translation")?;
                shift.iter_mut().zip(&s).for_each(|(a, b)| *a += b);
            }
            Some("identity") => {}
            other => {
                return Err(bad(what, format!("coordinate transformation {other:?} is not read (scale, translation)")))
            }
        }
    }
    Ok((scale, shift))
}

/// The sample type of a Zarr v3 or v2 name (v2 names carry a byte order first, `<u2`, `|u1`;
/// zarrs reads either order).
fn zarr_dtype(name: &str) -> Option<DType> {
    Some(match name.trim_start_matches(['<', '>', '|', '=']) {
        "uint8" | "u1" => DType::U8,
        "int8" | "i1" => DType::I8,
        "uint16" | "u2" => DType::U16,
        "int16" | "i2" => DType::I16,
        "uint32" | "u4" => DType::U32,
        "int32" | "i4" => DType::I32,
        "float32" | "f4" => DType::F32,
        "float64" | "f8" => DType::F64,
        _ => return None,
    })
}

/// A level's array metadata as the file states it, checked: shape, decoded chunk, sample type and
/// codec names.
struct ArrayMeta {
    shape: Vec<u64>,
    chunk: Vec<u64>,
    dtype: String,
    codecs: Vec<String>,
}

fn shape_of(v: &Value, what: &str, field: &str) -> Result<Vec<u64>> {
    let a = v.as_array().ok_or_else(|| bad(what, format!("{field} is not a list of sizes")))?;
    a.iter()
        .map(|x| match x.as_u64() {
            Some(n) if n > 0 => Ok(n),
            _ => Err(bad(what, format!("{field} holds {x}: sizes must be positive integers"))),
        })
        .collect()
}

fn array_meta(dir: &Path, v3: bool, n: usize) -> Result<ArrayMeta> {
    let file = dir.join(if v3 { "zarr.json" } else { ".zarray" });
    let what = file.display().to_string();
    let meta = read_json(&file, &what)?.ok_or_else(|| bad(&what, "missing: the level's array metadata"))?;
    let shape = shape_of(&meta["shape"], &what, "shape")?;
    let (mut chunk, dtype, codecs) = if v3 {
        if meta["node_type"].as_str() != Some("array") {
            return Err(bad(&what, "not an array (node_type)"));
        }
        if meta["chunk_grid"]["name"].as_str() != Some("regular") {
            return Err(bad(&what, format!("chunk grid {} is not read (regular)", meta["chunk_grid"]["name"])));
        }
        let chunk = shape_of(&meta["chunk_grid"]["configuration"]["chunk_shape"], &what, "chunk_shape")?;
        let dtype = meta["data_type"].as_str().unwrap_or_default().to_string();
        let codecs = meta["codecs"].as_array().map(|c| c.iter().map(codec_name).collect()).unwrap_or_default();
        (chunk, dtype, codecs)
    } else {
        let chunk = shape_of(&meta["chunks"], &what, "chunks")?;
        let dtype = meta["dtype"].as_str().unwrap_or_default().to_string();
        let mut codecs: Vec<String> =
            meta["filters"].as_array().map(|f| f.iter().map(id_name).collect()).unwrap_or_default();
        if !meta["compressor"].is_null() {
            codecs.push(id_name(&meta["compressor"]));
        }
        (chunk, dtype, codecs)
    };
    let kind = zarr_dtype(&dtype).ok_or_else(|| {
        bad(
            &what,
            format!("sample type {dtype:?} is not read (uint8, int8, uint16, int16, uint32, int32, float32, float64)"),
        )
    })?;
    if shape.len() != n || chunk.len() != n {
        return Err(bad(&what, format!("shape and chunks must have {n} sizes, one per axis of the image")));
    }
    // A sharded array decodes inner chunks; the shard's index holds 16 bytes per inner chunk.
    if v3 && meta["codecs"][0]["name"].as_str() == Some("sharding_indexed") {
        let inner = shape_of(&meta["codecs"][0]["configuration"]["chunk_shape"], &what, "the shards' chunk_shape")?;
        if inner.len() != n || inner.iter().zip(&chunk).any(|(i, s)| s % i != 0) {
            return Err(bad(&what, "the shards' chunk_shape must divide the shard shape, axis by axis"));
        }
        let per_shard = chunk.iter().zip(&inner).try_fold(1u64, |a, (s, i)| a.checked_mul(s / i));
        if per_shard.is_none_or(|c| c > MAX_SHARD_CHUNKS) {
            return Err(Error::TooLarge(format!("{what}: more than {MAX_SHARD_CHUNKS} chunks in a shard")));
        }
        chunk = inner;
    }
    let bytes = chunk.iter().try_fold(kind.size() as u64, |a, &c| a.checked_mul(c));
    if bytes.is_none_or(|b| b > MAX_CHUNK_BYTES) {
        return Err(Error::TooLarge(format!(
            "{what}: a chunk of {chunk:?} decodes to more than {MAX_CHUNK_BYTES} bytes"
        )));
    }
    Ok(ArrayMeta { shape, chunk, dtype, codecs })
}

/// A v3 codec's name; a sharded array's with its inner codecs.
fn codec_name(c: &Value) -> String {
    let name = c["name"].as_str().or(c.as_str()).unwrap_or("?");
    match c["configuration"]["codecs"].as_array() {
        Some(inner) if name == "sharding_indexed" => {
            format!("{name}({})", inner.iter().map(codec_name).collect::<Vec<_>>().join("+"))
        }
        _ => name.to_string(),
    }
}

fn id_name(c: &Value) -> String {
    c["id"].as_str().unwrap_or("?").to_string()
}

impl OmeZarr {
    /// The image at `dir`, its metadata and every level's array metadata read and checked: the
    /// axes (time and channel, then three spatial ones), each level's chunks within
    /// `MAX_CHUNK_BYTES`, and the pyramid consistent
    /// (levels finest first, each no finer than the one before, covering the same extent to within
    /// one of its voxels, with the same time points and channels).
    pub fn open(dir: &Path) -> Result<Self> {
        let what = dir.display().to_string();
        let (ms, version, zarr_v3) =
            root_multiscales(dir)?.ok_or_else(|| bad(&what, "not an OME-Zarr image: no multiscales metadata"))?;
        match (version.as_str(), zarr_v3) {
            ("0.4", false) | ("0.5", true) => {}
            ("", _) => {
                return Err(bad(&what, "the multiscales metadata gives no version (OME-NGFF 0.4 or 0.5 are read)"))
            }
            (v, _) => return Err(bad(&what, format!("OME-NGFF {v} is not read (0.4 on Zarr v2, 0.5 on Zarr v3)"))),
        }
        let axes: Vec<Axis> = ms["axes"]
            .as_array()
            .ok_or_else(|| bad(&what, "the multiscales metadata lists no axes"))?
            .iter()
            .map(|a| Axis {
                name: a["name"].as_str().unwrap_or_default().to_string(),
                kind: a["type"].as_str().unwrap_or_default().to_string(),
                unit: a["unit"].as_str().map(str::to_string),
            })
            .collect();
        let n = axes.len();
        let text: Vec<_> =
            axes.iter().map(|a| AxisText { name: &a.name, kind: &a.kind, unit: a.unit.as_deref() }).collect();
        let units = super::zarr_axes::spatial(&text, &what)?;
        let find = |kind: &str| (0..n - 3).find(|&i| axes[i].kind == kind);
        let (time_axis, channel_axis) = (find("time"), find("channel"));
        if (0..n - 3).any(|i| Some(i) != time_axis && Some(i) != channel_axis) {
            return Err(bad(&what, "an axis before the spatial ones is neither time nor channel"));
        }
        let (global_scale, global_shift) = transforms(&ms["coordinateTransformations"], n, &what)?;
        let datasets =
            ms["datasets"].as_array().ok_or_else(|| bad(&what, "the multiscales metadata lists no datasets"))?;
        if datasets.is_empty() || datasets.len() > MAX_LEVELS {
            return Err(bad(&what, format!("{} levels (1 to {MAX_LEVELS} are read)", datasets.len())));
        }
        let mut levels = Vec::new();
        let mut lead: Option<Vec<u64>> = None;
        for (l, d) in datasets.iter().enumerate() {
            let path = d["path"].as_str().ok_or_else(|| bad(&what, format!("level {l} has no path")))?;
            // The path names a folder inside the image: no way out of it.
            if path.is_empty() || path.split('/').any(|p| p.is_empty() || p == "." || p == "..") {
                return Err(bad(&what, format!("level {l}'s path {path:?} is not a folder inside the image")));
            }
            let meta = array_meta(&dir.join(path), zarr_v3, n)?;
            let (s, t) = transforms(&d["coordinateTransformations"], n, &what)?;
            // Each spatial axis in the unit of x.
            let unit = |a: usize| if a + 3 >= n { units[a + 3 - n] } else { 1.0 };
            let scale: Vec<f64> = (0..n).map(|a| s[a] * global_scale[a] * unit(a)).collect();
            let shift: Vec<f64> = (0..n).map(|a| (t[a] * global_scale[a] + global_shift[a]) * unit(a)).collect();
            // Array order (z, y, x) to the grid's (x, y, z).
            let xyz = |a: usize| n - 1 - a;
            if meta.shape.iter().any(|&d| d > u32::MAX as u64) {
                return Err(Error::TooLarge(format!(
                    "{what}: level {l}'s shape {:?} passes 2^32 voxels along an axis",
                    meta.shape
                )));
            }
            let spacing = [0, 1, 2].map(|a| scale[xyz(a)] as f32);
            super::check_spacing(spacing, &format!("{what} level {l}"))?;
            let origin = [0, 1, 2].map(|a| shift[xyz(a)]);
            if !origin.iter().all(|o| o.is_finite()) {
                return Err(bad(&what, format!("level {l}'s translation is not finite")));
            }
            let here = meta.shape[..n - 3].to_vec();
            if lead.as_ref().is_some_and(|first| *first != here) {
                return Err(bad(&what, format!("level {l} holds other time points or channels than level 0")));
            }
            lead.get_or_insert(here);
            levels.push(Level {
                path: path.to_string(),
                dims: [0, 1, 2].map(|a| meta.shape[xyz(a)] as u32),
                spacing,
                origin,
                chunk: meta.chunk,
                dtype: meta.dtype,
                codecs: meta.codecs,
            });
        }
        check_pyramid(&levels, &what)?;
        let lead = lead.unwrap_or_default();
        let count = |axis: Option<usize>| axis.map_or(Ok(1), |i| u32::try_from(lead[i]));
        let too_many = |_| bad(&what, "too many time points or channels");
        Ok(OmeZarr {
            version,
            name: ms["name"].as_str().map(str::to_string),
            axes,
            levels,
            times: count(time_axis).map_err(too_many)?,
            channels: count(channel_axis).map_err(too_many)?,
            time_axis,
            channel_axis,
        })
    }
}

/// Levels finest first, each no finer than the one before along any axis, all over the same extent
/// (to within one voxel of the coarser level: a halved odd size rounds).
fn check_pyramid(levels: &[Level], what: &str) -> Result<()> {
    let first = &levels[0];
    for (l, pair) in levels.windows(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        for k in 0..3 {
            if b.spacing[k] < a.spacing[k] || b.dims[k] > a.dims[k] {
                return Err(bad(
                    what,
                    format!("level {} is finer than level {l} along axis {k}: levels go finest first", l + 1),
                ));
            }
            let extent = |v: &Level| v.dims[k] as f64 * v.spacing[k] as f64;
            if (extent(b) - extent(first)).abs() > b.spacing[k] as f64 * 1.001 {
                return Err(bad(
                    what,
                    format!(
                        "level {}'s {} voxels of {} along axis {k} span {:.4}, level 0's {:.4}: its shape disagrees with its scale",
                        l + 1,
                        b.dims[k],
                        b.spacing[k],
                        extent(b),
                        extent(first)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// One level of an image read a slab at a time.
pub struct ZarrReader {
    array: Array<FilesystemStore>,
    kind: DType,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing.
    pub spacing: [f32; 3],
    /// The fixed index of each axis before the spatial ones (the time point, the channel).
    lead: Vec<u64>,
    /// Slices of a chunk along z.
    chunk_z: u32,
    /// The row of chunks last decoded: its first slice, the part of the plane (x and y from, to)
    /// and its samples.
    row: Option<(u32, [u32; 4], Vec<f32>)>,
    /// Only the chunks this view (and margin in pixels) may see are read (`only_in_view`).
    seen: Option<(crate::Camera, f32)>,
    /// Decoded chunks kept between reads (`use_cache`).
    cache: Option<super::ChunkCache>,
    /// Where this level's chunks are in the cache (`chunk` set per chunk).
    key: ChunkKey,
    what: String,
}

impl ZarrReader {
    /// Level `level` of `image` (at `dir`), at time point `time` and channel `channel`.
    pub fn open(dir: &Path, image: &OmeZarr, level: u32, time: u32, channel: u32) -> Result<Self> {
        let what = dir.display().to_string();
        let l = image.levels.get(level as usize).ok_or_else(|| {
            bad(
                &what,
                format!("no level {level}: the pyramid has {} (0 to {})", image.levels.len(), image.levels.len() - 1),
            )
        })?;
        super::voxel_count_within(&l.dims.map(u64::from), &format!("{what} level {level}"), MAX_STREAMED_VOXELS)?;
        if time >= image.times {
            return Err(bad(&what, format!("no time point {time}: the image has {}", image.times)));
        }
        if channel >= image.channels {
            return Err(bad(&what, format!("no channel {channel}: the image has {}", image.channels)));
        }
        super::zarr_chunks::some_chunk_stored(&dir.join(&l.path), level, &l.path, &what)?;
        let store = FilesystemStore::new(dir).map_err(|e| bad(&what, e))?;
        let array = Array::open(Arc::new(store), &format!("/{}", l.path))
            .map_err(|e| bad(&what, format!("level {level} ({}): {e}", l.path)))?;
        let n = image.axes.len();
        // zarrs read the same metadata: it must agree with what was checked.
        let shape: Vec<u64> = (0..3).rev().map(|a| l.dims[a] as u64).collect();
        if array.shape()[n - 3..] != shape[..] {
            return Err(bad(&what, format!("level {level}: zarrs reads shape {:?}", array.shape())));
        }
        let kind = zarr_dtype(&l.dtype).expect("checked by OmeZarr::open");
        let dtype = array.data_type();
        let agrees = match kind {
            DType::U8 => dtype.is::<dt::UInt8DataType>(),
            DType::I8 => dtype.is::<dt::Int8DataType>(),
            DType::U16 => dtype.is::<dt::UInt16DataType>(),
            DType::I16 => dtype.is::<dt::Int16DataType>(),
            DType::U32 => dtype.is::<dt::UInt32DataType>(),
            DType::I32 => dtype.is::<dt::Int32DataType>(),
            DType::F32 => dtype.is::<dt::Float32DataType>(),
            DType::F64 => dtype.is::<dt::Float64DataType>(),
        };
        if !agrees {
            return Err(bad(&what, format!("level {level}: zarrs reads another sample type than {}", l.dtype)));
        }
        let mut lead = vec![0u64; n - 3];
        if let Some(i) = image.time_axis {
            lead[i] = time as u64;
        }
        if let Some(i) = image.channel_axis {
            lead[i] = channel as u64;
        }
        let chunk_z = l.chunk[n - 3].min(l.dims[2] as u64) as u32;
        let what = format!("{what} level {level} ({})", l.path);
        let key = ChunkKey { image: dir.into(), level: l.path.clone(), lead: lead.clone(), chunk: Vec::new() };
        let (dims, spacing, row, seen, cache) = (l.dims, l.spacing, None, None, None);
        Ok(ZarrReader { array, kind, dims, spacing, lead, chunk_z, row, seen, cache, key, what })
    }

    /// Slices `z0..z0 + count` (x fastest) into `out`.
    pub fn read(&mut self, z0: u32, count: u32, out: &mut Vec<f32>) -> Result<()> {
        self.read_part(z0, count, [0, 0], [self.dims[0], self.dims[1]], out)
    }

    /// The part `lo..hi` (x and y) of slices `z0..z0 + count` into `out`, x fastest over the
    /// part: only the chunks the part touches are read.
    pub fn read_part(&mut self, z0: u32, count: u32, lo: [u32; 2], hi: [u32; 2], out: &mut Vec<f32>) -> Result<()> {
        let part = [lo[0], lo[1], hi[0], hi[1]];
        let plane = (hi[0] - lo[0]) as usize * (hi[1] - lo[1]) as usize;
        let first = z0 / self.chunk_z * self.chunk_z;
        let row_bytes = self.chunk_z as u64 * plane as u64 * 4;
        // A slab inside one row of chunks: the row decoded once, its slabs copied from it.
        if count > 0 && (z0 + count - 1) / self.chunk_z == z0 / self.chunk_z && row_bytes <= MAX_ROW_BYTES {
            if self.row.as_ref().is_none_or(|(at, p, _)| *at != first || *p != part) {
                let n = self.chunk_z.min(self.dims[2] - first);
                crate::error::check_host_memory(row_bytes, &format!("{}'s row of chunks", self.what))?;
                self.row = None;
                self.row = Some((first, part, self.samples(first, n, part)?));
            }
            let (_, _, row) = self.row.as_ref().expect("decoded above");
            let at = (z0 - first) as usize * plane;
            out.clear();
            out.extend_from_slice(&row[at..at + count as usize * plane]);
            return Ok(());
        }
        *out = self.samples(z0, count, part)?;
        Ok(())
    }

    /// After a failed read of `subset`: the first of its chunks that fails alone, and why (not
    /// searched when a whole chunk, a shard, would decode past `MAX_CHUNK_BYTES`).
    fn failing_chunk(&self, subset: &ArraySubset) -> Option<(String, zarrs::array::ArrayError)> {
        let chunks = self.array.chunks_in_array_subset(subset).ok()??;
        for idx in &chunks.indices() {
            let bytes =
                self.array.chunk_shape(&idx).ok()?.iter().map(|c| c.get()).product::<u64>() * self.kind.size() as u64;
            if bytes > MAX_CHUNK_BYTES {
                return None;
            }
            if let Err(e) = self.array.retrieve_chunk::<zarrs::array::ArrayBytes<'static>>(&idx) {
                return Some((self.array.chunk_key(&idx).to_string(), e));
            }
        }
        None
    }

    /// The array's samples at this time point and channel over `zyx` (along z, y, x).
    fn at_lead(&self, zyx: [std::ops::Range<u64>; 3]) -> ArraySubset {
        let ranges: Vec<std::ops::Range<u64>> = self.lead.iter().map(|&i| i..i + 1).chain(zyx).collect();
        ArraySubset::new_with_ranges(&ranges)
    }

    /// The part (x0, y0, x1, y1) of slices `z0..z0 + count` decoded, as f32, checked finite.
    fn samples(&self, z0: u32, count: u32, [x0, y0, x1, y1]: [u32; 4]) -> Result<Vec<f32>> {
        let subset = self.at_lead([z0..z0 + count, y0..y1, x0..x1].map(|r| r.start as u64..r.end as u64));
        let n = subset.num_elements();
        crate::error::check_host_memory(n * (4 + self.kind.size() as u64), &format!("{}'s slices", self.what))?;
        let chunks = self.array.chunks_in_array_subset(&subset).map_err(|e| bad(&self.what, e))?;
        let direct = self.seen.is_none() && self.cache.is_none();
        // Chunks a sparse image does not store read as its fill value without a decode each (one
        // chunk of a 1024^3 array took 18 s); the fill as a stored chunk would read it.
        // Each chunk with whether it is decoded: those stored, or every one for a view or a cache
        // (which test each in the loop below).
        let stored = |idx: &[u64]| !direct || self.key.image.join(self.array.chunk_key(idx).as_str()).exists();
        let indices: Vec<_> = chunks.iter().flat_map(|c| c.indices().into_iter()).map(|i| (stored(&i), i)).collect();
        let missing = indices.iter().find(|(read, _)| !read).map(|(_, idx)| idx);
        if direct && missing.is_none() {
            CHUNKS_READ.fetch_add(chunks.map_or(0, |c| c.num_elements()), std::sync::atomic::Ordering::Relaxed);
            return Ok(self.decoded(&subset, n, z0, count)?.into_f32());
        }
        let fill = match missing {
            Some(idx) => {
                let at = self.array.chunk_origin(idx).map_err(|e| bad(&self.what, e))?;
                let one =
                    ArraySubset::new_with_start_shape(at.clone(), vec![1; at.len()]).map_err(|e| bad(&self.what, e))?;
                self.decoded(&one, 1, z0, count)?.into_f32()[0]
            }
            // Chunk by chunk: those the view cannot see read as NaN (empty to the store's passes).
            None => f32::NAN,
        };
        let mut out = vec![fill; n as usize];
        let lead = self.lead.len();
        let grid = crate::Grid::centered(self.dims, self.spacing)?;
        let to = ([z0, y0, x0].map(u64::from), [count, y1 - y0, x1 - x0].map(u64::from));
        let spatial = |s: &ArraySubset| spatial(s, lead);
        for (_, idx) in indices.iter().filter(|(read, _)| *read) {
            let part =
                self.array.chunk_subset(idx).and_then(|c| Ok(c.overlap(&subset)?)).map_err(|e| bad(&self.what, e))?;
            let (start, shape) = spatial(&part);
            if !may_see_block(self.seen.as_ref(), &grid, (start, shape)) {
                continue;
            }
            // The chunk's samples at this time point and channel, within the array.
            let whole = self.array.chunk_subset_bounded(idx).map_err(|e| bad(&self.what, e))?;
            let block = spatial(&whole);
            let bytes = block.1.iter().product::<u64>() * 4;
            match &self.cache {
                Some(cache) if bytes <= MAX_CHUNK_BYTES => {
                    let whole = self.at_lead([0, 1, 2].map(|a| block.0[a]..block.0[a] + block.1[a]));
                    let key = ChunkKey { chunk: idx.to_vec(), ..self.key.clone() };
                    let values = cache.get_or_read(key, || {
                        crate::error::check_host_memory(bytes, &format!("{}'s chunk", self.what))?;
                        CHUNKS_READ.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        self.decoded(&whole, whole.num_elements(), z0, count)
                    })?;
                    copy_part(&mut out, to, block, &values, (start, shape));
                }
                _ => {
                    CHUNKS_READ.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let values = self.decoded(&part, part.num_elements(), z0, count)?;
                    copy_part(&mut out, to, (start, shape), &values, (start, shape));
                }
            }
        }
        Ok(out)
    }

    /// `subset` (`n` samples, of slices `z0..z0 + count` for messages) decoded: 8- and 16-bit
    /// integers as stored, the others as f32, checked finite.
    fn decoded(&self, subset: &ArraySubset, n: u64, z0: u32, count: u32) -> Result<Samples> {
        let err = |e: zarrs::array::ArrayError| match self.failing_chunk(subset) {
            Some((key, e)) => bad(&self.what, format!("chunk {key}: {e}")),
            None => bad(&self.what, format!("slices {z0}..{}: {e}", z0 + count)),
        };
        let a = &self.array;
        let f32s = |v: Vec<f32>| -> Result<Samples> {
            super::check_finite(&v, &self.what)?;
            Ok(Samples::F32(v))
        };
        let values = match self.kind {
            DType::U8 => Samples::U8(a.retrieve_array_subset(subset).map_err(err)?),
            DType::I8 => Samples::I8(a.retrieve_array_subset(subset).map_err(err)?),
            DType::U16 => Samples::U16(a.retrieve_array_subset(subset).map_err(err)?),
            DType::I16 => Samples::I16(a.retrieve_array_subset(subset).map_err(err)?),
            DType::U32 => f32s(super::held::held(
                a.retrieve_array_subset::<Vec<u32>>(subset).map_err(err)?.into_iter().map(f64::from),
                super::held::U32,
                &self.what,
            )?)?,
            DType::I32 => f32s(super::held::held(
                a.retrieve_array_subset::<Vec<i32>>(subset).map_err(err)?.into_iter().map(f64::from),
                super::held::I32,
                &self.what,
            )?)?,
            DType::F32 => f32s(a.retrieve_array_subset(subset).map_err(err)?)?,
            DType::F64 => f32s(super::held::held(
                a.retrieve_array_subset::<Vec<f64>>(subset).map_err(err)?.into_iter(),
                None,
                &self.what,
            )?)?,
        };
        if values.len() as u64 != n {
            return Err(bad(&self.what, format!("slices {z0}..{}: {} samples for {n}", z0 + count, values.len())));
        }
        Ok(values)
    }

    /// Read only the chunks `camera` (in the grid's centred frame) may see, within `margin_px`
    /// of the image's edges and one brick around: the others' samples read as NaN, which a
    /// store's passes leave empty (`BrickStore::load` with `VolumeHints::view`).
    pub fn only_in_view(&mut self, camera: crate::Camera, margin_px: f32) {
        self.seen = Some((camera, margin_px));
        self.row = None;
    }

    /// Read chunks through `cache`: those it holds are not read again, and those read are held
    /// there for later reads (of any level, view or reader).
    pub fn use_cache(&mut self, cache: super::ChunkCache) {
        cache.begin_read(Default::default());
        self.cache = Some(cache);
    }

    /// With a cache, a read of `region` (lo, hi; x, y, z) begins: the chunks it will use (those
    /// the view may see) are not let go while it lasts, so that what it finds held stays held.
    pub fn pin(&self, [lo, hi]: [[u32; 3]; 2]) -> Result<()> {
        let Some(cache) = &self.cache else { return Ok(()) };
        let region = self.at_lead([2, 1, 0].map(|a| lo[a] as u64..hi[a] as u64));
        let chunks = self.array.chunks_in_array_subset(&region).map_err(|e| bad(&self.what, e))?;
        let grid = crate::Grid::centered(self.dims, self.spacing)?;
        let mut pinned = std::collections::HashSet::new();
        for idx in chunks.iter().flat_map(|c| c.indices().into_iter()) {
            let part =
                self.array.chunk_subset(&idx).and_then(|c| Ok(c.overlap(&region)?)).map_err(|e| bad(&self.what, e))?;
            if may_see_block(self.seen.as_ref(), &grid, spatial(&part, self.lead.len())) {
                pinned.insert(ChunkKey { chunk: idx.to_vec(), ..self.key.clone() });
            }
        }
        cache.begin_read(pinned);
        Ok(())
    }
}

/// Every channel of the image at `dir` (`loaders::load_channels`), each read whole at
/// `hints.level` and `hints.time`.
pub(super) fn channels(dir: &Path, hints: &super::VolumeHints) -> Result<Vec<super::ScalarVolume>> {
    let what = dir.display().to_string();
    let image = OmeZarr::open(dir)?;
    if image.channels as u64 > super::MAX_FILE_CHANNELS {
        return Err(bad(
            &what,
            format!("{} channels: at most {} are drawn together", image.channels, super::MAX_FILE_CHANNELS),
        ));
    }
    (0..image.channels)
        .map(|c| {
            let reader = super::SliceReader::zarr(dir, &image, hints, c)?;
            super::voxel_count(&reader.dims.map(u64::from), &what)?;
            super::read_whole(reader, hints, &what)
        })
        .collect()
}
