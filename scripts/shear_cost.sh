#!/usr/bin/env bash
# What a sheared grid costs (issue 29): bonsai with its sform replaced by an axis-aligned one and by
# a 30-degree gantry tilt (each slice shifted along j by tan 30 per k), rendered at 512² from one
# anterior camera on the default (bricked) path and by the ray caster, the two files alternating in
# one run; prints the median frame time of each (splats: the sum of the stages' medians over 5
# frames, median over the rounds; the ray caster: one frame per round, median over the rounds).
#   scripts/shear_cost.sh [ROUNDS]    (default 5)
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS=${1:-5}
cargo build --release --quiet -p voxsplat-cli -p voxsplat-lab
work=target/shear
mkdir -p "$work"
python3 - "../shared/data/bonsai/bonsai.nii.gz" "$work" <<'PY'
import gzip, struct, sys, math
src, work = sys.argv[1], sys.argv[2]
data = bytearray(gzip.open(src).read())
for name, tilt in [("aligned", 0.0), ("tilted", math.tan(math.radians(30)))]:
    d = bytearray(data)
    struct.pack_into("<hh", d, 252, 0, 1)  # qform_code 0, sform_code 1 (scanner)
    struct.pack_into("<4f", d, 280, 1, 0, 0, 0)
    struct.pack_into("<4f", d, 296, 0, 1, tilt, 0)
    struct.pack_into("<4f", d, 312, 0, 0, 1, 0)
    with gzip.open(f"{work}/bonsai-{name}.nii.gz", "wb", compresslevel=1) as f:
        f.write(d)
PY
vs=./target/release/voxsplat
# `render` with the research switches (--repeat, the engine's paths, the reference's settings).
lab=./target/release/voxsplat-lab
# One camera for both: 700 mm anterior of each grid's centre (RAS), looking posterior, superior up
# (the default framing would fit each file's own box, and the tilted box is larger).
declare -A centre=([aligned]="127.5,127.5,127.5" [tilted]="127.5,201.1,127.5")
declare -A eye=([aligned]="127.5,827.5,127.5" [tilted]="127.5,901.1,127.5")
time_of() {  # name, extra flags...
  local f=$work/bonsai-$1.nii.gz
  local name=$1; shift
  "$lab" render --volume "$f" --tf bonsai --shade off --eye "${eye[$name]}" --target "${centre[$name]}" --up 0,0,1 \
    --size 512x512 --timings \
    --out "$work/$name-$mode.png" "$@" 2>&1 | grep -E "^[a-z_]+ +[0-9.]+ ms" | awk '{s += $2} END {printf "%.1f", s}'
}
declare -A t
for _ in $(seq "$ROUNDS"); do
  for mode in splats raycast; do
    flags=(--repeat 5)
    [ "$mode" = raycast ] && flags=(--raycast 0.5)  # one frame per round
    for name in aligned tilted; do
      t[$mode-$name]+="$(time_of "$name" "${flags[@]}") "
    done
  done
done
median() { tr ' ' '\n' | grep . | sort -n | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
echo "| path | axis-aligned ms | tilted 30° ms | tilted / aligned |"
echo "|---|---|---|---|"
for mode in splats raycast; do
  a=$(median <<< "${t[$mode-aligned]}")
  b=$(median <<< "${t[$mode-tilted]}")
  echo "| $mode | $a | $b | $(awk -v a="$a" -v b="$b" 'BEGIN {printf "%.2f", b / a}') |"
done
