"""PSNR over the object between a voxsplat frame and a VTK frame, and the gallery's side-by-side
picture (scripts/gallery.sh). voxsplat writes premultiplied RGBA on a transparent background, VTK RGB
on black: both are compared on black, over the pixels either draws (a channel above 2/255).
Also the luminance contrast (std / mean) of the voxsplat frame over the pixels it draws.
Usage: python gallery.py VOXSPLAT.png VTK.png OUT.png [SIDE]   (prints "psnr=DB pixels=N contrast=C")
"""
import sys
import numpy as np
from PIL import Image

vs_path, vtk_path, out = sys.argv[1:4]
side = int(sys.argv[4]) if len(sys.argv) > 4 else 256
vs = np.asarray(Image.open(vs_path).convert("RGBA"), dtype=np.float64) / 255.0
# PNG alpha is straight: composite over black.
vs_rgb = vs[..., :3] * vs[..., 3:4]
vtk = np.asarray(Image.open(vtk_path).convert("RGB"), dtype=np.float64) / 255.0
if vs_rgb.shape != vtk.shape:
    sys.exit(f"sizes differ: {vs_rgb.shape} {vtk.shape}")
mask = (vs_rgb.max(axis=2) > 2 / 255) | (vtk.max(axis=2) > 2 / 255)
n = int(mask.sum())
mse = float(((vs_rgb - vtk) ** 2)[mask].mean()) if n else 0.0
psnr = 10 * np.log10(1.0 / mse) if mse > 0 else float("inf")
pair = np.concatenate([vs_rgb, vtk], axis=1)
img = Image.fromarray((pair.clip(0, 1) * 255 + 0.5).astype(np.uint8))
img.resize((2 * side, side), Image.LANCZOS).save(out, optimize=True)
lum = vs_rgb @ np.array([0.2126, 0.7152, 0.0722])
drawn = vs[..., 3] > 0.05
contrast = float(lum[drawn].std() / lum[drawn].mean()) if drawn.any() else 0.0
print(f"psnr={psnr:.2f} pixels={n} contrast={contrast:.3f}")
