#!/usr/bin/env python3
"""The family of volumes nobody tuned the defaults for (issue 75), written as 8-bit NRRD into DIR.

    python3 scripts/family.py DIR [--small] [--only NAME,...]

From each shared file (bonsai, heptane, stent): 2x nearest-neighbour (`-nn2`: blocky, what a
resampled scan or mask looks like), 2x trilinear (`-lin2`), a thresholded binary mask (`-mask`)
and that mask 2x nearest-neighbour (`-mask2`). Beside them: a label volume of a few regions
(`labels`), a spherical shell one voxel thick (`shell`), white noise (`noise`) and the same noise
smoothed (`noise-smooth`), a field with spacing (1, 1, 4) (`aniso`), a sparse 1024^3 field
(`sparse1024`, 1 GiB) and the procedural 1024^3 field whose frame time issue 75's targets name
(`field1024`, 1 GiB: `voxsplat make-volume --procedural 1024`, a gyroid's thin shell in a ball,
placed in patient space as the others are; made with --vs, default target/release/voxsplat).
`--small` makes the CI subset instead: the same kinds from crops and at small sides, a few MiB in
all. Never commit what it writes. Prints one line per volume: name, file, the transfer function it
is drawn with.
"""
import argparse
import gzip
import os
import subprocess
import sys

import numpy as np

DATA = os.environ.get("VOXSPLAT_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))


# In patient space (x left, y posterior, z superior), so the anatomical views (--view anterior) apply.
def nrrd_header(x, y, z, spacing=(1.0, 1.0, 1.0), origin=0):
    """The attached header of a raw uint8 NRRD of x * y * z voxels in patient space, the first
    voxel's centre at (origin, origin, origin)."""
    return (
        "NRRD0004\ntype: uint8\ndimension: 3\n"
        f"sizes: {x} {y} {z}\nspace: left-posterior-superior\nspace origin: ({origin},{origin},{origin})\n"
        f"space directions: ({spacing[0]},0,0) (0,{spacing[1]},0) (0,0,{spacing[2]})\n"
        "encoding: raw\n\n"
    ).encode()


def write_nrrd(path, vol, spacing=(1.0, 1.0, 1.0)):
    """vol is indexed [z, y, x] (x fastest on disk), uint8."""
    vol = np.ascontiguousarray(vol, dtype=np.uint8)
    z, y, x = vol.shape
    with open(path, "wb") as f:
        f.write(nrrd_header(x, y, z, spacing))
        f.write(vol.tobytes())


def load_nifti(path):
    import nibabel

    return np.asarray(nibabel.load(path).dataobj).transpose(2, 1, 0)


def load_stent(path):
    with open(path, "rb") as f:
        raw = f.read()
    head, _, body = raw.partition(b"\n\n")
    fields = dict(
        line.split(": ", 1) for line in head.decode().splitlines()[1:] if ": " in line and not line.startswith("#")
    )
    sizes = [int(s) for s in fields["sizes"].split()]
    dtype = {"int16": "<i2", "short": "<i2", "signed short": "<i2"}[fields["type"]]
    if fields.get("encoding") == "gzip":
        body = gzip.decompress(body)
    return np.frombuffer(body, dtype=dtype).reshape(sizes[2], sizes[1], sizes[0])


def to_u8(v):
    v = v.astype(np.float32)
    lo, hi = float(v.min()), float(v.max())
    return np.round((v - lo) * (255.0 / max(hi - lo, 1e-9))).astype(np.uint8)


def nn2(v):
    return v.repeat(2, 0).repeat(2, 1).repeat(2, 2)


def lin2(v):
    from scipy.ndimage import zoom

    return np.clip(np.round(zoom(v.astype(np.float32), 2, order=1, mode="nearest")), 0, 255).astype(np.uint8)


def mask(v):
    # Above the mean of the non-zero voxels: a segmentation's blocky, binary silhouette.
    nz = v[v > 0]
    t = float(nz.mean()) if nz.size else 1.0
    return np.where(v > t, 255, 0).astype(np.uint8)


def ball_coords(n):
    c = (np.arange(n, dtype=np.float32) + 0.5) / n * 2.0 - 1.0
    return np.meshgrid(c, c, c, indexing="ij")  # z, y, x in [-1, 1]


def labels(n):
    z, y, x = ball_coords(n)
    out = np.zeros((n, n, n), np.uint8)
    out[(x * x + y * y + z * z) < 0.8**2] = 1
    out[((x - 0.25) ** 2 + y * y + z * z) < 0.35**2] = 2
    out[((x + 0.3) ** 2 + (y - 0.2) ** 2 + z * z) < 0.25**2] = 3
    out[(np.abs(x) < 0.1) & (np.abs(y + 0.3) < 0.4) & (np.abs(z) < 0.5)] = 4
    return out


def shell(n):
    # One voxel thick: the voxels whose centre lies within half a voxel of the sphere.
    z, y, x = ball_coords(n)
    r = np.sqrt(x * x + y * y + z * z) * (n / 2.0)
    return np.where(np.abs(r - 0.4 * n) <= 0.5, 255, 0).astype(np.uint8)


def noise(n, seed=7):
    return np.random.default_rng(seed).integers(0, 256, size=(n, n, n), dtype=np.uint8)


def smooth(v):
    from scipy.ndimage import gaussian_filter

    return to_u8(gaussian_filter(v.astype(np.float32), 2.0))


def aniso(n):
    # A smooth blob field sampled every 4 voxels in z (spacing 1, 1, 4): slices far apart.
    z, y, x = np.meshgrid(
        *[(np.arange(k, dtype=np.float32) + 0.5) / k * 2 - 1 for k in (n // 4, n, n)], indexing="ij"
    )
    f = np.exp(-3 * (x * x + y * y + z * z)) * (0.6 + 0.4 * np.sin(6 * x) * np.cos(5 * y))
    f[f < 0.25] = 0
    return to_u8(f)


def sparse(n, path):
    # A few small dense balls in an empty 1024^3 grid, written slice by slice.
    rng = np.random.default_rng(3)
    balls = [(rng.uniform(0.1, 0.9, 3) * n, rng.uniform(0.01, 0.04) * n) for _ in range(24)]
    with open(path, "wb") as f:
        f.write(nrrd_header(n, n, n))
        yy, xx = np.mgrid[0:n, 0:n].astype(np.float32) + 0.5
        for k in range(n):
            sl = np.zeros((n, n), np.uint8)
            for (cx, cy, cz), r in balls:
                dz = k + 0.5 - cz
                if abs(dz) < r:
                    d = np.sqrt((xx - cx) ** 2 + (yy - cy) ** 2 + dz * dz) / r
                    sl = np.maximum(sl, np.where(d < 1, np.round(255 * (1 - 0.5 * d)), 0).astype(np.uint8))
            f.write(sl.tobytes())


def procedural(n, path, vs, spacing=1, origin=0):
    """voxsplat's procedural field of side n, its header rewritten to place it in patient space
    (voxels `spacing` apart, the first voxel's centre at `origin` on each axis)."""
    tmp = path[: -len(".nrrd")] + "-part.nrrd"
    subprocess.run([vs, "make-volume", "--procedural", str(n), "--out", tmp], check=True, stdout=subprocess.DEVNULL)
    with open(tmp, "rb") as f, open(path, "wb") as g:
        head = f.read(4096)
        f.seek(head.index(b"\n\n") + 2)
        g.write(nrrd_header(n, n, n, (spacing,) * 3, origin))
        while chunk := f.read(1 << 26):
            g.write(chunk)
    os.remove(tmp)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dir")
    p.add_argument("--small", action="store_true", help="the CI subset: crops and small sides")
    p.add_argument("--only", help="comma-separated names to make")
    p.add_argument("--vs", default=os.path.join(os.path.dirname(__file__), "..", "target", "release", "voxsplat"),
                   help="the voxsplat that makes the procedural field")
    a = p.parse_args()
    os.makedirs(a.dir, exist_ok=True)
    only = set(a.only.split(",")) if a.only else None
    out = []

    def emit(name, tf, make, spacing=(1.0, 1.0, 1.0)):
        path = os.path.join(a.dir, name + ".nrrd")
        if only is None or name in only:
            if not os.path.exists(path):
                if callable(make):
                    vol = make()
                    if vol is not None:
                        write_nrrd(path, vol, spacing)
            out.append((name, path, tf))

    sources = {
        "bonsai": (lambda: load_nifti(os.path.join(DATA, "bonsai", "bonsai.nii.gz")), "bonsai"),
        "heptane": (lambda: load_nifti(os.path.join(DATA, "heptane", "heptane.nii.gz")), "ramp"),
        "stent": (lambda: to_u8(np.clip(load_stent(os.path.join(DATA, "stent", "stent.nrrd")), 0, 2000)), "ct"),
    }
    cache = {}

    def src(name):
        if name not in cache:
            v = sources[name][0]()
            if a.small:
                # A centred crop of 48 voxels a side (the stent: its middle 48 slices too).
                z, y, x = v.shape
                c = [s // 2 for s in v.shape]
                v = v[c[0] - 24 : c[0] + 24, c[1] - 24 : c[1] + 24, c[2] - 24 : c[2] + 24]
            cache[name] = v.astype(np.uint8)
        return cache[name]

    for name, (_, tf) in sources.items():
        emit(f"{name}-nn2", tf, lambda n=name: nn2(src(n)))
        emit(f"{name}-lin2", tf, lambda n=name: lin2(src(n)))
        emit(f"{name}-mask", "ramp", lambda n=name: mask(src(n)))
        emit(f"{name}-mask2", "ramp", lambda n=name: nn2(mask(src(n))))
    side = 48 if a.small else 256
    emit("labels", "ramp", lambda: (labels(side // 2 if not a.small else side) * 60).astype(np.uint8))
    emit("shell", "ramp", lambda: shell(side // 2 if not a.small else side))
    emit("noise", "ramp", lambda: noise(side if not a.small else 32))
    emit("noise-smooth", "ramp", lambda: smooth(noise(side if not a.small else 32)))
    emit("aniso", "ramp", lambda: aniso(side // 2 if not a.small else side), spacing=(1.0, 1.0, 4.0))
    if not a.small:
        path = os.path.join(a.dir, "sparse1024.nrrd")
        if (only is None or "sparse1024" in only) and not os.path.exists(path):
            sparse(1024, path)
        if only is None or "sparse1024" in only:
            out.append(("sparse1024", path, "ramp"))
        path = os.path.join(a.dir, "field1024.nrrd")
        if only is None or "field1024" in only:
            if not os.path.exists(path):
                procedural(1024, path, a.vs)
            out.append(("field1024", path, "ramp"))
    for name, path, tf in out:
        print(f"{name}|{path}|{tf}")


if __name__ == "__main__":
    sys.exit(main())
