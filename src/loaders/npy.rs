//! `.npy` arrays, through `npyz`, with their headers checked first: their length against the
//! bytes (npyz allocates what the length field says before it reads), and their text against the
//! plain dict numpy writes (npyz parses it with a general Python-literal grammar that backtracks
//! without bound on some headers: a 4 KB one ran for minutes; both found by fuzzing).
use super::{bad, check_finite, voxel_count};
use crate::error::{Error, Result};
use std::io::Read;
use std::path::Path;

/// `.npy` arrays of 2 or 3 dimensions (C order: the last axis is x), through `npyz`.
pub fn npy_from_bytes(bytes: &[u8], what: &str) -> Result<(Vec<u64>, Vec<f32>)> {
    let (start, end) = npy_header_span(bytes, what)?;
    if end > bytes.len() {
        return Err(bad(what, format!("npy: a header of {end} bytes in {} bytes", bytes.len())));
    }
    check_dict(&bytes[start..end], what)?;
    let npy = npyz::NpyFile::new(bytes).map_err(|e| bad(what, format!("npy: {e}")))?;
    let shape = npy.shape().to_vec();
    if shape.len() < 2 || shape.len() > 3 {
        return Err(bad(what, format!("npy array of rank {} (2 or 3 expected)", shape.len())));
    }
    if npy.order() != npyz::Order::C {
        return Err(bad(what, "Fortran-ordered npy arrays are not supported"));
    }
    let n = voxel_count(&shape, what)?;
    let dtype = npy.dtype();
    let npyz::DType::Plain(ts) = &dtype else { return Err(bad(what, "structured npy arrays are not supported")) };
    let size = ts.size_field();
    // The payload must be present before anything is allocated from the header's shape.
    if (bytes.len() as u64) < n * size {
        return Err(bad(what, "data is truncated"));
    }
    let values: Vec<f32> = match (ts.type_char(), size) {
        (npyz::TypeChar::Uint, 1) => read_all::<u8>(npy, what)?.into_iter().map(f32::from).collect(),
        (npyz::TypeChar::Uint, 2) => read_all::<u16>(npy, what)?.into_iter().map(f32::from).collect(),
        (npyz::TypeChar::Int, 2) => read_all::<i16>(npy, what)?.into_iter().map(f32::from).collect(),
        (npyz::TypeChar::Uint, 4) => {
            super::held::held(read_all::<u32>(npy, what)?.into_iter().map(f64::from), super::held::U32, what)?
        }
        (npyz::TypeChar::Float, 4) => read_all::<f32>(npy, what)?,
        (npyz::TypeChar::Float, 8) => super::held::held(read_all::<f64>(npy, what)?.into_iter(), None, what)?,
        (c, s) => {
            let kind = match c {
                npyz::TypeChar::Uint => "uint",
                npyz::TypeChar::Int => "int",
                npyz::TypeChar::Float => "float",
                npyz::TypeChar::Complex => "complex",
                npyz::TypeChar::Bool => "bool",
                _ => "other",
            };
            return Err(Error::Unsupported(format!(
                "{what}: npy type {kind}{} is not read (uint8, uint16, int16, uint32, float32 and float64 are)",
                s * 8
            )));
        }
    };
    if values.len() as u64 != n {
        return Err(bad(what, "data is truncated"));
    }
    check_finite(&values, what)?;
    Ok((shape, values))
}

fn read_all<T: npyz::Deserialize>(npy: npyz::NpyFile<&[u8]>, what: &str) -> Result<Vec<T>> {
    npy.into_vec::<T>().map_err(|e| bad(what, format!("npy data: {e}")))
}

/// An open `.npy` file's header bytes (magic to padding), its shape, and the bytes of data they
/// say follow.
fn npy_header(file: &mut std::fs::File, what: &str) -> Result<(Vec<u8>, Vec<u64>, u64)> {
    let io = |e| Error::Io { path: what.to_string(), source: e };
    let mut head = Vec::with_capacity(12);
    let got = file.take(12).read_to_end(&mut head).map_err(io)?;
    let (start, end) = npy_header_span(&head, what)?;
    file.take((end - got) as u64).read_to_end(&mut head).map_err(io)?;
    if head.len() < end {
        return Err(bad(what, format!("npy: a header of {end} bytes in a file of {}", head.len())));
    }
    check_dict(&head[start..end], what)?;
    let npy = npyz::NpyFile::new(&head[..]).map_err(|e| bad(what, format!("npy: {e}")))?;
    let shape = npy.shape().to_vec();
    let n = voxel_count(&shape, what)?;
    let npyz::DType::Plain(ts) = npy.dtype() else { return Err(bad(what, "structured npy arrays are not supported")) };
    let need = n.checked_mul(ts.size_field()).ok_or_else(|| bad(what, "size overflows"))?;
    Ok((head, shape, need))
}

/// Where the dict of an `.npy` header that starts `head` (its first 12 bytes at least) starts and
/// ends: refused past 1 MiB (npyz allocates what the length field says before it reads a byte).
fn npy_header_span(head: &[u8], what: &str) -> Result<(usize, usize)> {
    if head.len() < 10 || !head.starts_with(b"\x93NUMPY") {
        return Err(bad(what, "npy: not an .npy file (no \\x93NUMPY magic)"));
    }
    // Version 1 stores the header's length in 2 bytes, versions 2 and 3 in 4.
    let (len, start) = match head[6] {
        1 => (u16::from_le_bytes([head[8], head[9]]) as usize, 10),
        2 | 3 if head.len() >= 12 => (u32::from_le_bytes([head[8], head[9], head[10], head[11]]) as usize, 12),
        v => return Err(bad(what, format!("npy: unsupported format version {v}"))),
    };
    if len > 1 << 20 || start + len < head.len().min(12) {
        return Err(bad(what, format!("npy: a header of {len} bytes")));
    }
    Ok((start, start + len))
}

/// Refuse an `.npy` header that is not the plain dict numpy writes (`{'descr': '<f4',
/// 'fortran_order': False, 'shape': (2, 3), }`, padded): only its characters, brackets at most
/// two deep (the dict, the shape), before npyz's grammar sees it.
fn check_dict(text: &[u8], what: &str) -> Result<()> {
    let plain = |c: &u8| c.is_ascii_alphanumeric() || b"{}()'\":,<>|=_. \n\t".contains(c);
    let mut depth = 0u32;
    for c in text {
        if !plain(c) {
            return Err(bad(what, format!("npy: a header with '{}' (not the dict numpy writes)", c.escape_ascii())));
        }
        match c {
            b'{' | b'(' => depth += 1,
            b'}' | b')' => depth = depth.saturating_sub(1),
            _ => {}
        }
        if depth > 2 {
            return Err(bad(what, "npy: a header nested deeper than the dict numpy writes"));
        }
    }
    // The shape's size in checked arithmetic (npyz multiplies it out unchecked).
    let text = String::from_utf8_lossy(text);
    if let Some(dims) = text.split("shape").nth(1).and_then(|t| t.split('(').nth(1)).and_then(|t| t.split(')').next()) {
        let mut n = 1u64;
        for d in dims.split(',').map(|d| d.trim().trim_end_matches('L')).filter(|d| !d.is_empty()) {
            let d: u64 = d.parse().map_err(|_| bad(what, format!("npy: a shape of ({dims})")))?;
            n = n.checked_mul(d).ok_or_else(|| bad(what, format!("npy: a shape of ({dims}) overflows")))?;
        }
    }
    Ok(())
}

/// The shape an `.npy` file's header gives (its data unread): rank 2 is a height grid, 3 a volume.
pub fn npy_shape(path: &Path) -> Result<Vec<u64>> {
    let what = path.display().to_string();
    let mut file = std::fs::File::open(path).map_err(|e| Error::Io { path: what.clone(), source: e })?;
    Ok(npy_header(&mut file, &what)?.1)
}

/// An `.npy` file's header and exactly the data its shape and type need (checked against the
/// file's length first).
pub(super) fn read_npy(path: &Path, what: &str) -> Result<Vec<u8>> {
    let io = |e| Error::Io { path: what.to_string(), source: e };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let (mut bytes, _, need) = npy_header(&mut file, what)?;
    let on_disk = file.metadata().map_err(io)?.len();
    if on_disk < bytes.len() as u64 + need {
        return Err(bad(
            what,
            format!("data is truncated: {} bytes for {need}", on_disk.saturating_sub(bytes.len() as u64)),
        ));
    }
    file.take(need).read_to_end(&mut bytes).map_err(io)?;
    Ok(bytes)
}
