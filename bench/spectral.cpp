// `pathlab_bench spectral`: ns per call of the spectral building blocks (see spectral.hpp).
// Inputs are drawn before the timing (random rgb in [0, 1]^3 and random wavelength sets), and
// every result feeds a sum that is printed, so nothing is optimised away. Rounds interleave
// the figures; medians are reported.
#include "spectral.hpp"

#include <chrono>
#include <cstdio>
#include <functional>
#include <vector>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "core/rng.hpp"
#include "core/spectrum.hpp"
#include "spectral/blackbody.hpp"
#include "spectral/dense_spectrum.hpp"
#include "spectral/rgb_spectra.hpp"
#include "spectral/rgb_to_spectrum.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab::bench {

void spectral_suite(const SpectralOptions& o) {
    const int n = o.count;
    const int pool = 4096;  // distinct inputs, cycled (they stay in L1/L2 like a renderer's)
    Pcg32 rng(1, 0);
    std::vector<Vec3f> rgbs(pool);
    std::vector<SampledWavelengths> wls(pool);
    std::vector<Spectrum4> radiance(pool);
    std::vector<SigmoidPolynomial> polys(pool);
    const RgbToSpectrumTable& table = RgbToSpectrumTable::srgb();
    for (int i = 0; i < pool; ++i) {
        rgbs[size_t(i)] = Vec3f(rng.next_float(), rng.next_float(), rng.next_float());
        wls[size_t(i)] = SampledWavelengths::sample_visible(rng.next_float());
        radiance[size_t(i)] = Spectrum4(rng.next_float(), rng.next_float(), rng.next_float(), rng.next_float());
        polys[size_t(i)] = table(rgbs[size_t(i)]);
    }
    const BlackbodySpectrum blackbody(3200);
    const DenseSpectrum dense([&](double l) { return double(blackbody(float(l))); });
    double sink = 0;

    struct Figure {
        const char* name;
        std::function<void()> body;
        std::vector<double> ns = {};
    };
    std::vector<Figure> figures = {
        {"SampledWavelengths::sample_visible", [&] {
             float s = 0;
             for (int i = 0; i < n; ++i) s += SampledWavelengths::sample_visible(double(i & (pool - 1)) / pool)[3];
             sink += s;
         }},
        {"table lookup (rgb -> coefficients)", [&] {
             float s = 0;
             for (int i = 0; i < n; ++i) s += table(rgbs[size_t(i & (pool - 1))]).c2;
             sink += s;
         }},
        {"sigmoid polynomial at 4 lanes", [&] {
             float s = 0;
             for (int i = 0; i < n; ++i) {
                 const SigmoidPolynomial& p = polys[size_t(i & (pool - 1))];
                 const SampledWavelengths& wl = wls[size_t((i * 7) & (pool - 1))];
                 for (int l = 0; l < kSpectrumLanes; ++l) s += p(wl[l]);
             }
             sink += s;
         }},
        {"RgbAlbedoSpectrum: lookup + 4 lanes", [&] {
             float s = 0;
             for (int i = 0; i < n; ++i)
                 s += RgbAlbedoSpectrum(table, rgbs[size_t(i & (pool - 1))]).sample(wls[size_t((i * 7) & (pool - 1))]).average();
             sink += s;
         }},
        {"RgbIlluminantSpectrum: lookup + 4 lanes", [&] {
             float s = 0;
             for (int i = 0; i < n; ++i)
                 s += RgbIlluminantSpectrum(table, rgbs[size_t(i & (pool - 1))]).sample(wls[size_t((i * 7) & (pool - 1))]).average();
             sink += s;
         }},
        {"BlackbodySpectrum at 4 lanes", [&] {
             float s = 0;
             for (int i = 0; i < n; ++i) s += blackbody.sample(wls[size_t(i & (pool - 1))]).average();
             sink += s;
         }},
        {"DenseSpectrum (1 nm table) at 4 lanes", [&] {
             float s = 0;
             for (int i = 0; i < n; ++i) s += dense.sample(wls[size_t(i & (pool - 1))]).average();
             sink += s;
         }},
        {"film: XYZ estimator + to sRGB, per sample", [&] {
             Vec3d s(0.0);
             for (int i = 0; i < n; ++i)
                 s += spectral_sample_to_linear_srgb(radiance[size_t(i & (pool - 1))], wls[size_t((i * 7) & (pool - 1))]);
             sink += s.x + s.y + s.z;
         }},
        {"(RGB film: one sample's double accumulation)", [&] {
             Vec3d s(0.0);
             for (int i = 0; i < n; ++i) {
                 const Spectrum4& r = radiance[size_t(i & (pool - 1))];
                 s += Vec3d(r[0], r[1], r[2]);
             }
             sink += s.x + s.y + s.z;
         }},
    };
    for (int round = 0; round < o.repeats; ++round)
        for (Figure& f : figures) {
            const auto t0 = std::chrono::steady_clock::now();
            f.body();
            f.ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / n);
        }
    fmt::print("Spectral building blocks (table resolution {}), ns per call on one thread, median of {}:\n\n",
               table.resolution(), o.repeats);
    fmt::print("| operation | ns |\n|---|---|\n");
    for (const Figure& f : figures) fmt::print("| {} | {:.2f} |\n", f.name, median(f.ns));
    fmt::print("\n(checksum {:.6g})\n", sink);
}

}  // namespace pathlab::bench
