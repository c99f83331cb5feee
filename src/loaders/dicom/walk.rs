//! The length walk a DICOM file passes before dicom-rs reads it: dicom-rs sizes its buffers by
//! each element's declared length, so every length is checked against the file first, headers
//! read as dicom-rs's decoders read them (fuzzing found each rule here).
use super::super::bad;
use crate::error::Result;
use std::path::Path;

/// Most bytes of one DICOM file (an image of a series).
const MAX_FILE_BYTES: u64 = 1 << 30;

/// How a data set's elements are encoded.
#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    ImplicitLittle,
    ExplicitLittle,
    ExplicitBig,
}

/// The VRs dicom-rs reads with a long (4-byte) length in explicit VR, besides those it does not know.
const LONG_VRS: [&[u8; 2]; 10] = [b"OB", b"OD", b"OF", b"OL", b"OW", b"SQ", b"UC", b"UR", b"UT", b"UN"];

/// Walks a DICOM file's elements (the file meta group, then the data set in its transfer syntax)
/// before dicom-rs reads it, which sizes its buffers by each element's declared length: every
/// defined length must lie within the file; sequences and items are walked into. A deflated data
/// set is not walked: where it starts is returned, to be inflated (`inflated`) and walked then.
fn check_lengths(bytes: &[u8], what: &str) -> Result<Option<usize>> {
    if bytes.len() < 132 || &bytes[128..132] != b"DICM" {
        return Err(bad(what, "not a DICOM file (no DICM after the preamble)"));
    }
    // dicom-rs reads the meta group as far as its group length says, whatever groups it meets
    // there: walked as far (the group length's own element first), else to the first other group.
    let group_length = (bytes.len() >= 144 && bytes[132..136] == [2, 0, 0, 0] && &bytes[136..138] == b"UL")
        .then(|| u32::from_le_bytes([bytes[140], bytes[141], bytes[142], bytes[143]]) as usize);
    let (data, syntax) = match group_length {
        Some(n) => {
            let end = 144usize
                .checked_add(n)
                .filter(|&e| e <= bytes.len())
                .ok_or_else(|| bad(what, format!("DICOM: the file meta group's length {n} passes the file's end")))?;
            let (at, syntax) = walk(&bytes[..end], 144, Encoding::ExplicitLittle, false, what)?;
            (at, syntax)
        }
        None => walk(bytes, 132, Encoding::ExplicitLittle, true, what)?,
    };
    let encoding = match syntax.as_str() {
        "1.2.840.10008.1.2" => Encoding::ImplicitLittle,
        "1.2.840.10008.1.2.2" => Encoding::ExplicitBig,
        "1.2.840.10008.1.2.1.99" => return Ok(Some(data)),
        _ => Encoding::ExplicitLittle,
    };
    walk(bytes, data, encoding, false, what).map(|_| None)
}

/// The elements from `pos` (only the meta group's, group 2, with `meta`): where they end, and the
/// Transfer Syntax UID when the meta group names one.
fn walk(bytes: &[u8], mut pos: usize, enc: Encoding, meta: bool, what: &str) -> Result<(usize, String)> {
    use dicom_core::dictionary::{DataDictionary, VirtualVr};
    let big = enc == Encoding::ExplicitBig;
    let u16_at = |p: usize| {
        let b = [bytes[p], bytes[p + 1]];
        if big {
            u16::from_be_bytes(b)
        } else {
            u16::from_le_bytes(b)
        }
    };
    let u32_at = |p: usize| {
        let b = [bytes[p], bytes[p + 1], bytes[p + 2], bytes[p + 3]];
        if big {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        }
    };
    let mut syntax = String::new();
    // Inside encapsulated pixel data (undefined length): its items hold compressed fragments,
    // skipped by their lengths, not walked into, until the sequence delimiter.
    let mut encapsulated = false;
    while pos < bytes.len() {
        let short = || bad(what, format!("DICOM: an element header is cut off at byte {pos}"));
        if pos + 8 > bytes.len() {
            return Err(short());
        }
        let (group, element) = (u16_at(pos), u16_at(pos + 2));
        if meta && group != 2 {
            break;
        }
        let (header, len, container, vr) = if group == 0xFFFE {
            // An item (walked into) or a delimiter.
            (8, u32_at(pos + 4), true, None)
        } else if enc == Encoding::ImplicitLittle {
            let tag = dicom_core::Tag(group, element);
            let vr = dicom_dictionary_std::StandardDataDictionary.by_tag(tag).and_then(|e| match e.vr {
                VirtualVr::Exact(vr) => Some(vr),
                _ => None,
            });
            (8, u32_at(pos + 4), vr == Some(dicom_core::VR::SQ), vr)
        } else {
            let vr = &bytes[pos + 4..pos + 6];
            // As dicom-rs reads the header (dicom-encoding's explicit decoders): these VRs, and a VR
            // it does not know (read as UN), have a long one; every other VR it knows a short one,
            // OV, SV and UV included (a fuzzed file with an OV pixel data element made it read a
            // 4 GB length where this walk read the standard's 144 bytes).
            let known = dicom_core::VR::from_binary([vr[0], vr[1]]);
            let long = known.is_none() || LONG_VRS.iter().any(|v| v.as_slice() == vr);
            if long {
                if pos + 12 > bytes.len() {
                    return Err(short());
                }
                (12, u32_at(pos + 8), vr == b"SQ", known)
            } else {
                (8, u16_at(pos + 6) as u32, false, known)
            }
        };
        // dicom-rs reads a binary element's whole values only, so a length that is not a multiple
        // of its value's size leaves it reading the next header from inside this value (a fuzzed
        // FL of 2 bytes made it read a length of 4 GB).
        use dicom_core::VR;
        let size = match vr {
            Some(VR::SS | VR::US | VR::OW) => 2,
            Some(VR::FL | VR::SL | VR::UL | VR::AT | VR::OF | VR::OL) => 4,
            Some(VR::FD | VR::SV | VR::UV | VR::OD | VR::OV) => 8,
            _ => 1,
        };
        if len != u32::MAX && len % size != 0 {
            return Err(bad(
                what,
                format!(
                    "DICOM: element ({group:04X},{element:04X}) holds {len} bytes: not whole values of {size} bytes"
                ),
            ));
        }
        // Delimiters hold nothing, and an item lies within the file: dicom-rs reads a delimiter's
        // length as a value's (a fuzzed one of 4 GB after a stray item).
        if group == 0xFFFE && element != 0xE000 && len != 0 {
            return Err(bad(what, format!("DICOM: delimiter (FFFE,{element:04X}) declares {len} bytes, not 0")));
        }
        if group == 0xFFFE
            && len != u32::MAX
            && (pos + header).checked_add(len as usize).is_none_or(|e| e > bytes.len())
        {
            return Err(bad(
                what,
                format!("DICOM: item (FFFE,{element:04X}) declares {len} bytes past the file's end"),
            ));
        }
        pos += header;
        // Encapsulated pixel data: dicom-rs reads only (7FE0,0010) of undefined length as
        // fragments, and every other element of undefined length as a sequence, its items'
        // elements walked here too (a fuzzed OB of undefined length, walked as fragments, hid an
        // element of 3.7 GB in its item).
        if (group, element) == (0x7FE0, 0x10) && len == u32::MAX {
            encapsulated = true;
            continue;
        }
        if encapsulated && !(group == 0xFFFE && matches!(element, 0xE000 | 0xE0DD)) {
            // dicom-rs reads whatever stands there as an item's header and its length (a fuzzed
            // one read a tag as a length of 3.7 GB).
            return Err(bad(
                what,
                format!("DICOM: encapsulated pixel data holds ({group:04X},{element:04X}) where an item belongs"),
            ));
        }
        if encapsulated {
            encapsulated = element != 0xE0DD;
        } else if len == u32::MAX || container {
            // Undefined lengths (sequences) and sequences hold elements.
            continue;
        }
        let end = pos.checked_add(len as usize).filter(|&e| e <= bytes.len()).ok_or_else(|| {
            bad(what, format!("DICOM: element ({group:04X},{element:04X}) declares {len} bytes past the file's end"))
        })?;
        if (group, element) == (2, 0x10) {
            syntax = String::from_utf8_lossy(&bytes[pos..end]).trim_end_matches(['\0', ' ']).to_string();
        }
        pos = end;
    }
    Ok((pos, syntax))
}

/// A DICOM file read whole (within `MAX_FILE_BYTES`) and its lengths checked (`check_lengths`); a
/// deflated data set inflated first (`inflated`).
pub(super) fn checked_bytes(path: &Path, what: &str) -> Result<Vec<u8>> {
    let bytes = super::super::read_bounded(path, MAX_FILE_BYTES, what)?;
    let Some(data) = check_lengths(&bytes, what)? else {
        return Ok(bytes);
    };
    let bytes = inflated(&bytes, data, what)?;
    match check_lengths(&bytes, what)? {
        None => Ok(bytes),
        Some(_) => Err(bad(what, "DICOM: a deflated data set inflates to another deflated one")),
    }
}

/// A file whose data set (from byte `data`) is deflated (Deflated Explicit VR Little Endian, PS3.5
/// A.5: raw deflate, no zlib header) rewritten with it inflated, within `MAX_FILE_BYTES`, behind a
/// meta group that names Explicit VR Little Endian: dicom-rs 0.8 does not inflate, and the walk
/// checks the inflated data set's lengths as any other's. The meta group was walked already.
fn inflated(bytes: &[u8], data: usize, what: &str) -> Result<Vec<u8>> {
    use std::io::Read;
    let cut = || bad(what, "DICOM: the file meta group is cut off");
    let mut meta = Vec::new();
    let mut pos = 132;
    while pos < data {
        let head = bytes.get(pos..pos + 8).ok_or_else(cut)?;
        let vr = [head[4], head[5]];
        let long = dicom_core::VR::from_binary(vr).is_none() || LONG_VRS.contains(&&vr);
        let (header, len) = if long {
            let b = bytes.get(pos + 8..pos + 12).ok_or_else(cut)?;
            (12, u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        } else {
            (8, u16::from_le_bytes([head[6], head[7]]) as usize)
        };
        let end = (pos + header).checked_add(len).filter(|&e| e <= data).ok_or_else(cut)?;
        match [u16::from_le_bytes([head[0], head[1]]), u16::from_le_bytes([head[2], head[3]])] {
            // The group's length, written anew below.
            [2, 0] => {}
            [2, 0x10] => {
                meta.extend_from_slice(&head[..4]);
                meta.extend_from_slice(b"UI\x14\x00");
                meta.extend_from_slice(b"1.2.840.10008.1.2.1\0");
            }
            _ => meta.extend_from_slice(&bytes[pos..end]),
        }
        pos = end;
    }
    let mut out = bytes[..132].to_vec();
    out.extend_from_slice(b"\x02\x00\x00\x00UL\x04\x00");
    out.extend_from_slice(&(meta.len() as u32).to_le_bytes());
    out.extend_from_slice(&meta);
    let room = MAX_FILE_BYTES.saturating_sub(out.len() as u64);
    let fails = |e: std::io::Error| bad(what, format!("DICOM: the deflated data set does not inflate: {e}"));
    // Inflated once into nothing to learn its length: a bomb is refused before its bytes are held.
    let len =
        std::io::copy(&mut flate2::read::DeflateDecoder::new(&bytes[data..]).take(room + 1), &mut std::io::sink())
            .map_err(fails)?;
    if len > room {
        return Err(bad(what, format!("DICOM: the deflated data set inflates past {} MiB", MAX_FILE_BYTES >> 20)));
    }
    crate::error::check_host_memory(out.len() as u64 + len, &format!("{what}'s inflated data set"))?;
    out.reserve_exact(len as usize);
    flate2::read::DeflateDecoder::new(&bytes[data..]).take(len).read_to_end(&mut out).map_err(fails)?;
    Ok(out)
}

/// Most tiles of a JPEG 2000 codestream (OpenJPEG sizes its tile table by their count).
const MAX_J2K_TILES: u64 = 1 << 16;

/// JPEG 2000 pixel data (its fragments) checked before it is decoded: each codestream's SIZ
/// must describe one component of `size` (Columns, Rows) in at most `MAX_J2K_TILES` tiles, and
/// there must be one per frame. dicom-rs's adapter writes the decoded samples into a frame sized
/// by Rows and Columns, past its end when the codestream is larger (a fuzzed file panicked it),
/// and OpenJPEG sizes its buffers by the SIZ.
pub(super) fn check_j2k(fragments: &[Vec<u8>], size: [u32; 2], frames: u32, what: &str) -> Result<()> {
    let be16 = |b: &[u8], i: usize| u16::from_be_bytes([b[i], b[i + 1]]) as u64;
    let be32 = |b: &[u8], i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]) as u64;
    let mut found = 0u32;
    for f in fragments {
        for i in (0..f.len().saturating_sub(3)).filter(|&i| f[i..i + 4] == [0xFF, 0x4F, 0xFF, 0x51]) {
            let siz = |why: String| bad(what, format!("JPEG 2000 codestream {}: {why}", found + 1));
            if i + 45 > f.len() {
                return Err(siz("its SIZ is cut off".into()));
            }
            let [x, y, x0, y0] = [8, 12, 16, 20].map(|o| be32(f, i + o));
            let [tw, th, tx0, ty0] = [24, 28, 32, 36].map(|o| be32(f, i + o));
            let (components, dx, dy) = (be16(f, i + 40), f[i + 43] as u64, f[i + 44] as u64);
            if components != 1 || dx == 0 || dy == 0 {
                return Err(siz(format!(
                    "{components} components sampled {dx} x {dy}: one component, every pixel, is read"
                )));
            }
            let (w, h) =
                (x.div_ceil(dx).saturating_sub(x0.div_ceil(dx)), y.div_ceil(dy).saturating_sub(y0.div_ceil(dy)));
            if [w, h] != [size[0] as u64, size[1] as u64] {
                return Err(siz(format!("{w} x {h} pixels, not Columns x Rows = {} x {}", size[0], size[1])));
            }
            let tiles = if tw == 0 || th == 0 || tx0 > x0 || ty0 > y0 {
                u64::MAX
            } else {
                x.saturating_sub(tx0).div_ceil(tw).saturating_mul(y.saturating_sub(ty0).div_ceil(th))
            };
            if tiles > MAX_J2K_TILES {
                return Err(siz(format!("tiles of {tw} x {th}: at most {MAX_J2K_TILES} tiles are read")));
            }
            found += 1;
        }
    }
    if found < frames {
        return Err(bad(what, format!("{found} JPEG 2000 codestreams for {frames} frames")));
    }
    Ok(())
}

/// The Series Instance UID (0020,000E) found in the first 64 KiB of a file whose header does not
/// read (cut short, malformed), in explicit or implicit VR little endian, or `None`.
pub(super) fn series_uid(path: &Path) -> Option<String> {
    use std::io::Read;
    let mut head = Vec::new();
    std::fs::File::open(path).ok()?.take(64 << 10).read_to_end(&mut head).ok()?;
    let at = head.windows(4).position(|w| w == [0x20, 0x00, 0x0e, 0x00])?;
    let h = head.get(at..at + 8)?;
    let len = if &h[4..6] == b"UI" {
        u16::from_le_bytes([h[6], h[7]]) as usize
    } else {
        u32::from_le_bytes([h[4], h[5], h[6], h[7]]) as usize
    };
    let value = head.get(at + 8..at + 8 + len.min(64))?;
    let uid = std::str::from_utf8(value).ok()?.trim_end_matches(['\0', ' ']);
    (!uid.is_empty() && uid.bytes().all(|b| b.is_ascii_digit() || b == b'.')).then(|| uid.to_string())
}
