"""Writes a time series from the shared bonsai as a 4-D NIfTI (nibabel; its fourth axis in
seconds) for `voxsplat-lab series` and `voxsplat animate --volume` (not committed: 16 MiB a time
point).

    python3 scripts/make_series.py ball OUT.nii [T]    # a bright ball crosses the still bonsai
    python3 scripts/make_series.py noise OUT.nii [T]   # every stored voxel jitters (fMRI-like)

`ball` is a time-lapse where little changes per time point; `noise` the worst case, where every
brick the bonsai fills changes.
"""
import sys

import nibabel
import numpy as np

DATA = __file__.rsplit("/", 2)[0] + "/../shared/data/bonsai/bonsai.nii.gz"


def main(kind, out, t="8"):
    t = int(t)
    src = nibabel.load(DATA)
    bonsai = np.asarray(src.dataobj).astype(np.uint8)
    n = bonsai.shape[0]
    frames = []
    rng = np.random.default_rng(7)
    for i in range(t):
        v = bonsai.copy()
        if kind == "ball":
            x, y, z = np.ogrid[:n, :n, :n]
            cx = n * (0.15 + 0.7 * i / max(t - 1, 1))
            r = np.sqrt((x - cx) ** 2 + (y - 0.7 * n) ** 2 + (z - 0.6 * n) ** 2)
            v[r < n / 20] = 200
        elif kind == "noise":
            jitter = rng.integers(-3, 4, size=v.shape)
            v = np.where(v > 0, np.clip(v.astype(np.int16) + jitter, 1, 255), 0).astype(np.uint8)
        else:
            sys.exit(f"unknown kind {kind}: ball or noise")
        frames.append(v)
    img = nibabel.Nifti1Image(np.stack(frames, axis=-1), src.affine)
    img.header.set_xyzt_units("mm", "sec")
    nibabel.save(img, out)


if __name__ == "__main__":
    main(*sys.argv[1:])
