#!/usr/bin/env bash
# voxsplat's benchmark on a machine with a GPU but no Rust and no internet (docs/BENCHMARK.md).
#   scripts/gpu-bench.sh stage   here: build the release binary and put it, the Vulkan loader and
#                                validation-layer packages and the data into .gpubench/ and .gl/
#                                (both git-excluded), to carry to the GPU machine
#   scripts/gpu-bench.sh run     there, from the repository root: unpack the loaders, describe the
#                                device, run the quick suite once with validation (a first pass:
#                                any message fails it), once under best practices and once under
#                                GPU-assisted validation, then the full suite for timings; reports in
#                                .gpubench/out (or $OUT when set)
# With the device tool: run `scripts/gpu-bench.sh stage` here, then
#   run(command="bash scripts/gpu-bench.sh run", carry=[".gpubench", ".gl"])
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
stage)
  cargo build --release -p voxsplat-cli
  grep -qx '/.gpubench/' .git/info/exclude 2>/dev/null || echo /.gpubench/ >>.git/info/exclude
  grep -qx '/.gl/' .git/info/exclude 2>/dev/null || echo /.gl/ >>.git/info/exclude
  rm -rf .gpubench && mkdir -p .gpubench/data .gl /tmp/amd64/partial
  cp target/release/voxsplat .gpubench/
  data=${VOXSPLAT_DATA:-../shared/data}
  for d in bonsai stent heptane rmnp; do cp -r "$data/$d" .gpubench/data/; done
  if ! ls .gl/libvulkan1_*.deb >/dev/null 2>&1; then
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    # shellcheck disable=SC2086
    apt-get $o update >/dev/null
    # shellcheck disable=SC2086
    (cd .gl && apt-get $o download libvulkan1 vulkan-validationlayers >/dev/null)
  fi
  du -sh .gpubench .gl
  ;;
run)
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
  b=.gpubench/voxsplat
  export VOXSPLAT_DATA=$PWD/.gpubench/data
  out=${OUT:-.gpubench/out}
  mkdir -p "$out"
  # The loader may not find NVIDIA's ICD by itself (the device tool's README): point at it.
  icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  if [ -f "$icd" ] && { ! $b device >/dev/null 2>&1 || $b device | grep -q '(Cpu'; }; then
    export VK_DRIVER_FILES=$icd
  fi
  $b device | tee "$out/device.txt"
  $b device --toml >"$out/device.toml"
  cache=.gpubench/cache
  # Validation first: every case drawn once with the Khronos layer; a message fails the case.
  $b bench --quick --validation --warmup 0 --frames 1 --cache "$cache" --json "$out/validation.json" \
    2>&1 | tee "$out/validation.txt"
  # The layer's extra checks (docs/RELIABILITY.md, "The validation layer's extra checks"): best
  # practices with NVIDIA's own, and GPU-assisted validation with the buffer bounds lavapipe
  # cannot build. A finding is recorded, and the times still run.
  sed 's/gpuav_buffer_oob = false/gpuav_buffer_oob = true/' tests/validation/gpu-assisted.txt >"$out/gpu-assisted.txt"
  for s in "$PWD/tests/validation/best-practices.txt" "$(cd "$out" && pwd)/gpu-assisted.txt"; do
    n=$(basename "$s" .txt)
    VK_LAYER_SETTINGS_PATH=$s $b bench --quick --validation --warmup 0 --frames 1 --cache "$cache" \
      --json "$out/layers-$n.json" 2>&1 | tee "$out/layers-$n.txt" || echo "layers $n: findings above"
  done
  # Then the times: the whole suite, its made volumes kept in the cache between calls.
  $b bench --cache "$cache" --json "$out/full.json" ${BENCH_ARGS:-} 2>&1 | tee "$out/full.txt"
  ;;
*)
  echo "usage: scripts/gpu-bench.sh stage|run" >&2
  exit 2
  ;;
esac
