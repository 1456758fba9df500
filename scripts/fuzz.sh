#!/usr/bin/env bash
# Fuzzes the scene-file loader with libFuzzer (clang, AddressSanitizer, UBSan).
#   scripts/fuzz.sh [SECONDS]     default 660 (11 minutes)
# Crashing inputs are written to build-fuzz/crashes/; copy them to tests/data/xml_regressions/
# once fixed, where `make test` keeps loading them.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-660}
if ! command -v clang++ >/dev/null; then
    sudo_cmd=""; [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
    $sudo_cmd apt-get update && $sudo_cmd apt-get install -y --no-install-recommends clang
fi
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DPATHLAB_BUILD_FUZZ=ON -DPATHLAB_BUILD_TESTS=OFF -DPATHLAB_BUILD_BENCH=OFF
cmake --build build-fuzz -j "$(nproc)" --target fuzz_scene_xml
mkdir -p build-fuzz/corpus build-fuzz/crashes
cp -n scenes/*.xml tests/data/xml_regressions/* build-fuzz/corpus/ 2>/dev/null || true
build-fuzz/fuzz/fuzz_scene_xml build-fuzz/corpus -dict=fuzz/scene_xml.dict -max_total_time="$seconds" \
    -max_len=4096 -timeout=5 -rss_limit_mb=2048 -artifact_prefix=build-fuzz/crashes/ -print_final_stats=1
