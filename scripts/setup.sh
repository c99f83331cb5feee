#!/usr/bin/env bash
# Installs what voxsplat needs on Debian 12 beyond Rust: lavapipe (Mesa's CPU Vulkan driver), the
# Vulkan loader, the Khronos validation layers, and the static shaderc/glslang/SPIRV-Tools libraries
# that build.rs links through .cargo/config.toml; Xvfb and the X libraries winit opens, for the
# windowed viewer's headless test (examples/viewer.rs); dcm2niix and pydicom, for the DICOM tests.
# Idempotent: does nothing when all are present.
# With --mpi, also OpenMPI and libclang: what `--features mpi` (sort-last rendering, rsmpi) builds
# and runs with (docs/SCALE.md).
set -euo pipefail
mpi=()
[ "${1:-}" = "--mpi" ] && mpi=(openmpi-bin libopenmpi-dev libclang-dev)
pkgs=(mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-validationlayers libshaderc-dev glslang-dev spirv-tools
  xvfb xauth libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0 dcm2niix "${mpi[@]}")
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
# The DICOM tests read pydicom's bundled test series (cli/tests/dicom.rs).
python3 -c "import pydicom" 2>/dev/null || python3 -m pip install --quiet pydicom
# pyjpegls (CharLS) writes and decodes the JPEG-LS images the DICOM tests read against.
python3 -c "import jpeg_ls" 2>/dev/null || python3 -m pip install --quiet "pyjpegls==1.5.1"
# nibabel writes the NIfTI files cli/tests/series.rs and sample_types.rs read (not every Python
# image has it).
python3 -c "import nibabel" 2>/dev/null || python3 -m pip install --quiet "nibabel==5.3.2"
# pynrrd writes the 4-D NRRD series cli/tests/series.rs reads.
python3 -c "import nrrd" 2>/dev/null || python3 -m pip install --quiet "pynrrd==1.1.3"
# The OME-Zarr tests write their images with the ome-zarr package (cli/tests/zarr.rs); 0.18 writes
# OME-NGFF 0.4 and 0.5 through zarr-python 3.
python3 -c "import ome_zarr, zarr; assert zarr.__version__ >= '3'" 2>/dev/null || python3 -m pip install --quiet "ome-zarr==0.18.0"
# scripts/sparse-truth.py (the sparse 1024^3 member's reference, and its test in cli/tests/family.rs)
# reads and writes EXR frames with OpenEXR and finds the volume's clumps with scipy.
python3 -c "import OpenEXR, scipy" 2>/dev/null || python3 -m pip install --quiet "OpenEXR==3.5.3" scipy
command -v cargo >/dev/null || { echo "setup: cargo not found; install Rust first (https://rustup.rs)" >&2; exit 1; }
