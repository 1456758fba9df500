// Agreement of direct-light with the course's own direct-illumination reference images
// (8-bit, gamma 2.2), judged as `pathlab check` judges them (tools/course_reference.hpp).
#include <gtest/gtest.h>

#include "image/image_io.hpp"
#include "biased_estimators.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "render_helpers.hpp"
#include "judge/course_reference.hpp"

namespace pathlab::test {
namespace {

// Samples per pixel by scene, so each render's noise stays well under the 1-level criterion:
// the emitting ceiling (2, 3) is light-sampled from points millimetres away (variance ~1/d^2),
// and the environment (6, 7) is sampled uniformly over the sphere, wasting most samples.
constexpr int kSpp[8] = {32, 32, 256, 256, 32, 32, 256, 256};

Image8 course_reference(int scene) {
    return read_png8(shared_dir() + "/npgr010-refs/direct/" + std::to_string(scene) + ".png");
}

BlockComparison compare(const SceneDescription& desc, int scene, int spp) {
    const RenderResult r = render_scene(desc, "direct-light", 512, 512, spp, 1234);
    return compare_with_course_reference(r.film.mean(), course_reference(scene), r.film.standard_error());
}

class CourseReference : public ::testing::TestWithParam<int> {};

TEST_P(CourseReference, DirectLightMatches) {
    const int scene = GetParam();
    const BlockComparison cmp = compare(make_builtin_scene(scene), scene, kSpp[scene]);
    RecordProperty("comparison", cmp.describe());
    EXPECT_TRUE(cmp.passes()) << cmp.describe();
    EXPECT_GT(cmp.pixels_compared, 200'000);  // the margin around saturated pixels stays small
}
INSTANTIATE_TEST_SUITE_P(Scenes, CourseReference, ::testing::Range(0, 8));

// Tests of the test: plausible bugs must fail it.
TEST(CourseReferenceCheck, FailsWithAPhongLobeTwentyPercentTooWeak) {
    SceneDescription d = make_builtin_scene(1);
    for (Material& m : d.materials) std::get<PhongMaterial>(m.model).specular *= 0.8f;
    const BlockComparison cmp = compare(d, 1, kSpp[1]);
    EXPECT_FALSE(cmp.passes()) << cmp.describe();
}

TEST(CourseReferenceCheck, FailsWithAPointLightFivePercentTooBright) {
    SceneDescription d = make_builtin_scene(0);
    for (FreeLight& l : d.lights) std::get<PointLight>(l).intensity *= 1.05f;
    const BlockComparison cmp = compare(d, 0, kSpp[0]);
    EXPECT_FALSE(cmp.passes()) << cmp.describe();
}

TEST(CourseReferenceCheck, FailsWithAnAreaLightThreePercentTooBright) {
    SceneDescription d = make_builtin_scene(4);
    for (MeshDesc& m : d.meshes)
        if (!is_black(m.emission)) m.emission *= 1.03f;
    const BlockComparison cmp = compare(d, 4, kSpp[4]);
    EXPECT_FALSE(cmp.passes()) << cmp.describe();
}

TEST(CourseReferenceCheck, FailsWithoutTheReceiverCosine) {
    const auto scene = Scene::build(make_builtin_scene(0));
    RenderSettings rs;
    rs.spp = kSpp[0];
    rs.seed = 1234;
    const RenderResult r = render(*scene, DirectLightWithoutCosine(), rs);
    const BlockComparison cmp = compare_with_course_reference(r.film.mean(), course_reference(0), r.film.standard_error());
    EXPECT_FALSE(cmp.passes()) << cmp.describe();
}

}  // namespace
}  // namespace pathlab::test
