#!/usr/bin/env bash
# The defaults on volumes nobody tuned them for (issue 75): each member of scripts/family.py's
# family, at each size and view, drawn with the defaults and with --lod off, both scored against
# the supersampled CPU ray caster (`voxsplat-lab render --raycast 0.25 --raycast-stop 1e-4 --cpu --supersample
# K`, K x K rays a pixel: $K, or by default 512 / size and at least 2, times side / 512 past 512
# voxels a side, so that a volume's thumbnail still has a ray for about every voxel across) by PSNR over the covered pixels (`voxsplat compare`'s first figure), with the median frame
# time of $FRAMES frames (stage times summed). Prints a markdown table; a row whose default lies
# more than 1 dB below --lod off's PSNR and under 50 dB is marked MISS; past the ray casters' 2^28
# voxels the reference is cast clump by clump, a clump past 2^27 voxels tile by tile
# (scripts/sparse-truth.py; needs python's OpenEXR), or,
# where that cannot be done, the default is scored against --lod off's frame (no reference).
#   SMALL=1 WORK=target/family-small SIZES="32 128 512" VIEWS="auto anterior grazing" ONLY=bonsai-nn2,shell scripts/family-bench.sh
set -euo pipefail
cd "$(dirname "$0")/.."
WORK=${WORK:-target/family}
FRAMES=${FRAMES:-3}
SIZES=${SIZES:-"32 128 512"}
VIEWS=${VIEWS:-"auto anterior grazing"}
EXTRA=${EXTRA:-}
# VS: another build of voxsplat to draw the frames with (the references are cached in $WORK).
if [ -z "${VS:-}" ]; then cargo build --release --quiet -p voxsplat-cli -p voxsplat-lab; fi
vs=${VS:-./target/release/voxsplat}
# `render` with the research switches (--repeat, the reference's settings): the lab beside it.
lab=$(dirname "$vs")/voxsplat-lab
# SMALL=1: the small family (crops; what the CI test draws).
args=()
[ -n "${ONLY:-}" ] && args+=(--only "$ONLY")
[ -n "${SMALL:-}" ] && args+=(--small)
members=$(python3 scripts/family.py "$WORK" --vs "$vs" "${args[@]}")
psnr() { $vs compare "$1" "$2" | awk '/^psnr:/ {print $2}'; }
# The grazing view: from the patient's right, nearly along the x axis (10 degrees up, 6 across),
# so the faces along x are seen edge-on; the family's files are in LPS patient space (RAS here).
view_flags() { # view file
  case "$1" in
    grazing) python3 - "$2" <<'PY'
import re, sys
head = open(sys.argv[1], "rb").read(4096).split(b"\n\n")[0].decode()
n = [int(v) for v in re.search(r"sizes: (.*)", head).group(1).split()]
s = [float(v) for v in re.findall(r"\(([-0-9.e]+),0,0\)|\(0,([-0-9.e]+),0\)|\(0,0,([-0-9.e]+)\)", head) for v in v if v]
c = [-(n[0] - 1) * s[0] / 2, -(n[1] - 1) * s[1] / 2, (n[2] - 1) * s[2] / 2]
d = 1.9 * max(k * t for k, t in zip(n, s))
e = [c[0] + 0.98 * d, c[1] + 0.1 * d, c[2] + 0.17 * d]
print("--eye %.3f,%.3f,%.3f --target %.3f,%.3f,%.3f" % (*e, *c))
PY
    ;;
    *) echo "--view $1" ;;
  esac
}
frame() { # out flags... -> median ms
  local out=$1; shift
  # shellcheck disable=SC2068
  $lab render "$@" --repeat "$FRAMES" --timings --out "$out" 2>&1 | awk '/ ms$/ {s += $2} END {printf "%.0f", s}'
}
echo "| volume | size | view | default dB | --lod off dB | default ms | --lod off ms | ratio | |"
echo "|---|---:|---|---:|---:|---:|---:|---:|---|"
while IFS='|' read -r name file tf; do
  for size in $SIZES; do
    for view in $VIEWS; do
      # shellcheck disable=SC2046
      common=(--volume "$file" --tf "$tf" --size "${size}x${size}" $(view_flags "$view" "$file"))
      # Past 512 voxels a side, proportionally more (the 1024^3 field at 512^2: 2 x 2 rays lie
      # 54 dB from 4 x 4, where its voxels are a quarter of a pixel).
      side=$(head -c 1024 "$file" | awk '/^sizes:/ { m = 0; for (i = 2; i <= NF; i++) if ($i > m) m = $i; print m; exit }')
      k=${K:-$(( (512 / size > 2 ? 512 / size : 2) * (side > 512 ? side / 512 : 1) ))}
      ref="$WORK/truth-$name-$size-$view-k$k.exr"
      # The ray casters hold at most 2^28 voxels. Past that (the sparse 1024^3 field) the reference
      # is cast clump by clump (scripts/sparse-truth.py: each clump of voxels cut out and cast on
      # its own, the frames composited in depth order), and every frame of the row is drawn with
      # the view's camera made explicit (a --view would frame each clump on its own). Where that
      # cannot be done either, the default is scored against --lod off's frame and the row says so.
      against=""
      crops="$WORK/truth-$name-$size-$view-k$k-crops.exr"
      if [ -f "$crops" ] || { [ ! -f "$ref" ] &&
        ! $lab render "${common[@]}" --raycast 0.25 --raycast-stop 1e-4 --cpu --supersample "$k" \
          --out "$ref" >/dev/null 2>"$WORK/err.txt"; }; then
        if [ ! -f "$crops" ]; then
          grep -q "too large" "$WORK/err.txt" || { echo "| $name | $size | $view | refused: $(head -c 120 "$WORK/err.txt" | tr '\n|' '  ') | | | | | |"; continue; }
        fi
        # shellcheck disable=SC2046
        if cam=$(python3 scripts/sparse-truth.py "$file" --camera --tf "$tf" --vs "$lab" -- --size "${size}x${size}" $(view_flags "$view" "$file") 2>"$WORK/err.txt"); then
          # shellcheck disable=SC2206
          common=(--volume "$file" --tf "$tf" $cam)
          ref=$crops
          [ -f "$ref" ] || python3 scripts/sparse-truth.py "$file" "$ref" --tf "$tf" --vs "$lab" --work "$WORK/crops" -- \
            "${common[@]:4}" --raycast 0.25 --raycast-stop 1e-4 --cpu --supersample "$k" 2>>"$WORK/err.txt" || ref=""
        else
          ref=""
        fi
        [ -n "$ref" ] || against=" (against --lod off)"
      fi
      # shellcheck disable=SC2086
      d_ms=$(frame "$WORK/default.exr" "${common[@]}" $EXTRA)
      o_ms=$(frame "$WORK/off.exr" "${common[@]}" --lod off)
      if [ -n "$against" ]; then
        d="$(psnr "$WORK/default.exr" "$WORK/off.exr")$against"
        o="-"
      else
        d=$(psnr "$WORK/default.exr" "$ref")
        o=$(psnr "$WORK/off.exr" "$ref")
      fi
      mark=$(awk -v d="$d" -v o="$o" 'BEGIN { if (o == "-") print "no reference"; else if (d != "inf" && d < o - 1 && d < 50) print "MISS" }')
      ratio=$(awk -v a="$d_ms" -v b="$o_ms" 'BEGIN { if (b > 0) printf "%.2f", a / b }')
      echo "| $name | $size | $view | $d | $o | $d_ms | $o_ms | $ratio | $mark |"
    done
  done
done <<< "$members"
