// Chi-square goodness-of-fit of a direction sampler against its own density, in the style of
// Mitsuba 3's chi2 tests: draw N samples into a (theta, phi) histogram around a chosen axis,
// integrate the claimed pdf over every cell numerically, pool cells with small expected
// counts, and compute the p-value of the Pearson statistic. Samplers may reject (return no
// direction); rejections form one more cell whose expected count is N (1 - integral of pdf).
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/frame.hpp"
#include "samplers/sampler.hpp"

namespace pathlab::test {

// Upper tail P(X >= x) of the chi-square distribution with `dof` degrees of freedom.
double chi2_survival(double x, int dof);

struct Chi2Options {
    int theta_bins = 40, phi_bins = 80;
    // Bin edges theta_k = pi (k / theta_bins)^theta_power: > 1 refines bins near the axis,
    // so narrow lobes centred on it are resolved.
    double theta_power = 1;
    int integration_steps = 24;  // midpoint-rule points per cell and dimension
    int samples = 1'000'000;
    uint64_t seed = 1;
};

struct Chi2Result {
    double statistic = 0, p_value = 0;
    int dof = 0;
    double pdf_integral = 0;  // integral of the pdf over the sphere
    double rejected_fraction = 0;
    // Samples in cells whose integrated pdf is zero. Pooled with the other small cells (a
    // cell may hold a sliver of support that the integration grid misses), so they count
    // against the fit without failing it outright.
    double zero_pdf_samples = 0;
    std::string describe() const;
};

// Pearson's test of observed against expected counts (same cells), pooling cells whose
// expected count is below 5. The last cell holds rejected samples (see chi2_directions).
Chi2Result chi2_from_counts(const std::vector<double>& observed, const std::vector<double>& expected);

using DirectionSampler = std::function<std::optional<Vec3f>(Vec2f)>;
using DirectionPdf = std::function<float(const Vec3f&)>;

// `axis` is the pole of the histogram's spherical coordinates (directions are in the same
// space as sampler and pdf use).
Chi2Result chi2_directions(const DirectionSampler& sample, const DirectionPdf& pdf, const Vec3f& axis,
                           const Chi2Options& options = {});

// Per-test significance level: 1% for the whole suite, split over `tests` tests (Sidak).
double sidak_alpha(int tests, double family_alpha = 0.01);

// Number of chi-square goodness-of-fit tests in the whole suite (an upper bound), and the
// resulting per-test level: a false alarm anywhere in the suite has probability <= 1%.
// 64 for the warps, lights, Phong and Sobol tests, 96 for the microfacet BSDFs
// (test_microfacet.cpp: 79 at present), 32 for emission sampling, camera importance and the
// adjoint BSDFs, 16 for the phase functions and free-flight sampling (test_media.cpp: 15), 16 for
// the envmap, spot and IES lights (10 at present), 8 for the Markov chains' toy targets
// (test_pssmlt.cpp: 3 at present), 8 for path guiding's distributions (test_ppg.cpp: 6 at present).
constexpr int kSuiteChi2Tests = 64 + 96 + 32 + 16 + 16 + 8 + 8;
inline double suite_chi2_alpha() { return sidak_alpha(kSuiteChi2Tests); }

// A unit incoming direction theta degrees from the normal (+z), at an azimuth off the axes so
// that anisotropic lobes are tested away from their symmetry planes.
inline Vec3f incoming(float theta_degrees) {
    const float t = theta_degrees * kPi / 180.0f;
    return normalize(Vec3f(std::sin(t) * 0.8f, std::sin(t) * 0.6f, std::cos(t)));
}

}  // namespace pathlab::test
