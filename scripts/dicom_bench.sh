#!/usr/bin/env bash
# DICOM loading throughput (issue 47's target): a CT series of SLICES 512 x 512 16-bit images
# (default 256, 128 MiB of pixel data) written by pydicom from the procedural field, read by
# `voxsplat-lab load` (the dense volume and the bricked store) beside dcm2niix converting it to an
# uncompressed NIfTI; medians of 5 alternating rounds, in MB/s of pixel data. With `jpegls` each
# image is compressed as JPEG-LS lossless (CharLS, through pydicom and pyjpegls), and the peer is
# pydicom decoding the series into one array with CharLS (pyjpegls): Debian's dcm2niix is built
# without JPEG-LS. Never committed (target/).
#   scripts/dicom_bench.sh [SLICES] [jpegls]
set -euo pipefail
cd "$(dirname "$0")/.."
slices=${1:-256}
syntax=${2:-plain}
case "$syntax" in plain|jpegls) ;; *) echo "dicom_bench.sh: the second argument is plain or jpegls, not $syntax" >&2; exit 2;; esac
dir=target/dicom-bench
rm -rf "$dir" && mkdir -p "$dir/series" "$dir/out"
cargo build --release --quiet
python3 - "$dir/series" "$slices" "$syntax" <<'PY'
import sys
import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, generate_uid
out, n, syntax = sys.argv[1], int(sys.argv[2]), sys.argv[3]
series, study, frame = generate_uid(), generate_uid(), generate_uid()
x = np.arange(512, dtype=np.float32) - 256
for k in range(n):
    r = np.sqrt(x[None, :] ** 2 + x[:, None] ** 2 + (k - n / 2) ** 2 * 4)
    img = (1000 * np.cos(r / 20) * np.exp(-r / 300) - 200).astype(np.int16)
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID = CTImageStorage, generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID, ds.SOPInstanceUID = CTImageStorage, meta.MediaStorageSOPInstanceUID
    ds.Modality, ds.SeriesInstanceUID, ds.StudyInstanceUID, ds.FrameOfReferenceUID = "CT", series, study, frame
    ds.PatientName, ds.PatientID, ds.InstanceNumber = "bench", "bench", n - k
    ds.Rows, ds.Columns, ds.PixelSpacing, ds.SliceThickness = 512, 512, [0.5, 0.5], 1.0
    ds.ImageOrientationPatient, ds.ImagePositionPatient = [1, 0, 0, 0, 1, 0], [-128, -128, float(k)]
    ds.RescaleSlope, ds.RescaleIntercept = 1, -1024
    ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
    ds.PixelData = img.tobytes()
    if syntax == "jpegls":
        from pydicom.uid import JPEGLSLossless
        ds.compress(JPEGLSLossless, img, encoding_plugin="pyjpegls")
    pydicom.dcmwrite(f"{out}/im{k:04d}.dcm", ds, enforce_file_format=True)
PY
mb=$(python3 -c "print(512 * 512 * 2 * $slices / 1e6)")
# Warm the page cache: both readers then read from memory. Five rounds, each voxsplat's two reads
# then dcm2niix's conversion, alternating so that the machine's drift falls on both.
cat "$dir"/series/* > /dev/null
rows=()
for _ in 1 2 3 4 5; do
  out=$(./target/release/voxsplat-lab load "$dir/series" --repeat 1)
  dense=$(echo "$out" | grep "dense volume" | awk -F'|' '{print $3}' | tr -d ' s')
  bricked=$(echo "$out" | grep "bricked store" | awk -F'|' '{print $3}' | tr -d ' s')
  rm -f "$dir"/out/*
  t0=$(date +%s.%N)
  if [ "$syntax" = jpegls ]; then
    python3 -c "import glob, sys, numpy, pydicom; numpy.stack([pydicom.dcmread(f).pixel_array for f in sorted(glob.glob(sys.argv[1] + '/*.dcm'))])" "$dir/series"
  else
    dcm2niix -o "$dir/out" -f bench -z n "$dir/series" > /dev/null
  fi
  t1=$(date +%s.%N)
  rows+=("$dense $bricked $(python3 -c "print($t1 - $t0)")")
done
echo "pixel data: $syntax, $(du -sm "$dir/series" | cut -f1) MiB on disk"
python3 - "$mb" "$syntax" "${rows[@]}" <<'PY'
import statistics, sys
mb = float(sys.argv[1])
runs = [list(map(float, r.split())) for r in sys.argv[3:]]
med = [statistics.median(r[i] for r in runs) for i in range(3)]
peer = "pydicom + pyjpegls (CharLS) into one array" if sys.argv[2] == "jpegls" else "dcm2niix to an uncompressed NIfTI"
print(f"| read ({mb:.1f} MB of pixel data, median of {len(runs)} alternating rounds) | time | MB/s | against the peer |")
print("|---|---:|---:|---:|")
for name, t in zip(["voxsplat, dense volume (load_volume)", "voxsplat, bricked store (BrickStore::load)", peer], med):
    print(f"| {name} | {t:.3f} s | {mb / t:.0f} | {t / med[2]:.2f}x its time |")
PY
