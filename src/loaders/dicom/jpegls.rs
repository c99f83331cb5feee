//! JPEG-LS pixel data (transfer syntaxes 1.2.840.10008.1.2.4.80 lossless and .81 near-lossless),
//! decoded by `pure_jpegls` (ITU-T T.87 in pure Rust): dicom-rs decodes it only through the C++
//! CharLS. One component per pixel; a frame's codestream may span several fragments.
use super::super::bad;
use crate::error::{Error, Result};
use dicom_dictionary_std::tags;
use dicom_object::InMemDicomObject;

/// Whether transfer syntax `uid` is JPEG-LS.
pub(super) fn is_jpegls(uid: &str) -> bool {
    uid == "1.2.840.10008.1.2.4.80" || uid == "1.2.840.10008.1.2.4.81"
}

/// Every frame's samples, in storage order, of `obj`'s JPEG-LS pixel data: `frames` frames of
/// `size` (Columns, Rows), each read as DICOM stores it (Bits Stored bits, two's complement when
/// Pixel Representation is 1).
pub(super) fn frames(obj: &InMemDicomObject, size: [u32; 2], frames: u32, what: &str) -> Result<Vec<Vec<f64>>> {
    let int = |tag, name: &str| -> Result<u32> {
        let e = obj.element(tag).map_err(|_| bad(what, format!("no {name}")))?;
        e.to_int::<u32>().map_err(|e| bad(what, format!("{name}: {e}")))
    };
    let allocated = int(tags::BITS_ALLOCATED, "Bits Allocated")?;
    let stored = int(tags::BITS_STORED, "Bits Stored")?;
    let signed = int(tags::PIXEL_REPRESENTATION, "Pixel Representation")? == 1;
    // T.87 codes 2 to 16 bits a sample.
    if !matches!(allocated, 8 | 16) || !(2..=allocated).contains(&stored) {
        return Err(Error::Unsupported(format!(
            "{what}: JPEG-LS with Bits Allocated {allocated} and Bits Stored {stored}: \
             8 or 16 bits allocated, 2 to 16 stored, are read"
        )));
    }
    let pixel_data = obj.element(tags::PIXEL_DATA).map_err(|_| bad(what, "no Pixel Data"))?;
    let fragments = pixel_data
        .value()
        .fragments()
        .ok_or_else(|| bad(what, "JPEG-LS pixel data is not encapsulated (no fragments)"))?;
    let streams = codestreams(fragments, what)?;
    if streams.len() != frames as usize {
        return Err(bad(what, format!("{} JPEG-LS codestreams for {frames} frames", streams.len())));
    }
    streams
        .iter()
        .enumerate()
        .map(|(k, stream)| {
            let at = |e: jpegls::CodecError| {
                let size = match e {
                    jpegls::CodecError::DimensionMismatch { .. } => {
                        format!(" (Columns x Rows = {} x {})", size[0], size[1])
                    }
                    _ => String::new(),
                };
                bad(what, format!("JPEG-LS codestream {}: {e}{size}", k + 1))
            };
            let (samples, _, _) = jpegls::decode(stream, size[0], size[1]).map_err(at)?;
            Ok(samples.into_iter().map(|v| sample(v, stored, signed)).collect())
        })
        .collect()
}

/// The codestreams in `fragments`, one a frame: a fragment that opens with SOI (FF D8) starts one,
/// and the fragments after it until the next continue it. A codestream's scan never holds FF D8
/// (T.87 stuffs a 0 bit after every FF), so a continuing fragment cannot open with it.
fn codestreams(fragments: &[Vec<u8>], what: &str) -> Result<Vec<Vec<u8>>> {
    let mut streams: Vec<Vec<u8>> = Vec::new();
    for f in fragments {
        match streams.last_mut() {
            _ if f.starts_with(&[0xFF, 0xD8]) => streams.push(f.clone()),
            Some(last) => last.extend_from_slice(f),
            None => return Err(bad(what, "JPEG-LS pixel data: the first fragment does not start a codestream (SOI)")),
        }
    }
    Ok(streams)
}

/// A decoded sample as DICOM reads it: its low `stored` bits, sign-extended when `signed` (T.87
/// codes them unsigned).
fn sample(v: u16, stored: u32, signed: bool) -> f64 {
    let v = v as u32 & ((1u32 << stored) - 1);
    if signed && v >> (stored - 1) == 1 {
        v as f64 - (1u32 << stored) as f64
    } else {
        v as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_spans_fragments_until_the_next_soi() {
        let f = |b: &[u8]| b.to_vec();
        let s = codestreams(&[f(&[0xFF, 0xD8, 1]), f(&[2, 3]), f(&[0xFF, 0xD8, 4]), f(&[5])], "x").unwrap();
        assert_eq!(s, vec![vec![0xFF, 0xD8, 1, 2, 3], vec![0xFF, 0xD8, 4, 5]]);
        let e = codestreams(&[f(&[1, 2]), f(&[0xFF, 0xD8])], "x").unwrap_err().to_string();
        assert!(e.contains("first fragment"), "{e}");
    }

    #[test]
    fn samples_keep_their_stored_bits_and_sign() {
        assert_eq!(sample(0x0FFF, 12, true), -1.0);
        assert_eq!(sample(0x0800, 12, true), -2048.0);
        assert_eq!(sample(0x07FF, 12, true), 2047.0);
        assert_eq!(sample(0xF7FF, 12, true), 2047.0, "bits above Bits Stored are not the sample's");
        assert_eq!(sample(0xFFFF, 12, false), 4095.0);
        assert_eq!(sample(0x8000, 16, true), -32768.0);
        assert_eq!(sample(0x8000, 16, false), 32768.0);
    }
}
