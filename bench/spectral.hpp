#pragma once

namespace pathlab::bench {

struct SpectralOptions {
    int count = 2000000;  // evaluations per timing
    int repeats = 5;      // timings per figure (median reported)
};

// `pathlab_bench spectral`: the cost of the spectral layer's building blocks (src/spectral/),
// in ns per call on one thread: wavelength sampling, the RGB -> spectrum table lookup, the
// sigmoid at 4 lanes, an RGB emitter's spectrum (D65 times the sigmoid), a black body, the film's
// XYZ estimator per sample, and the RGB film's accumulation of one sample for scale.
void spectral_suite(const SpectralOptions& o);

}  // namespace pathlab::bench
