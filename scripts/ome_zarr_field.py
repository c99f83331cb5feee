"""Writes the procedural field of `voxsplat make-volume --procedural N` (a gyroid's thin shell inside
a ball) as an OME-Zarr image (OME-NGFF 0.5, Zarr v3, 64³ chunks, zstd) with its pyramid, for issue
47's target: a volume larger than host memory. Never committed (2048³ takes about a gigabyte).

    python3 scripts/ome_zarr_field.py N OUT.zarr [LEVELS]     # e.g. 2048 target/large/field2048.zarr

Written a slab of 64 slices at a time, every level as it goes (each a 2x2x2 mean of the one
below), so no level is ever held whole; the image's metadata is ome-zarr's (its FormatV05).
"""
import json
import sys
import time

import numpy as np
import zarr


def slab(n, z0, count):
    """Slices z0..z0+count of the field, u8 (voxsplat's formula, in float32), 8 slices at a time
    (arrays that stay in cache)."""
    c = n * 0.5
    f = np.float32(6.0 * np.pi / n)
    x = np.arange(n, dtype=np.float32) + np.float32(0.5 - c)
    sx, cx = np.sin(f * x), np.cos(f * x)
    # sin(f x) cos(f y) over the plane, and x² + y², computed once.
    plane_g = sx[None, :] * cx[:, None]
    plane_r = x[None, :] ** 2 + x[:, None] ** 2
    out = np.empty((count, n, n), np.uint8)
    for k in range(count):
        z = np.float32(z0 + k + 0.5 - c)
        sz, cz = np.sin(f * z), np.cos(f * z)
        # sin(f y) cos(f z) + sin(f z) cos(f x), then the plane's term.
        g = plane_g + (sx[:, None] * cz + sz * cx[None, :])
        r = np.sqrt(plane_r + z * z) / np.float32(c)
        shell = np.maximum(np.float32(1.0) - np.abs(g) / np.float32(0.45), np.float32(0.0))
        v = np.where(r < 0.95, shell * (np.float32(1.0) - np.float32(0.5) * r), np.float32(0.0))
        out[k] = np.round(v * np.float32(255.0))
    return out


def halve(a):
    """The 2x2x2 mean (a's sides even), rounded half up."""
    s = a.astype(np.uint16)
    s = s[0::2] + s[1::2]
    s = s[:, 0::2] + s[:, 1::2]
    s = s[:, :, 0::2] + s[:, :, 1::2]
    return ((s + 4) // 8).astype(np.uint8)


def main(n, out, levels=4):
    chunk = 64
    assert n % chunk == 0 and chunk >= 1 << (levels - 1), "N a multiple of 64, at most 7 levels"
    root = zarr.open_group(out, mode="w", zarr_format=3)
    arrays = []
    for l in range(levels):
        side = n >> l
        arrays.append(root.create_array(f"s{l}", shape=(side,) * 3, chunks=(min(chunk, side),) * 3, dtype="uint8",
                                        compressors=zarr.codecs.ZstdCodec(level=1), fill_value=0))
    datasets = [{"path": f"s{l}", "coordinateTransformations": [
        {"type": "scale", "scale": [float(1 << l)] * 3},
        {"type": "translation", "translation": [0.5 * ((1 << l) - 1)] * 3}]} for l in range(levels)]
    axes = [{"name": a, "type": "space", "unit": "micrometer"} for a in "zyx"]
    root.attrs["ome"] = {"version": "0.5", "multiscales": [{"name": f"field{n}", "axes": axes, "datasets": datasets}]}
    # Each level's pending slices, written once a row of chunks is whole.
    pending = [[] for _ in range(levels)]
    written = [0] * levels
    t = time.time()
    for z0 in range(0, n, chunk):
        a = slab(n, z0, min(chunk, n - z0))
        for l in range(levels):
            if l > 0:
                a = halve(a)
            pending[l].append(a)
            rows = np.concatenate(pending[l]) if len(pending[l]) > 1 else pending[l][0]
            side = n >> l
            whole = rows.shape[0] - rows.shape[0] % min(chunk, side)
            if whole or written[l] + rows.shape[0] == side:
                upto = rows.shape[0] if written[l] + rows.shape[0] == side else whole
                arrays[l][written[l]:written[l] + upto] = rows[:upto]
                written[l] += upto
                pending[l] = [rows[upto:]] if upto < rows.shape[0] else []
        print(f"\rslices {z0 + chunk}/{n} ({time.time() - t:.0f} s)", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    assert written == [n >> l for l in range(levels)], written
    print(json.dumps({"levels": [n >> l for l in range(levels)], "seconds": round(time.time() - t, 1)}))


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2], *(int(a) for a in sys.argv[3:]))
