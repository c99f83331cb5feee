#!/usr/bin/env bash
# Runs every cargo-fuzz target for a fixed number of executions (default 200,000 each) and prints
# the executions and crashes per target; docs/RELIABILITY.md records a run. cargo-fuzz needs
# nightly features: on a stable-only machine RUSTC_BOOTSTRAP=1 enables them.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
runs="${1:-200000}"
export RUSTC_BOOTSTRAP=1
for t in nrrd nifti npy tiff raw toml; do
  mkdir -p "fuzz/corpus/$t"
  if cargo fuzz run "$t" "fuzz/corpus/$t" -- -runs="$runs" -max_len=4096 > "/tmp/fuzz-$t.log" 2>&1; then
    echo "$t: $runs executions, 0 crashes"
  else
    echo "$t: CRASH (see /tmp/fuzz-$t.log and fuzz/artifacts/$t)"
  fi
done
