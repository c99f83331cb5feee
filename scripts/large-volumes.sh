#!/usr/bin/env bash
# Makes the large test volumes of issue 23 (never committed): the 256³ bonsai upsampled 2x to 512³
# (128 MiB) and the procedural 1024³ field (1 GiB), as 8-bit NRRD in DIR (default target/large).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-target/large}
mkdir -p "$dir"
cargo build --release --quiet
data=${VOXSPLAT_DATA:-../shared/data}
./target/release/voxsplat make-volume --from "$data/bonsai/bonsai.nii.gz" --factor 2 --out "$dir/bonsai512.nrrd"
./target/release/voxsplat make-volume --procedural 1024 --out "$dir/procedural1024.nrrd"
