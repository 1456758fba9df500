// pssmlt: the primary-sample-space chain keeps its target density (a 1D toy with a known
// density, chi-square of independent chains' states: large and small steps together, small
// steps alone from a stationary start, and a lazily created second number); the integrator
// converges to pt-mis's image (per-pixel z-tests on the course scenes, RGB and spectral); it
// fails for an estimator without the rejected proposals' weight; and it is deterministic (1 and
// 2 threads, a render continued from where another stopped).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "chi2.hpp"
#include "integrators/mlt/pssmlt.hpp"
#include "integrators/path/volpath.hpp"
#include "job/render_job.hpp"
#include "job/usage_error.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "samplers/sampler.hpp"
#include "scene_helpers.hpp"

namespace pathlab::test {
namespace {

// A density on [0, 1) with a sharp peak and a flat floor, the kind of target MLT is for.
double toy_density(double x) { return 0.2 + std::exp(-0.5 * std::pow((x - 0.7) / 0.05, 2)) + (x < 0.1 ? 1.5 : 0.0); }

// Pearson's test of chain states against toy_density (40 bins, each integrated numerically).
Chi2Result against_toy_density(const std::vector<float>& states) {
    constexpr int kBins = 40;
    std::vector<double> observed(kBins + 1, 0.0), expected(kBins + 1, 0.0);
    for (float x : states) observed[size_t(std::min(kBins - 1, int(x * kBins)))] += 1;
    double total = 0;
    for (int b = 0; b < kBins; ++b) {
        double sum = 0;
        for (int k = 0; k < 200; ++k) sum += toy_density((b + (k + 0.5) / 200) / kBins) / 200;
        expected[size_t(b)] = sum, total += sum;
    }
    for (int b = 0; b < kBins; ++b) expected[size_t(b)] *= double(states.size()) / total;
    return chi2_from_counts(observed, expected);
}

// Independent chains, each `steps` Metropolis-Hastings steps on toy_density from `start`; the
// histogram of their last states against the density's bin integrals.
template <class Start>
Chi2Result toy_chains(float sigma, float large, int steps, Start start, bool wrong_acceptance = false, int chains = 20000) {
    std::vector<float> states;
    for (int c = 0; c < chains; ++c) {
        PrimarySamples state(sigma, large);
        state.restart(17, uint64_t(c));
        state.start_iteration(true);
        float x = start(state, c);
        state.accept();
        for (int s = 0; s < steps; ++s) {
            state.start_iteration();
            const float y = state.next1d();
            const double a = std::min(1.0, toy_density(y) / toy_density(x));
            if (wrong_acceptance ? state.uniform() < 0.5f : state.uniform() < a) {
                state.accept();
                x = y;
            } else {
                state.reject();
            }
        }
        states.push_back(x);
    }
    return against_toy_density(states);
}

// The first state: the first number (uniform; the chains then need steps to forget it).
float uniform_start(PrimarySamples& state, int) { return state.next1d(); }

TEST(PrimarySamples, LargeAndSmallStepsKeepTheTargetDensity) {
    const Chi2Result r = toy_chains(0.01f, 0.3f, 200, uniform_start);
    EXPECT_GT(r.p_value, suite_chi2_alpha()) << r.describe();
}

TEST(PrimarySamples, SmallStepsAloneKeepTheTargetDensity) {
    // From a stationary start, small steps only (wide ones, so that 50 of them move a state
    // far): the kernel alone must keep the density (detailed balance of the symmetric Gaussian
    // step, wrapped, with Metropolis acceptance).
    constexpr int kChains = 20000;
    std::vector<float> states;
    for (int c = 0; c < kChains; ++c) {
        PrimarySamples state(0.08f, 0.0f);
        // A stationary first state: restart until a large step's number passes rejection sampling.
        Pcg32 accept_rng(99, uint64_t(c));
        float x;
        for (uint64_t k = 0;; ++k) {
            state.restart(17, uint64_t(c) * 1000003u + k);
            state.start_iteration(true);
            x = state.next1d();
            if (accept_rng.next_float() * 2.8 < toy_density(x)) break;
        }
        state.accept();
        for (int s = 0; s < 50; ++s) {
            state.start_iteration(false);
            const float y = state.next1d();
            if (state.uniform() < std::min(1.0, toy_density(y) / toy_density(x))) {
                state.accept();
                x = y;
            } else {
                state.reject();
            }
        }
        states.push_back(x);
    }
    const Chi2Result r = against_toy_density(states);
    EXPECT_GT(r.p_value, suite_chi2_alpha()) << r.describe();
}

TEST(PrimarySamples, ANumberCreatedDuringTheChainIsUniformAndIndependent) {
    // The target depends on the second number only after the first passes a threshold, so the
    // second number is created lazily, in the middle of the chain, and by rejected proposals
    // too; its marginal under the target is known: density(x2) for the chains whose x1 < 0.5.
    constexpr int kChains = 20000;
    const auto target = [](double x1, double x2) { return x1 < 0.5 ? toy_density(x2) : 1.0; };
    std::vector<float> states;
    for (int c = 0; c < kChains; ++c) {
        PrimarySamples state(0.02f, 0.3f);
        state.restart(23, uint64_t(c));
        state.start_iteration(true);
        float x1 = state.next1d(), x2 = x1 < 0.5f ? state.next1d() : -1.0f;
        state.accept();
        double fx = target(x1, x2 < 0 ? 0.5 : x2);
        for (int s = 0; s < 200; ++s) {
            state.start_iteration();
            const float y1 = state.next1d();
            const float y2 = y1 < 0.5f ? state.next1d() : -1.0f;
            const double fy = target(y1, y2 < 0 ? 0.5 : y2);
            if (state.uniform() < std::min(1.0, fy / fx)) {
                state.accept();
                x1 = y1, x2 = y2, fx = fy;
            } else {
                state.reject();
            }
        }
        if (x1 < 0.5f) states.push_back(x2);
    }
    const Chi2Result r = against_toy_density(states);
    EXPECT_GT(states.size(), size_t(kChains / 4));
    EXPECT_GT(r.p_value, suite_chi2_alpha()) << r.describe();
}

// Test of the test: a chain that accepts half its proposals whatever they are does not keep the density.
TEST(PrimarySamples, TheHistogramTestRejectsAWrongAcceptanceRule) {
    const Chi2Result r = toy_chains(0.01f, 0.3f, 200, uniform_start, /*wrong_acceptance=*/true);
    EXPECT_LT(r.p_value, 1e-6) << r.describe();
}

TEST(PrimarySamples, RejectRestoresTheStateAndSamplerReadsIt) {
    PrimarySamples state(0.01f, 0.0f);
    state.restart(5, 6);
    state.start_iteration(true);
    Sampler sampler(state);
    const float a = sampler.next1d();
    const Vec2f b = sampler.next2d();
    state.accept();
    state.start_iteration(false);
    Sampler again(state);
    const float a2 = again.next1d();
    EXPECT_NE(a2, a);
    EXPECT_LT(std::min(std::abs(a2 - a), 1 - std::abs(a2 - a)), 0.1f);
    state.reject();
    state.start_iteration(false);
    // After the reject the state is the first one again: a new small step starts from a, b.
    Sampler third(state);
    const float a3 = third.next1d();
    const Vec2f b3 = third.next2d();
    EXPECT_LT(std::min(std::abs(a3 - a), 1 - std::abs(a3 - a)), 0.1f);
    EXPECT_LT(std::min(std::abs(b3.x - b.x), 1 - std::abs(b3.x - b.x)), 0.1f);
    EXPECT_EQ(state.dimensions(), 3u);
}

// ---- the integrator ------------------------------------------------------------------------

IntegratorOptions mlt_options(bool spectral = false) {
    IntegratorOptions o;
    o.spectral = spectral;
    o.mlt_chains = 4;  // 16 mutations per chain and pass at 8x8
    o.mlt_bootstrap = 256;
    return o;
}

// Each comparison raises a false alarm with probability <= 1e-4 (image_statistics.hpp).
const AgreementOptions kAgreement{1e-3, 1e-4};

AgreementResult compare_with_pt_mis(int scene, Integrator& mlt, uint64_t spp, bool spectral = false) {
    const SceneDescription d = make_builtin_scene(scene);
    const RenderResult a = render_integrator(d, mlt, 8, 8, spp, 401);
    IntegratorOptions o;
    o.spectral = spectral;
    const RenderResult b = spectral ? render_integrator(d, *make_pixel_integrator<SpectralTransport>("pt-mis", o), 8, 8, spp, 402)
                                    : render_integrator(d, *make_pixel_integrator<RgbTransport>("pt-mis", o), 8, 8, spp, 402);
    return test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), kAgreement);
}

class PssmltAgreement : public ::testing::TestWithParam<int> {};

TEST_P(PssmltAgreement, ConvergesToPtMisImage) {
    Pssmlt<RgbTransport> mlt(mlt_options());
    const AgreementResult r = compare_with_pt_mis(GetParam(), mlt, 4096);
    EXPECT_TRUE(r.agree) << "scene " << GetParam() << ": " << r.describe();
}
INSTANTIATE_TEST_SUITE_P(Scenes, PssmltAgreement, ::testing::Values(0, 1, 2, 3, 4, 5, 6, 7));

TEST(PssmltAgreement, ConvergesInSpectralMode) {
    Pssmlt<SpectralTransport> mlt(mlt_options(true));
    const AgreementResult r = compare_with_pt_mis(5, mlt, 2048, true);
    EXPECT_TRUE(r.agree) << r.describe();
}

// In a scene with media the chains' paths are volpath's: the light box in chromatic fog.
TEST(PssmltAgreement, ConvergesToVolpathInFog) {
    const SceneDescription d = light_box_in_fog();
    Pssmlt<RgbTransport> mlt(mlt_options());
    const RenderResult a = render_integrator(d, mlt, 8, 8, 4096, 401);
    const auto volpath = make_volpath({});
    const RenderResult b = render_integrator(d, *volpath, 8, 8, 4096, 402);
    const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), kAgreement);
    EXPECT_TRUE(r.agree) << r.describe();
}

// Test of the test: without the current state's expected-value weight (1 - a) / I(X) the image
// is wrong, and the comparison says so.
TEST(PssmltAgreement, DetectsAMissingRejectionWeight) {
    IntegratorOptions o = mlt_options();
    Pssmlt<RgbTransport> mlt(o, ChainFaults{.drop_current_weight = true});
    EXPECT_FALSE(compare_with_pt_mis(4, mlt, 1024).agree);
}

TEST(Pssmlt, SameBytesWithOneAndTwoThreadsAndWhenContinued) {
    expect_same_bytes_on_threads_and_continued([] { return std::make_unique<Pssmlt<RgbTransport>>(mlt_options()); });
}

TEST(Pssmlt, OptionsAreItsOwnAndChecked) {
    JobRequest r;
    r.algorithm = "pssmlt";
    r.mlt_chains = 8, r.mlt_bootstrap = 100, r.mlt_large_step = 0.5f, r.mlt_sigma = 0.05f;
    RenderJob job(4, r);
    EXPECT_EQ(job.integrator_options().mlt_chains, 8);
    EXPECT_EQ(job.integrator_options().mlt_bootstrap, 100);
    JobRequest other;
    other.algorithm = "bdpt", other.mlt_chains = 8;
    EXPECT_NE(refusal_of(other).find("set the Markov chains of pssmlt and mmlt, not bdpt's"), std::string::npos) << refusal_of(other);
    JobRequest bad = r;
    bad.mlt_large_step = 1.5f;
    EXPECT_NE(refusal_of(bad).find("--large-step must be 0 to 1"), std::string::npos) << refusal_of(bad);
    JobRequest sobol = r;
    sobol.sampler = SamplerKind::Sobol;
    EXPECT_NE(refusal_of(sobol).find("pssmlt takes no --sampler sobol"), std::string::npos) << refusal_of(sobol);
}

}  // namespace
}  // namespace pathlab::test
