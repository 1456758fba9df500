#!/bin/bash
# Mitsuba 3's render-test suite, judged as its src/render/tests/test_renders.py judges it, with
# pathlab as the renderer. DIR is a checkout of github.com/mitsuba-renderer/mitsuba-data (its
# tests/scenes and common folders; nothing of it is part of pathlab).
#
# For every DIR/tests/scenes/*/NAME_INTEGRATOR.xml with a reference refs/NAME_ref_rgb.exr and
# its per-sample variance refs/NAME_ref_rgb_var.exr: render with -D integrator=INTEGRATOR at
# spp = 2e6 / pixels, seed 0, and judge with `pathlab compare --z-test` (a z-test per pixel and
# channel in XYZ, Sidak-corrected alpha 0.01, pass when 99.75% of the pixel-channels pass).
# One line per scene, then a summary; the renders are kept in OUT (default: a temporary folder).
#
# The z-test divides by the variance of Mitsuba's estimator, so an unbiased estimator that is
# noisier fails it. By default the scenes are rendered with Mitsuba 3's estimator choices where
# pathlab's differ: lights chosen uniformly (--light-sampler uniform; pathlab's default picks
# them by power), the power heuristic (--mis power) in path, direct and volpath, as Mitsuba's
# path tracers weigh their samples, and Russian roulette from Mitsuba's default depth (rr_depth
# 5; pathlab's own starts after 3 bounces, which adds variance to the rare long paths of the
# media scenes). --pathlab-defaults renders with pathlab's own defaults
# instead (the same expected image, other variances).
#
# Usage: scripts/mitsuba-suite.sh DIR [OUT] [--pathlab-defaults] [-- extra pathlab options, e.g. --threads 2]
set -u
usage="usage: $0 MITSUBA_DATA_DIR [OUT] [--pathlab-defaults] [-- pathlab options]  (MITSUBA_DATA_DIR/tests/scenes must exist)"
if [ $# -lt 1 ] || [ ! -d "$1/tests/scenes" ]; then
    echo "$usage" >&2
    exit 2
fi
data=$(cd "$1" && pwd)
shift
out=""
as_mitsuba=1
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    case "$1" in
        --pathlab-defaults) as_mitsuba=0 ;;
        -*) echo "$0: unknown option '$1'" >&2; echo "$usage" >&2; exit 2 ;;
        *) [ -z "$out" ] || { echo "$usage" >&2; exit 2; }; out=$1 ;;
    esac
    shift
done
[ $# -gt 0 ] && [ "$1" = "--" ] && shift
here=$(cd "$(dirname "$0")/.." && pwd)
pathlab=${PATHLAB:-$here/build/pathlab}
[ -x "$pathlab" ] || { echo "$0: $pathlab is not built (make, or set PATHLAB)" >&2; exit 2; }
[ -n "$out" ] || out=$(mktemp -d)
mkdir -p "$out"

pass=0 fail=0 broken=0 skipped=0
if [ $as_mitsuba -eq 1 ]; then
    echo "estimators: Mitsuba 3's choices (lights chosen uniformly, the power heuristic; --pathlab-defaults for pathlab's)"
else
    echo "estimators: pathlab's defaults"
fi
printf '%-58s %-14s %s\n' "scene" "result" "detail"
for scene in "$data"/tests/scenes/*/*.xml; do
    folder=$(dirname "$scene")
    name=$(basename "$scene" .xml)
    integrator=${name##*_}
    base=${name%_*}
    ref=$folder/refs/${base}_ref_rgb.exr
    var=$folder/refs/${base}_ref_rgb_var.exr
    label=$(basename "$folder")/$name
    if [ ! -f "$ref" ] || [ ! -f "$var" ]; then
        printf '%-58s %-14s %s\n' "$label" "SKIP" "no refs/${base}_ref_rgb.exr with its _var"
        skipped=$((skipped + 1))
        continue
    fi
    size=$("$pathlab" info "$ref" | head -1 | sed -n 's/.*: \([0-9]*\)x\([0-9]*\) .*/\1 \2/p')
    read -r w h <<<"$size"
    spp=$((2000000 / (w * h)))
    img=$out/$(basename "$folder")-$name.exr
    start=$(date +%s.%N)
    choices=()
    if [ $as_mitsuba -eq 1 ]; then
        case "$integrator" in
            # Russian roulette from Mitsuba's default rr_depth 5: its path plays it after bounce 5 on,
            # its volpath after bounce 6 on (at the top of the next iteration, depth > rr_depth).
            path) choices=(--light-sampler uniform --mis power --rr-depth 5) ;;
            volpath | volpathmis) choices=(--light-sampler uniform --mis power --rr-depth 6) ;;
            direct) choices=(--light-sampler uniform --mis power) ;;
        esac
    fi
    if ! err=$("$pathlab" "$scene" -D "integrator=$integrator" --spp "$spp" --seed 0 -q -o "$img" "${choices[@]}" "$@" 2>&1 >/dev/null); then
        printf '%-58s %-14s %s\n' "$label" "CANNOT RENDER" "$(printf '%s' "$err" | grep -m1 -i 'error' | sed "s|$data/||g")"
        broken=$((broken + 1))
        continue
    fi
    seconds=$(echo "$(date +%s.%N) - $start" | bc)
    verdict=$("$pathlab" compare "$img" "$ref" --z-test "$var" --spp "$spp" 2>&1)
    status=$?
    detail=$(printf '%s' "$verdict" | sed -n 's/^\(PASS\|FAIL\): \([0-9.]*%\) of .*; mean of A - B in XYZ \([-+0-9.]*%\) of B.*/\2 pass, mean \3/p')
    [ -n "$detail" ] || detail=$(printf '%s' "$verdict" | head -1)
    detail="$detail, $spp spp, $(printf '%.1f' "$seconds") s"
    if [ $status -eq 0 ]; then
        printf '%-58s %-14s %s\n' "$label" "PASS" "$detail"
        pass=$((pass + 1))
    else
        printf '%-58s %-14s %s\n' "$label" "FAIL" "$detail"
        fail=$((fail + 1))
    fi
done
echo "summary: $pass pass, $fail fail, $broken cannot render, $skipped skipped (renders in $out)"
[ $fail -eq 0 ] && [ $broken -eq 0 ]
