// pm (Jensen's photon mapping): its bias against pt-mis, measured, shrinks as the photon count
// grows (the k nearest photons then lie within a smaller disc); a radiance estimate without pi
// fails that; the caustic map holds only photons that came through Dirac lobes alone; images
// are bit-identical with 1 and 2 threads.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "integrators/integrators.hpp"
#include "integrators/photon/pm.hpp"
#include "job/renderer.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

constexpr int kSize = 16;

// The bias of pm's image against a pt-mis reference (bias_rms: both images' noise subtracted).
double bias(const Scene& scene, const Image& ref, const Image& ref_se, int64_t photons, PmFaults faults = {}) {
    IntegratorOptions o;
    o.photons = photons;
    PhotonMapper<RgbTransport> pm(o, faults);
    RenderSettings rs;
    rs.width = rs.height = kSize, rs.spp = 2048, rs.seed = 8;
    const RenderResult a = render(scene, pm, rs);
    return bias_rms(a.film.mean(), a.film.standard_error(), ref, ref_se);
}

// Scene 2 (diffuse box, ceiling light), 16x16, 2048 samples per pixel: 16x the photons (1000
// and 16000 light paths: discs of the 50 nearest photons some 0.5 and 0.13 wide) must give
// less than 0.6 of the bias (the disc has 1/16 of the area; the bias of a smooth density falls
// with the area, near edges and corners with the radius: 1/4); a kernel without pi must give
// more than twice the bias. (The measure has a floor: the camera side's noise, the same in
// every run with one seed, is subtracted only on average.)
TEST(PmBias, ShrinksAsThePhotonCountGrowsAndNeedsPi) {
    const auto scene = Scene::build(make_builtin_scene(2));
    const std::unique_ptr<Integrator> pt = find_integrator("pt-mis")->make({});
    RenderSettings rs;
    rs.width = rs.height = kSize, rs.spp = 16384, rs.seed = 4;
    const RenderResult ref = render(*scene, *pt, rs);
    const Image m = ref.film.mean(), se = ref.film.standard_error();
    const double few = bias(*scene, m, se, 1000), many = bias(*scene, m, se, 16000);
    const double no_pi = bias(*scene, m, se, 16000, PmFaults{.no_pi_in_kernel = true});
    const std::string all = fmt::format("bias: 1000 light paths {:.5f}, 16000 {:.5f}, 16000 without pi {:.5f}", few, many, no_pi);
    EXPECT_GT(few, 0.0) << "the bias must be seen at all: " << all;
    EXPECT_LT(many, 0.6 * few) << all;
    EXPECT_GT(no_pi, 2 * few) << all;
}

TEST(PmMaps, TheCausticMapHoldsOnlyPhotonsThroughDiracLobes) {
    IntegratorOptions o;
    o.photons = 20000;
    const auto box = Scene::build(make_builtin_scene(2));
    const PerspectiveCamera c1(box->camera(), 8, 8);
    PhotonMapper<RgbTransport> diffuse(o);
    diffuse.prepare(RenderContext{*box, c1, 8, 8, 1, SamplerKind::Independent, 32});
    EXPECT_GT(diffuse.global_photons(), 20000u);
    EXPECT_EQ(diffuse.caustic_photons(), 0u) << "no Dirac lobes in scene 2";
    const auto glass = Scene::build(load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/caustic.xml"));
    const PerspectiveCamera c2(glass->camera(), 8, 8);
    PhotonMapper<RgbTransport> caustic(o);
    caustic.prepare(RenderContext{*glass, c2, 8, 8, 1, SamplerKind::Independent, 32});
    EXPECT_GT(caustic.caustic_photons(), 100u) << "the glass ball focuses photons";
    EXPECT_LT(caustic.caustic_photons(), caustic.global_photons());
}

TEST(PmDeterminism, OneAndTwoThreadsGiveBitIdenticalImages) {
    for (const int scene : {3, 6}) {
        RenderResult runs[2];
        for (const int threads : {1, 2}) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
            const auto s = Scene::build(make_builtin_scene(scene));
            IntegratorOptions o;
            o.photons = 20000;
            PhotonMapper<RgbTransport> pm(o);
            RenderSettings rs;
            rs.width = 40, rs.height = 30, rs.spp = 2, rs.seed = 9;
            runs[threads - 1] = render(*s, pm, rs);
        }
        EXPECT_TRUE(bit_identical(runs[0].film.mean(), runs[1].film.mean())) << scene;
    }
}

}  // namespace
}  // namespace pathlab::test
