#!/usr/bin/env bash
# Does a frame cost what the picture needs? The 256³ bonsai and its 2x upsampling (512³, placed
# where the 256³ is, so the default view is the same), the procedural field at 256³ and 1024³
# (scripts/large-volumes.sh), 512², each file's default view and preset: voxsplat's frame at its
# defaults, at the previous defaults (Gaussian kernel, no early termination, no levels of detail),
# and VTK's fixed-point CPU ray caster (scripts/vtk_file.py: same camera, shading as voxsplat's
# preset has it), alternating the tools file by file in one run. Frame times are wall-clock medians
# of $FRAMES frames after a warm-up (voxsplat: `voxsplat-lab render --repeat`, the first frame dropped by taking
# the median). PSNR against the supersampled reference (scripts/reference.sh; files the dense
# loaders take). Prints markdown tables.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV_VTK:-$HOME/.cache/peers/venv}
LARGE=${LARGE:-target/large}
WORK=${WORK:-target/reference}
FRAMES=${FRAMES:-5}
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import vtk" 2>/dev/null; then
  python3 -m venv "$VENV" && "$VENV/bin/pip" install -q vtk numpy pillow
fi
[ -f "$LARGE/procedural1024.nrrd" ] || ./scripts/large-volumes.sh "$LARGE" >&2
[ -f "$LARGE/procedural256.nrrd" ] || ./target/release/voxsplat make-volume --procedural 256 --out "$LARGE/procedural256.nrrd" >&2
cargo build --release --quiet -p voxsplat-cli -p voxsplat-lab
mkdir -p "$WORK"
export VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
vs=./target/release/voxsplat
# `render` with the research switches (--repeat, the engine's paths, the reference's settings).
lab=./target/release/voxsplat-lab
PREVIOUS="--kernel gaussian --early-termination 0 --lod off"
stages=()
wall() { sed -nE 's/^frame, wall: +([0-9.]+) ms.*/\1/p' <<< "$1"; }
echo "| file | stored voxels | VTK fixed point ms | voxsplat ms (defaults) | VTK / voxsplat | previous defaults ms | PSNR dB against the reference: defaults, previous |"
echo "|---|---:|---:|---:|---:|---:|---|"
for spec in "../shared/data/bonsai/bonsai.nii.gz|bonsai" "$LARGE/bonsai512.nrrd|bonsai" "$LARGE/procedural256.nrrd|ramp" "$LARGE/procedural1024.nrrd|ramp"; do
  f=${spec%|*}; tf=${spec#*|}
  name=$(basename "$f")
  shade=(); $vs info "$f" >/dev/null
  [ "$tf" = bonsai ] && shade=(--shade)
  log=$($lab render --volume "$f" --tf "$tf" --size 512x512 --repeat $((FRAMES + 1)) --timings --out "$WORK/cost-$name.exr" 2>&1)
  cam=$(grep "camera (grid frame)" <<< "$log")
  stored=$(sed -nE 's/^([0-9]+) stored voxels in.*/\1/p' <<< "$log" | head -1)
  vtk=$("$VENV/bin/python" scripts/vtk_file.py --file "$f" --tf "$tf" --frames "$FRAMES" --camera "$cam" "${shade[@]}" \
    --out "$WORK/vtk-$name.png" 2>&1 | grep -E "median=")
  vtk_ms=$(sed -E 's/.*median=([0-9.]+)s.*/\1/' <<< "$vtk" | awk '{print $1 * 1000}')
  # shellcheck disable=SC2086
  prev=$($lab render --volume "$f" --tf "$tf" --size 512x512 --repeat $((FRAMES + 1)) --timings $PREVIOUS \
    --out "$WORK/cost-prev-$name.exr" 2>&1)
  ms=$(wall "$log"); prev_ms=$(wall "$prev")
  ratio=$(awk -v a="$vtk_ms" -v b="$ms" 'BEGIN {printf "%.3f", a / b}')
  psnr="-"
  ref="$WORK/truth-$name-k4-s0.25.exr"
  if [ "$stored" -le 268435456 ] && [ "$name" != procedural1024.nrrd ]; then
    [ -f "$ref" ] || $lab render --volume "$f" --tf "$tf" --size 512x512 --raycast 0.25 --raycast-stop 1e-4 --cpu \
      --supersample 4 --out "$ref" >/dev/null 2>&1
    p() { $vs compare "$1" "$ref" | awk '/^psnr:/ {print $2}'; }
    psnr="$(p "$WORK/cost-$name.exr"), $(p "$WORK/cost-prev-$name.exr")"
  fi
  echo "| $name ($tf) | $stored | $vtk_ms | $ms | $ratio | $prev_ms | $psnr |"
  printf '%s\n' "$log" > "$WORK/log-$name.txt"
  printf '%s\n' "$prev" > "$WORK/log-prev-$name.txt"
  stages+=("$name|$stored|$WORK/log-$name.txt" "$name, previous defaults|$stored|$WORK/log-prev-$name.txt")
done
# Where the time goes: each stage's median, per stored voxel and per splat drawn.
echo
echo "| file, settings | splats drawn (bricks: visible, coarser, hidden; waves) | stage: ms, ns per stored voxel, ns per splat drawn |"
echo "|---|---|---|"
for s in "${stages[@]}"; do
  IFS='|' read -r label stored file <<< "$s"
  log=$(cat "$file")
  drawn=$(sed -nE 's/^drawn: ([0-9]+) splats from ([0-9]+) of [0-9]+ bricks \(([0-9]+) drawn coarser, [0-9]+ of them nodes of several bricks, ([0-9]+) hidden.*, ([0-9]+) waves/\1|\2, \3, \4; \5/p' <<< "$log")
  splats=${drawn%%|*}
  cells=$(grep -E "^[a-z_]+ +[0-9.]+ ms$" <<< "$log" | awk -v v="$stored" -v n="$splats" \
    '{printf "%s%s %.0f, %.0f, %.0f", sep, $1, $2, $2 * 1e6 / v, $2 * 1e6 / n; sep = "; "}')
  echo "| $label | $splats (${drawn#*|}) | $cells |"
done
