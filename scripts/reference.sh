#!/usr/bin/env bash
# The honest reference and what scores against it (docs/MODEL.md, "The reference"): per gallery
# file at 512² and its default view, the CPU ray caster at 0.25-voxel steps with K x K rays per
# pixel averaged (`voxsplat-lab render --raycast 0.25 --supersample K --raycast-stop 1e-4 --cpu`), its
# convergence (K/2 and 2K rays per axis, and half the step, against it), then voxsplat's frames
# (the defaults, and each FLAGS set of $VARIANTS) scored against it: median frame time over
# $FRAMES frames (stage times summed) and PSNR. Truths are cached in $WORK (target/reference).
# Prints a markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${VOXSPLAT_DATA:-../shared/data}
WORK=${WORK:-target/reference}
K=${K:-4}
FRAMES=${FRAMES:-3}
LARGE=${LARGE:-target/large}
# One variant a line: a label, '|', then render flags ('' : the defaults).
VARIANTS=${VARIANTS:-"defaults|"}
mkdir -p "$WORK"
cargo build --release --quiet -p voxsplat-cli -p voxsplat-lab
vs=./target/release/voxsplat
# `render` with the research switches (--repeat, the engine's paths, the reference's settings).
lab=./target/release/voxsplat-lab
[ -f "$WORK/procedural256.nrrd" ] || $vs make-volume --procedural 256 --out "$WORK/procedural256.nrrd" >&2
[ -f "$WORK/head256.nrrd" ] || $vs make-volume --phantom 256 --out "$WORK/head256.nrrd" >&2
FILES=${FILES:-"bonsai|$DATA/bonsai/bonsai.nii.gz|bonsai
heptane|$DATA/heptane/heptane.nii.gz|ramp
stent|$DATA/stent/stent.nrrd|ct
procedural|$WORK/procedural256.nrrd|ramp
head-phantom|$WORK/head256.nrrd|mri"}
psnr() { $vs compare "$1" "$2" | awk '/^psnr:/ {print $2}'; }
truth() { # name file tf k step -> path
  local t="$WORK/truth-$1-k$4-s$5.exr"
  [ -f "$t" ] || $lab render --volume "$2" --tf "$3" --size 512x512 --raycast "$5" --raycast-stop 1e-4 --cpu \
    --supersample "$4" --out "$t" >/dev/null
  echo "$t"
}
echo "| data | preset | reference: k=$((K / 2)) / k=$((2 * K)) / half step, dB from it | variant | median ms | PSNR dB |"
echo "|---|---|---|---|---:|---:|"
while IFS='|' read -r name file tf; do
  ref=$(truth "$name" "$file" "$tf" "$K" 0.25)
  conv="$(psnr "$(truth "$name" "$file" "$tf" $((K / 2)) 0.25)" "$ref") / $(psnr "$(truth "$name" "$file" "$tf" $((2 * K)) 0.25)" "$ref") / $(psnr "$(truth "$name" "$file" "$tf" "$K" 0.125)" "$ref")"
  while IFS='|' read -r label flags; do
    # shellcheck disable=SC2086
    ms=$($lab render --volume "$file" --tf "$tf" --size 512x512 --repeat "$FRAMES" --timings $flags \
      --out "$WORK/frame.exr" 2>&1 | awk '/ ms$/ {s += $2} END {printf "%.0f", s}')
    echo "| $name | $tf | $conv | $label | $ms | $(psnr "$WORK/frame.exr" "$ref") |"
    conv=""
  done <<< "$VARIANTS"
done <<< "$FILES"
