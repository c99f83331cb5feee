//! Files read whole, refused from their length before a byte is read when they pass a cap.
use super::bad;
use crate::error::{Error, Result};
use std::io::Read;
use std::path::Path;

/// Most bytes of a text file the library reads whole: a transfer function (4,096 points at most)
/// or an animation's keyframes.
pub const MAX_TEXT_BYTES: u64 = 1 << 20;

/// A text file (transfer function, animation) read whole, refused past `MAX_TEXT_BYTES` before it
/// is parsed, or when it is not UTF-8.
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    let bytes = read_bounded(path, MAX_TEXT_BYTES, what)?;
    String::from_utf8(bytes).map_err(|_| bad(what, "not UTF-8 text"))
}

/// The whole of `path`, refused without reading it when it holds more than `limit` bytes (and
/// never reading more than `limit` + 1 from a device or pipe that does not say its length).
pub(super) fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>> {
    let io = |e| Error::Io { path: what.to_string(), source: e };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if meta.is_file() && meta.len() > limit {
        return Err(Error::TooLarge(format!("{what}: {} bytes, more than the {limit} a loader reads", meta.len())));
    }
    let mut out = Vec::new();
    file.take(limit + 1).read_to_end(&mut out).map_err(io)?;
    if out.len() as u64 > limit {
        return Err(Error::TooLarge(format!("{what}: more than the {limit} bytes a loader reads")));
    }
    Ok(out)
}
