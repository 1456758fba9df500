#!/usr/bin/env bash
# Renders the golden images that tests/test_golden_images.cpp compares against, bit for bit.
# They were made once, by the per-pixel estimator core at commit d26934e (before the
# integrator architecture of issue 14), and must never be re-made to make a test pass: an
# integrator refactoring that changes any of them has changed an estimator's result.
# Re-made once, from the same commit d26934e, when Embree was pinned to its AVX2 kernels
# (src/geometry/accel.cpp): the first set came from a machine whose Embree ran AVX-512 kernels,
# which round hit points differently in the last bits, so 52 of these images could not be
# reproduced on an AVX2-only machine. d26934e with that one line patched rendered this set, and
# the code of issue 35 (integrators written once) renders all 138 bit for bit the same.
# The rough materials' images (roughconductor-beckmann, roughconductor, roughdielectric,
# roughplastic: 36 files) were re-made on 2026-12-05 by the code of that day, with
# `tests/data/golden/make.sh build/pathlab rough`, when those materials changed (not an
# estimator): shadowing-masking became Mitsuba 3's separable G1(wi) G1(wo) and roughplastic took
# Mitsuba 3's coating tables, so that Mitsuba's render tests pass (docs/scene-format.md). Every
# other image is still the d26934e one.
# Usage (from the repository root, with that commit built): tests/data/golden/make.sh build/pathlab [FILTER]
# (FILTER: only the images whose file name contains it)
set -euo pipefail
bin=${1:-build/pathlab}
filter=${2:-}
out=tests/data/golden
algorithms=(eyelight direct-light direct-uniform direct-cosine direct-brdf direct-mis pt-naive pt-mis3 pt-mis)
files=(example materials/plastic materials/roughconductor-beckmann materials/roughconductor materials/roughdielectric
       materials/roughplastic materials/smooth)
for a in "${algorithms[@]}"; do
  for s in 0 1 2 3 4 5 6 7; do
    [[ "$s-$a.pfm" == *"$filter"* ]] || continue
    "$bin" -q --scene "$s" -a "$a" --resolution 16x16 --spp 4 --seed 7 -o "$out/$s-$a.pfm"
  done
  for f in "${files[@]}"; do
    [[ "$(basename "$f")-$a.pfm" == *"$filter"* ]] || continue
    "$bin" -q --scene "scenes/$f.xml" -a "$a" --resolution 16x12 --spp 4 --seed 7 -o "$out/$(basename "$f")-$a.pfm"
  done
done
# The Sobol sampler, depth limits and Russian roulette settings.
[ -z "$filter" ] || exit 0
"$bin" -q --scene 3 -a pt-mis --sampler sobol --resolution 16x16 --spp 8 --seed 7 -o "$out/3-pt-mis-sobol.pfm"
"$bin" -q --scene 5 -a pt-mis3 --max-depth 2 --rr-depth 0 --resolution 16x16 --spp 8 --seed 7 -o "$out/5-pt-mis3-depth2-rr0.pfm"
"$bin" -q --scene scenes/materials/smooth.xml -a pt-naive --max-depth 5 --resolution 16x12 --spp 8 --seed 7 -o "$out/smooth-pt-naive-depth5.pfm"
