// Shared pieces of pathlab's benchmarks: medians, RMSE against a reference with the
// reference's own noise removed, and one-call renders.
#pragma once

#include <algorithm>
#include <functional>
#include <cmath>
#include <string>
#include <vector>

#include "job/renderer.hpp"

namespace pathlab::bench {

inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Reference {
    Image mean;
    double noise_mse = 0;  // mean squared standard error of the reference's pixels
};

// Root mean squared error over all pixels and channels, with the reference's expected squared
// error (its noise) subtracted, so a finite-spp reference does not inflate the figure.
inline double rmse(const Image& img, const Reference& ref) {
    double sum = 0;
    for (size_t i = 0; i < img.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double d = double(img[i][c]) - ref.mean[i][c];
            sum += d * d;
        }
    return std::sqrt(std::max(0.0, sum / double(3 * img.pixel_count()) - ref.noise_mse));
}

// One render of `size` x `size` pixels: `spp` samples per pixel, or (spp = 0) `seconds`.
// `algorithm` may carry a photon radius: "vcm:radius=0.005".
RenderResult run(const Scene& scene, const std::string& algorithm, int size, int spp, double seconds, uint64_t seed,
                 std::function<void(const Film&, const RenderStats&)> after_pass = {},
                 SamplerKind sampler = SamplerKind::Independent);
Reference make_reference(const Scene& scene, const std::string& algorithm, int size, int spp);

// Peak resident set size of this process so far, in MiB.
double peak_rss_mib();

}  // namespace pathlab::bench
