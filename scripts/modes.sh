#!/usr/bin/env bash
# The rendering modes' page (docs/bench/modes.md) and charts (docs/bench/modes-*.svg): each mode's
# default frame of the gallery's bonsai and stent at 512² beside the ray caster in the same mode,
# speed against accuracy (`voxsplat-lab modes`, one process; absolute times are this machine's).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
target/release/voxsplat-lab modes --size 512 --frames 5 --charts docs/bench > docs/bench/modes.md
