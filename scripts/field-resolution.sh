#!/usr/bin/env bash
# Does the procedural 1024³ field's picture need its full resolution? The same function sampled at
# 512³ and 256³ (`make-volume --procedural N`), placed over the 1024³ field (spacing 2 and 4, the
# first voxel's centre at 0.5 and 1.5) with the ramp preset's opacity, given per voxel length, raised
# to the longer voxels (1 - (1 - a)^k), each drawn at full detail at 512² from the field's default
# view and scored against the 1024³ field's reference over the covered pixels.
# docs/log/2026-12-06-the-field-shows-its-voxels.md.
#
#   scripts/field-resolution.sh
#
# Needs the family's field1024 and its 512² reference, which
#   ONLY=field1024 SIZES=512 VIEWS=auto scripts/family-bench.sh
# makes (the reference is cast tile by tile: about an hour here). Writes ~150 MiB under $WORK.
set -euo pipefail
cd "$(dirname "$0")/.."
FAMILY=${FAMILY:-target/family}
WORK=${WORK:-target/field-resolution}
FRAMES=${FRAMES:-3}
field="$FAMILY/field1024.nrrd"
ref="$FAMILY/truth-field1024-512-auto-k4-crops.exr"
for f in "$field" "$ref"; do
  [ -f "$f" ] || { echo "field-resolution: $f is missing; make it with: ONLY=field1024 SIZES=512 VIEWS=auto scripts/family-bench.sh" >&2; exit 1; }
done
if [ -z "${VS:-}" ]; then cargo build --release --quiet -p voxsplat-cli -p voxsplat-lab; fi
vs=${VS:-./target/release/voxsplat}
# `render` with the research switches (--repeat, the reference's settings): the lab beside it.
lab=$(dirname "$vs")/voxsplat-lab
mkdir -p "$WORK"
# shellcheck disable=SC2207
cam=($(python3 scripts/sparse-truth.py "$field" --camera --tf ramp --vs "$vs" -- --size 512x512))
python3 - "$WORK" "$vs" <<'EOF'
import os, sys
sys.path.insert(0, "scripts")
from family import procedural

work, vs = sys.argv[1], sys.argv[2]
for n in (512, 256):
    k = 1024 // n
    out = os.path.join(work, f"field{n}.nrrd")
    # Voxel i of n covers the 1024³ field's voxels k i .. k i + k - 1: its centre lies at k i + (k - 1) / 2.
    if not os.path.exists(out):
        procedural(n, out, vs, k, (k - 1) / 2)
# The ramp preset (grey and opacity rising linearly from a tenth of the range to 0.6), with the
# opacity of a voxel k times as long, in 37 points.
for k in (1, 2, 4):
    points = ["[0.0, [0, 0, 0, 0]]"]
    for i in range(37):
        v = 0.1 + 0.9 * i / 36
        g = (v - 0.1) / 0.9
        a = 1 - (1 - 0.6 * g) ** k
        points.append(f"[{v:.5f}, [{g:.5f}, {g:.5f}, {g:.5f}, {a:.5f}]]")
    with open(os.path.join(work, f"ramp{k}.toml"), "w") as f:
        f.write("points = [" + ", ".join(points) + "]\n")
EOF
echo "| volume | splats | ms | dB against the 1024³ reference |"
echo "|---|---:|---:|---:|"
for row in "1024:$field:1" "512:$WORK/field512.nrrd:2" "256:$WORK/field256.nrrd:4"; do
  IFS=: read -r n file k <<<"$row"
  "$lab" render --volume "$file" --tf "$WORK/ramp$k.toml" "${cam[@]}" --lod off --repeat "$FRAMES" --timings \
    --out "$WORK/frame$n.exr" >"$WORK/frame$n.log" 2>&1
  splats=$(grep -o "drawn: [0-9]* splats" "$WORK/frame$n.log" | awk '{printf "%.1f M", $2 / 1e6}')
  ms=$(awk '/ ms$/ {s += $2} END {printf "%.0f", s}' "$WORK/frame$n.log")
  db=$("$vs" compare "$WORK/frame$n.exr" "$ref" | awk '/^psnr:/ {print $2}')
  echo "| $n³ samples, \`--lod off\` | $splats | $ms | $db |"
done
