#!/usr/bin/env bash
# Renders a fixed matrix of 123 frames through the CLI (every order, compositing mode, raster
# variant and kernel on both backends, AA, early termination, budgets, render scale, the ray caster,
# the truth, four motion-blurred animations, and eight bricked volumes from ../shared/data) and
# prints a hash of each frame's exact RGBA32F pixels (lab/examples/pixel_hash.rs). Run it with the binaries before and after a refactor and diff
# the outputs: a change that changes no image changes no hash. (Issue 22 ran it at every commit.)
# The matrix uses the research switches, so it renders with `voxsplat-lab render`, and animates
# with `voxsplat animate` (before issue 77 one binary did both: give it twice).
# Usage: scripts/image-hashes.sh [RENDER_BINARY [ANIMATE_BINARY]] > hashes.txt
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet -p voxsplat-lab --bin voxsplat-lab --example pixel_hash
cargo build --release --quiet -p voxsplat-cli --bin voxsplat
bin=${1:-target/release/voxsplat-lab}
animate=${2:-target/release/voxsplat}
hash=target/release/examples/pixel_hash
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() { # name, args...
  local name=$1; shift
  "$bin" render "$@" --out "$out/$name.exr" >/dev/null 2>&1 || { echo "$name FAILED"; return; }
  echo "$name $($hash "$out/$name.exr")"
}
for be in gpu cpu; do
  cpu=(); [ $be = cpu ] && cpu=(--cpu)
  for scene in cube40 cube40-attenuated; do
    s=(--scene $scene --size 96x80 "${cpu[@]}")
    for order in pbtf btf wbtf sorted; do
      run $be-$scene-splat-graphics-$order "${s[@]}" --order $order --raster graphics
    done
    run $be-$scene-splat-graphics-ftb "${s[@]}" --raster graphics --direction ftb
    run $be-$scene-splat-points "${s[@]}" --raster points
    run $be-$scene-splat-compute "${s[@]}" --raster compute
    run $be-$scene-splat-compute-btf "${s[@]}" --raster compute --direction btf
    run $be-$scene-splat-compute-wbtf "${s[@]}" --raster compute --order wbtf
    run $be-$scene-splat-compute-et "${s[@]}" --raster compute --early-termination 0.01
    run $be-$scene-splat-auto "${s[@]}"
    for r in graphics points compute; do
      run $be-$scene-sheet-$r "${s[@]}" --accumulate sheet --raster $r
      run $be-$scene-slab-$r "${s[@]}" --accumulate slab --raster $r
    done
    run $be-$scene-sheet-btf "${s[@]}" --accumulate sheet --direction btf --raster graphics
    run $be-$scene-sheet-et "${s[@]}" --accumulate sheet --early-termination 0.01 --raster graphics
    run $be-$scene-sheet-budget "${s[@]}" --accumulate sheet --sheet-budget-mib 1 --raster graphics
    run $be-$scene-slab-thick "${s[@]}" --accumulate slab --slab-thickness 2.5 --raster compute
    run $be-$scene-cubic-swan "${s[@]}" --kernel cubic --aa swan --raster graphics
    run $be-$scene-narrow-ewa "${s[@]}" --kernel narrow --aa ewa --raster compute
    run $be-$scene-scaled "${s[@]}" --render-scale 0.5 --raster compute
    run $be-$scene-raycast "${s[@]}" --raycast 0.5
    run $be-$scene-ortho "${s[@]}" --ortho 70 --raster graphics
  done
  run $be-plane-grazing-swan --scene plane --view grazing --aa swan --size 128x96 "${cpu[@]}" --raster graphics
  run $be-plane-grazing-compute --scene plane --view grazing --size 128x96 "${cpu[@]}" --raster compute
  run $be-plane-grazing-sheet --scene plane --view grazing --size 128x96 "${cpu[@]}" --accumulate sheet --raster compute
done
run truth-cube40 --scene cube40 --size 64x48 --truth
# Bricked volumes from ../shared/data (or $VOXSPLAT_DATA): levels of detail with their nodes, waves
# of hidden bricks, precomputed gradients, a store streamed through a small budget, the CPU mirrors.
data=${VOXSPLAT_DATA:-../shared/data}
if [ -d "$data/bonsai" ]; then
  b=(--volume "$data/bonsai/bonsai.nii.gz" --tf bonsai)
  st=(--volume "$data/stent/stent.nrrd" --tf ct)
  run bricked-bonsai "${b[@]}" --size 128x128
  run bricked-bonsai-lod-off "${b[@]}" --size 128x128 --lod off
  run bricked-bonsai-nodes "${b[@]}" --lod-nodes --size 48x48
  run bricked-bonsai-flat "${b[@]}" --size 128x128 --shade off --early-termination 0
  run bricked-stent "${st[@]}" --size 128x128
  run bricked-stent-streamed "${st[@]}" --size 128x128 --gpu-budget-mib 4
  run bricked-stent-cpu "${st[@]}" --size 64x64 --cpu
  run bricked-heptane --volume "$data/heptane/heptane.nii.gz" --tf ramp --size 96x96
fi
for blur in splat accum:3; do
  for comp in splat sheet; do
    d="$out/anim-$blur-$comp"
    "$animate" animate --anim rotating-box --blur $blur --accumulate $comp --format exr --out-dir "$d" >/dev/null 2>&1 \
      || { echo "anim-$blur-$comp FAILED"; continue; }
    echo "anim-$blur-$comp $($hash "$d"/*.exr | sha256sum | cut -c1-16)"
  done
done
