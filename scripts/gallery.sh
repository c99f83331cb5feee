#!/usr/bin/env bash
# The gallery (docs/GALLERY.md): every real dataset in ../shared/data, one procedural volume and
# the T1 head phantom (make-volume --phantom; no brain MRI in ../shared/data)
# at 512², voxsplat beside VTK's GPU ray caster (vtkGPUVolumeRayCastMapper on llvmpipe through EGL),
# the same file, preset and view (voxsplat's default camera, handed to VTK: scripts/vtk_file.py
# --camera), in one run, the two tools alternating file by file. voxsplat: `voxsplat-lab render --repeat 5
# --timings` (default path, median of each stage, summed); VTK: median of 5 frames after a warm-up.
# PSNR over the object (scripts/gallery.py), and the luminance contrast over the object of each
# voxsplat frame (std / mean; the shaded rows against the unshaded decide `SHADED_PRESETS`).
# Writes docs/img/gallery/NAME.png (voxsplat left, VTK right, 256² each) and prints the markdown
# table docs/GALLERY.md and docs/RESULTS.md carry.
# The terrain (rmnp) beside VTK's textured surface of the same height grid (scripts/vtk_terrain.py).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV_VTK:-$HOME/.cache/peers/venv}
DATA=${VOXSPLAT_DATA:-../shared/data}
FRAMES=${FRAMES:-5}
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import vtk, PIL, numpy" 2>/dev/null; then
  python3 -m venv "$VENV" && "$VENV/bin/pip" install -q vtk numpy pillow
fi
cargo build --release --quiet -p voxsplat-cli -p voxsplat-lab
export VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
work=target/gallery
out=docs/img/gallery
mkdir -p "$work" "$out"
[ -f "$work/procedural256.nrrd" ] || ./target/release/voxsplat make-volume --procedural 256 --out "$work/procedural256.nrrd" >&2
# No brain MRI in ../shared/data: the mri preset is shown on the T1 head phantom.
[ -f "$work/head256.nrrd" ] || ./target/release/voxsplat make-volume --phantom 256 --out "$work/head256.nrrd" >&2
vs=./target/release/voxsplat
# `render` with the research switches (--repeat, the engine's paths, the reference's settings).
lab=./target/release/voxsplat-lab
echo "| data | preset, view | voxsplat ms | VTK GPU ray cast ms | VTK / voxsplat | PSNR over the object, dB | contrast |"
echo "|---|---|---|---|---|---|---|"
while IFS='|' read -r name file tf shade; do
  flags=(--shade off)
  [ "$shade" = shade ] && flags=(--shade)
  log=$("$lab" render --volume "$file" --tf "$tf" "${flags[@]}" --size 512x512 --repeat "$FRAMES" --timings \
    --out "$work/$name-voxsplat.png" 2>&1)
  cam=$(grep "camera (grid frame)" <<< "$log")
  if "$vs" info "$file" | grep "^orientation: none" >/dev/null; then view=framing; else view=oblique; fi
  ms=$(grep -E "^[a-z_]+ +[0-9.]+ ms" <<< "$log" | awk '{s += $2} END {printf "%.1f", s}')
  vflags=()
  [ "$shade" = shade ] && vflags+=(--shade)
  vtk=$("$VENV/bin/python" scripts/vtk_file.py --file "$file" --tf "$tf" --mapper gpu --camera "$cam" "${vflags[@]}" \
    --frames "$FRAMES" --out "$work/$name-vtk.png")
  vtk_ms=$(sed -E 's/.*median=([0-9.]+)s.*/\1/' <<< "$vtk" | awk '{printf "%.1f", $1 * 1000}')
  psnr=$("$VENV/bin/python" scripts/gallery.py "$work/$name-voxsplat.png" "$work/$name-vtk.png" "$out/$name.png" \
    | tr '\n' ' ')
  contrast=$(sed -E 's/.*contrast=([0-9.]+).*/\1/' <<< "$psnr")
  psnr=$(sed -E 's/psnr=([0-9.inf]+).*/\1/' <<< "$psnr")
  ratio=$(awk -v a="$vtk_ms" -v b="$ms" 'BEGIN {printf "%.2f", a / b}')
  echo "| $name | $tf${shade:+, shaded}, $view | $ms | $vtk_ms | $ratio | $psnr | $contrast |"
done <<ROWS
bonsai|$DATA/bonsai/bonsai.nii.gz|bonsai|shade
heptane|$DATA/heptane/heptane.nii.gz|ramp|
stent|$DATA/stent/stent.nrrd|ct|
procedural|$work/procedural256.nrrd|ramp|
head-phantom|$work/head256.nrrd|mri|
bonsai-flat|$DATA/bonsai/bonsai.nii.gz|bonsai|
stent-shaded|$DATA/stent/stent.nrrd|ct|shade
heptane-shaded|$DATA/heptane/heptane.nii.gz|ramp|shade
procedural-shaded|$work/procedural256.nrrd|ramp|shade
head-phantom-shaded|$work/head256.nrrd|mri|shade
ROWS
# The terrain: voxsplat's voxel columns beside VTK's textured surface of the same heights and colours
# (scripts/vtk_terrain.py), voxsplat's default fly-over.
dem=$DATA/rmnp/rmnp-dem.tif
rgb=$DATA/rmnp/rmnp-rgb.png
log=$("$lab" render --terrain "$dem" --color "$rgb" --size 512x512 --repeat "$FRAMES" --timings \
  --out "$work/rmnp-voxsplat.png" 2>&1)
t=$(grep -E "^[a-z_]+ +[0-9.]+ ms" <<< "$log" | awk '{s += $2} END {printf "%.1f", s}')
vtk=$("$VENV/bin/python" scripts/vtk_terrain.py --dem "$dem" --color "$rgb" --camera "$(grep "camera (grid frame)" <<< "$log")" \
  --frames "$FRAMES" --out "$work/rmnp-vtk.png")
vtk_ms=$(sed -E 's/.*median=([0-9.]+)s.*/\1/' <<< "$vtk" | awk '{printf "%.1f", $1 * 1000}')
r=$("$VENV/bin/python" scripts/gallery.py "$work/rmnp-voxsplat.png" "$work/rmnp-vtk.png" "$out/rmnp.png")
ratio=$(awk -v a="$vtk_ms" -v b="$t" 'BEGIN {printf "%.2f", a / b}')
echo "| rmnp (terrain; VTK: a textured surface) | colour image, fly-over | $t | $vtk_ms | $ratio | $(sed -E 's/psnr=([0-9.inf]+).*/\1/' <<< "$r") | $(sed -E 's/.*contrast=([0-9.]+).*/\1/' <<< "$r") |"
