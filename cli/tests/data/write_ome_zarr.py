"""Writes OME-Zarr images with the ome-zarr package (cli/tests/zarr.rs), and each level as the
.npy zarr-python reads back from it: the files voxsplat reads, written and read by others.

    python3 write_ome_zarr.py bonsai NIFTI OUT   # 0.4 (Zarr v2, zstd) and 0.5 (Zarr v3, sharded) pyramids
    python3 write_ome_zarr.py series OUT         # t, c, z, y, x: 3 time points of 2 channels, blosc
    python3 write_ome_zarr.py bonsai-t NIFTI OUT # t, z, y, x: 3 time points of the bonsai, moved along x
"""
import sys

import nibabel
import numpy as np
import zarr
from numcodecs import Blosc
from ome_zarr.format import FormatV04, FormatV05
from ome_zarr.io import parse_url
from ome_zarr.writer import write_image


def write(path, data, fmt, axes, **kw):
    root = zarr.group(store=parse_url(path, mode="w", fmt=fmt).store)
    write_image(image=data, group=root, axes=axes, fmt=fmt, **kw)
    image = zarr.open_group(path, mode="r")
    ms = dict(image.attrs)["ome"]["multiscales"] if "ome" in image.attrs else image.attrs["multiscales"]
    for i, d in enumerate(ms[0]["datasets"]):
        save(f"{path}.level{i}.npy", image[d["path"]][:])


def save(path, a):
    # As 3-D (time points and channels one after another along z): voxsplat's .npy is 2-D or 3-D.
    np.save(path, a.reshape(-1, *a.shape[-2:]))


def bonsai(nifti, out):
    # nibabel's array is x, y, z; OME-Zarr stores z, y, x.
    data = np.ascontiguousarray(np.asarray(nibabel.load(nifti).dataobj).astype(np.uint8).T)
    levels = [{"z": 2, "y": 2, "x": 2}, {"z": 4, "y": 4, "x": 4}]
    scale = {"z": 1.5, "y": 1.0, "x": 1.0}
    write(f"{out}/v04.zarr", data, FormatV04(), "zyx", scale_factors=levels, scale=scale,
          storage_options={"chunks": (32, 64, 64)})
    write(f"{out}/v05.zarr", data, FormatV05(), "zyx", scale_factors=levels, scale=scale,
          storage_options={"chunks": (16, 32, 32), "shards": (32, 64, 64)})


def series(out):
    t, c, z, y, x = np.indices((3, 2, 20, 24, 28), dtype=np.float32)
    data = (np.sin(x / 3 + t) * np.cos(y / 4 - z / 5) * 100 + c * 50).astype(np.int16)
    write(f"{out}/tczyx.zarr", data, FormatV04(), "tczyx", scale_factors=[{"z": 2, "y": 2, "x": 2}],
          storage_options={"chunks": (1, 1, 8, 8, 8), "compressor": Blosc(cname="lz4", shuffle=Blosc.SHUFFLE)})
    save(f"{out}/tczyx.npy", data)


def bonsai_t(nifti, out):
    data = np.ascontiguousarray(np.asarray(nibabel.load(nifti).dataobj).astype(np.uint8).T)
    data = np.stack([np.roll(data, 8 * t, axis=2) for t in range(3)])
    write(f"{out}/t.zarr", data, FormatV04(), "tzyx", scale_factors=[{"z": 2, "y": 2, "x": 2}],
          scale={"t": 1.0, "z": 1.5, "y": 1.0, "x": 1.0}, storage_options={"chunks": (1, 32, 64, 64)})


if __name__ == "__main__":
    {"bonsai": bonsai, "series": series, "bonsai-t": bonsai_t}[sys.argv[1]](*sys.argv[2:])
