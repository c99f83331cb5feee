#!/usr/bin/env bash
# The 1,000-frame soak of docs/RELIABILITY.md (CI runs shorter versions as tests): once without the
# validation layer (host RSS and GPU allocations must stay flat after warm-up) and once with it
# (no message may appear; the layer's own bookkeeping grows a little per frame).
# A fixed mmap threshold and one malloc arena keep glibc from adding one-off steps that are not
# leaks (see SoakReport::rss_growth).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
frames="${1:-1000}"
cargo build --release --quiet
export MALLOC_ARENA_MAX=1 MALLOC_MMAP_THRESHOLD_=131072
echo "== without validation"
./target/release/voxsplat-lab soak --frames "$frames"
echo "== with validation"
./target/release/voxsplat-lab soak --frames "$frames" --validation
