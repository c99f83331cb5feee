#!/usr/bin/env bash
# Runs every cargo-fuzz target (fuzz/fuzz_targets: one per loader, the streamed store, image stacks,
# DICOM series, OME-Zarr images and their metadata alone, file names and patterns, terrain
# heights, and the transfer-function, animation, positions and sidecar TOML files) for a fixed
# number of executions (default 1,000,000 each) from its committed seeds and corpus
# (fuzz/seeds/TARGET, fuzz/corpus/TARGET),
# then minimises the corpus (`cargo fuzz cmin`) so what is committed stays small, and prints the
# executions, crashes and corpus size per target; docs/RELIABILITY.md records a run. An input that
# runs past 10 s, or past 2 GB, counts as a crash.
#   scripts/fuzz.sh [RUNS]          FUZZ_TARGETS="nrrd tf" scripts/fuzz.sh 1000   (a subset)
# A crash leaves its input in fuzz/artifacts/TARGET; copy it into fuzz/seeds/TARGET as found-NAME once
# fixed (the corpus is minimised and may drop it), and
# tests/fuzz_corpus.rs replays it on every CI run. fuzz/seeds/make.py rewrites the seed files.
# cargo-fuzz needs nightly features: on a stable-only machine RUSTC_BOOTSTRAP=1 enables them.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
runs="${1:-1000000}"
export RUSTC_BOOTSTRAP=1
all="nrrd nifti npy tiff raw slices heights tf animation positions sidecar stacks dicom zarr zarr_meta names"
for t in ${FUZZ_TARGETS:-$all}; do
  log="/tmp/fuzz-$t.log"
  mkdir -p "fuzz/corpus/$t"
  if cargo fuzz run "$t" "fuzz/corpus/$t" "fuzz/seeds/$t" -- -runs="$runs" -max_len=4096 -rss_limit_mb=2048 -timeout=10 > "$log" 2>&1; then
    done_runs=$(grep -o "Done [0-9]* runs" "$log" | grep -o "[0-9]*" || echo "?")
    cargo fuzz cmin "$t" "fuzz/corpus/$t" -- -max_len=4096 >> "$log" 2>&1
    echo "$t: $done_runs executions, 0 crashes, $(ls "fuzz/corpus/$t" | wc -l) corpus files"
  else
    echo "$t: CRASH (see $log and fuzz/artifacts/$t)"
  fi
done
