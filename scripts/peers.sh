#!/usr/bin/env bash
# voxsplat beside its peers (issue 9): the shared scene of ../shared/peers rendered by VTK's
# fixed-point CPU ray caster (also casting one ray every D pixels, D in VTK_ISDS: its own
# speed-accuracy knob, through scripts/vtk_isd.py), VTK's GPU ray caster (llvmpipe) and every voxsplat mode, in the same run,
# alternating tool by tool for ROUNDS rounds (each a warm-up then the median of 5 frames), at 128^3
# and 256^3, 512x512. Every image is scored against one truth: voxsplat's ray integration of the
# interpolated scalar at a 0.1-voxel step, first checked against VTK's ray casters at the same small
# sample distance (GPU: float; fixed point: drifts as the distance shrinks, docs/MODEL.md). Writes docs/bench/peers.md (table) and docs/bench/peers-*.png (strips);
# `voxsplat-lab matrix --results` includes peers.md in docs/RESULTS.md.
# Installs VTK (PyPI) in a virtual environment when missing: ~/.cache/peers/venv, as the peers do.
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS=${ROUNDS:-2}
SIZES=${SIZES:-"128 256"}
PEERS=${PEERS:-../shared/peers}
VENV=${VENV_VTK:-$HOME/.cache/peers/venv}
OUT=${OUT:-target/peers}
VTK_ISDS=${VTK_ISDS:-"1.25 1.5 2 2.5"}
./scripts/setup.sh
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import vtk, numpy, PIL" 2>/dev/null; then
  python3 -m venv "$VENV" && "$VENV/bin/pip" install -q vtk numpy pillow
fi
cargo build --release --quiet
mkdir -p "$OUT" docs/bench
export VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
VTK="$VENV/bin/python $PEERS/vtk/vtk_volume.py"
# Median frame time in ms from the peer script's last line (median=...s), the command on the arguments.
vtk_ms() { "$@" 2>/dev/null | tail -1 | sed -E 's/.*median=([0-9.]+)s.*/\1/' | awk '{print $1 * 1000}'; }
: > "$OUT/times.csv"
for n in $SIZES; do
  # References: VTK at a 0.1 sample distance (both casters), voxsplat's two truths at a 0.1 step.
  for m in gpu fixed; do
    $VTK --mapper $m --n "$n" --size 512 --frames 1 --warmup 0 --sample 0.1 --out "$OUT/vtk-$m-fine-$n.png" >/dev/null 2>&1
  done
  ./target/release/voxsplat-lab peer --n "$n" --frames 5 --warmup 0 --out-dir "$OUT" --truth-step 0.1 >/dev/null
  for r in $(seq "$ROUNDS"); do
    for m in fixed gpu; do
      ms=$(vtk_ms $VTK --mapper $m --n "$n" --size 512 --frames 5 --warmup 2 --out "$OUT/vtk-$m-$n.png")
      echo "$n,$r,vtk $m,$ms" >> "$OUT/times.csv"
    done
    for d in $VTK_ISDS; do
      ms=$(VTK_IMAGE_SAMPLE_DISTANCE=$d vtk_ms "$VENV/bin/python" scripts/vtk_isd.py "$PEERS/vtk/vtk_volume.py" \
        --mapper fixed --n "$n" --size 512 --frames 5 --warmup 2 --out "$OUT/vtk-fixed-isd-$d-$n.png")
      echo "$n,$r,vtk fixed isd $d,$ms" >> "$OUT/times.csv"
    done
    ./target/release/voxsplat-lab peer --n "$n" --frames 5 --warmup 2 --out-dir "$OUT" | tail -n +2 \
      | sed "s/^/$n,$r,voxsplat /" >> "$OUT/times.csv"
  done
done
"$VENV/bin/python" scripts/peers_report.py "$OUT" docs/bench "$SIZES"
echo "wrote docs/bench/peers.md and its section of docs/RESULTS.md"
