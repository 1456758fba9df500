// Small helpers shared by the tests that render.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "job/render_job.hpp"
#include "job/usage_error.hpp"
#include "job/renderer.hpp"
#include "judge/image_statistics.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::test {

inline RenderResult render_scene(const SceneDescription& desc, const std::string& algorithm, int width, int height,
                                 int spp, uint64_t seed = 1, IntegratorOptions options = {}) {
    JobRequest request;
    request.algorithm = algorithm;
    request.spp = uint64_t(spp);
    request.max_depth = options.max_depth;
    request.rr_depth = options.rr_depth;
    request.mis_power = options.mis_power;
    request.width = width;
    request.height = height;
    request.seed = seed;
    RenderJob job(scene_choice_of(desc), request);
    return job.run();
}

// A per-pixel estimator by name for transport T (RGB by default), for tests that call radiance()
// on chosen rays.
template <class T = RgbTransport>
std::unique_ptr<PixelIntegrator<T>> make_pixel_integrator(const std::string& name, IntegratorOptions options = {}) {
    options.spectral = T::spectral;
    std::unique_ptr<Integrator> i = find_integrator(name)->make(options);
    auto* p = dynamic_cast<PixelIntegrator<T>*>(i.get());
    if (!p) throw std::invalid_argument(name + " is not a pixel integrator");
    i.release();
    return std::unique_ptr<PixelIntegrator<T>>(p);
}

// Each of `algorithms` against `reference` on scene d (size x size pixels, spp samples, seeds 101
// and 202): per-pixel z-tests at a false-alarm rate of 1e-3 over the image, and no invalid samples.
inline void expect_estimators_agree(const SceneDescription& d, const std::string& reference, const std::vector<std::string>& algorithms,
                                    int size, int spp) {
    const RenderResult ref = render_scene(d, reference, size, size, spp, 202);
    EXPECT_EQ(ref.stats.invalid_samples, 0u) << reference;
    for (const std::string& algorithm : algorithms) {
        const RenderResult a = render_scene(d, algorithm, size, size, spp, 101);
        const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), ref.film.mean(), ref.film.standard_error(),
                                                 AgreementOptions{1e-3, 1e-4});
        ::testing::Test::RecordProperty(algorithm, r.describe());
        EXPECT_TRUE(r.agree) << algorithm << " vs " << reference << ": " << r.describe();
        EXPECT_EQ(a.stats.invalid_samples, 0u) << algorithm;
    }
}

inline std::string shared_dir() { return PATHLAB_SHARED_DIR; }

// One render of a scene with a given integrator object (its options and faults as made).
inline RenderResult render_integrator(const SceneDescription& d, Integrator& integrator, int width, int height, uint64_t spp,
                                      uint64_t seed) {
    const auto scene = Scene::build(d);
    RenderSettings rs;
    rs.width = width, rs.height = height, rs.spp = spp, rs.seed = seed;
    return render(*scene, integrator, rs);
}

// Built-in scene `scene` at 12x8, seed 9, rendered by `integrator` on `threads` threads; with
// `into`, added to that film from sample `first` on (a render continued where another stopped).
inline RenderResult render_on_threads(Integrator& integrator, int scene, int threads, uint64_t spp, uint64_t first = 0,
                                      Film* into = nullptr) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const auto built = Scene::build(make_builtin_scene(scene));
    RenderSettings rs;
    rs.width = 12, rs.height = 8, rs.spp = spp, rs.seed = 9, rs.first_sample = first;
    if (into) {
        RenderResult r;
        r.stats = render_into(*built, integrator, rs, *into);
        return r;
    }
    return render(*built, integrator, rs);
}

// Why RenderJob refuses request q on course scene 4 ("" when it accepts it).
inline std::string refusal_of(const JobRequest& q) {
    try {
        RenderJob job(4, q);
    } catch (const UsageError& e) {
        return e.what();
    }
    return "";
}

// `make()`'s integrator gives the same film on scene 3 with 1 and 2 threads, and when 7 passes
// are continued by 9 more.
template <class Make>
void expect_same_bytes_on_threads_and_continued(Make make) {
    const auto run = [&](int threads, uint64_t spp, uint64_t first = 0, Film* into = nullptr) {
        const auto integrator = make();
        return render_on_threads(*integrator, 3, threads, spp, first, into);
    };
    const RenderResult one = run(1, 16), two = run(2, 16);
    EXPECT_TRUE(one.film.identical(two.film));
    RenderResult half = run(2, 7);
    run(1, 9, 7, &half.film);
    EXPECT_TRUE(half.film.identical(one.film));
}

inline bool bit_identical(const Image& a, const Image& b) {
    return a.pixel_count() == b.pixel_count() && std::memcmp(a.data(), b.data(), a.pixel_count() * sizeof(Rgb)) == 0;
}

// The RMS difference of two Monte Carlo images with both images' own noise subtracted,
// sqrt(max(0, mean(d^2 - se_a^2 - se_b^2))): what is left is bias (0 when it is below the noise).
inline double bias_rms(const Image& a, const Image& se_a, const Image& b, const Image& se_b) {
    double sum = 0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double d = double(a[i][c]) - b[i][c];
            sum += d * d - double(se_a[i][c]) * se_a[i][c] - double(se_b[i][c]) * se_b[i][c];
        }
    return std::sqrt(std::max(0.0, sum / double(3 * a.pixel_count())));
}

}  // namespace pathlab::test
