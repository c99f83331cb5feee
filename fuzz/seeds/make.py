"""Writes the fuzz targets' seed files into fuzz/seeds/<target>/ (committed; run it to remake them).

Small valid files of each format, made by independent writers where there is one (nibabel for
NIfTI, tifffile for TIFF, numpy for npy, PIL for PNG); the slices and heights targets take a first
byte that picks the file's kind (see their sources).
"""
import gzip, io, os, sys
import numpy as np

root = os.path.dirname(os.path.abspath(__file__))


def put(target, name, data, prefix="seed-"):
    """A seed the loader reads (`seed-`), or one it must refuse with an error (`refused-`)."""
    d = os.path.join(root, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, prefix + name), "wb") as f:
        f.write(data)


vol = (np.arange(4 * 3 * 2, dtype=np.uint8) * 9).reshape(2, 3, 4)  # z, y, x
nrrd_raw = (b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 3 2\nspacings: 1 1 2\nencoding: raw\n\n"
            + vol.tobytes())
nrrd_gz = (b"NRRD0005\n# a comment\ntype: short\ndimension: 3\nsizes: 4 3 2\nendian: little\n"
           b"space: right-anterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0.5,1.5)\n"
           b"space origin: (0,0,0)\nencoding: gzip\n\n" + gzip.compress(vol.astype("<i2").tobytes()))
nrrd_skip = (b"NRRD0004\ntype: float\ndimension: 3\nsizes: 4 3 2\nendian: big\nbyte skip: 4\nline skip: 0\n"
             b"encoding: raw\n\n" + b"\0\0\0\0" + vol.astype(">f4").tobytes())
put("nrrd", "raw.nrrd", nrrd_raw)
put("nrrd", "gzip.nrrd", nrrd_gz)
put("nrrd", "skip.nrrd", nrrd_skip, "refused-")  # byte skip is refused by name

try:
    import nibabel as nib
    img = nib.Nifti1Image(vol.transpose(2, 1, 0).astype(np.int16), np.diag([1.0, 1.0, 2.0, 1.0]))
    img.header.set_qform(np.diag([1.0, 1.0, 2.0, 1.0]), code=1)
    nii = img.to_bytes()
    put("nifti", "plain.nii", nii)
    put("nifti", "plain.nii.gz", gzip.compress(nii))
    img2 = nib.Nifti1Image(vol.transpose(2, 1, 0).astype(np.float32), np.eye(4))
    img2.header.set_slope_inter(2.0, -1.0)
    put("nifti", "scaled.nii", img2.to_bytes())
except ImportError:
    sys.exit("nibabel is needed for the NIfTI seeds (pip install nibabel)")

for dt in ["<u1", "<u2", "<i2", "<f4", ">f8"]:
    buf = io.BytesIO()
    np.save(buf, vol.astype(dt))
    put("npy", f"{dt[1:]}.npy", buf.getvalue())

import tifffile
for dt in ["uint8", "uint16", "int16", "float32"]:
    buf = io.BytesIO()
    tifffile.imwrite(buf, (np.arange(12).reshape(3, 4) * 7).astype(dt))
    put("tiff", f"{dt}.tif", buf.getvalue())

put("raw", "u8", bytes([0]) + vol.tobytes())
put("raw", "f32", bytes([3]) + vol.astype("<f4").tobytes())

# slices: the first byte picks nrrd, nii, nii.gz (see fuzz_targets/slices.rs).
put("slices", "raw.nrrd", b"\0" + nrrd_raw)
put("slices", "gzip.nrrd", b"\0" + nrrd_gz)
put("slices", "skip.nrrd", b"\0" + nrrd_skip, "refused-")
put("slices", "plain.nii", b"\1" + nii)
put("slices", "plain.nii.gz", b"\2" + gzip.compress(nii))
# Series: a 4-D NIfTI over time (nibabel, seconds) and a 4-D NRRD whose last axis is time.
series = np.stack([vol.transpose(2, 1, 0) + t for t in range(3)], axis=-1)
img4 = nib.Nifti1Image(series.astype(np.uint8), np.eye(4))
img4.header.set_xyzt_units("mm", "sec")
put("slices", "series.nii", b"\1" + img4.to_bytes())
put("slices", "series.nrrd", b"\0" + b"NRRD0004\ntype: uchar\ndimension: 4\nsizes: 4 3 2 3\n"
    b"kinds: space space space time\nencoding: raw\n\n" + series.transpose(3, 2, 1, 0).astype(np.uint8).tobytes())

# heights: the first byte picks png, tif, npy (see fuzz_targets/heights.rs).
from PIL import Image
buf = io.BytesIO()
Image.fromarray((np.arange(12).reshape(3, 4) * 5000).astype(np.uint16)).save(buf, format="PNG")
put("heights", "u16.png", b"\0" + buf.getvalue())
buf = io.BytesIO()
tifffile.imwrite(buf, np.arange(12, dtype=np.float32).reshape(3, 4))
put("heights", "f32.tif", b"\1" + buf.getvalue())
buf = io.BytesIO()
np.save(buf, np.arange(12, dtype=np.float32).reshape(3, 4))
put("heights", "f32.npy", b"\2" + buf.getvalue())

put("tf", "points.toml", b'points = [[0.0, [0, 0, 0, 0]], [0.3, [1, 0.5, 0.2, 0.4]], [1.0, [1, 1, 1, 1]]]\n'
    b'range = [-10.0, 300.0]\n')
put("tf", "preset.toml", b'points = [[0.1, [0.2, 0.4, 1, 0]], [0.9, [1, 1, 0.8, 0.9]]]\n')
put("animation", "keys.toml", b'scene = "cube60"\nframes = 24\nshutter = 1.0\nsize = [64, 64]\n[camera]\n'
    b'eye = [0.0, 45.0, 120.0]\ntarget = [0.0, 0.0, 0.0]\northo = 110.0\n[[keyframe]]\nframe = 0\n'
    b'rotate = [0.0, 1.0, 0.0, 0.0]\n[[keyframe]]\nframe = 24\nrotate = [0.0, 1.0, 0.0, 144.0]\n'
    b'eye = [1.0, 40.0, 100.0]\ntarget = [0.0, 1.0, 0.0]\n')
put("positions", "xz.toml", b"x = [0.0, 1.0, 2.5, 4.0]\nz = [0, 3]\n")
put("sidecar", "raw.toml", b'dims = [4, 3, 2]\ndtype = "uint16"\nendian = "big"\nspacing = [1.0, 1.0, 2.0]\n')

# Image stacks read as volumes (the stacks target): a value (z, y, x) -> ((z * 4 + y) * 5 + x) * 7 % 251
# (tests/stacks.rs reads these seeds back).
stack = (np.arange(3 * 4 * 5) * 7 % 251).astype(np.uint16).reshape(3, 4, 5)
buf = io.BytesIO()
tifffile.imwrite(buf, stack, imagej=True, resolution=(1 / 0.5, 1 / 0.25),
                 metadata={"spacing": 2.0, "unit": "um", "axes": "ZYX"})
put("stacks", "imagej.tif", buf.getvalue())
buf = io.BytesIO()
tifffile.imwrite(buf, stack.astype(np.float32) / 4, ome=True, photometric="minisblack",
                 metadata={"axes": "ZYX", "PhysicalSizeX": 0.3, "PhysicalSizeY": 0.4, "PhysicalSizeZ": 1.5})
put("stacks", "ome.tif", buf.getvalue())
buf = io.BytesIO()
tifffile.imwrite(buf, np.zeros((2, 4, 5, 3), np.uint8), photometric="rgb")
put("stacks", "rgb.tif", buf.getvalue(), "refused-")
buf = io.BytesIO()
with tifffile.TiffWriter(buf) as t:
    t.write(np.zeros((4, 5), np.uint8))
    t.write(np.zeros((3, 5), np.uint8))
put("stacks", "sizes.tif", buf.getvalue(), "refused-")
buf = io.BytesIO()
tifffile.imwrite(buf, np.zeros((2, 3, 4, 5), np.uint8), imagej=True, metadata={"axes": "ZCYX"})
put("stacks", "channels.tif", buf.getvalue(), "refused-")

# DICOM (the dicom target): one CT image written by pydicom, one without its Pixel Spacing, a
# multi-frame RT Dose grid, an enhanced image of two frames, a JPEG 2000 image, a JPEG-LS
# one, and a deflated data set.
try:
    import pydicom
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, generate_uid

    def ct(spacing=True):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
        meta.MediaStorageSOPInstanceUID = "1.2.3.4.5.6.7"
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.SOPClassUID, ds.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
        ds.Modality, ds.SeriesInstanceUID = "CT", "1.2.3.4.5.6.8"
        ds.Rows, ds.Columns = 3, 4
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.ImagePositionPatient = [0, 0, 0]
        if spacing:
            ds.PixelSpacing = [0.5, 0.5]
        ds.RescaleSlope, ds.RescaleIntercept = 1, -1024
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
        ds.PixelData = (np.arange(12, dtype=np.int16) * 100).tobytes()
        buf = io.BytesIO()
        pydicom.dcmwrite(buf, ds, enforce_file_format=True)
        return buf.getvalue()

    def dose(offsets=(0, 2.5, 5)):
        # A multi-frame RT Dose grid: 3 frames of 32-bit samples placed by a Grid Frame Offset Vector
        # (uneven offsets: resampled onto even slices).
        ds = pydicom.dcmread(io.BytesIO(ct()))
        ds.Modality = "RTDOSE"
        del ds.RescaleSlope, ds.RescaleIntercept
        ds.NumberOfFrames, ds.GridFrameOffsetVector, ds.DoseGridScaling = 3, list(offsets), 1e-4
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 32, 32, 31, 0
        ds.PixelData = (np.arange(36, dtype=np.uint32) * 1000).tobytes()
        buf = io.BytesIO()
        pydicom.dcmwrite(buf, ds, enforce_file_format=True)
        return buf.getvalue()

    def enhanced():
        # An enhanced image: 2 frames placed by per-frame Plane Position, the rest shared.
        from pydicom.sequence import Sequence
        ds = pydicom.dcmread(io.BytesIO(ct()))
        shared = Dataset()
        shared.PlaneOrientationSequence = Sequence([Dataset()])
        shared.PlaneOrientationSequence[0].ImageOrientationPatient = ds.ImageOrientationPatient
        shared.PixelMeasuresSequence = Sequence([Dataset()])
        shared.PixelMeasuresSequence[0].PixelSpacing = ds.PixelSpacing
        del ds.ImageOrientationPatient, ds.ImagePositionPatient, ds.PixelSpacing
        ds.SharedFunctionalGroupsSequence = Sequence([shared])
        frames = []
        for z in (2.0, 0.0):
            item = Dataset()
            item.PlanePositionSequence = Sequence([Dataset()])
            item.PlanePositionSequence[0].ImagePositionPatient = [0, 0, z]
            frames.append(item)
        ds.PerFrameFunctionalGroupsSequence = Sequence(frames)
        ds.NumberOfFrames = 2
        ds.PixelData = (np.arange(24, dtype=np.int16) * 50).tobytes()
        buf = io.BytesIO()
        pydicom.dcmwrite(buf, ds, enforce_file_format=True)
        return buf.getvalue()

    def j2k():
        # A JPEG 2000 image (lossless, encoded by Pillow's OpenJPEG), encapsulated.
        from PIL import Image
        from pydicom.encaps import encapsulate
        ds = pydicom.dcmread(io.BytesIO(ct()))
        ds.PixelRepresentation = 0
        j = io.BytesIO()
        Image.fromarray((np.arange(12, dtype=np.uint16) * 100).reshape(3, 4)).save(j, "JPEG2000", irreversible=False)
        ds.file_meta.TransferSyntaxUID = "1.2.840.10008.1.2.4.90"
        ds.PixelData = encapsulate([j.getvalue()])
        ds["PixelData"].VR = "OB"
        ds["PixelData"].is_undefined_length = True
        buf = io.BytesIO()
        pydicom.dcmwrite(buf, ds, enforce_file_format=True)
        return buf.getvalue()

    def jpegls():
        # The enhanced image compressed as JPEG-LS (lossless, by CharLS through pyjpegls), each
        # frame's codestream in two fragments.
        from pydicom.encaps import encapsulate, generate_frames
        from pydicom.uid import JPEGLSLossless
        ds = pydicom.dcmread(io.BytesIO(enhanced()))
        # 16 x 16 frames: CharLS refuses frames so small that their codestream outgrows them.
        ds.Rows = ds.Columns = 16
        ds.PixelData = (np.arange(512, dtype=np.int16) * 7).tobytes()
        ds.compress(JPEGLSLossless, encoding_plugin="pyjpegls")
        streams = list(generate_frames(ds.PixelData, number_of_frames=2))
        ds.PixelData = encapsulate(streams, fragments_per_frame=2, has_bot=True)
        buf = io.BytesIO()
        pydicom.dcmwrite(buf, ds, enforce_file_format=True)
        return buf.getvalue()

    def deflated():
        # The CT image with its data set deflated (Deflated Explicit VR Little Endian).
        ds = pydicom.dcmread(io.BytesIO(ct()))
        ds.file_meta.TransferSyntaxUID = "1.2.840.10008.1.2.1.99"
        buf = io.BytesIO()
        pydicom.dcmwrite(buf, ds, enforce_file_format=True)
        return buf.getvalue()

    put("dicom", "ct.dcm", ct())
    put("dicom", "deflated.dcm", deflated())
    put("dicom", "no-spacing.dcm", ct(False), "refused-")
    put("dicom", "dose.dcm", dose())
    put("dicom", "dose-uneven.dcm", dose((0, 1, 3.5)))
    put("dicom", "enhanced.dcm", enhanced())
    put("dicom", "j2k.dcm", j2k())
    put("dicom", "jpegls.dcm", jpegls())
except ImportError:
    print("pydicom missing: the dicom seeds are left as they are", file=sys.stderr)

# OME-Zarr (the zarr target): small two-level images written by the ome-zarr package, each packed as
# a first byte (0: Zarr v2 / NGFF 0.4, 1: Zarr v3 / 0.5) and its files joined by "\n--\n": the
# root metadata, level 0's array metadata and only chunk, level 1's (see the target's source).
try:
    import json, tempfile
    import zarr
    from numcodecs import Blosc
    from ome_zarr.format import FormatV04, FormatV05
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image

    def zarr_seed(fmt, **options):
        v3 = fmt.version == "0.5"
        data = (np.arange(4 * 6 * 8, dtype=np.uint16) * 7).reshape(4, 6, 8)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "image.zarr")
            root = zarr.group(store=parse_url(path, mode="w", fmt=fmt).store)
            write_image(image=data, group=root, axes="zyx", fmt=fmt, scale_factors=[{"z": 2, "y": 2, "x": 2}],
                        storage_options=dict(chunks=(4, 6, 8), **options))
            meta, array, chunk = (("zarr.json", "zarr.json", "c/0/0/0") if v3 else (".zattrs", ".zarray", "0/0/0"))
            read = lambda p: open(os.path.join(path, p), "rb").read()
            # The target names the levels 0 and 1.
            top = json.loads(read(meta))
            ms = top["attributes"]["ome"]["multiscales"] if v3 else top["multiscales"]
            for i, ds in enumerate(ms[0]["datasets"]):
                ds["path"] = str(i)
            parts = [json.dumps(top).encode()]
            for level in ("s0", "s1"):
                parts += [read(f"{level}/{array}"), read(f"{level}/{chunk}")]
            return bytes([int(v3)]) + b"\n--\n".join(parts)

    put("zarr", "v2-zstd", zarr_seed(FormatV04()))
    put("zarr", "v2-blosc", zarr_seed(FormatV04(), compressor=Blosc(cname="lz4", shuffle=Blosc.SHUFFLE)))
    put("zarr", "v3-zstd", zarr_seed(FormatV05()))
    put("zarr", "v3-sharded", zarr_seed(FormatV05(), shards=(4, 6, 8)))
except ImportError:
    print("ome-zarr missing: the zarr seeds are left as they are", file=sys.stderr)
