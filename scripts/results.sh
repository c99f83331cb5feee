#!/usr/bin/env bash
# Regenerates docs/RESULTS.md and the charts in docs/bench/ from one full benchmark run on this
# machine (the matrix, the roofline and the scaling series; several minutes on lavapipe).
# Hand-written commentary lives in docs/results-notes.md and is appended verbatim.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
# The bricked-volume study first (its section is included by the bench's report): the 512³ bonsai
# is made, never committed.
./scripts/large-volumes.sh target/large
cargo run --release --quiet -- lab bricks --large target/large/bonsai512.nrrd --lod-chart docs/bench/lod-peer256.svg > docs/bench/bricks.md
./scripts/bricks-vtk.sh >> docs/bench/bricks.md
cargo run --release --quiet -- lab kernels --chart docs/bench/kernels.svg > docs/bench/kernels.md
cargo run --release --quiet -- lab antialias > docs/bench/antialias.md
cargo run --release --quiet -- lab motion-orders > docs/bench/motion-orders.md
cargo run --release --quiet -- lab matrix --out-dir docs/bench --results docs/RESULTS.md "$@"
