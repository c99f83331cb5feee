#!/usr/bin/env bash
# Regenerates docs/RESULTS.md (one page: frames beside VTK, speed against accuracy, the targets, a
# table of the detail pages) and docs/bench/ (the detail pages and charts) from one full run on this
# machine: the bricked-volume study and VTK on the same files, the kernels, anti-aliasing and
# motion-order studies, then the matrix, the roofline and the scaling series (about an hour on
# lavapipe). Hand-written commentary lives in docs/results-notes.md and is appended verbatim.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
# The bricked-volume study first (its section is included by the bench's report): the 512³ bonsai
# is made, never committed.
./scripts/large-volumes.sh target/large
cargo run --release --quiet -p voxsplat-lab -- bricks --large target/large/bonsai512.nrrd --lod-chart docs/bench/lod-peer256.svg > docs/bench/bricks.md
./scripts/bricks-vtk.sh >> docs/bench/bricks.md
cargo run --release --quiet -p voxsplat-lab -- kernels --chart docs/bench/kernels.svg > docs/bench/kernels.md
cargo run --release --quiet -p voxsplat-lab -- antialias > docs/bench/antialias.md
cargo run --release --quiet -p voxsplat-lab -- motion-orders > docs/bench/motion-orders.md
./scripts/modes.sh > docs/bench/modes.md
cargo run --release --quiet -p voxsplat-lab -- matrix --out-dir docs/bench --results docs/RESULTS.md "$@"
