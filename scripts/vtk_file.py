"""VTK's ray casters on a volume file, beside voxsplat: the same file, transfer-function preset and
view as `voxsplat render --volume FILE --tf TF`, 512x512 by default. Prints the median frame time.
The view is voxsplat's framing camera (src/camera.rs) unless --camera gives the line `voxsplat render`
prints ("camera (grid frame): eye X,Y,Z target X,Y,Z up X,Y,Z fov F"): voxsplat's grid frame is
centred on the grid, VTK's image starts at voxel (0, 0, 0), and both run the file's axes as stored
(files whose affine is left-handed, which voxsplat stores x-reversed, are not taken).
--mapper fixed: the fixed-point CPU ray caster (issue 23); gpu: vtkGPUVolumeRayCastMapper (llvmpipe
through EGL here). --shade: VTK's gradient shading, as voxsplat's --shade. --sample-distance D:
the ray step in world units (VTK's default 1, a voxel at spacing 1; the PNG has no alpha).
Usage: python vtk_file.py --file F.nrrd|F.nii.gz --tf bonsai|ramp|ct|mri --frames 5 --out out.png
"""
import argparse, math, statistics, sys, time
import vtk
from vtk_common import offscreen, set_camera, write_png

ap = argparse.ArgumentParser()
ap.add_argument("--file", required=True)
ap.add_argument("--tf", default="bonsai")
ap.add_argument("--size", type=int, default=512)
ap.add_argument("--frames", type=int, default=5)
ap.add_argument("--warmup", type=int, default=1)
ap.add_argument("--out", default="vtk.png")
ap.add_argument("--mapper", default="fixed", choices=["fixed", "gpu"])
ap.add_argument("--camera", default=None, help="voxsplat's 'camera (grid frame)' line")
ap.add_argument("--shade", action="store_true")
ap.add_argument("--sample-distance", type=float, default=None, help="ray step in world units (VTK's default: 1)")
a = ap.parse_args()

# voxsplat's presets (src/classify.rs): density normalised over the data's range, RGB, opacity of
# one voxel length of material.
PRESETS = {
    "ramp": [(0.1, (0, 0, 0, 0)), (1.0, (1, 1, 1, 0.6))],
    "ct": [(0.0, (0, 0, 0, 0)), (0.12, (0, 0, 0, 0)), (0.2, (0.8, 0.3, 0.2, 0.03)), (0.45, (1, 0.9, 0.8, 0.6)),
           (1.0, (1, 1, 1, 0.95))],
    "bonsai": [(0.0, (0, 0, 0, 0)), (0.22, (0, 0, 0, 0)), (0.25, (0.22, 0.6, 0.12, 0.35)), (0.31, (0.25, 0.6, 0.15, 0.35)),
               (0.36, (0.55, 0.33, 0.14, 0.9)), (1.0, (0.65, 0.42, 0.25, 0.95))],
    "mri": [(0.0, (0, 0, 0, 0)), (0.3, (0, 0, 0, 0)), (0.4, (0.85, 0.62, 0.5, 0.015)), (0.5, (0.85, 0.62, 0.5, 0.015)),
            (0.6, (0.8, 0.5, 0.5, 0.12)), (0.85, (0.95, 0.9, 0.82, 0.5)), (1.0, (1, 0.97, 0.9, 0.8))],
}

t0 = time.perf_counter()
if a.file.endswith(".nrrd") or a.file.endswith(".nhdr"):
    reader = vtk.vtkNrrdReader()
else:
    reader = vtk.vtkNIFTIImageReader()
reader.SetFileName(a.file)
reader.Update()
img = reader.GetOutput()
load_s = time.perf_counter() - t0
lo, hi = img.GetScalarRange()
dims = img.GetDimensions()
sp = img.GetSpacing()

ctf = vtk.vtkColorTransferFunction()
otf = vtk.vtkPiecewiseFunction()
for d, (r, g, b, op) in PRESETS[a.tf]:
    v = lo + d * (hi - lo)
    ctf.AddRGBPoint(v, r, g, b)
    otf.AddPoint(v, op)
prop = vtk.vtkVolumeProperty()
prop.SetColor(ctf)
prop.SetScalarOpacity(otf)
prop.SetScalarOpacityUnitDistance(max(sp))
prop.SetInterpolationTypeToLinear()
if a.shade:
    prop.ShadeOn()
    prop.SetAmbient(0.3)
    prop.SetDiffuse(0.7)
    prop.SetSpecular(0.25)
    prop.SetSpecularPower(20.0)
else:
    prop.ShadeOff()

if a.mapper == "gpu":
    mapper = vtk.vtkGPUVolumeRayCastMapper()
else:
    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
mapper.SetAutoAdjustSampleDistances(0)
if a.sample_distance:
    mapper.SetSampleDistance(a.sample_distance)
mapper.SetInputData(img)
mapper.SetBlendModeToComposite()
volume = vtk.vtkVolume()
volume.SetMapper(mapper)
volume.SetProperty(prop)
ren, rw = offscreen(a.size)
ren.AddVolume(volume)

cam = ren.GetActiveCamera()
if a.camera:
    # voxsplat's grid frame is centred on the grid; VTK's image starts at its origin.
    org = img.GetOrigin()
    set_camera(cam, a.camera, [org[i] + (dims[i] - 1) * sp[i] / 2 for i in range(3)])
else:
    # voxsplat's Camera::framing.
    ext = [(dims[i] - 1) * sp[i] for i in range(3)]
    c = [e / 2 for e in ext]
    radius = 0.5 * max(math.sqrt(sum(e * e for e in ext)), 1.0)
    dist = radius / math.sin(math.radians(17.5)) * 1.05
    d = (0.55, 0.45, 1.0)
    n = math.sqrt(sum(x * x for x in d))
    cam.SetFocalPoint(*c)
    cam.SetPosition(*[c[i] + d[i] / n * dist for i in range(3)])
    cam.SetViewUp(0, 1, 0)
    cam.SetViewAngle(35.0)
ren.ResetCameraClippingRange()

for i in range(a.warmup):
    rw.Render()
times = []
for i in range(a.frames):
    cam.Azimuth(0.5 if i % 2 == 0 else -0.5)
    ren.ResetCameraClippingRange()
    t = time.perf_counter()
    rw.Render()
    times.append(time.perf_counter() - t)
if a.frames % 2 == 1:
    # Back to the view asked for before the picture is taken.
    cam.Azimuth(-0.5)
    ren.ResetCameraClippingRange()
    rw.Render()
write_png(rw, a.out)
print(f"file={a.file} dims={dims} load={load_s:.3f}s median={statistics.median(times):.3f}s")
