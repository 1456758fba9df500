// The light tracer (lt) converges to the path tracers' image: per-pixel z-tests against pt-mis
// on the 8 course scenes and on two scene files with glass and mirrors (pixels whose first
// camera vertex is specular left out: black by design), at a stated false-alarm rate. It must
// fail for a light tracer that drops the camera's cos/d^2 or the emission sample's 1/pdf. And
// it is deterministic: 1 and 2 threads give the same bytes, and a render continued from where
// another stopped equals the one-shot render.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "integrators/bidir/light_tracer.hpp"
#include "judge/image_statistics.hpp"
#include "judge/specular_mask.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

// Each comparison raises a false alarm with probability <= 1e-4 (image_statistics.hpp); with
// the 10 comparisons here the file's false-alarm rate stays below 0.1%.
const AgreementOptions kAgreement{1e-3, 1e-4};
// Light tracing's connections to the camera are heavy-tailed on glossy surfaces (a sharp Phong
// lobe evaluated towards the camera is large only rarely), so per-pixel standard errors need
// many samples to be reliable: small images, many samples.
constexpr uint64_t kSpp = 32768;

SceneDescription scene_of(const std::string& key) {
    if (looks_like_scene_file(key)) return load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/tests/data/scenes/" + key);
    return make_builtin_scene(std::stoi(key));
}

AgreementResult compare_with_pt_mis(const std::string& key, Integrator& lt, int w, int h, uint64_t spp = kSpp) {
    const SceneDescription d = scene_of(key);
    const RenderResult a = render_integrator(d, lt, w, h, spp, 301);
    const RenderResult b = render_scene(d, "pt-mis", w, h, int(spp), 302);
    const auto scene = Scene::build(d);
    const std::vector<uint8_t> mask = specular_first_vertex_mask(*scene, w, h, 16, /*dilate=*/false);
    AgreementOptions o = kAgreement;
    o.excluded = &mask;
    return test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), o);
}

class LightTracerAgreement : public ::testing::TestWithParam<std::string> {};

TEST_P(LightTracerAgreement, ConvergesToThePathTracersImage) {
    LightTracer<RgbTransport> lt({});
    const bool file = looks_like_scene_file(GetParam());
    const AgreementResult r = file ? compare_with_pt_mis(GetParam(), lt, 16, 12, 16384) : compare_with_pt_mis(GetParam(), lt, 8, 8);
    ::testing::Test::RecordProperty("agreement", r.describe());
    EXPECT_TRUE(r.agree) << GetParam() << ": " << r.describe();
    if (file) { EXPECT_GT(r.excluded, 10) << "the scene must show specular surfaces"; }
}
INSTANTIATE_TEST_SUITE_P(Scenes, LightTracerAgreement,
                         ::testing::Values("0", "1", "2", "3", "4", "5", "6", "7", "specular-box.xml", "specular-sky.xml"),
                         [](const auto& info) {
                             std::string n = info.param;
                             for (char& c : n) if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return "scene_" + n;
                         });

// Tests of the test: the same comparison fails for a light tracer without the camera's
// geometry term and for one without the emission sample's density.
TEST(LightTracerAgreement, DetectsAMissingCameraGeometryTerm) {
    LightTracerFaults f;
    f.drop_camera_geometry = true;
    LightTracer<RgbTransport> lt({}, f);
    EXPECT_FALSE(compare_with_pt_mis("2", lt, 8, 8, 4096).agree);
}

TEST(LightTracerAgreement, DetectsAMissingEmissionPdf) {
    LightTracerFaults f;
    f.drop_emission_pdf = true;
    LightTracer<RgbTransport> lt({}, f);
    EXPECT_FALSE(compare_with_pt_mis("4", lt, 8, 8, 4096).agree);
}

RenderResult lt_render(const std::string& key, int threads, uint64_t spp, uint64_t first = 0) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const auto scene = Scene::build(scene_of(key));
    LightTracer<RgbTransport> lt({});
    RenderSettings rs;
    rs.width = 40, rs.height = 30, rs.spp = spp, rs.seed = 9, rs.first_sample = first;
    return render(*scene, lt, rs);
}

TEST(LightTracerDeterminism, OneAndTwoThreadsGiveBitIdenticalImages) {
    for (const char* key : {"5", "specular-sky.xml"}) {
        const RenderResult one = lt_render(key, 1, 6), two = lt_render(key, 2, 6);
        EXPECT_TRUE(bit_identical(one.film.mean(), two.film.mean())) << key;
        EXPECT_TRUE(bit_identical(one.film.standard_error(), two.film.standard_error())) << key;
        EXPECT_EQ(one.stats.rays, two.stats.rays) << key;
    }
}

TEST(LightTracerDeterminism, ARenderSplitIntoTwoPartsSumsToTheOneShotRender) {
    const RenderResult whole = lt_render("5", 2, 8);
    // Continued into the same film: bit for bit.
    const auto scene = Scene::build(scene_of("5"));
    LightTracer<RgbTransport> lt({});
    RenderSettings rs;
    rs.width = 40, rs.height = 30, rs.spp = 3, rs.seed = 9;
    Film film(40, 30);
    render_into(*scene, lt, rs, film);
    rs.first_sample = 3, rs.spp = 5;
    render_into(*scene, lt, rs, film);
    EXPECT_TRUE(bit_identical(film.mean(), whole.film.mean()));
    EXPECT_TRUE(bit_identical(film.standard_error(), whole.film.standard_error()));
    // Rendered separately and merged: the same sums up to the order of two additions.
    Film merged = lt_render("5", 2, 3).film;
    merged.merge(lt_render("5", 1, 5, 3).film);
    for (size_t i = 0; i < merged.pixel_count(); ++i) {
        ASSERT_EQ(merged.count(i), whole.film.count(i));
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(merged.sum(i)[c], whole.film.sum(i)[c], 1e-12 * std::max(1.0, std::abs(whole.film.sum(i)[c])));
    }
}

}  // namespace
}  // namespace pathlab::test

namespace pathlab::test {
namespace {

// The pixels lt cannot see: none in the course scenes (no specular materials), the mirror,
// the glass and the plastic cube in specular-box.xml, and nothing else.
TEST(LightTracerCheck, SpecularFirstVertexMaskMarksMirrorsGlassAndPlasticOnly) {
    for (int s = 0; s < 8; ++s) {
        const auto scene = Scene::build(make_builtin_scene(s));
        EXPECT_EQ(count_marked(specular_first_vertex_mask(*scene, 32, 32)), 0u) << "scene " << s;
    }
    const auto scene = Scene::build(scene_of("specular-box.xml"));
    const std::vector<uint8_t> exact = specular_first_vertex_mask(*scene, 48, 48, 4, false);
    const std::vector<uint8_t> dilated = specular_first_vertex_mask(*scene, 48, 48, 4, true);
    const PerspectiveCamera camera(scene->camera(), 48, 48);
    size_t specular_centres = 0;
    for (size_t i = 0; i < exact.size(); ++i) {
        Intersection hit;
        const bool specular = scene->intersect(camera.generate(float(i % 48) + 0.5f, float(i / 48) + 0.5f), hit) &&
                              (scene->material(hit.material).lobes() & kLobeSpecular);
        specular_centres += specular;
        if (specular) { EXPECT_TRUE(exact[i]) << "pixel " << i; }  // its centre sees a specular surface
        if (exact[i]) { EXPECT_TRUE(dilated[i]); }
    }
    EXPECT_GT(specular_centres, 100u);
    EXPECT_LT(count_marked(dilated), exact.size() / 3);
}

}  // namespace
}  // namespace pathlab::test
