#!/usr/bin/env bash
# Bricked volumes beside VTK's fixed-point CPU ray caster on the same files (issue 23): the 256³
# bonsai, its 2x upsampling (512³) and the procedural 1024³ field (scripts/large-volumes.sh), the
# same transfer-function preset and view (scripts/vtk_file.py copies voxsplat's framing camera),
# 512x512, alternating the two tools file by file in one run. Each voxsplat run is its own process
# (`voxsplat-lab bricks --volume`: load, store, median frame at full detail and with levels of detail,
# peak RSS). Prints a markdown table and
# draws docs/bench/bricks-scaling.svg (frame time against voxels, both tools); its CSV,
# docs/bench/bricks-scaling.csv, is the third panel of the bench's scaling.svg.
# Installs VTK (PyPI) in a virtual environment when missing, as scripts/peers.sh does.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV_VTK:-$HOME/.cache/peers/venv}
LARGE=${LARGE:-target/large}
FRAMES=${FRAMES:-5}
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import vtk" 2>/dev/null; then
  python3 -m venv "$VENV" && "$VENV/bin/pip" install -q vtk numpy pillow
fi
[ -f "$LARGE/procedural1024.nrrd" ] || ./scripts/large-volumes.sh "$LARGE" >&2
cargo build --release --quiet -p voxsplat-cli -p voxsplat-lab
export VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
cat <<'TEXT'
### Beside VTK on the same files

`scripts/bricks-vtk.sh`, one run, the two tools alternating file by file: VTK's fixed-point CPU ray
caster (`scripts/vtk_file.py`: the same preset mapped over the data's range, opacity per voxel
length, voxsplat's framing camera) and voxsplat's bricked GPU path (`voxsplat-lab bricks --volume`, its
own process per file), 512², 5 frames after a warm-up, medians. voxsplat alternates full detail
with levels of detail (`--lod auto`, 1 px; PSNR against its own full detail): the fifth column is
the levels of detail's moonshot, LOD frame time against VTK's. The last column holds both frames' PSNR against a
converged truth, the supersampled reference (`voxsplat-lab render --raycast 0.25 --supersample 4 --raycast-stop
1e-4 --cpu`: 4 x 4 rays per pixel, trilinear scalars through the same transfer function;
docs/MODEL.md), for the files the dense loaders take (at most 2²⁸ voxels; not the 1024³).

TEXT
csv=docs/bench/bricks-scaling.csv
echo "voxels,vtk_ms,voxsplat_ms" > "$csv"
echo "| file | VTK fixed point: load s, median ms, peak RSS MiB | voxsplat bricked, GPU path (1 GiB budget) | VTK ms / voxsplat ms | VTK ms / voxsplat LOD ms | PSNR dB against the ray-cast truth: full detail, LOD |"
echo "|---|---|---|---|---|---|"
for f in ../shared/data/bonsai/bonsai.nii.gz "$LARGE/bonsai512.nrrd" "$LARGE/procedural1024.nrrd"; do
  tf=bonsai; [[ $f == *procedural* ]] && tf=ramp
  vtk=$( { /usr/bin/time -f "rss=%M" "$VENV/bin/python" scripts/vtk_file.py --file "$f" --tf $tf --frames "$FRAMES" \
    --out "target/vtk-$(basename "$f").png"; } 2>&1 | grep -E "median=|rss=" | tr '\n' ' ')
  vs=$(./target/release/voxsplat-lab bricks --volume "$f" --tf $tf --frames "$FRAMES")
  vtk_ms=$(sed -E 's/.*median=([0-9.]+)s.*/\1/' <<< "$vtk" | awk '{print $1 * 1000}')
  vtk_load=$(sed -E 's/.*load=([0-9.]+)s.*/\1/' <<< "$vtk")
  vtk_rss=$(sed -E 's/.*rss=([0-9]+).*/\1/' <<< "$vtk" | awk '{printf "%.0f", $1 / 1024}')
  vs_ms=$(sed -E 's/.*median frame ([0-9.]+) ms.*/\1/' <<< "$vs")
  lod_ms=$(sed -E 's/.*levels of detail \(1 px\) ([0-9.]+) ms.*/\1/' <<< "$vs")
  ratio=$(awk -v a="$vtk_ms" -v b="$vs_ms" 'BEGIN {printf "%.3f", a / b}')
  lod_ratio=$(awk -v a="$vtk_ms" -v b="$lod_ms" 'BEGIN {printf "%.3f", a / b}')
  voxels=$(sed -E 's/^[^:]*: ([0-9]+) voxels.*/\1/' <<< "$vs")
  truth="-"
  if [ "$voxels" -le 268435456 ]; then
    t=target/truth-$(basename "$f").exr
    ./target/release/voxsplat-lab render --volume "$f" --tf $tf --size 512x512 --raycast 0.25 --supersample 4 \
      --raycast-stop 1e-4 --cpu --out "$t" >/dev/null
    psnr=()
    for lod in off auto; do
      ./target/release/voxsplat-lab render --volume "$f" --tf $tf --size 512x512 --raster compute --direction ftb \
        --lod $lod --lod-pixels 1 --out "target/frame-$lod.exr" >/dev/null
      psnr+=("$(./target/release/voxsplat compare "target/frame-$lod.exr" "$t" | sed -nE 's/^psnr: *([0-9.]+) dB.*/\1/p')")
    done
    truth="${psnr[0]}, ${psnr[1]}"
  fi
  echo "| $(basename "$f") ($tf) | $vtk_load, $vtk_ms, $vtk_rss | ${vs#*: } | $ratio | $lod_ratio | $truth |"
  echo "$voxels,$vtk_ms,$vs_ms" >> "$csv"
done
./target/release/voxsplat-lab bricks --chart "$csv" --chart-out docs/bench/bricks-scaling.svg
echo
echo "![bricked volumes against VTK, frame time against voxels](bench/bricks-scaling.svg)"
