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
echo "step 0.25 in the same mode (premultiplied RGBA). \`iso V\`: the isosurface at V (the file's units),"
echo "its surface splats made on the device each frame; its ray caster has no empty-space skipping."
echo
echo "| volume | mode | frame ms | ÷ composite, every voxel | ÷ composite, default | ray caster ms (step 0.5) | PSNR dB |"
echo "|---|---|---:|---:|---:|---:|---:|"
# volume, file, TF, the isosurface's value (in the file's units)
for spec in "bonsai ../shared/data/bonsai/bonsai.nii.gz bonsai 60" "stent ../shared/data/stent/stent.nrrd ct 1000"; do
  set -- $spec
  name=$1; vol=$2; tf=$3; iso=$4
  dense=$(wall --volume "$vol" --tf "$tf" --dense)
  default=$(wall --volume "$vol" --tf "$tf")
  for mode in composite mip minip average xray iso; do
    value=""
    [ "$mode" = iso ] && value="--iso $iso"
    # shellcheck disable=SC2086
    if [ "$mode" = composite ]; then ms=$dense; same=--dense; else ms=$(wall --volume "$vol" --tf "$tf" --mode "$mode" $value); same=; fi
    ray=$(ray_ms --volume "$vol" --tf "$tf" --mode "$mode" $value)
    "$B" render --volume "$vol" --tf "$tf" --mode "$mode" $value $same --out "$tmp/splat.exr" 2>/dev/null
    "$B" render --volume "$vol" --tf "$tf" --mode "$mode" $value --raycast 0.25 --out "$tmp/ray.exr" 2>/dev/null
    p=$(psnr "$tmp/splat.exr" "$tmp/ray.exr")
    r1=$(awk -v a="$ms" -v b="$dense" 'BEGIN {printf "%.2f", a / b}')
    r2=$(awk -v a="$ms" -v b="$default" 'BEGIN {printf "%.2f", a / b}')
    [ "$mode" = iso ] && mode="iso $iso"
    echo "| $name | $mode | $ms | $r1 | $r2 | $ray | $p |"
  done
done
