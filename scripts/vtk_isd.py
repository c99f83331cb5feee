"""Run the peers' VTK script (read-only, ../shared/peers/vtk/vtk_volume.py) with the fixed-point
caster casting one ray every D pixels (vtkFixedPointVolumeRayCastMapper::SetImageSampleDistance,
its rays interpolated to the full image): VTK's own speed-accuracy knob, the counterpart of
voxsplat's --render-scale 1/D. Everything else is the peer script unchanged.
usage: VTK_IMAGE_SAMPLE_DISTANCE=D python vtk_isd.py PEER_SCRIPT [its arguments]"""
import os
import runpy
import sys

import vtk

distance = float(os.environ.get("VTK_IMAGE_SAMPLE_DISTANCE", "1"))
if not 0.1 <= distance <= 16.0:
    sys.exit(f"VTK_IMAGE_SAMPLE_DISTANCE={distance} is outside [0.1, 16]")
if len(sys.argv) < 2:
    sys.exit(__doc__)

_Fixed = vtk.vtkFixedPointVolumeRayCastMapper


def _fixed_with_distance():
    m = _Fixed()
    # The peer script turns automatic adjustment off, so this distance is used as set.
    m.SetImageSampleDistance(distance)
    return m


vtk.vtkFixedPointVolumeRayCastMapper = _fixed_with_distance
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
