"""VTK beside `voxsplat render --terrain DEM --color IMAGE` (the gallery, issue 29): the height grid
as a textured surface (vtkPolyData, one point per cell at its height, coloured by the same image
pixel voxsplat's column takes), in voxsplat's terrain frame (src/terrain.rs: x = column, y = rows
northward, z = height level (h - min) / cell * vscale, cell = relief / (max(width, rows) / 6) by
default; centred on the grid) seen by the camera line `voxsplat render` prints. Prints the median
frame time. Usage: python vtk_terrain.py --dem D.tif --color C.png --camera LINE --out out.png
"""
import argparse, statistics, time
import numpy as np
import vtk
from vtk_common import offscreen, set_camera, write_png
from PIL import Image
from vtk.util import numpy_support

ap = argparse.ArgumentParser()
ap.add_argument("--dem", required=True)
ap.add_argument("--color", required=True)
ap.add_argument("--camera", required=True)
ap.add_argument("--vscale", type=float, default=1.0)
ap.add_argument("--size", type=int, default=512)
ap.add_argument("--frames", type=int, default=5)
ap.add_argument("--out", default="vtk-terrain.png")
a = ap.parse_args()

h = np.asarray(Image.open(a.dem), dtype=np.float64)
rows, w = h.shape
hmin, hmax = h.min(), h.max()
cell = max((hmax - hmin) / (max(w, rows) / 6.0), 1e-6)
level = (h - hmin) / cell * a.vscale
nz = int(np.round(level.max())) + 1
img = np.asarray(Image.open(a.color).convert("RGB"))
ih, iw = img.shape[:2]
r, x = np.mgrid[0:rows, 0:w]
px = np.minimum(((x + 0.5) / w * iw).astype(int), iw - 1)
py = np.minimum(((r + 0.5) / rows * ih).astype(int), ih - 1)
colors = img[py, px].reshape(-1, 3).astype(np.uint8)
# voxsplat's grid frame: column x, j = rows - 1 - r, level k, centred.
pts = np.stack([x - (w - 1) / 2, (rows - 1 - r) - (rows - 1) / 2, np.round(level) - (nz - 1) / 2], axis=-1).reshape(-1, 3)
points = vtk.vtkPoints()
points.SetData(numpy_support.numpy_to_vtk(pts.astype(np.float64), deep=True))
grid = vtk.vtkStructuredGrid()
grid.SetDimensions(w, rows, 1)
grid.SetPoints(points)
scal = numpy_support.numpy_to_vtk(colors, deep=True, array_type=vtk.VTK_UNSIGNED_CHAR)
scal.SetName("rgb")
grid.GetPointData().SetScalars(scal)
geom = vtk.vtkStructuredGridGeometryFilter()
geom.SetInputData(grid)
mapper = vtk.vtkPolyDataMapper()
mapper.SetInputConnection(geom.GetOutputPort())
mapper.SetColorModeToDirectScalars()
actor = vtk.vtkActor()
actor.SetMapper(mapper)
actor.GetProperty().LightingOff()
ren, rw = offscreen(a.size)
ren.AddActor(actor)
cam = ren.GetActiveCamera()
set_camera(cam, a.camera)
ren.ResetCameraClippingRange()
rw.Render()
times = []
for i in range(a.frames):
    t = time.perf_counter()
    rw.Render()
    times.append(time.perf_counter() - t)
write_png(rw, a.out)
print(f"dem={a.dem} cells={w}x{rows} median={statistics.median(times):.4f}s")
