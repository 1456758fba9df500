// BDPT's MIS weights on hand-built paths: for paths through diffuse, glossy and specular
// vertices to area, point and environment lights, the weight bdpt gives each strategy (s, t)
// equals the balance (and power) heuristic computed here directly from the strategies' own
// path densities, the weights of the strategies that can produce a path sum to 1, each lies in
// [0, 1], and none is NaN. The densities below are written out from their definitions, not
// taken from the subpath code.
#include "mis_harness.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

// The sum of the balance heuristic weights bdpt gives the strategies that can make f.
double weight_sum(const MisHarness& h, const FullPath& f) {
    const int n = int(f.p.size()) - 1;
    double sum = 0;
    for (int s = 0; s <= n; ++s) {
        if (!h.valid(f, s)) continue;
        std::vector<PathVertex<RgbTransport>> light, camera;
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
            std::vector<PathVertex<RgbTransport>> light, camera;
            h.subpaths(f, s, light, camera, power);
            const float w = h.bdpt(power).mis_weight(h.ctx(), light, s, camera, n + 1 - s, h.sampled_end(f, s));
            const float oracle = h.bdpt(power).mis_weight_oracle(h.ctx(), light, s, camera, n + 1 - s, h.sampled_end(f, s));
            const double expected = h.direct_weight(f, s, power);
            EXPECT_NEAR(w, oracle, 1e-5 * oracle + 1e-12) << what << (power ? " (power)" : " (balance)") << ", s=" << s << ": running vs walk";
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

// Area light paths, through the mirror too; the point light; the environment.
TEST(BdptMis, HandBuiltPaths) {
    for (const LightKind kind : {LightKind::Area, LightKind::Point, LightKind::Environment}) {
        const MisHarness h(kind);
        for (const NamedPath& p : hand_built_paths(h)) expect_weights(h, p.path, p.name);
    }
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

// On traced paths: a render whose every weight comes from the ratio walk equals, pixel by pixel,
// the render of the same samples weighted from the running quantities (to 1e-4 relative; the
// weights differ in rounding only): point, area and environment lights, glass, mirrors, glossy
// Phong, plastic (a Dirac coat over a diffuse base), both heuristics, and a dispersive prism in
// spectral mode (subpaths that carry the hero wavelength alone).
template <class T>
void expect_same_render(const std::string& key, bool power) {
    const SceneDescription d = looks_like_scene_file(key) ? load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + key)
                                                          : make_builtin_scene(std::stoi(key));
    IntegratorOptions o;
    o.mis_power = power;
    Bdpt<T> running(o), walk(o, BdptFaults{.ratio_walk = true});
    const Image a = render_integrator(d, running, 24, 18, 4, 77).film.mean();
    const Image b = render_integrator(d, walk, 24, 18, 4, 77).film.mean();
    double total = 0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            total += b[i][c];
            ASSERT_NEAR(a[i][c], b[i][c], 1e-4 * std::abs(b[i][c]) + 1e-7) << key << (power ? " (power)" : "") << ", pixel " << i;
        }
    EXPECT_GT(total, 0.0) << key;
}

TEST(BdptMis, RunningWeightsEqualTheWalkOnTracedPaths) {
    for (const bool power : {false, true})
        for (const char* key : {"1", "5", "7", "smallvcm-box.xml", "materials/plastic.xml"}) expect_same_render<RgbTransport>(key, power);
    expect_same_render<SpectralTransport>("prism.xml", false);
}

// On traced subpaths through SmallVCM's mirror and glass balls: a Dirac vertex gives its
// neighbours the densities of its lobe's coefficient (the probability of choosing it, in (0, 1],
// the same both ways) across the edge, cosine and distance included, not 0: the weights of
// caustics seen through glass depend on it (docs/estimators.md, "Against SmallVCM itself").
TEST(BdptMis, DiracVerticesPassTheirCoefficientToTheirNeighbours) {
    const auto scene = Scene::build(load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/smallvcm-balls.xml"));
    const PerspectiveCamera camera(scene->camera(), 64, 64);
    const RenderContext ctx{*scene, camera, 64, 64, 7, SamplerKind::Independent, 32};
    const Bdpt<RgbTransport> bdpt{IntegratorOptions{}};
    std::vector<PathVertex<RgbTransport>> path;
    int checked = 0;
    for (uint64_t j = 0; j < 20000; ++j)
        for (const bool light_side : {false, true}) {
            Sampler sampler(7, j, 0);
            if (light_side) bdpt.light_subpath(ctx, sampler, RgbWavelengths{}, path);
            else bdpt.camera_subpath(ctx, size_t(j % 4096), sampler, RgbWavelengths{}, path);
            for (size_t i = 1; i + 1 < path.size(); ++i) {
                if (!path[i].delta || path[i + 1].infinite) continue;
                // The coefficient as the next vertex's density, and as the previous one's reverse density.
                const double forward = path[i + 1].pdf_fwd / to_area_density(1.0f, path[i], path[i + 1]);
                const double backward = path[i - 1].pdf_rev / to_area_density(1.0f, path[i], path[i - 1]);
                ASSERT_GT(forward, 0.0) << (light_side ? "light" : "camera") << " subpath " << j << ", vertex " << i;
                ASSERT_LE(forward, 1.0 + 1e-5);
                ASSERT_NEAR(backward, forward, 1e-4 * forward) << (light_side ? "light" : "camera") << " subpath " << j << ", vertex " << i;
                ++checked;
            }
        }
    EXPECT_GT(checked, 1000);
}

}  // namespace
}  // namespace pathlab::test
