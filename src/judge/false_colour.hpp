// False-colour pictures of a signed difference A - B: the Rec. 709 luminance difference per
// pixel on a diverging colour map (Moreland's cool-warm: blue where A is darker than B, grey at
// zero, red where A is brighter), saturating at +-scale. Pixels non-finite in either image
// are drawn pure green, a colour the map never uses.
#pragma once

#include <array>
#include <cstdint>

#include "image/image.hpp"

namespace pathlab {

// The map's colour for t in [-1, 1] (clamped): t = -1 blue, 0 grey, +1 red.
std::array<uint8_t, 3> diverging_colour(double t);

// A scale that shows most of the image: the `quantile` of |luminance difference| over finite
// pixels (so a few fireflies do not wash the rest out); 1 if the images are equal.
double difference_scale(const Image& a, const Image& b, double quantile = 0.99);

// Throws ImageSizeMismatch when sizes differ, std::invalid_argument for a non-positive scale.
Image8 false_colour_difference(const Image& a, const Image& b, double scale);

// A horizontal colour bar (-scale left, +scale right) for legends.
Image8 diverging_colour_bar(int width, int height);

// Magnitudes (per-pixel standard errors) on a sequential map (viridis: dark blue at 0, green,
// yellow at `scale` and beyond); the mean of a pixel's three channels is shown, NaN/Inf in red.
std::array<uint8_t, 3> sequential_colour(double t);  // t in [0, 1] (clamped)
// The `quantile` of the per-pixel channel mean over finite pixels (1 if all are 0).
double magnitude_scale(const Image& img, double quantile = 0.99);
Image8 false_colour_magnitude(const Image& img, double scale);
Image8 sequential_colour_bar(int width, int height);

}  // namespace pathlab
