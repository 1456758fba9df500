#!/bin/sh
# RGB images of lt and bdpt rendered at commit 7d99cd4, before spectral mode reached them
# (tests/test_spectral_bidir.cpp, SpectralBidir.RgbImagesAreThoseRenderedBeforeSpectralMode,
# renders them again and compares bit for bit). Run from the repository root with that build.
# Re-made once, from the same commit 7d99cd4 with Embree pinned to its AVX2 kernels (see
# src/geometry/accel.cpp and ../make.sh): the first set came from an AVX-512 machine.
# smooth-bdpt.pfm re-made by the commit that counts Dirac lobes with their coefficients in
# bdpt's MIS weights (issue 36): the weights of paths through its mirror and glass changed (the
# image converges to the same answer: tests/test_bdpt.cpp); the other five are unchanged.
set -e
S=scenes/materials/smooth.xml
for spec in "5-bdpt:5:bdpt" "7-bdpt:7:bdpt" "1-lt:1:lt" "6-lt:6:lt" "smooth-bdpt:$S:bdpt" "smooth-lt:$S:lt"; do
    IFS=: read f sc a <<EOT
$spec
EOT
    build/pathlab render --scene "$sc" -a "$a" --resolution 16x12 --spp 4 --seed 7 -q -o "tests/data/golden/bidir/$f.pfm"
done
