// Mitsuba 3's render test (src/render/tests/test_renders.py): an image of `spp` samples per pixel
// against a reference and the reference's per-sample variance, a two-sided z-test per pixel and
// channel in CIE XYZ, each at the Sidak-corrected level alpha_1 = 1 - (1 - alpha)^(1 / pixels); the
// image passes when at least `min_pass` of its pixel-channels do. As there, the variance is
// floored at 1e-4 and converted to XYZ by the same matrix as the colours, and the reference's own
// noise is ignored (it has 32k samples).
#pragma once

#include <cstdint>

#include "image/image.hpp"

namespace pathlab {

struct PixelZTestOptions {
    uint64_t spp = 1;          // the samples per pixel of the image under test
    double alpha = 0.01;       // the false-alarm rate of the whole image
    double min_pass = 0.9975;  // the share of pixel-channels that must pass
};

struct PixelZTest {
    uint64_t tested = 0, passed = 0;  // pixel-channels (3 per pixel)
    double alpha_per_test = 0;        // Sidak's level
    double min_p_value = 1;
    double mean_relative_diff = 0;    // sum(image - ref) / sum(ref) over X, Y and Z: the sign says which is brighter
    bool pass = false;
    double pass_fraction() const { return tested ? double(passed) / double(tested) : 0.0; }
};

// std::invalid_argument when the three images differ in size or spp is 0.
PixelZTest pixel_z_test(const Image& image, const Image& reference, const Image& reference_variance,
                        const PixelZTestOptions& options);

// Linear sRGB (Rec. 709 primaries, D65) to XYZ, the matrix Mitsuba 3 uses (core/spectrum.h).
Rgb srgb_to_xyz(const Rgb& c);

}  // namespace pathlab
