// BDPT's MIS weights on hand-built paths: for paths through diffuse, glossy and specular
// vertices to area, point and environment lights, the weight bdpt gives each strategy (s, t)
// equals the balance (and power) heuristic computed here directly from the strategies' own
// path densities, the weights of the strategies that can produce a path sum to 1, each lies in
// [0, 1], and none is NaN. The densities below are written out from their definitions, not
// taken from the subpath code.
#include "mis_harness.hpp"

namespace pathlab::test {
namespace {

// The sum of the balance heuristic weights bdpt gives the strategies that can make f.
double weight_sum(const MisHarness& h, const FullPath& f) {
    const int n = int(f.p.size()) - 1;
    double sum = 0;
    for (int s = 0; s <= n; ++s) {
        if (!h.valid(f, s)) continue;
        std::vector<PathVertex> light, camera;
        h.subpaths(f, s, light, camera);
        sum += h.bdpt(false).mis_weight(h.ctx(), light, s, camera, n + 1 - s, h.sampled_end(f, s));
    }
    return sum;
}

void expect_weights(const MisHarness& h, const FullPath& f, const std::string& what) {
    ASSERT_TRUE(f.problem.empty()) << what << ": " << f.problem;
    const int n = int(f.p.size()) - 1;
    for (const bool power : {false, true}) {
        double sum = 0;
        int strategies = 0;
        for (int s = 0; s <= n; ++s) {
            if (!h.valid(f, s)) continue;
            ++strategies;
            std::vector<PathVertex> light, camera;
            h.subpaths(f, s, light, camera);
            const float w = h.bdpt(power).mis_weight(h.ctx(), light, s, camera, n + 1 - s, h.sampled_end(f, s));
            const double expected = h.direct_weight(f, s, power);
            ASSERT_FALSE(std::isnan(w)) << what << " s=" << s;
            EXPECT_GE(w, 0.0f) << what;
            EXPECT_LE(w, 1.0f) << what;
            EXPECT_NEAR(w, expected, 1e-4 + 1e-4 * expected) << what << (power ? " (power)" : " (balance)") << ", s=" << s;
            sum += w;
        }
        EXPECT_GT(strategies, 0) << what;
        EXPECT_NEAR(sum, 1.0, 1e-4) << what << (power ? " (power)" : " (balance)");
    }
}

TEST(BdptMis, AreaLightPaths) {
    const MisHarness h(LightKind::Area);
    const Vec3f on_light(0.1f, 0.45f, 2.5f), on_glossy(1.2f, 1.1f, 0.7f), a(0.2f, 0.4f, 0.0f), b(-0.4f, 2.5f, 1.0f);
    expect_weights(h, h.build({a, on_light}), "camera-floor-light");
    expect_weights(h, h.build({a, on_glossy, on_light}), "camera-floor-glossy-light");
    expect_weights(h, h.build({a, b, on_light}), "camera-floor-wall-light");
    expect_weights(h, h.build({on_glossy, a, b, on_light}), "camera-glossy-floor-wall-light");
    expect_weights(h, h.build({on_light}), "camera-light");  // the light seen directly
}

TEST(BdptMis, PathsThroughAMirror) {
    const MisHarness h(LightKind::Area);
    const Vec3f on_light(0.1f, 0.45f, 2.5f), on_mirror(-1.2f, 1.0f, 0.8f);
    const Vec3f f1 = floor_point_reflected_to(on_mirror, on_light);
    expect_weights(h, h.build({f1, on_mirror, kReflect}), "camera-floor-mirror-light");
    // A vertical mirror cannot send light from the floor back down: mirrors seen first.
    const Vec3f low_mirror(-1.2f, 0.6f, 0.3f);
    expect_weights(h, h.build({low_mirror, kReflect, on_light}), "camera-mirror-floor-light");
    expect_weights(h, h.build({low_mirror, kReflect, Vec3f(-0.4f, 2.5f, 1.0f), on_light}), "camera-mirror-floor-wall-light");
}

// The test of the tests: weights that leave next-event estimation out of their sums no longer
// sum to 1 on paths it can make.
TEST(BdptMis, DetectsADroppedStrategy) {
    const MisHarness h(LightKind::Area, BdptFaults{.drop_nee_strategy = true});
    const Vec3f on_light(0.1f, 0.45f, 2.5f), a(0.2f, 0.4f, 0.0f), b(-0.4f, 2.5f, 1.0f);
    const FullPath f = h.build({a, b, on_light});
    ASSERT_TRUE(f.problem.empty()) << f.problem;
    EXPECT_GT(weight_sum(h, f), 1.0 + 1e-3);
}

TEST(BdptMis, PointLightPaths) {
    const MisHarness h(LightKind::Point);
    const Vec3f a(0.2f, 0.4f, 0.0f);
    expect_weights(h, h.build({a}), "camera-floor-point");
    expect_weights(h, h.build({a, Vec3f(1.2f, 1.1f, 0.7f)}), "camera-floor-glossy-point");
    expect_weights(h, h.build({Vec3f(-1.2f, 0.6f, 0.3f), kReflect}), "camera-mirror-floor-point");
    expect_weights(h, h.build({Vec3f(-1.2f, 0.6f, 0.3f), kReflect, Vec3f(-0.4f, 2.5f, 1.0f)}), "camera-mirror-floor-wall-point");
}

TEST(BdptMis, EnvironmentPaths) {
    const MisHarness h(LightKind::Environment);
    const Vec3f a(0.2f, 0.4f, 0.0f);
    expect_weights(h, h.build({a}, {0.2f, 0.1f, 1.0f}), "camera-floor-sky");
    expect_weights(h, h.build({a, Vec3f(1.2f, 1.1f, 0.7f)}, {-1.0f, 0.2f, 0.5f}), "camera-floor-glossy-sky");
    expect_weights(h, h.build({Vec3f(-1.2f, 0.6f, 0.3f), kReflect}, {0.1f, 0.3f, 1.0f}), "camera-mirror-floor-sky");
}

}  // namespace
}  // namespace pathlab::test
