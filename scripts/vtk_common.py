"""What scripts/vtk_file.py and scripts/vtk_terrain.py share: an off-screen window on black,
voxsplat's camera line on a VTK camera, and the window written as PNG."""
import vtk


def offscreen(size):
    """A renderer on black in an off-screen `size` x `size` window: (renderer, window)."""
    ren = vtk.vtkRenderer()
    ren.SetBackground(0, 0, 0)
    rw = vtk.vtkRenderWindow()
    rw.SetOffScreenRendering(1)
    rw.AddRenderer(ren)
    rw.SetSize(size, size)
    return ren, rw


def set_camera(cam, line, shift=(0.0, 0.0, 0.0)):
    """Point `cam` as the line `voxsplat render` prints ("camera (grid frame): eye X,Y,Z target
    X,Y,Z up X,Y,Z fov F"), its points moved by `shift` (voxsplat's grid frame -> VTK's)."""
    f = line.split()
    vec = lambda k: [float(x) for x in f[f.index(k) + 1].split(",")]
    eye, target = vec("eye"), vec("target")
    cam.SetPosition(*[eye[i] + shift[i] for i in range(3)])
    cam.SetFocalPoint(*[target[i] + shift[i] for i in range(3)])
    cam.SetViewUp(*vec("up"))
    cam.SetViewAngle(float(f[f.index("fov") + 1]))


def write_png(window, path):
    """The window's current picture as a PNG."""
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(window)
    w2i.Update()
    wr = vtk.vtkPNGWriter()
    wr.SetFileName(path)
    wr.SetInputConnection(w2i.GetOutputPort())
    wr.Write()
