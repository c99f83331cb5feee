#!/usr/bin/env bash
# The projection modes' page (docs/bench/modes.md): each mode's default frame of two gallery
# volumes at 512² from the default view on this machine (the median of 5, `render --timings
# --repeat 5`; a bricked store, every voxel drawn), beside the composited frame of every voxel
# (host splats, `--dense`) and the default (bricked) composited frame; the
# ray caster in the same mode (step 0.5); and the splats' PSNR against a fine ray cast (step 0.25)
# in the same mode. One process per frame; absolute times are this machine's.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
B=target/release/voxsplat
tmp=target/modes
mkdir -p "$tmp"
wall() { "$B" render "$@" --timings --repeat 5 --out "$tmp/x.exr" 2>/dev/null | awk '/frame, wall/ {print $3}'; }
ray_ms() { "$B" render "$@" --raycast 0.5 --timings --out "$tmp/x.exr" 2>/dev/null | awk '{s += $2} END {printf "%.1f", s}'; }
psnr() { "$B" compare "$1" "$2" | awk '/psnr/ {print $2}'; }
echo "# Projection modes"
echo
echo "\`scripts/modes.sh\` on $(nproc) cores, lavapipe ($(date -u +%Y-%m-%d)): 512², the default view and kernel,"
echo "\`--raster auto\` (the compute tile compositor here). A projection's frame is the default: the"
echo "bricked store, every voxel drawn. *Composite, every voxel* draws the same voxels as host splats"
echo "composited front to back (\`--dense\`); *composite, default* is the default frame (the bricked"
echo "store with levels of detail and early termination). PSNR: the splat frame against a ray cast at"
echo "step 0.25 in the same mode (premultiplied RGBA)."
echo
echo "| volume | mode | frame ms | ÷ composite, every voxel | ÷ composite, default | ray caster ms (step 0.5) | PSNR dB |"
echo "|---|---|---:|---:|---:|---:|---:|"
for spec in "bonsai ../shared/data/bonsai/bonsai.nii.gz bonsai" "stent ../shared/data/stent/stent.nrrd ct"; do
  set -- $spec
  name=$1; vol=$2; tf=$3
  dense=$(wall --volume "$vol" --tf "$tf" --dense)
  default=$(wall --volume "$vol" --tf "$tf")
  for mode in composite mip minip average xray; do
    if [ "$mode" = composite ]; then ms=$dense; same=--dense; else ms=$(wall --volume "$vol" --tf "$tf" --mode "$mode"); same=; fi
    ray=$(ray_ms --volume "$vol" --tf "$tf" --mode "$mode")
    "$B" render --volume "$vol" --tf "$tf" --mode "$mode" $same --out "$tmp/splat.exr" 2>/dev/null
    "$B" render --volume "$vol" --tf "$tf" --mode "$mode" --raycast 0.25 --out "$tmp/ray.exr" 2>/dev/null
    p=$(psnr "$tmp/splat.exr" "$tmp/ray.exr")
    r1=$(awk -v a="$ms" -v b="$dense" 'BEGIN {printf "%.2f", a / b}')
    r2=$(awk -v a="$ms" -v b="$default" 'BEGIN {printf "%.2f", a / b}')
    echo "| $name | $mode | $ms | $r1 | $r2 | $ray | $p |"
  done
done
