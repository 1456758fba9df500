// ic: Ward and Heckbert's gradients predict a record made a little further away better than the
// record alone; without a cache (--ic-error 0) ic agrees with pt-mis by the z-test; the error
// against pt-mis falls as the threshold does; 1 and 2 threads give the same bytes and records.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "integrators/cache/ic.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

RenderResult render_with(const SceneDescription& d, Integrator& integrator, int w, int h, uint64_t spp, uint64_t seed = 5,
                         int threads = 0) {
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const auto scene = Scene::build(d);
    RenderSettings rs;
    rs.width = w, rs.height = h, rs.spp = spp, rs.seed = seed;
    return render(*scene, integrator, rs);
}

IntegratorOptions ic_options(float error, int rays = 256, bool gradients = true) {
    IntegratorOptions o;
    o.ic_error = error;
    o.ic_rays = rays;
    o.ic_gradients = gradients;
    return o;
}

// Over 150 first hits of scene 2 (64x64 pixel centres, chosen at random), a record gathered
// with 1024 rays at x predicts the irradiance at the first hit x' two pixels to the right
// (walls, floor, the balls: offsets along the surface and turned normals) against a 4096-ray
// record there. With the gradients, E + (n x n') . grad_r + (x' - x) . grad_t, the mean
// squared error must be below 0.7 of the record alone's, E.
TEST(IcGradients, PredictANearbyRecordBetterThanTheRecordAlone) {
    const SceneDescription d = make_builtin_scene(2);
    const auto scene = Scene::build(d);
    const PerspectiveCamera camera(scene->camera(), 64, 64);
    const RenderContext ctx{*scene, camera, 64, 64, 3, SamplerKind::Independent, 32};
    IrradianceCaching<RgbTransport> coarse(ic_options(0.0f, 1024)), fine(ic_options(0.0f, 4096));
    coarse.prepare(ctx, {}), fine.prepare(ctx, {});
    Sampler pick(11, 0, 0);
    double with = 0, without = 0;
    int points = 0;
    while (points < 150) {
        const float px = 2 + 58 * pick.next1d(), py = 2 + 60 * pick.next1d();
        Intersection h0, h1;
        const Ray r0 = camera.generate(px, py), r1 = camera.generate(px + 2, py);
        if (!scene->intersect(r0, h0) || !scene->intersect(r1, h1)) continue;
        const ShadingPoint a = make_shading_point(*scene, h0, r0.d), b = make_shading_point(*scene, h1, r1.d);
        if (a.material->is_black() || b.material->is_black() || dot(a.frame.n, b.frame.n) < 0.9f) continue;  // not across an edge
        Sampler sa(21, uint64_t(points), 0), sb(22, uint64_t(points), 0);
        const IrradianceRecord ra = coarse.make_record(*scene, a, sa), rb = fine.make_record(*scene, b, sb);
        const Vec3f rot = cross(ra.n, b.frame.n), dp = b.p - ra.p;
        for (int c = 0; c < 3; ++c) {
            const double predicted = ra.E[c] + dot(rot, ra.grad_r[c]) + dot(dp, ra.grad_t[c]);
            with += (predicted - rb.E[c]) * (predicted - rb.E[c]);
            without += (ra.E[c] - rb.E[c]) * (ra.E[c] - rb.E[c]);
        }
        ++points;
    }
    EXPECT_LT(with, 0.7 * without) << fmt::format("MSE with gradients {:.6g}, without {:.6g}", with / points, without / points);
}

// --ic-error 0: no record is ever valid, every first hit gathers for itself with one ray, and ic
// is path tracing with one diffuse gather: it agrees with pt-mis by the per-pixel z-test (scenes
// 2 and 4, 16x16; 1e-3 per pixel, 1e-4 for the family).
TEST(IcConsistency, WithoutACacheItAgreesWithThePathTracer) {
    for (const int index : {2, 4}) {
        const SceneDescription d = make_builtin_scene(index);
        IrradianceCaching<RgbTransport> ic(ic_options(0.0f));
        const std::unique_ptr<Integrator> pt = find_integrator("pt-mis")->make({});
        const RenderResult a = render_with(d, ic, 16, 16, 4096, 3), b = render_with(d, *pt, 16, 16, 8192, 4);
        const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(),
                                                 AgreementOptions{1e-3, 1e-4});
        EXPECT_TRUE(r.agree) << index << ": " << r.describe();
        EXPECT_EQ(ic.cache().size(), 0u);
    }
}

// The mean of an image's luminance.
double mean_luminance(const Image& im) {
    double sum = 0;
    for (size_t i = 0; i < im.pixel_count(); ++i) sum += luminance(im[i]);
    return sum / double(im.pixel_count());
}

// The cache's error against pt-mis (32x32; 256 spp in scene 2, 1024 in scene 4 whose direct
// light is noisier), measured as the noise lets it be seen: in scene 2 the RMS difference with
// both images' noise subtracted, in scene 4 (whose per-pixel noise hides that) the difference of
// the images' mean luminance (interpolation brightens it, mostly where records reach over darker
// corners). Each falls as the threshold does (a = 0.4, 0.2, 0.1), and the record count grows.
TEST(IcConvergence, TheErrorFallsWithTheThreshold) {
    for (const int index : {2, 4}) {
        const SceneDescription d = make_builtin_scene(index);
        const std::unique_ptr<Integrator> pt = find_integrator("pt-mis")->make({});
        const uint64_t spp = index == 2 ? 256 : 1024;
        const RenderResult ref = render_with(d, *pt, 32, 32, 16 * spp, 4);
        std::vector<double> mean_error, rms_error;
        std::vector<size_t> records;
        for (const float a : {0.4f, 0.2f, 0.1f}) {
            IrradianceCaching<RgbTransport> ic(ic_options(a));
            const RenderResult r = render_with(d, ic, 32, 32, spp, 3);
            mean_error.push_back(std::abs(mean_luminance(r.film.mean()) - mean_luminance(ref.film.mean())));
            rms_error.push_back(bias_rms(r.film.mean(), r.film.standard_error(), ref.film.mean(), ref.film.standard_error()));
            records.push_back(ic.cache().size());
        }
        const std::string all = fmt::format("scene {}: mean error {:.5f} {:.5f} {:.5f}, RMS bias {:.5f} {:.5f} {:.5f}, records {} {} {}",
                                            index, mean_error[0], mean_error[1], mean_error[2], rms_error[0], rms_error[1], rms_error[2],
                                            records[0], records[1], records[2]);
        // Scene 2: the mean is within its noise at every threshold (the brightening and the
        // darkening cancel), the per-pixel bias is not; scene 4: the other way round.
        const std::vector<double>& e = index == 2 ? rms_error : mean_error;
        EXPECT_GT(e[0], e[1]) << all;
        EXPECT_GT(e[1], e[2]) << all;
        EXPECT_LT(records[0], records[1]) << all;
        EXPECT_LT(records[1], records[2]) << all;
    }
}

TEST(IcDeterminism, OneAndTwoThreadsGiveTheSameRecordsAndBytes) {
    for (const int index : {3, 6}) {
        const SceneDescription d = make_builtin_scene(index);
        IrradianceCaching<RgbTransport> one(ic_options(0.2f)), two(ic_options(0.2f));
        const RenderResult a = render_with(d, one, 40, 30, 4, 9, 1), b = render_with(d, two, 40, 30, 4, 9, 2);
        EXPECT_TRUE(bit_identical(a.film.mean(), b.film.mean())) << index;
        ASSERT_EQ(one.cache().size(), two.cache().size()) << index;
        EXPECT_GT(one.cache().size(), 10u) << index;
        for (size_t i = 0; i < one.cache().size(); ++i) {
            ASSERT_EQ(one.cache().records()[i].pixel, two.cache().records()[i].pixel);
            ASSERT_EQ(one.cache().records()[i].R, two.cache().records()[i].R);
        }
    }
}

}  // namespace
}  // namespace pathlab::test
