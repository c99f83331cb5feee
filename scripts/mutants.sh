#!/usr/bin/env bash
# Mutation check (issues 25, 44): plants thirty-one known bugs one at a time, runs the tests that should
# catch each, and prints a markdown table; exits 1 when a bug survives (no test failed). Each
# mutant costs a release rebuild of the library and one test binary: incremental (below), about
# 15-30 s each here after the first; the last result lives in docs/RELIABILITY.md. The tree is
# restored after every mutant, also on Ctrl-C.
#   scripts/mutants.sh            all thirty-one
#   scripts/mutants.sh octant     the ones whose name contains "octant"
#   scripts/mutants.sh --sample N N of them in a row, starting where the commit's hash points, so
#                                 successive commits cover the whole list (CI runs 6: thirty
#                                 cost ~23 minutes of its 90, see docs/RELIABILITY.md)
set -euo pipefail
cd "$(dirname "$0")/.."
# Each mutant changes a line or two of the library: rustc's incremental cache rebuilds only the
# code units that changed (measured here: 65 s a mutant without it, 16-24 s with it after the
# first). Dependencies are never built incrementally, so this rebuilds none of them.
export CARGO_INCREMENTAL=1
# name | file | exact text (must occur once) | replacement | cargo test arguments
MUTANTS=(
  "swap the octant order|src/order.rs|for octant in 0..8u32 {|for octant in (0..8u32).rev() {|-p voxsplat --lib tests::order::"
  "drop (k/d)^2|src/cpu/splat_params.rs|let mut energy = 1.0 / (scale * scale * grow * grow);|let mut energy = 1.0 / (grow * grow);|-p voxsplat --lib tests::aa::"
  "off-by-one in the tile bins|src/cpu/tile.rs|            for tx in x0..=x1 {|            for tx in x0..x1 {|-p voxsplat --lib tests::raster::early_termination_in_the_tile_compositor"
  "skip a stage (tile offsets)|src/recording.rs|        e.run(&Dispatch::new(StageId::TileOffsets, Only, [1, 1, 1], List::Order, bytes)?)?;|        let _ = StageId::TileOffsets;|-p voxsplat --lib tests::raster::compute_raster_is_bit_identical"
  "wrong blend equation (alpha)|src/cpu/composite.rs|                        a + (1.0 - a) * acc[3],|                        a + acc[3],|-p voxsplat --lib tests::gpu::gpu_matches_cpu_mirror_for_every"
  "stale TF (no new classification)|src/bricks.rs|        self.classification = next_classification();\n        Ok(())|        Ok(())|-p voxsplat --lib tests::lod::the_pyramid_follows_the_classification"
  "boxes composited nearest first|src/distributed.rs|        s.plane >= split[s.axis]|        s.plane < split[s.axis]|--features mpi --test commands distributed::one_two"
  "world eye into the grid frame by the rotation, not its inverse|src/orient.rs|(self.rotation.transpose() * (p.as_dvec3() - self.center)).as_vec3()|(self.rotation * (p.as_dvec3() - self.center)).as_vec3()|-p voxsplat --lib tests::orient::a_sheared_grid_renders"
  "a sheared grid's eye mapped into index space without the shear|src/volume.rs|        let y = (d.y - h[2] * z) / s.y;|        let y = d.y / s.y;|-p voxsplat --lib tests::orient::the_validator_runs_on_sheared"
  "the occlusion map's box mask shifted a pixel|src/cpu/tile_occlusion.rs|let row = ((1u32 << (zx - ax + 1)) - 1) << ax;|let row = ((1u32 << (zx - ax + 1)) - 1) << ax >> 1;|-p voxsplat --lib tests::bricked::the_occlusion_map"
  "motion-blurred frames drop hidden bricks|src/cpu/brick_hidden.rs|        if f.blur[0] > 0.0 {|        if f.blur[0] > 1e30 {|-p voxsplat --lib tests::bricked::motion_blurred"
  "a value range's span in f32 (overflows)|src/classify.rs|let span = if hi > lo { hi as f64 - lo as f64 } else { 1.0 };|let span = if hi > lo { (hi - lo) as f64 } else { 1.0 };|-p voxsplat --lib tests::hostile::ranges_wider"
  "NRRD byte skip read as data|src/loaders/nrrd.rs|if value != \"0\" =>|if false =>|-p voxsplat --lib tests::hostile::nrrd_skips"
  "a TF point's third element dropped|src/classify.rs|if s.next_element::<IgnoredAny>()?.is_some() {|if false && s.next_element::<IgnoredAny>()?.is_some() {|-p voxsplat --lib tests::hostile::transfer_function_points"
  "a partial brick stored as uniform|src/bricks/build.rs|if count as usize == BRICK_VOXELS && qmin == qmax {|if qmin == qmax {|-p voxsplat --lib tests::bricks::uniform"
  "the cull margin widened by anti-aliasing|src/cpu/splat_params.rs|let mut visible = clear >= CULL_RADII * base;|let mut visible = clear >= CULL_RADII * base * cell_footprint_scale(frame, depth, cell);|-p voxsplat --lib tests::aa::anti_aliasing_never"
  "a slab's depth profile widened by anti-aliasing|src/cpu/footprint.rs|/ (1.0 + p.screen[1].abs()) / p.screen[3];|/ (1.0 + p.screen[1].abs());|-p voxsplat --lib tests::aa::slab_mode"
  "shells counted away from the eye on its low side|src/order.rs|if b[a] < split[a] { split[a] - 1 - b[a] } else|if b[a] < split[a] { b[a] } else|-p voxsplat --lib tests::bricked::waves_front"
  "a mask word's count taken past it|src/bricks.rs|below[i] = below[i - 1] + words[i - 1].count_ones();|below[i] = below[i - 1] + words[i].count_ones();|-p voxsplat --lib tests::bricked::gpu_frames_match"
  "a voxel's stored differences one-sided|src/bricks/gradients.rs|block[i + s] - block[i - s]|block[i + s] - block[i]|-p voxsplat --lib tests::bricks::every_stored_voxel"
  "a voxel's differences read a record on, on the device|glsl/shared/brick.glsl|    uint i = gradients[h] + rank;|    uint i = gradients[h] + rank + 1u;|-p voxsplat --lib tests::bricked::gpu_frames_match"
  "a projection's maximum taken as a sum|src/cpu/tile_composite.rs|acc = [acc[0].max(q.emit[0] * w), acc[1].max(w), acc[2], acc[3]];|acc = [acc[0] + q.emit[0] * w, acc[1] + w, acc[2], acc[3]];|-p voxsplat --lib tests::modes::an_axis_aligned"
  "the host's depth ignored on the device|glsl/tile_composite.comp|live = q.inv2.w <= host_depth[uint(xy.y) * size.x + uint(xy.x)];|live = true;|-p voxsplat --lib tests::depth::a_plane"
  "a hidden label drawn|src/labels.rs|Some(l) if l.visible && l.opacity > 0.0 =>|Some(l) if l.opacity > 0.0 =>|-p voxsplat --lib tests::labels::labels_are_never"
  "an isosurface row's first cell skipped (the grid's low faces open)|src/cpu/iso_count.rs|            for c in b * seg..cells.min((b + 1) * seg) {|            for c in (b * seg).max(1)..cells.min((b + 1) * seg) {|-p voxsplat --lib tests::iso::surface_lies"
  "an isosurface pixel's visible depth from any disc|src/cpu/tile_composite.rs|if w >= SURFACE_VISIBLE * inputs.table[0] {|if w > 0.0 {|-p voxsplat --lib tests::iso::surface_lies"
  "an isosurface's cells counted and listed with those wholly inside, on the device|glsl/shared/iso.glsl|            if (m != 0u && m != 255u) {|            if (m != 0u) {|-p voxsplat --lib tests::iso::gpu_matches"
  "MIP's footprints at the kernel's full radius, on the device|glsl/shared/params.glsl|base *= PROJECT_SHRINK;|base *= 1.0;|-p voxsplat --lib tests::modes::an_axis_aligned"
  "a voxel beyond a clipping plane claims a texel, on the device|glsl/shared/texels.glsl|            if (dot(frame.clip[i].xyz, p) + frame.clip[i].w < 0.0) return false;|            if (false) return false;|-p voxsplat --lib tests::modes::a_projection_s_texels_keep_the_clipping_planes"
  "a texel kept by its last claim, not its largest|src/cpu/project_texels.rs|out.texels[t] = out.texels[t].max(claim_of(inputs, ijk, rec >> 16));|out.texels[t] = claim_of(inputs, ijk, rec >> 16);|-p voxsplat --lib tests::modes::an_axis_aligned_projection_of_a_store_draws_one_voxel_a_column"
  "a coarse cell's neighbours not counted, on the device|glsl/brick_pyramid.comp|    edge_errors(1u, lane);|    ;|-p voxsplat --lib tests::lod::the_cut_sees_a_blocky_silhouette"
)
filter=${1:-}
sample=0
if [[ $filter == --sample ]]; then
  sample=${2:?mutants.sh: --sample takes a count}
  filter=
fi
total=${#MUTANTS[@]}
if (( sample > 0 && sample < total )); then
  # The commit's hash picks the first; without git (a tarball) the first is the list's first.
  hash=$(git rev-parse --short=8 HEAD 2>/dev/null || echo 0)
  first=$(( 16#$hash % total ))
  picked=()
  for (( i = 0; i < sample; i++ )); do picked+=("${MUTANTS[(first + i) % total]}"); done
  MUTANTS=("${picked[@]}")
  echo "mutants.sh: $sample of $total, from number $((first + 1)) (commit $hash)"
fi
backup=$(mktemp -d)
restore() {
  for p in "$backup"/*.path; do [ -e "$p" ] && cp "${p%.path}" "$(cat "$p")"; done
  rm -rf "$backup"
}
trap restore EXIT
echo "| bug | file | tests | result | seconds |"
echo "|---|---|---|---|---:|"
survived=0
for m in "${MUTANTS[@]}"; do
  IFS='|' read -r name file from to tests <<< "$m"
  [[ -n $filter && $name != *$filter* ]] && continue
  key=$(echo "$file" | tr / _)
  cp "$file" "$backup/$key" && echo "$file" > "$backup/$key.path"
  python3 - "$file" "$from" "$to" <<'PY'
import sys
path, old, new = sys.argv[1], sys.argv[2].replace("\\n", "\n"), sys.argv[3].replace("\\n", "\n")
text = open(path).read()
if text.count(old) != 1:
    sys.exit(f"mutants.sh: '{old}' occurs {text.count(old)} times in {path}: update the mutant")
open(path, "w").write(text.replace(old, new))
PY
  start=$(date +%s)
  # shellcheck disable=SC2086
  if cargo test --release -q $tests > "target/mutant.log" 2>&1; then
    # A filter that names no test runs none and passes: that is the list's fault, not a survivor.
    if ! grep -qE "test result: ok\. [1-9]" target/mutant.log; then
      result="**ran no test: the filter names none**"
    else
      result="**survived**"
    fi
    survived=1
  elif grep -q "^error\[E" target/mutant.log; then
    result="**did not compile**"; survived=1
  else
    # The first failing test, from the "failures:" list (`cargo test -q` prints no per-test lines).
    first=$(grep -m1 -E "^    [a-z0-9_:]+$" target/mutant.log | tr -d ' ' || true)
    failed=$(grep -cE "^    [a-z0-9_:]+$" target/mutant.log || true)
    result="caught: \`$first\` (failing tests listed: $failed)"
  fi
  cp "$backup/$key" "$file" && rm "$backup/$key" "$backup/$key.path"
  echo "| $name | \`$file\` | \`cargo test $tests\` | $result | $(( $(date +%s) - start )) |"
done
exit $survived
