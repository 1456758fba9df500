#!/usr/bin/env bash
# Fuzzes pathlab's readers of untrusted files with libFuzzer (clang, AddressSanitizer, UBSan).
#   scripts/fuzz.sh TARGET [SECONDS]   TARGET: scene_xml, exr, hdr, pfm, png, jpeg, bmp, obj, vol, vdb, ies, ply,
#                                      serialized, spd, checkpoint, or all
#                                      (all: each target in turn for SECONDS); default 660 s
#   scripts/fuzz.sh [SECONDS]          the scene-file loader, as before (scene_xml)
# Seeds: the shipped scenes, meshes and IES files, images and meshes written by fuzz_make_seeds
# (pathlab's own writers and the libraries it links), and the regression corpora under tests/data/.
# Crashing or hanging inputs are written to build-fuzz/crashes/TARGET-*; once fixed, copy them
# to tests/data/xml_regressions/, tests/data/image_regressions/, tests/data/obj_regressions/ or
# tests/data/vol_regressions/ or tests/data/ies_regressions/,
# where `make test` keeps loading them. Each run's log is build-fuzz/fuzz-TARGET.log and its
# figures (executions, exec/s, coverage) are summarised at the end.
# On a shared machine run it as `nice -n 19 scripts/fuzz.sh ...`.
set -euo pipefail
cd "$(dirname "$0")/.."

all_targets=(scene_xml exr hdr pfm png jpeg bmp obj vol vdb ies ply serialized spd checkpoint)
if [[ $# -eq 0 || $1 =~ ^[0-9]+$ ]]; then
    targets=(scene_xml)
    seconds=${1:-660}
else
    case $1 in
        all) targets=("${all_targets[@]}") ;;
        scene_xml | exr | hdr | pfm | png | jpeg | bmp | obj | vol | vdb | ies | ply | serialized | spd | checkpoint) targets=("$1") ;;
        *) echo "fuzz.sh: unknown target '$1' (valid: ${all_targets[*]}, all)" >&2; exit 2 ;;
    esac
    seconds=${2:-660}
fi
[[ $seconds =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2; }

if ! command -v clang++ >/dev/null; then
    sudo_cmd=""; [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
    $sudo_cmd apt-get update && $sudo_cmd apt-get install -y --no-install-recommends clang
fi
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ "${launcher[@]}" \
    -DPATHLAB_BUILD_FUZZ=ON -DPATHLAB_BUILD_TESTS=OFF -DPATHLAB_BUILD_BENCH=OFF
build_targets=()
for t in "${targets[@]}"; do build_targets+=("fuzz_$t"); done
[[ ${targets[*]} != scene_xml && ${targets[*]} != ies ]] && build_targets+=(fuzz_make_seeds)
[[ " ${targets[*]} " == *" vdb "* ]] && build_targets+=(fuzz_vdb_fixtures)
cmake --build build-fuzz -j "$(nproc)" --target "${build_targets[@]}"
mkdir -p build-fuzz/crashes

# UBSan reports stop the run (and count as crashes), as ASan's do.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}

seeded=0
make_seeds() {
    if ((seeded == 0)); then
        rm -rf build-fuzz/seeds
        build-fuzz/fuzz/fuzz_make_seeds build-fuzz/seeds
        seeded=1
    fi
}

summaries=()
for t in "${targets[@]}"; do
    max_len=16384
    extra=()
    case $t in
        scene_xml)
            corpus=build-fuzz/corpus  # where the scene-file corpus has always been
            mkdir -p "$corpus"
            cp -n scenes/*.xml tests/data/scenes/*.xml tests/data/scenes/mitsuba/*.xml tests/data/xml_regressions/* "$corpus"/ 2>/dev/null || true
            max_len=4096
            ;;
        obj)
            # tinyobjloader triangulates a polygon in time quadratic in its size: long inputs
            # are mostly slow, not new.
            max_len=4096
            corpus=build-fuzz/corpus-obj
            mkdir -p "$corpus"
            make_seeds
            cp -n scenes/meshes/*.obj build-fuzz/seeds/obj/* "$corpus"/ 2>/dev/null || true
            cp -n tests/data/obj_regressions/* "$corpus"/ 2>/dev/null || true
            ;;
        vol)
            corpus=build-fuzz/corpus-vol
            mkdir -p "$corpus"
            make_seeds
            cp -n build-fuzz/seeds/vol/* "$corpus"/ 2>/dev/null || true
            cp -n tests/data/vol_regressions/* "$corpus"/ 2>/dev/null || true
            ;;
        vdb)
            corpus=build-fuzz/corpus-vdb
            mkdir -p "$corpus"
            make_seeds
            build-fuzz/fuzz/fuzz_vdb_fixtures build-fuzz/seeds/vdb
            cp -n build-fuzz/seeds/vdb/* "$corpus"/ 2>/dev/null || true
            # OpenVDB leaks the node it was reading when the file ends inside it (the stream
            # throws; RootNode::readTopology holds it by a raw pointer): one node per refused
            # file, theirs, so leaks are not reported for this target.
            extra=(-detect_leaks=0)
            ;;
        ply | serialized)
            corpus=build-fuzz/corpus-$t
            mkdir -p "$corpus"
            make_seeds
            cp -n build-fuzz/seeds/"$t"/* tests/data/scenes/mitsuba/meshes/*."$t" "$corpus"/ 2>/dev/null || true
            ;;
        ies)
            corpus=build-fuzz/corpus-ies
            mkdir -p "$corpus"
            cp -n tests/data/ies/*.ies scenes/ies/*.ies "$corpus"/ 2>/dev/null || true
            cp -n tests/data/ies_regressions/* "$corpus"/ 2>/dev/null || true
            ;;
        *)
            corpus=build-fuzz/corpus-$t
            mkdir -p "$corpus"
            make_seeds
            cp -n build-fuzz/seeds/"$t"/* "$corpus"/ 2>/dev/null || true
            cp -n tests/data/image_regressions/*."$t" "$corpus"/ 2>/dev/null || true
            if [[ $t == jpeg ]]; then cp -n tests/data/image_regressions/*.jpg "$corpus"/ 2>/dev/null || true; fi
            ;;
    esac
    dict=fuzz/$t.dict
    echo "fuzz.sh: $t for $seconds s (corpus $corpus, dictionary $dict)"
    status=0
    build-fuzz/fuzz/fuzz_"$t" "$corpus" -dict="$dict" -max_total_time="$seconds" -max_len="$max_len" -timeout=10 \
        -rss_limit_mb=2048 -artifact_prefix=build-fuzz/crashes/"$t"- -print_final_stats=1 "${extra[@]}" 2>&1 | tee build-fuzz/fuzz-"$t".log ||
        status=$?
    log=build-fuzz/fuzz-$t.log
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
    ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
    result=$([[ $status -eq 0 ]] && echo "no crash" || echo "FAILED (exit $status, see build-fuzz/crashes/$t-*)")
    summaries+=("$t: $seconds s, ${execs:-?} executions, ${rate:-?} exec/s, coverage ${cov:-?} edges (${ft:-?} features), $result")
    [[ $status -eq 0 ]] || break
done
echo
printf 'fuzz.sh: %s\n' "${summaries[@]}"
for s in "${summaries[@]}"; do [[ $s == *FAILED* ]] && exit 1; done
exit 0
