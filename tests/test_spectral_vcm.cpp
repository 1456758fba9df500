// vcm and bpm in spectral mode (docs/spectral.md, "Spectral vcm and bpm"): both agree with
// spectral pt-mis on a course scene and on a room lit through dispersive glass (light subpaths,
// photons and, behind a second pane, camera subpaths hero-only), and give the same bytes with 1
// and 2 threads.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include <fmt/format.h>

#include "integrators/integrators.hpp"
#include "job/render_job.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"
#include "spectral_helpers.hpp"

namespace pathlab::test {
namespace {


RenderResult render_spectral(const Scene& scene, const std::string& name, IntegratorOptions o, int size, uint64_t spp, uint64_t seed,
                             uint64_t first = 0, SamplerKind sampler = SamplerKind::Independent) {
    o.spectral = true;
    const std::unique_ptr<Integrator> integrator = find_integrator(name)->make(o);
    RenderSettings rs;
    rs.width = size, rs.height = size, rs.spp = spp, rs.seed = seed, rs.spectral = true, rs.first_sample = first;
    rs.sampler = sampler;
    return render(scene, *integrator, rs);
}

Vec3d image_average(const Image& m) {
    Vec3d sum(0.0);
    for (size_t i = 0; i < m.pixel_count(); ++i) sum += Vec3d(m[i]);
    return sum / double(m.pixel_count());
}

// The image mean per channel and its standard error.
struct MeanSe {
    Vec3d mean{0.0}, se{0.0};
};

// pt-mis: every sample draws its own wavelengths, so pixels are independent and the image
// mean's standard error comes from the film's per-pixel ones.
MeanSe pt_mis_mean(const Scene& scene, int size, uint64_t spp, int max_depth) {
    IntegratorOptions o;
    o.max_depth = max_depth;
    const RenderResult r = render_spectral(scene, "pt-mis", o, size, spp, 71);
    const Image se = r.film.standard_error();
    MeanSe out;
    out.mean = image_average(r.film.mean());
    for (size_t i = 0; i < se.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) out.se[c] += double(se[i][c]) * se[i][c];
    for (int c = 0; c < 3; ++c) out.se[c] = std::sqrt(out.se[c]) / double(se.pixel_count());
    return out;
}

// vcm or bpm: the pixels of one pass share the pass's wavelengths (a tint of the whole pass) and
// its photons, so they are correlated; the standard error comes from the spread of the means of
// kBlocks blocks of consecutive passes (one render split by first_sample: blocks are independent;
// their different radii only widen the spread).
constexpr int kBlocks = 16;
MeanSe vcm_block_mean(const Scene& scene, const std::string& name, int size, int passes_per_block, int max_depth, float radius) {
    IntegratorOptions o;
    o.max_depth = max_depth;
    o.photon_radius = radius;
    std::vector<Vec3d> means;
    for (int k = 0; k < kBlocks; ++k)
        means.push_back(image_average(
            render_spectral(scene, name, o, size, uint64_t(passes_per_block), 72, uint64_t(k) * uint64_t(passes_per_block), SamplerKind::Sobol)
                .film.mean()));
    MeanSe out;
    for (const Vec3d& m : means) out.mean += m / double(kBlocks);
    for (const Vec3d& m : means)
        for (int c = 0; c < 3; ++c) out.se[c] += (m[c] - out.mean[c]) * (m[c] - out.mean[c]);
    for (int c = 0; c < 3; ++c) out.se[c] = std::sqrt(out.se[c] / double(kBlocks - 1) / double(kBlocks));
    return out;
}

// |a - b| <= 4.5 sigma per channel (t with 15 degrees of freedom dominates: 4e-4 per channel).
void expect_agree(const MeanSe& a, const MeanSe& b, const std::string& what) {
    for (int c = 0; c < 3; ++c) {
        const double sigma = std::hypot(a.se[c], b.se[c]), z = (a.mean[c] - b.mean[c]) / sigma;
        std::printf("%s channel %d: %.4f +- %.4f against %.4f +- %.4f, z %.2f\n", what.c_str(), c, a.mean[c], a.se[c], b.mean[c], b.se[c], z);
        EXPECT_LE(std::abs(z), 4.5) << what << " channel " << c << ": " << a.mean[c] << " against pt-mis " << b.mean[c] << ", sigma "
                                    << sigma;
    }
}

// Both estimate spectral pt-mis's image (the same spectra; only the sampling differs; merging's
// blur over a small radius, 3% of the scene's radius shrinking from there, is below the noise):
// course scene 3 (glossy), the room under the dispersive pane, and behind a second pane. 3
// scenes x 2 integrators x 3 channels = 18 tests at 4.5 sigma: false alarms below 1% in all.
TEST(SpectralVcm, VcmAndBpmAgreeWithSpectralPtMis) {
    struct Case {
        std::string name;
        std::unique_ptr<Scene> scene;
        int max_depth;
        uint64_t pt_spp;       // pt-mis's samples per pixel
        int passes_per_block;  // vcm's and bpm's: 16 blocks of this many passes
    };
    std::vector<Case> cases;
    cases.push_back({"scene 3", Scene::build(make_builtin_scene(3)), 3, 512, 8});
    cases.push_back({"under the dispersive pane", Scene::build(load_scene_text(dispersive_room(false, 16), "room.xml", ".")), 6, 2048, 16});
    cases.push_back({"behind a dispersive pane too", Scene::build(load_scene_text(dispersive_room(true, 16), "room.xml", ".")), 6, 2048, 16});
    for (const Case& c : cases) {
        const MeanSe pt = pt_mis_mean(*c.scene, 16, c.pt_spp, c.max_depth);
        const float radius = 0.03f * c.scene->scene_sphere().radius;
        for (const char* name : {"vcm", "bpm"}) expect_agree(vcm_block_mean(*c.scene, name, 16, c.passes_per_block, c.max_depth, radius), pt, c.name + " " + name);
    }
}

// ---- determinism -----------------------------------------------------------------------------

RenderResult render_threads(const SceneChoice& choice, const std::string& algorithm, int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    JobRequest request;
    request.algorithm = algorithm;
    request.spp = 2;
    request.width = 24;
    request.height = 16;
    request.seed = 9;
    request.spectral = true;
    RenderJob job(choice, request);
    return job.run();
}

// Scene 5 and the room behind both panes: the same mean and standard-error bytes and ray counts.
TEST(SpectralVcm, OneAndTwoThreadsGiveTheSameBytes) {
    const std::vector<SceneChoice> choices = {builtin_scene_choice(5),
                                              scene_choice_of(load_scene_text(dispersive_room(true, 16), "room.xml", "."))};
    for (const SceneChoice& choice : choices)
        for (const char* algorithm : {"vcm", "bpm"}) {
            const RenderResult one = render_threads(choice, algorithm, 1), two = render_threads(choice, algorithm, 2);
            const std::string what = choice.name + " " + algorithm;
            EXPECT_TRUE(bit_identical(one.film.mean(), two.film.mean())) << what;
            EXPECT_TRUE(bit_identical(one.film.standard_error(), two.film.standard_error())) << what;
            EXPECT_EQ(one.stats.rays, two.stats.rays) << what;
        }
}

}  // namespace
}  // namespace pathlab::test
