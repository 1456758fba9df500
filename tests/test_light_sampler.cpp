// The light samplers (--light-sampler uniform|power|bvh|ris): each one's pmf over the lights sums
// to 1 at every shading point, its choices follow its pmf (chi-square), the pmf the BSDF-sampled
// half of MIS reads for a light equals the probability of choosing it (infinite lights
// included), ris's resampled estimate is unbiased (z-test), and every sampler converges to the
// same image (per-pixel z-tests).
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include "integrators/common/direct_lighting.hpp"
#include "job/usage_error.hpp"
#include "judge/image_statistics.hpp"
#include "lights/light_bounds.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

const LightSamplerKind kKinds[] = {LightSamplerKind::Uniform, LightSamplerKind::Power, LightSamplerKind::Bvh, LightSamplerKind::Ris};

// Every kind of light at once: a triangle-mesh emitter, an emitting sphere, a point, a spot, an
// IES-less omni light, a directional sun and a constant sky (two lights at infinity).
const char* kMixedLights = R"(<scene version="3.0.0">
    <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform><bsdf type="diffuse"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="180"/><translate z="2"/></transform>
        <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
    <shape type="sphere"><point name="center" value="1.5, 0.5, 0.8"/><float name="radius" value="0.2"/>
        <emitter type="area"><rgb name="radiance" value="2, 1, 0.5"/></emitter></shape>
    <emitter type="point"><point name="position" value="-1, -1, 1"/><rgb name="intensity" value="3"/></emitter>
    <emitter type="spot"><transform name="to_world"><lookat origin="0, 2, 2" target="0, 0, 0"/></transform>
        <rgb name="intensity" value="20"/><float name="cutoff_angle" value="25"/></emitter>
    <emitter type="directional"><vector name="direction" value="0.3, 0.2, -1"/><rgb name="irradiance" value="1"/></emitter>
    <emitter type="constant"><rgb name="radiance" value="0.1, 0.2, 0.4"/></emitter>
</scene>)";

SceneDescription mixed_lights(LightSamplerKind kind) {
    SceneDescription d = load_scene_text(kMixedLights, "mixed-lights.xml", ".");
    d.light_sampler = kind;
    return d;
}

SceneDescription many_lights(LightSamplerKind kind, float split = 0) {
    SceneDescription d = load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/many-lights.xml");
    d.light_sampler = kind;
    d.light_split = split;
    return d;
}

// Shading points: (p, n) with p in the scene's bounds and n a random unit vector or 0 (a medium).
std::vector<std::pair<Vec3f, Vec3f>> shading_points(const Scene& scene, int count) {
    Sampler rng(7, 0, 0);
    std::vector<std::pair<Vec3f, Vec3f>> out;
    const Vec3f c = scene.bounds_center();
    const float r = scene.bounds_radius();
    for (int i = 0; i < count; ++i) {
        const Vec3f p = c + Vec3f(rng.next1d() - 0.5f, rng.next1d() - 0.5f, rng.next1d() - 0.5f) * r;
        const Vec3f n = i % 5 == 4 ? Vec3f(0.0f) : square_to_uniform_sphere(rng.next2d());
        out.emplace_back(p, n);
    }
    return out;
}

// The running mean, variance and standard error of a sample of estimates.
struct Moments {
    double sum = 0, sum2 = 0;
    int n = 0;
    void add(double x) { sum += x, sum2 += x * x, ++n; }
    double mean() const { return sum / n; }
    double variance() const { return std::max(0.0, sum2 / n - mean() * mean()); }
    double standard_error() const { return std::sqrt(variance() / n); }
};

class LightSamplers : public ::testing::TestWithParam<LightSamplerKind> {};

TEST_P(LightSamplers, PmfSumsToOneAndIsWhatChooseReturns) {
    for (const bool many : {false, true}) {
        const auto scene = Scene::build(many ? many_lights(GetParam()) : mixed_lights(GetParam()));
        const LightSampler& s = scene->light_sampler();
        const int n = int(scene->lights().size());
        ASSERT_GT(n, many ? 4000 : 6);
        Sampler rng(11, 0, 0);
        for (const auto& [p, nrm] : shading_points(*scene, many ? 40 : 400)) {
            double sum = 0;
            for (int i = 0; i < n; ++i) {
                const float pmf = s.pmf(p, nrm, i);
                ASSERT_GE(pmf, 0.0f);
                sum += pmf;
            }
            // The bvh may choose no light (index -1) where the bounds of a node's children rule
            // every light below it out: its pmf then sums to less than 1, the rest is "none".
            if (GetParam() != LightSamplerKind::Bvh && GetParam() != LightSamplerKind::Ris) EXPECT_NEAR(sum, 1.0, 1e-4) << "many=" << many;
            else EXPECT_LE(sum, 1.0 + 1e-4) << "many=" << many;
            for (int k = 0; k < 20; ++k) {
                const LightChoice c = s.choose(p, nrm, rng.next1d());
                if (c.index < 0) {
                    EXPECT_LT(sum, 1.0 - 1e-6) << "no light chosen where the pmf sums to 1";
                    continue;
                }
                EXPECT_EQ(c.pmf, s.pmf(p, nrm, c.index)) << "light " << c.index;  // bit for bit: MIS reads the same number
                EXPECT_GT(c.pmf, 0.0f);
            }
        }
    }
}

// The histogram of 400k choices at fixed points against the pmf: Pearson's chi-square over the
// cells with an expected count of at least 5 (the rest pooled), at a false-alarm rate of 1e-6
// per point (z of the Wilson-Hilferty approximation > 4.75).
TEST_P(LightSamplers, ChoicesFollowThePmf) {
    for (const bool many : {false, true}) {
        const auto scene = Scene::build(many ? many_lights(GetParam()) : mixed_lights(GetParam()));
        const LightSampler& s = scene->light_sampler();
        const int n = int(scene->lights().size());
        const auto points = shading_points(*scene, 3);
        for (const auto& [p, nrm] : points) {
            constexpr int kDraws = 400000;
            std::vector<int> count(size_t(n), 0);
            Sampler rng(13, 0, 0);
            for (int k = 0; k < kDraws; ++k) {
                const LightChoice c = s.choose(p, nrm, rng.next1d());
                if (c.index >= 0) ++count[size_t(c.index)];
            }
            double chi2 = 0, pooled_expected = 0, pooled_observed = 0, total = 0;
            int cells = 0, none = kDraws;
            for (int i = 0; i < n; ++i) total += s.pmf(p, nrm, i), none -= count[size_t(i)];
            // "No light" is one more cell, of probability 1 - the sum.
            count.push_back(none);
            for (int i = 0; i <= n; ++i) {
                const double expected = (i < n ? double(s.pmf(p, nrm, i)) : std::max(0.0, 1 - total)) * kDraws;
                if (expected < 1e-3) {
                    EXPECT_EQ(count[size_t(i)], 0) << "light " << i << " (" << n << ": none) chosen with pmf " << expected / kDraws;
                } else if (expected < 5) {
                    pooled_expected += expected, pooled_observed += count[size_t(i)];
                } else {
                    chi2 += (count[size_t(i)] - expected) * (count[size_t(i)] - expected) / expected, ++cells;
                }
            }
            if (pooled_expected >= 5) chi2 += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) / pooled_expected, ++cells;
            if (cells < 2) continue;
            const double dof = cells - 1;
            const double z = (std::cbrt(chi2 / dof) - (1 - 2 / (9 * dof))) / std::sqrt(2 / (9 * dof));
            EXPECT_LT(z, 4.75) << "chi2 " << chi2 << " over " << dof << " degrees of freedom, many=" << many;
        }
    }
}

// The pmf the BSDF-sampled half finds (trace_to_emitter) equals light sampling's own, for
// directions towards every kind of light a ray can hit: the surfaces and the sky (pbrt-v4
// PR 163 mis-sampled infinite lights in its BVH sampler).
TEST_P(LightSamplers, BsdfSampledHitsGetTheSamplersPdf) {
    const auto scene = Scene::build(mixed_lights(GetParam()));
    Sampler rng(5, 0, 0);
    int surfaces = 0, sky = 0;
    for (int k = 0; k < 4000; ++k) {
        const Vec3f p(rng.next1d() * 4 - 2, rng.next1d() * 4 - 2, 0.001f);
        const Vec3f n(0, 0, 1);
        const LightChoice c = scene->choose_light(p, n, rng.next1d());
        if (c.index < 0) continue;
        const Light& light = scene->lights()[size_t(c.index)];
        const auto ls = sample_light(light, p, rng.next2d());
        if (!ls || ls->delta || ls->wi.z <= 0) continue;
        const EmitterHit e = trace_to_emitter(*scene, Ray{p, ls->wi, kInf}, p, n);
        const int found = e.hit ? e.isect.light : scene->environment_light();
        if (found != c.index) continue;  // occluded by another emitter
        // (A point sampled at a sphere's silhouette, |cos| < 0.02, is left out: there the area density's
        // 1 / cos changes by tens of per cent between the sampled point and the ray's hit a rounding
        // error away, pdf_li's conditioning, not the sampler's pmf.)
        if (!is_black(ls->normal) && std::abs(dot(ls->normal, ls->wi)) < 0.02f) continue;
        const float expected = c.pmf * ls->pdfW;
        ASSERT_NEAR(e.pdf_light, expected, 2e-3f * expected) << "light " << c.index;
        (e.hit ? surfaces : sky)++;
    }
    EXPECT_GT(surfaces, 100);
    EXPECT_GT(sky, 100);
}

INSTANTIATE_TEST_SUITE_P(Kinds, LightSamplers, ::testing::ValuesIn(kKinds),
                         [](const ::testing::TestParamInfo<LightSamplerKind>& i) { return std::string(light_sampler_name(i.param)); });

// The bvh ranks lights by their bounds: below one ceiling tile, facing it, the tile is chosen far
// more often than its share of the power; a tile facing away (seen from above the ceiling) is
// never chosen.
// uniform: every emitter alike (each free light, sphere and emitting mesh is one), an emitting
// mesh's triangles by their areas, as Mitsuba 3 chooses: a mesh of triangles of areas 0.5 and 1.5
// beside the mixed scene's six emitters.
TEST(LightSamplers, UniformChoosesEmittersAlikeAndAMeshsTrianglesByArea) {
    SceneDescription d = mixed_lights(LightSamplerKind::Uniform);
    MeshDesc m;
    m.positions = {{0, 0, 3}, {1, 0, 3}, {0, 1, 3}, {3, 1, 3}};
    m.triangles = {{0, 2, 1}, {1, 2, 3}};  // areas 0.5 and 1.5, facing down
    m.emission = Rgb(1.0f);
    d.meshes.push_back(m);
    const std::unique_ptr<Scene> scene = Scene::build(d);
    const std::vector<Light>& lights = scene->lights();
    ASSERT_EQ(lights.size(), 9u);  // 4 free lights, the rectangle's 2 triangles, the new mesh's 2, the sphere
    const Vec3f p(0.2f, 0.1f, 0.5f), n(0, 0, 1);
    double total = 0;
    for (int i = 0; i < 9; ++i) {
        const float pmf = scene->light_pmf(p, n, i);
        total += pmf;
        if (i == 4 || i == 5) EXPECT_FLOAT_EQ(pmf, 1.0f / 14) << i;  // the rectangle's halves
        else if (i == 6) EXPECT_FLOAT_EQ(pmf, 1.0f / 7 * 0.25f) << i;
        else if (i == 7) EXPECT_FLOAT_EQ(pmf, 1.0f / 7 * 0.75f) << i;
        else EXPECT_FLOAT_EQ(pmf, 1.0f / 7) << i;
    }
    EXPECT_NEAR(total, 1.0, 1e-6);
}

// The light tree's importance, four groups at a time in 4-wide arithmetic with every sine and
// cosine kept times the distance (light_bounds.hpp), is the bound its comment states, computed
// here with angles in double: phi cos(theta') / max(d^2, near r^2) times cos(max(0, theta_i - theta_b)),
// theta' = max(0, theta_w - theta_o - theta_b), 0 beyond theta_e; inside the bounding sphere
// phi / (near r^2). For single lights of every kind, unions of them, and an empty lane (0), at
// points around them with a surface's normal or none (a medium). Points within 1e-3 rad of
// theta' = theta_e, where the bound jumps to 0, are skipped.
double documented_importance(const LightBounds& b, const Vec3f& p, const Vec3f& n, bool& near_cutoff) {
    near_cutoff = false;
    if (!(b.phi > 0)) return 0.0;
    const double dx = double(p.x) - b.centre.x, dy = double(p.y) - b.centre.y, dz = double(p.z) - b.centre.z;
    const double dd = dx * dx + dy * dy + dz * dz, r = b.radius, near2 = double(b.near) * r * r;
    if (dd <= r * r) return std::min(double(b.phi) / std::max(near2, 1e-20), 1e30);
    const double d = std::sqrt(dd);
    double cos_w = (b.w.x * dx + b.w.y * dy + b.w.z * dz) / d;
    if (b.two_sided) cos_w = std::abs(cos_w);
    const double theta_b = std::asin(std::min(1.0, r / d)), theta_w = std::acos(std::clamp(cos_w, -1.0, 1.0));
    const double theta_p = std::max(0.0, std::max(0.0, theta_w - b.theta_o) - theta_b);
    near_cutoff = theta_w - b.theta_o > -1e-3 && std::abs(std::max(0.0, theta_w - b.theta_o) - theta_b - b.theta_e) < 1e-3;
    if (theta_p > b.theta_e) return 0.0;
    double importance = b.phi * std::cos(theta_p) / std::max(dd, near2);
    if (n.x != 0 || n.y != 0 || n.z != 0) {
        const double theta_i = std::acos(std::min(1.0, std::abs(n.x * dx + n.y * dy + n.z * dz) / d));
        importance *= std::cos(std::max(0.0, theta_i - theta_b));
    }
    return importance;
}

TEST(LightBvh, FourLaneImportanceIsTheDocumentedBound) {
    const auto scene = Scene::build(mixed_lights(LightSamplerKind::Bvh));
    std::vector<LightBounds> groups;
    for (const Light& light : scene->lights())
        if (!(light_flags(light) & kLightInfinite)) groups.push_back(light_bounds(light, scene->scene_sphere()));
    ASSERT_GE(groups.size(), 5u);  // the area light's two triangles, the sphere, the point, the spot
    const size_t singles = groups.size();
    for (size_t i = 0; i + 1 < singles; ++i) groups.push_back(unite(groups[i], groups[i + 1]));
    LightBounds all;
    for (size_t i = 0; i < singles; ++i) all = unite(all, groups[i]);
    groups.push_back(all);
    groups.emplace_back();  // an empty lane: phi 0

    Sampler rng(11, 0, 0);
    int compared = 0, total = 0;
    for (size_t first = 0; first < groups.size(); first += 3) {
        LightBounds4 lanes;
        size_t lane_group[4];
        for (int k = 0; k < 4; ++k) lane_group[k] = (first + size_t(k)) % groups.size(), lanes.set(k, groups[lane_group[k]]);
        for (int i = 0; i < 400; ++i) {
            const Vec3f p = Vec3f(rng.next1d() - 0.5f, rng.next1d() - 0.5f, rng.next1d()) * 6.0f;
            const Vec3f n = i % 4 == 3 ? Vec3f(0.0f) : square_to_uniform_sphere(rng.next2d());
            float got[4];
            lanes.importance(p, n).store(got);
            for (int k = 0; k < 4; ++k) {
                const LightBounds& b = groups[lane_group[k]];
                bool near_cutoff;
                const double want = documented_importance(b, p, n, near_cutoff);
                ++total;
                if (near_cutoff) continue;
                // Float rounding: relative 1e-3, or 1e-4 of the bound without its cosines.
                const Vec3f d = p - b.centre;
                const double scale = b.phi / std::max(double(dot(d, d)), double(b.near) * b.radius * b.radius + 1e-20);
                EXPECT_NEAR(got[k], want, 1e-3 * want + 1e-4 * scale) << "group " << lane_group[k] << ", lane " << k << ", point " << i;
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 0.95 * total);

    // The comparison's power: a triangle of the area light (theta_o 0, theta_e pi/2) with its
    // emission's spread written as cos(theta_e - 0.3) differs from the bound at many points.
    const auto triangle = std::find_if(groups.begin(), groups.end(), [](const LightBounds& b) { return b.theta_o == 0 && b.phi > 0; });
    ASSERT_NE(triangle, groups.end());
    LightBounds4 wrong;
    wrong.set(0, *triangle);
    wrong.cos_e[0] = std::cos(triangle->theta_e - 0.3f);
    int differ = 0;
    for (int i = 0; i < 400; ++i) {
        const Vec3f p = Vec3f(rng.next1d() - 0.5f, rng.next1d() - 0.5f, rng.next1d()) * 6.0f;
        float got[4];
        wrong.importance(p, Vec3f(0.0f)).store(got);
        bool near_cutoff;
        const double want = documented_importance(*triangle, p, Vec3f(0.0f), near_cutoff);
        if (std::abs(got[0] - want) > 1e-3 * want + 1e-6) ++differ;
    }
    EXPECT_GT(differ, 10);
}

TEST(LightBvh, PrefersNearLightsAndRulesOutLightsFacingAway) {
    const auto bvh = Scene::build(many_lights(LightSamplerKind::Bvh));
    const auto power = Scene::build(many_lights(LightSamplerKind::Power));
    const Vec3f p(-5.925f, 0.125f, 2.5f), up(0, 0, 1);  // 0.5 below the first tile of the ceiling grid
    int nearest = -1;
    float best = kInf;
    for (size_t i = 0; i < bvh->lights().size(); ++i)
        if (const auto* t = std::get_if<TriangleLight>(&bvh->lights()[i])) {
            const float d = length(t->p0 + (t->e1 + t->e2) / 3.0f - p);
            if (d < best) best = d, nearest = int(i);
        }
    ASSERT_GE(nearest, 0);
    EXPECT_GT(bvh->light_pmf(p, up, nearest), 20 * power->light_pmf(p, up, nearest));
    // Above the ceiling (z = 3; the tiles hang at z = 2.999 facing down): every tile faces away.
    const Vec3f above(1, 12, 4);
    int facing_away = 0;
    for (size_t i = 0; i < bvh->lights().size(); ++i) {
        const auto* t = std::get_if<TriangleLight>(&bvh->lights()[i]);
        ASSERT_TRUE(t && t->normal.z < -0.99f) << "light " << i << " is not a tile facing down";
        ASSERT_EQ(bvh->light_pmf(above, Vec3f(0.0f), int(i)), 0.0f) << "light " << i;
        ++facing_away;
    }
    EXPECT_GT(facing_away, 4000);
}

// Every sampler converges to the same image: pt-mis with uniform, bvh and ris against power, per-pixel
// z-tests (false-alarm rate 1e-4 per comparison), on a course scene whose glossy surfaces give
// BSDF sampling much of the MIS weight (ris weighing its sample with its own density instead of
// the source density fails here at |z| 29) and on the many-light scene.
TEST(LightSamplerAgreement, EverySamplerConvergesToTheSameImage) {
    const AgreementOptions agreement{1e-3, 1e-4};
    for (const bool many : {false, true}) {
        auto render_with = [&](LightSamplerKind kind, uint64_t seed, float split = 0) {
            JobRequest r;
            r.algorithm = "pt-mis";
            r.spp = many ? 256 : 2048;
            r.width = r.height = 12;
            r.seed = seed;
            r.max_depth = 3;
            r.light_sampler = kind;
            if (split > 0) r.light_split = split;
            RenderJob job(many ? scene_choice_of(many_lights(kind)) : builtin_scene_choice(3), r);
            return job.run();
        };
        const RenderResult base = render_with(LightSamplerKind::Power, 1);
        for (const LightSamplerKind kind : {LightSamplerKind::Uniform, LightSamplerKind::Bvh, LightSamplerKind::Ris}) {
            const RenderResult a = render_with(kind, 2);
            const AgreementResult res = test_agreement(a.film.mean(), a.film.standard_error(), base.film.mean(), base.film.standard_error(), agreement);
            EXPECT_TRUE(res.agree) << light_sampler_name(kind) << " vs power, many=" << many << ": " << res.describe();
        }
        // bvh with adaptive splitting (a threshold that splits the top levels on most of the hall's floor).
        const RenderResult a = render_with(LightSamplerKind::Bvh, 3, 0.5f);
        const AgreementResult res = test_agreement(a.film.mean(), a.film.standard_error(), base.film.mean(), base.film.standard_error(), agreement);
        EXPECT_TRUE(res.agree) << "bvh with splitting vs power, many=" << many << ": " << res.describe();
    }
}

// The same bytes with 1 and 2 threads (the tree is read-only; every choice is a function of the
// sample's own numbers); bvh also with splitting.
TEST(LightBvh, DeterministicAcrossThreadCounts) {
    for (const float split : {0.0f, 0.5f})
    for (const LightSamplerKind kind : {LightSamplerKind::Bvh, LightSamplerKind::Ris}) {
        if (split > 0 && kind != LightSamplerKind::Bvh) continue;
        SceneDescription d = many_lights(kind, split);
        JobRequest r;
        r.algorithm = "pt-mis";
        r.spp = 4;
        r.width = 32, r.height = 24;
        r.light_sampler = kind;
        if (split > 0) r.light_split = split;
        auto run = [&](int threads) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
            RenderJob job(scene_choice_of(d), r);
            return job.run();
        };
        const RenderResult a = run(1), b = run(2);
        EXPECT_TRUE(bit_identical(a.film.mean(), b.film.mean())) << light_sampler_name(kind) << " split " << split;
    }
}

// volpath's next-event estimation in a medium (the phase function as ris's target) and on
// surfaces in fog: ris against power, per-pixel z-tests as above.
TEST(LightSamplerAgreement, RisInFogConvergesToPowersImage) {
    auto render_with = [&](LightSamplerKind kind, uint64_t seed, float split = 0) {
        JobRequest r;
        r.algorithm = "volpath";
        r.spp = 1024;
        r.width = r.height = 10;
        r.seed = seed;
        r.max_depth = 3;
        r.light_sampler = kind;
        if (split > 0) r.light_split = split;
        RenderJob job(scene_choice_of(load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/fog-box.xml")), r);
        return job.run();
    };
    const RenderResult base = render_with(LightSamplerKind::Power, 1);
    // ris, and bvh with a threshold low enough to split the fog box's light (two triangles) at most points.
    for (const auto& [kind, split] : {std::pair{LightSamplerKind::Ris, 0.0f}, std::pair{LightSamplerKind::Bvh, 0.05f}}) {
        const RenderResult a = render_with(kind, 2, split);
        const AgreementResult res = test_agreement(a.film.mean(), a.film.standard_error(), base.film.mean(), base.film.standard_error(),
                                                   AgreementOptions{1e-3, 1e-4});
        EXPECT_TRUE(res.agree) << light_sampler_name(kind) << " split " << split << ": " << res.describe();
    }
}

// Resampled importance sampling at a point (light_resampling.hpp): with g the unshadowed
// irradiance of a light sample, the mean of g(y) / pdf over ris's samples equals the mean of
// g(x) / p over the plain bvh sampler's (a z-test at a false-alarm rate of 1e-6), for the target
// t = g and for a target that differs from g (Talbot's estimator is unbiased for any t that is
// positive where g is); with t = g its variance per sample is a fraction of bvh's. Every kind of
// light (delta, infinite, area) and the many-light floor.
TEST(LightRis, ResampledEstimateIsUnbiasedAndLowersVariance) {
    for (const bool many : {false, true}) {
        const auto scene = Scene::build(many ? many_lights(LightSamplerKind::Ris) : mixed_lights(LightSamplerKind::Ris));
        ASSERT_EQ(scene->light_sampler().candidates(), kDefaultRisCandidates);
        const Vec3f n(0, 0, 1);
        const auto points = many ? std::vector<Vec3f>{Vec3f(0, 2, 0.01f), Vec3f(1, 12, 0.01f)}
                                 : std::vector<Vec3f>{Vec3f(0.3f, -0.2f, 0.001f), Vec3f(-1.2f, 0.7f, 0.001f)};
        for (const Vec3f& p : points) {
            auto g = [&](const LightSample& ls, int) { return luminance(ls.Le) * std::max(0.0f, dot(n, ls.wi)); };
            auto other = [&](const LightSample& ls, int i) { return g(ls, i) * (0.2f + ls.wi.x * ls.wi.x); };
            Moments plain;
            Sampler rng(17, 0, 0);
            for (int k = 0; k < 400000; ++k) {
                double sum = 0;
                for_each_nee_sample(*scene, p, n, rng, 1, g, [&](const NeeSample& s) { sum += g(s.ls, 0) / s.pdf; });
                plain.add(sum);
            }
            for (const bool exact : {true, false}) {
                Moments ris;
                for (int k = 0; k < 50000; ++k) {
                    const auto s = exact ? resample_nee(*scene, p, n, rng, kDefaultRisCandidates, g)
                                         : resample_nee(*scene, p, n, rng, kDefaultRisCandidates, other);
                    ris.add(s ? g(s->ls, 0) / s->pdf : 0.0);
                }
                const double z = (ris.mean() - plain.mean()) / std::hypot(ris.standard_error(), plain.standard_error());
                EXPECT_LT(std::abs(z), 4.9) << "many=" << many << " exact=" << exact << ": ris " << ris.mean() << " +- "
                                            << ris.standard_error() << ", bvh " << plain.mean() << " +- " << plain.standard_error();
                if (exact) {
                    EXPECT_LT(ris.variance() * 3, plain.variance()) << "many=" << many;
                }
            }
        }
    }
}

TEST(LightSamplerOption, RefusedByIntegratorsThatDoNotChooseLightsAtShadingPoints) {
    JobRequest r;
    r.algorithm = "bdpt";
    r.light_sampler = LightSamplerKind::Bvh;
    try {
        RenderJob job(builtin_scene_choice(4), r);
        FAIL() << "bdpt accepted --light-sampler";
    } catch (const UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("pt-mis"), std::string::npos) << e.what();
    }
    r.algorithm = "volpath";
    EXPECT_NO_THROW(RenderJob(builtin_scene_choice(4), r));
}

TEST(LightSamplerOption, LightSplitOnlyWithBvhAndInRange) {
    JobRequest r;
    r.algorithm = "pt-mis";
    r.light_split = 0.5f;
    EXPECT_THROW(RenderJob(builtin_scene_choice(4), r), UsageError);
    r.light_sampler = LightSamplerKind::Ris;
    EXPECT_THROW(RenderJob(builtin_scene_choice(4), r), UsageError);
    r.light_sampler = LightSamplerKind::Bvh;
    EXPECT_NO_THROW(RenderJob(builtin_scene_choice(4), r));
    for (const float bad : {-0.5f, kMaxLightSplit * 2, std::numeric_limits<float>::quiet_NaN()}) {
        r.light_split = bad;
        EXPECT_THROW(RenderJob(builtin_scene_choice(4), r), UsageError) << bad;
    }
}

TEST(LightSamplerOption, RisCandidatesOnlyWithRisAndInRange) {
    JobRequest r;
    r.algorithm = "pt-mis";
    r.ris_candidates = 4;
    EXPECT_THROW(RenderJob(builtin_scene_choice(4), r), UsageError);
    r.light_sampler = LightSamplerKind::Ris;
    EXPECT_NO_THROW(RenderJob(builtin_scene_choice(4), r));
    for (const int bad : {0, kMaxRisCandidates + 1}) {
        r.ris_candidates = bad;
        EXPECT_THROW(RenderJob(builtin_scene_choice(4), r), UsageError) << bad;
    }
}


// The variance of one light sample's estimate of the unshadowed irradiance at points of the
// hall's floor, sum_i E_i^2 / pmf_i - (sum_i E_i)^2 (E_i of a small tile: L A cos cos / d^2):
// the bvh's is a fraction of power's.
TEST(LightBvh, LowersTheVarianceOfUnshadowedIrradianceOnTheManyLightFloor) {
    const auto bvh = Scene::build(many_lights(LightSamplerKind::Bvh));
    const auto power = Scene::build(many_lights(LightSamplerKind::Power));
    const Vec3f n(0, 0, 1);
    for (const Vec3f p : {Vec3f(0, 2, 0.01f), Vec3f(1, 12, 0.01f), Vec3f(-2, 22, 0.01f)}) {
        double sum = 0, v_bvh = 0, v_power = 0;
        for (size_t i = 0; i < bvh->lights().size(); ++i) {
            const auto& t = std::get<TriangleLight>(bvh->lights()[i]);
            const Vec3f c = t.p0 + (t.e1 + t.e2) / 3.0f, d = c - p;
            const float d2 = dot(d, d);
            const Vec3f w = d / std::sqrt(d2);
            const double e = mean(t.radiance) * t.area * std::max(0.0f, -dot(t.normal, w)) * std::max(0.0f, dot(n, w)) / d2;
            sum += e;
            v_bvh += e * e / bvh->light_pmf(p, n, int(i));
            v_power += e * e / power->light_pmf(p, n, int(i));
        }
        v_bvh -= sum * sum, v_power -= sum * sum;
        RecordProperty("variance_ratio", std::to_string(v_power / v_bvh));
        EXPECT_LT(v_bvh * 3, v_power) << "at (" << p.x << ", " << p.y << "): power " << v_power << ", bvh " << v_bvh;
    }
}

// Adaptive splitting (--light-split): at points of the hall's floor and of the mixed-light
// scene, every light choose_split returns carries the pmf pmf() gives it (bit for bit: the
// BSDF-sampled half of MIS reads it), no light comes twice, and the sum over the returned lights
// of E_i / pmf_i (E_i: light i's unshadowed irradiance at the point, or 1 for every light of
// positive pmf) has the mean sum_i E_i (a z-test at a false-alarm rate of 1e-6 per point); on
// the hall its variance is below the unsplit bvh's per choice.
TEST(LightBvh, SplittingIsUnbiasedAndItsPmfIsWhatMisReads) {
    for (const bool many : {true, false}) {
        SceneDescription d = many ? many_lights(LightSamplerKind::Bvh) : mixed_lights(LightSamplerKind::Bvh);
        d.light_split = 0.5f;
        const auto split = Scene::build(d);
        d.light_split = 0;
        const auto plain = Scene::build(d);
        ASSERT_GT(split->light_sampler().split(), 0.0f);
        const auto points = many ? std::vector<Vec3f>{Vec3f(0, 2, 0.01f), Vec3f(1, 12, 0.01f), Vec3f(-2, 22, 0.01f)}
                                 : std::vector<Vec3f>{Vec3f(0.3f, -0.2f, 0.001f), Vec3f(-1.2f, 0.7f, 0.001f)};
        const Vec3f n(0, 0, 1);
        int split_points = 0;
        for (const Vec3f& p : points) {
            // E_i: the unshadowed irradiance of a light (its power over distance squared, times the
            // receiver's cosine, for the tiles; 1 for the rest).
            const auto E = [&](int i) -> double {
                const auto* t = std::get_if<TriangleLight>(&split->lights()[size_t(i)]);
                if (!t) return 1.0;
                const Vec3f c = t->p0 + (t->e1 + t->e2) / 3.0f, dv = c - p;
                const float d2 = dot(dv, dv);
                const Vec3f w = dv / std::sqrt(d2);
                return mean(t->radiance) * t->area * std::max(0.0f, -dot(t->normal, w)) * std::max(0.0f, dot(n, w)) / d2;
            };
            double expected_e = 0, expected_count = 0;
            for (int i = 0; i < int(split->lights().size()); ++i)
                if (split->light_pmf(p, n, i) > 0) expected_e += E(i), expected_count += 1;
            Moments e_split, count_split, e_plain;
            Sampler rng(23, 0, 0);
            int most = 0;
            for (int k = 0; k < 100000; ++k) {
                LightChoice chosen[kMaxSplitLights];
                const int m = split->light_sampler().choose_split(p, n, rng.next1d(), chosen);
                ASSERT_LE(m, kMaxSplitLights);
                most = std::max(most, m);
                double e = 0, c = 0;
                for (int j = 0; j < m; ++j) {
                    ASSERT_EQ(chosen[j].pmf, split->light_pmf(p, n, chosen[j].index)) << "light " << chosen[j].index;
                    for (int l = 0; l < j; ++l) ASSERT_NE(chosen[l].index, chosen[j].index);
                    e += E(chosen[j].index) / chosen[j].pmf, c += 1 / chosen[j].pmf;
                }
                e_split.add(e), count_split.add(c);
                const LightChoice one = plain->choose_light(p, n, rng.next1d());
                e_plain.add(one.index >= 0 ? E(one.index) / one.pmf : 0.0);
            }
            split_points += most > 1;
            for (const auto& [m, target, what] : {std::tuple{&e_split, expected_e, "irradiance"}, std::tuple{&count_split, expected_count, "count"}}) {
                const double z = (m->mean() - target) / m->standard_error();
                EXPECT_LT(std::abs(z), 4.9) << "many=" << many << " at (" << p.x << ", " << p.y << ") " << what << ": " << m->mean() << " +- "
                                            << m->standard_error() << " against " << target;
            }
            if (many) EXPECT_LT(e_split.variance() * 2, e_plain.variance()) << "at (" << p.x << ", " << p.y << ")";
        }
        EXPECT_GT(split_points, 0) << "many=" << many << ": no point split";
    }
}

}  // namespace
}  // namespace pathlab::test
