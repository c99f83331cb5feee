//! A DICOM file's pixel data decoded into raw samples, frame by frame: dicom-pixeldata's
//! decoders, JPEG-LS in pure Rust, 32-bit samples read as words, and transfer syntaxes without a
//! decoder refused by name.
use super::super::bad;
use crate::error::{Error, Result};
use dicom_dictionary_std::tags;
use dicom_pixeldata::{ConvertOptions, ModalityLutOption, PixelDecoder, VoiLutOption};

/// Every frame's raw samples of `obj`, a file of `frames` frames of `size` (Columns, Rows) in
/// transfer syntax `syntax`.
pub(super) fn decode(
    obj: &dicom_object::FileDicomObject<dicom_object::InMemDicomObject>,
    syntax: &str,
    size: [u32; 2],
    frames: u32,
    what: &str,
) -> Result<Vec<Vec<f64>>> {
    if super::jpegls::is_jpegls(syntax) {
        return super::jpegls::frames(obj, size, frames, what);
    }
    let failed = |e: &dyn std::fmt::Display| bad(what, format!("pixel data (transfer syntax {syntax}): {e}"));
    if syntax.starts_with("1.2.840.10008.1.2.4.9") || syntax.starts_with("1.2.840.10008.1.2.4.20") {
        let pixel_data = obj.element(tags::PIXEL_DATA).map_err(|e| failed(&e))?;
        let fragments = pixel_data.value().fragments().unwrap_or_default();
        super::walk::check_j2k(fragments, size, frames, what)?;
    }
    let pixels = obj.decode_pixel_data().map_err(|e| match undecoded(syntax) {
        Some(refusal) => Error::Unsupported(format!("{what}: {refusal}")),
        None => failed(&e),
    })?;
    let options = ConvertOptions::new().with_modality_lut(ModalityLutOption::None).with_voi_lut(VoiLutOption::Identity);
    let frame = |f: u32| -> Result<Vec<f64>> {
        if pixels.bits_allocated() != 32 || pixels.samples_per_pixel() != 1 {
            return pixels.to_vec_frame_with_options(f, &options).map_err(|e| failed(&e));
        }
        // 32-bit samples (RT Dose), which dicom-pixeldata's conversion does not take: the
        // decoded frame's words. dicom-rs reads big-endian pixel data (OW) as 16-bit
        // little-endian words, so a big-endian file's sample is its high word first.
        let signed = pixels.pixel_representation() == dicom_pixeldata::PixelRepresentation::Signed;
        let big = syntax == "1.2.840.10008.1.2.2";
        let words = pixels.frame_data(f).map_err(|e| failed(&e))?.chunks_exact(4);
        Ok(words
            .map(|b| {
                let u = if big {
                    (u16::from_le_bytes([b[0], b[1]]) as u32) << 16 | u16::from_le_bytes([b[2], b[3]]) as u32
                } else {
                    u32::from_le_bytes([b[0], b[1], b[2], b[3]])
                };
                if signed {
                    u as i32 as f64
                } else {
                    u as f64
                }
            })
            .collect())
    };
    (0..frames).map(frame).collect()
}

/// Why pixel data in transfer syntax `uid` is not decoded, naming it, or `None` when it is (or is
/// unknown, and the decoder's own error says more).
fn undecoded(uid: &str) -> Option<String> {
    use dicom_encoding::TransferSyntaxIndex;
    let ts = dicom_transfer_syntax_registry::TransferSyntaxRegistry.get(uid)?;
    (!ts.can_decode_all()).then(|| {
        format!(
            "pixel data in {} ({uid}) is not decoded: dicom-rs has no decoder for it \
             (uncompressed, RLE, JPEG, JPEG-LS and JPEG 2000 are)",
            ts.name()
        )
    })
}
