#!/usr/bin/env bash
# Throughput of two pathlab binaries measured in interleaved runs (A, B, A, B, ...), so that a
# change can be judged on a shared machine: medians of samples/s of each and the median of the
# per-pair ratios B / A. EXTRA: more options for both, e.g. --spectral.
#   bench/versus.sh A_BINARY B_BINARY [REPEATS] [SECONDS] [SCENES] [ALGORITHM] [SIZE] [EXTRA]
# e.g. the integrator rework of issue 14 against the commit before it:
#   git worktree add /tmp/pathlab-old d26934e && cmake -S /tmp/pathlab-old -B /tmp/pathlab-old/build \
#     -DPATHLAB_BUILD_TESTS=OFF -DPATHLAB_BUILD_BENCH=OFF && cmake --build /tmp/pathlab-old/build --target pathlab
#   bench/versus.sh /tmp/pathlab-old/build/pathlab build/pathlab 5 4 0,3,5,7 pt-mis
set -euo pipefail
a=$1 b=$2 repeats=${3:-5} seconds=${4:-4} scenes=${5:-0,3,5,7} algorithm=${6:-pt-mis} size=${7:-256} extra=${8:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rate() {  # binary scene -> samples/s
    # shellcheck disable=SC2086  # EXTRA is a list of options
    "$1" -q --scene "$2" -a "$algorithm" --resolution "${size}x${size}" --time "$seconds" --seed 7 $extra \
        --stats "$tmp/s.json" -o "$tmp/i.exr" >/dev/null
    grep -o '"samples_per_second": [0-9.e+-]*' "$tmp/s.json" | awk '{print $2}'
}
median() { sort -g | awk '{v[NR]=$1} END {print (NR % 2) ? v[(NR+1)/2] : (v[NR/2] + v[NR/2+1]) / 2}'; }
echo "| scene | A Msamples/s | B Msamples/s | B / A |"
echo "|---|---|---|---|"
IFS=, read -ra list <<< "$scenes"
for s in "${list[@]}"; do
    : > "$tmp/a"; : > "$tmp/b"; : > "$tmp/r"
    for ((k = 0; k < repeats; ++k)); do
        ra=$(rate "$a" "$s"); rb=$(rate "$b" "$s")
        echo "$ra" >> "$tmp/a"; echo "$rb" >> "$tmp/b"; awk -v x="$ra" -v y="$rb" 'BEGIN {print y / x}' >> "$tmp/r"
    done
    printf '| %s | %.3f | %.3f | %.3f |\n' "$s" "$(median < "$tmp/a" | awk '{print $1 / 1e6}')" \
        "$(median < "$tmp/b" | awk '{print $1 / 1e6}')" "$(median < "$tmp/r")"
done
