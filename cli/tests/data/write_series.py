"""Writes a time series the way others write one (cli/tests/series.rs): a 4-D NIfTI with nibabel
(its fourth axis in seconds) and as numbered 3-D files, a 4-D NRRD with pynrrd (kinds space space space time, gzip) and an
OME-Zarr image with a t, z, y, x axis with the ome-zarr package, of the same voxels: a still blob and a bright ball moving along x, every time point spanning the
same values (0 to 250).

    python3 write_series.py OUT
"""
import sys

import nibabel
import nrrd
import numpy as np
import zarr
from ome_zarr.format import FormatV05
from ome_zarr.io import parse_url
from ome_zarr.writer import write_image

T, X, Y, Z = 6, 40, 36, 32


def volume(t):
    x, y, z = np.indices((X, Y, Z), dtype=np.float32)
    r = np.sqrt(((x - 20) / 14) ** 2 + ((y - 18) / 12) ** 2 + ((z - 16) / 11) ** 2)
    v = np.where(r < 1, 40 + 120 * (1 - r), 0)
    ball = np.sqrt((x - 8 - 4 * t) ** 2 + (y - 26) ** 2 + (z - 20) ** 2)
    v = np.where(ball < 5, 250 - 10 * ball, v)
    return v.astype(np.uint8)


def main(out):
    xyzt = np.stack([volume(t) for t in range(T)], axis=-1)
    img = nibabel.Nifti1Image(xyzt, np.eye(4))
    img.header.set_xyzt_units("mm", "sec")
    nibabel.save(img, f"{out}/series.nii.gz")
    # The same time points as numbered files (t2 before t10: ordered by number, not by name).
    for t in range(T):
        nibabel.save(nibabel.Nifti1Image(xyzt[..., t], np.eye(4)), f"{out}/vol_t{t * 4}.nii.gz")
    nrrd.write(f"{out}/series.nrrd", xyzt, {"kinds": ["space", "space", "space", "time"], "encoding": "gzip"})
    tzyx = np.ascontiguousarray(xyzt.transpose(3, 2, 1, 0))
    root = zarr.group(store=parse_url(f"{out}/series.zarr", mode="w", fmt=FormatV05()).store)
    write_image(image=tzyx, group=root, axes="tzyx", fmt=FormatV05(), scale_factors=[],
                storage_options={"chunks": (1, 16, 16, 16)})


if __name__ == "__main__":
    main(*sys.argv[1:])
