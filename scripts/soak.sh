#!/usr/bin/env bash
# The 1,000-frame soak of docs/RELIABILITY.md (CI runs a 100-frame version as a test).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
# A fixed mmap threshold keeps large transient buffers out of the heap (see SoakReport::rss_growth).
MALLOC_ARENA_MAX=1 MALLOC_MMAP_THRESHOLD_=131072 cargo run --release --quiet -- soak --frames "${1:-1000}" --validation
