#!/usr/bin/env python3
"""The supersampled ray-cast reference of a volume too large for the ray casters, by crops.

    python3 scripts/sparse-truth.py VOLUME.nrrd OUT.exr --tf TF [--vs BIN] -- RENDER_FLAGS...
    python3 scripts/sparse-truth.py VOLUME.nrrd --camera --tf TF -- --size WxH --view NAME

The second form prints the explicit camera flags of a view of the whole volume (from `render
--plan`), for the frames to be scored against the reference to be drawn with the same camera.

The ray casters hold at most 2^28 voxels (a dense field of 16 bytes a voxel), so a sparse 1024^3
field (scripts/family.py's `sparse1024`) has no reference of its own. Where its non-empty voxels lie
in separate clumps, the reference is exact without the whole grid: each clump is cut out with a
margin of empty voxels (wider than the trilinear support, so every sample inside reads what the
whole grid holds there), placed where it lies in patient space (its NRRD space origin), ray cast
on its own with the same camera, and the clumps' premultiplied frames are composited front to back
in the order of their bounding spheres' power distances from the eye (a visibility order for
disjoint spheres). Crops whose boxes meet are merged into one, so no voxel is drawn twice.

A clump of more than --tile voxels (default 2^27; the procedural 1024^3 field is one clump) is cut
into tiles, each cut out with two voxels more past its inner faces (the trilinear support) and cast
with --clip planes at those faces, so its rays sample only its own cells. The tiles are composited
in a visibility order of the grid of tiles (per axis, tiles nearer the eye's slab first, axis after
axis: a ray from the eye moves away from it on every axis). On the 256^3 procedural field cut into
8 and in 64 tiles the composite lies 84-88 dB from the whole cast (128^2, three views). The ray
caster cuts a ray's last sample to what is left of it before the plane (it counted up to a step
past it, twice over in two tiles: 67-76 dB before).

RENDER_FLAGS must fix the camera explicitly (--eye, --target, --up, --fov or --ortho, and --size;
not a --view, which frames each crop on its own voxels) and carry the ray caster's flags
(--raycast 0.25 --raycast-stop 1e-4 --cpu --supersample K). TF is a preset or a TOML file; a preset
is written out with the whole volume's value range (a crop's range is its own). Needs numpy, scipy
and OpenEXR (pip install OpenEXR). Works only on raw uint8 NRRDs with axis-aligned unit directions,
in LPS or RAS patient space (what scripts/family.py writes); anything else is refused.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import numpy as np
import OpenEXR
import scipy.ndimage

MARGIN = 3  # empty voxels kept around a clump: the trilinear support and the occupancy's one voxel
TILE = 1 << 27  # voxels a crop may hold (the ray caster's dense field takes 16 bytes each, up to 2^28)
BRICK = 4  # clumps are found on bricks of this side (26-connected), then cut to their voxels

PRESETS = {"ramp": "points = [[0.1, [0, 0, 0, 0]], [1.0, [1, 1, 1, 0.6]]]"}  # src/classify.rs


def header(path):
    with open(path, "rb") as f:
        raw = f.read(1 << 16)
    end = raw.find(b"\n\n")
    if not raw.startswith(b"NRRD") or end < 0:
        sys.exit(f"{path}: not a NRRD with an attached header")
    head = raw[:end].decode()
    fields = dict(
        (k.strip(), v.strip()) for k, v in (line.split(":", 1) for line in head.splitlines()[1:] if ":" in line)
    )
    if fields.get("type") not in ("uint8", "uchar", "unsigned char") or fields.get("encoding") != "raw":
        sys.exit(f"{path}: only raw uint8 NRRDs are supported")
    dims = [int(v) for v in fields["sizes"].split()]
    dirs = re.findall(r"\(([^)]*)\)", fields.get("space directions", ""))
    vec = [[float(c) for c in d.split(",")] for d in dirs]
    if len(dims) != 3 or len(vec) != 3 or any(vec[a][b] != (1.0 if a == b else 0.0) for a in range(3) for b in range(3)):
        sys.exit(f"{path}: only unit, axis-aligned space directions are supported")
    space = fields.get("space", "")
    if space not in ("left-posterior-superior", "right-anterior-superior"):
        # The crops are placed by their space origin, and --eye is in patient coordinates only for
        # a file placed in patient space.
        sys.exit(f"{path}: only NRRDs in LPS or RAS patient space (a space field) are supported; for a file "
                 "without one, draw and score a copy whose header adds `space: left-posterior-superior`, "
                 "`space origin: (0,0,0)` and unit `space directions`")
    origin = [float(c) for c in re.findall(r"[-0-9.e+]+", fields.get("space origin", "(0,0,0)"))]
    if len(origin) != 3:
        sys.exit(f"{path}: a space origin of three numbers is needed")
    return dims, space, origin, end + 2


def clumps(vol):
    """Voxel boxes [lo, hi) (x, y, z) of the non-empty clumps, merged until no two boxes meet."""
    nz, ny, nx = vol.shape
    b = BRICK
    occ = np.zeros(((nz + b - 1) // b, (ny + b - 1) // b, (nx + b - 1) // b), bool)
    for z0 in range(0, nz, b):
        slab = np.asarray(vol[z0 : z0 + b])
        pad = np.zeros((b, occ.shape[1] * b, occ.shape[2] * b), np.uint8)
        pad[: slab.shape[0], :ny, :nx] = slab
        occ[z0 // b] = pad.reshape(b, occ.shape[1], b, occ.shape[2], b).max(axis=(0, 2, 4)) > 0
    labels, count = scipy.ndimage.label(occ, structure=np.ones((3, 3, 3)))
    boxes = []
    for sl in scipy.ndimage.find_objects(labels):
        # The clump's bricks, cut to its voxels, then widened by the margin (kept inside the grid).
        sub = np.asarray(vol[sl[0].start * b : sl[0].stop * b, sl[1].start * b : sl[1].stop * b, sl[2].start * b : sl[2].stop * b])
        # Its voxels' bounds from each axis's projection (not np.nonzero: a dense clump holds 10^8).
        lo, hi = [], []
        for ax, keep in ((2, (0, 1)), (1, (0, 2)), (0, (1, 2))):
            hit = np.flatnonzero(sub.any(axis=keep))
            lo.append(int(hit[0]) + sl[ax].start * b)
            hi.append(int(hit[-1]) + sl[ax].start * b + 1)
        boxes.append([[max(0, v - MARGIN) for v in lo], [min(n, v + MARGIN) for v, n in zip(hi, (nx, ny, nz))]])
    merged = True
    while merged:
        merged = False
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                a, c = boxes[i], boxes[j]
                if all(a[0][k] < c[1][k] and c[0][k] < a[1][k] for k in range(3)):
                    boxes[i] = [[min(a[0][k], c[0][k]) for k in range(3)], [max(a[1][k], c[1][k]) for k in range(3)]]
                    del boxes[j]
                    merged = True
                    break
            if merged:
                break
    return boxes


def tiles(box, eye, most):
    """A clump's box cut into tiles of at most `most` voxels (halving its longest side), each as its
    own cells [lo, hi) and a sort key that orders them front to back from `eye` (index space): per
    axis, how many tiles lie between a tile and the eye's slab, compared axis after axis. A ray
    from the eye moves away from it on every axis, so it meets tiles in that order (PBTF, chapter 2)."""
    lo, hi = list(box[0]), list(box[1])
    cuts = [1, 1, 1]
    while np.prod([(hi[k] - lo[k] + cuts[k] - 1) // cuts[k] + 4 for k in range(3)]) > most:
        k = max(range(3), key=lambda a: (hi[a] - lo[a]) / cuts[a])
        cuts[k] *= 2
    edges = [[lo[k] + (hi[k] - lo[k]) * i // cuts[k] for i in range(cuts[k] + 1)] for k in range(3)]
    # The tile whose cells (index i covers [i - 0.5, i + 0.5)) hold the eye's coordinate, or the end one nearest it.
    at = [min(max(int(np.searchsorted(edges[k], eye[k] + 0.5, side="right")) - 1, 0), cuts[k] - 1) for k in range(3)]
    out = []
    for i in range(cuts[0]):
        for j in range(cuts[1]):
            for m in range(cuts[2]):
                idx = (i, j, m)
                own = [[edges[k][idx[k]] for k in range(3)], [edges[k][idx[k] + 1] for k in range(3)]]
                out.append((own, tuple(abs(idx[k] - at[k]) for k in range(3))))
    return out


def write_crop(path, vol, box, own, space, origin):
    """Writes voxels `box` of `vol` as a NRRD placed where they lie; returns the value sum of its
    part `own` (the cells the crop stands for: the voxels past them are only trilinear support)."""
    (x0, y0, z0), (x1, y1, z1) = box
    crop = np.ascontiguousarray(vol[z0:z1, y0:y1, x0:x1])
    o = [origin[0] + x0, origin[1] + y0, origin[2] + z0]
    with open(path, "wb") as f:
        f.write(
            (
                f"NRRD0004\ntype: uint8\ndimension: 3\nsizes: {x1 - x0} {y1 - y0} {z1 - z0}\n"
                f"space: {space}\nspace origin: ({o[0]},{o[1]},{o[2]})\n"
                "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\n\n"
            ).encode()
        )
        f.write(crop.tobytes())
    (a0, b0, c0), (a1, b1, c1) = own
    return int(crop[c0 - z0 : c1 - z0, b0 - y0 : b1 - y0, a0 - x0 : a1 - x0].sum(dtype=np.int64))


def read_exr(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGBA" in ch:
            return np.asarray(ch["RGBA"].pixels, np.float64)
        return np.stack([np.asarray(ch[c].pixels, np.float64) for c in "RGBA"], axis=-1)


def write_exr(path, img):
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    channels = {c: np.ascontiguousarray(img[..., i], np.float32) for i, c in enumerate("RGBA")}
    with OpenEXR.File(header, channels) as f:
        f.write(path)


def flag(flags, name):
    """A flag's comma-separated numbers, given as `NAME V` or `NAME=V` (negative values need =)."""
    for i, f in enumerate(flags):
        if f == name and i + 1 < len(flags):
            return [float(v) for v in flags[i + 1].split(",")]
        if f.startswith(name + "="):
            return [float(v) for v in f[len(name) + 1 :].split(",")]
    return None


def camera(a, flags, dims, sign, origin):
    """The view's camera, as `render --plan` prints it in the grid's centred frame, as flags in
    patient coordinates (RAS: the file's LPS axes with x and y turned)."""
    plan = subprocess.run([a.vs, "render", "--volume", a.volume, "--tf", a.tf, *flags, "--plan"], check=True,
                          capture_output=True, text=True)
    plan = plan.stdout + plan.stderr
    m = re.search(r"camera \(grid frame\): eye (\S+) target (\S+) up (\S+) fov (\S+)", plan)
    if not m:
        sys.exit(f"no perspective camera in the plan:\n{plan}")
    centre = [origin[k] + (dims[k] - 1) / 2 for k in range(3)]
    point = lambda v: ",".join(f"{sign[k] * (float(c) + centre[k]):.4f}" for k, c in enumerate(v.split(",")))
    up = ",".join(f"{sign[k] * float(c):.4f}" for k, c in enumerate(m.group(3).split(",")))
    size = [f for i, f in enumerate(flags) if f.startswith("--size") or (i > 0 and flags[i - 1] == "--size")]
    return [f"--eye={point(m.group(1))}", f"--target={point(m.group(2))}", f"--up={up}", "--fov", m.group(4), *size]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("volume")
    p.add_argument("out", nargs="?")
    p.add_argument("--camera", action="store_true", help="print the explicit camera flags of the view and stop")
    p.add_argument("--tf", required=True)
    p.add_argument("--vs", default=os.path.join(os.path.dirname(__file__), "..", "target", "release", "voxsplat-lab"))
    p.add_argument("--work", help="where the crops go (default: a temporary folder)")
    p.add_argument("--tile", type=int, default=TILE, help=f"most voxels a crop holds; larger clumps are cut into tiles (default {TILE})")
    argv = sys.argv[1:]
    if "--" not in argv:
        p.error("give the render flags after --")
    cut = argv.index("--")
    a = p.parse_args(argv[:cut])
    flags = argv[cut + 1 :]
    dims, space, origin, offset = header(a.volume)
    sign = [-1.0, -1.0, 1.0] if space.startswith("left-posterior") else [1.0, 1.0, 1.0]
    if a.camera:
        print(" ".join(camera(a, flags, dims, sign, origin)))
        return 0
    if a.out is None:
        p.error("give OUT.exr, or --camera")
    if any(f == "--view" or f.startswith("--view=") for f in flags) or flag(flags, "--eye") is None or flag(flags, "--target") is None:
        sys.exit("give the camera explicitly (--eye, --target, --up, --fov): a --view frames each crop on its own")
    vol = np.memmap(a.volume, np.uint8, "r", offset=offset, shape=(dims[2], dims[1], dims[0]))
    boxes = clumps(vol)
    work = a.work or tempfile.mkdtemp(prefix="sparse-truth-")
    os.makedirs(work, exist_ok=True)
    # One pass over the volume: its value range (a preset's, not each crop's) and its value sum.
    lo, hi, total = 255, 0, 0
    for z0 in range(0, dims[2], 64):
        s = np.asarray(vol[z0 : z0 + 64])
        lo, hi, total = min(lo, int(s.min())), max(hi, int(s.max())), total + int(s.sum(dtype=np.int64))
    tf = a.tf
    if tf in PRESETS:
        tf = os.path.join(work, "tf.toml")
        with open(tf, "w") as f:
            f.write(f"{PRESETS[a.tf]}\nrange = [{float(lo)}, {float(hi)}]\n")
    elif not os.path.exists(tf):
        sys.exit(f"--tf {tf}: a preset this script knows ({', '.join(PRESETS)}) or a TOML file")
    # The eye in the grid's index space: patient (RAS) coordinates back through the LPS/RAS frame.
    eye = flag(flags, "--eye")
    eye_ijk = np.array([eye[k] * sign[k] - origin[k] for k in range(3)])
    order, summed = [], 0
    for n, box in enumerate(boxes):
        lo, hi = np.array(box[0], float), np.array(box[1], float)
        c, r = (lo + hi - 1) / 2, np.linalg.norm(hi - lo) / 2
        crops = []
        for t, (own, key) in enumerate(tiles(box, eye_ijk, a.tile)):
            path = os.path.join(work, f"crop{n}-{t}.nrrd")
            # The tile's voxels and two more past each inner face (the trilinear support of the
            # samples up to that face), its rays clipped to its own half-open cells there.
            cut = [[max(box[0][k], own[0][k] - 2) for k in range(3)], [min(box[1][k], own[1][k] + 2) for k in range(3)]]
            summed += write_crop(path, vol, cut, own, space, origin)
            # --clip takes the crop's grid frame: index less the crop's first voxel and its centre.
            centre = [cut[0][k] + (cut[1][k] - cut[0][k] - 1) / 2 for k in range(3)]
            clips = []
            for k in range(3):
                unit = lambda v: ",".join(str(v if j == k else 0.0) for j in range(3))
                if own[0][k] > box[0][k]:  # keep index >= lo - 0.5
                    clips.append(f"--clip={unit(1.0)},{centre[k] - (own[0][k] - 0.5)}")
                if own[1][k] < box[1][k]:  # keep index <= hi - 0.5
                    clips.append(f"--clip={unit(-1.0)},{own[1][k] - 0.5 - centre[k]}")
            crops.append((key, path, clips))
        crops.sort()
        order.append((float(np.dot(c - eye_ijk, c - eye_ijk) - r * r), n, crops))
    # Every non-empty voxel lies in exactly one crop's own cells (the sums agree).
    if summed != total:
        sys.exit(f"the crops hold {summed} of the volume's value sum {total}: a clump was missed")
    order.sort()
    # K x K rays a pixel: each crop cast K times larger with one ray a pixel, composited ray by ray,
    # then K x K averaged (what --supersample K does inside one cast). Compositing the crops' pixel
    # means instead would be wrong where two clumps share a pixel: each covers a part of it.
    k = int(flag(flags, "--supersample")[0]) if flag(flags, "--supersample") else 1
    size = flag([f.replace("x", ",") for f in flags], "--size")
    if size is None:
        sys.exit("give --size WxH")
    w, h = int(size[0]), int(size[1])
    fine = list(flags)
    for name, value in (("--supersample", "1"), ("--size", f"{w * k}x{h * k}")):
        for i, f in enumerate(fine):
            if f == name:
                fine[i + 1] = value
            elif f.startswith(name + "="):
                fine[i] = f"{name}={value}"
    acc = None
    for _, n, crops in order:
        for _, path, clips in crops:
            exr = path[:-5] + ".exr"
            subprocess.run([a.vs, "render", "--volume", path, "--tf", tf, *fine, *clips, "--out", exr], check=True,
                           stdout=subprocess.DEVNULL)
            img = read_exr(exr)
            acc = img if acc is None else acc + (1.0 - acc[..., 3:4]) * img
    acc = acc.reshape(h, k, w, k, 4).mean(axis=(1, 3))
    write_exr(a.out, acc)
    print(f"{len(boxes)} crops composited into {a.out}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
