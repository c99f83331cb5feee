#!/usr/bin/env bash
# Renders the pictures of docs/GALLERY.md: the 60^3 cube of Figs 2.25-2.27 from close perspective views where
# BTF (view A) and WBTF (view B) draw back-face rows over front-face rows, beside PBTF.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet -p voxsplat-lab
a=(--eye 70,20,12 --target 0,0,0)
b=(--eye 20,40,50 --target -40,-10,-10)
for o in btf wbtf pbtf; do
  ./target/release/voxsplat-lab render --scene cube60 "${a[@]}" --fov 75 --size 256x256 --order "$o" --out "docs/img/a-$o.png"
done
for o in wbtf pbtf; do
  ./target/release/voxsplat-lab render --scene cube60 "${b[@]}" --fov 75 --size 256x256 --order "$o" --out "docs/img/b-$o.png"
done
