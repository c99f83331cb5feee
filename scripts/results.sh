#!/usr/bin/env bash
# Regenerates docs/RESULTS.md and the charts in docs/bench/ from one full benchmark run on this
# machine (the matrix, the roofline and the scaling series; several minutes on lavapipe).
# Hand-written commentary lives in docs/results-notes.md and is appended verbatim.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
cargo run --release --quiet -- bench --out-dir docs/bench --results docs/RESULTS.md "$@"
