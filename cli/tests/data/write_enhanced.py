"""Writes an enhanced MR image (one multi-frame file placed by per-frame functional groups) for
the DICOM tests: a ball and a ramp, 24 x 20 pixels, 12 frames stored out of order, on an oblique
plane, with a shared rescale. Usage: write_enhanced.py OUT.dcm [--times N] [--items K] [--signed]
[--jpegls FRAGMENTS]"""
import argparse

import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.sequence import Sequence
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

ap = argparse.ArgumentParser()
ap.add_argument("out")
ap.add_argument("--times", type=int, default=1, help="temporal positions (time point t: the frames plus 100 t)")
ap.add_argument("--items", type=int, default=None, help="per-frame items to write (default: one per frame)")
ap.add_argument("--signed", action="store_true", help="store 12-bit signed samples (v - 1000), the same values after rescale")
ap.add_argument("--jpegls", type=int, default=0, help="compress as JPEG-LS lossless, each frame in this many fragments")
a = ap.parse_args()

cols, rows, n = 24, 20, 12
z, y, x = np.mgrid[0:n, 0:rows, 0:cols].astype(np.float64)
ball = ((x - 12) ** 2 + (y - 9) ** 2 + ((z - 6) * 1.5) ** 2) < 49
vol = (ball * 900 + x * 10 + z * 5).astype(np.uint16)  # stored values; Rescale: 2 v - 100

angle = np.radians(30)
row = np.array([np.cos(angle), np.sin(angle), 0.0])
col = np.array([0.0, 0.0, -1.0])  # an oblique coronal plane
normal = np.cross(row, col)
spacing, step = (0.8, 0.9), 2.5
origin = np.array([-10.0, 20.0, 35.0])

order = list(range(n))
rng = np.random.default_rng(7)
rng.shuffle(order)

meta = FileMetaDataset()
meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.4.1"
meta.MediaStorageSOPInstanceUID = generate_uid()
meta.TransferSyntaxUID = ExplicitVRLittleEndian
ds = Dataset()
ds.file_meta = meta
ds.SOPClassUID = meta.MediaStorageSOPClassUID
ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
ds.StudyInstanceUID, ds.SeriesInstanceUID = generate_uid(), generate_uid()
ds.FrameOfReferenceUID = generate_uid()
ds.Modality, ds.SeriesDescription, ds.SeriesNumber, ds.InstanceNumber = "MR", "enhanced", 1, 1
ds.PatientName, ds.PatientID = "Phantom", "0"
ds.ImageType = ["ORIGINAL", "PRIMARY", "M", "NONE"]
ds.Rows, ds.Columns = rows, cols
ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = (16, 12, 11, 1) if a.signed else (16, 16, 15, 0)
frames = [(t, k) for k in order for t in range(a.times)]  # time points interleaved
ds.NumberOfFrames = len(frames)
ds.ContentDate, ds.ContentTime, ds.AcquisitionDateTime = "20260101", "120000", "20260101120000"

shared = Dataset()
measures = Dataset()
measures.PixelSpacing = [spacing[0], spacing[1]]
measures.SliceThickness = step
shared.PixelMeasuresSequence = Sequence([measures])
plane = Dataset()
plane.ImageOrientationPatient = [float(v) for v in (*row, *col)]
shared.PlaneOrientationSequence = Sequence([plane])
rescale = Dataset()
rescale.RescaleSlope, rescale.RescaleIntercept, rescale.RescaleType = 2, (1900 if a.signed else -100), "US"
shared.PixelValueTransformationSequence = Sequence([rescale])
ds.SharedFunctionalGroupsSequence = Sequence([shared])

items = []
for t, k in frames:
    item = Dataset()
    pos = Dataset()
    pos.ImagePositionPatient = [float(v) for v in origin + normal * step * k]
    item.PlanePositionSequence = Sequence([pos])
    content = Dataset()
    content.StackID = "1"
    content.InStackPositionNumber = k + 1
    content.TemporalPositionIndex = t + 1
    content.DimensionIndexValues = [t + 1, k + 1]
    item.FrameContentSequence = Sequence([content])
    items.append(item)
ds.PerFrameFunctionalGroupsSequence = Sequence(items[: a.items] if a.items is not None else items)
pixels = np.stack([vol[k] + 100 * t for t, k in frames])
pixels = (pixels.astype(np.int16) - 1000) if a.signed else pixels.astype(np.uint16)
ds.PixelData = pixels.tobytes()
if a.jpegls:
    # pydicom's JPEG-LS encoder (CharLS, through pyjpegls), then each frame's codestream split.
    from pydicom.encaps import encapsulate, generate_frames
    from pydicom.uid import JPEGLSLossless

    ds.compress(JPEGLSLossless, pixels, encoding_plugin="pyjpegls")
    streams = list(generate_frames(ds.PixelData, number_of_frames=len(frames)))
    ds.PixelData = encapsulate(streams, fragments_per_frame=a.jpegls, has_bot=True)
ds.save_as(a.out, enforce_file_format=True)
