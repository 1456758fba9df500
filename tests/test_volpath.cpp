// volpath: without media it is pt-mis bit for bit; with an index-matched medium of sigma_t = 0
// (and dielectric boundaries around media) it agrees with pt-mis; closed forms (an albedo-1
// medium inside an emitting sphere stays at Le, homogeneous and in a grid, chromatic; single
// scattering in a slab); MIS on and off agree; 1 and 2 threads give the same bytes.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <fstream>
#include <iterator>

#include "../tools/smoke_grid.hpp"
#include "geometry/shape_meshes.hpp"
#include "media/grid_files.hpp"
#include "integrators/path/volpath.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scene_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

std::string source_path(const std::string& relative) { return std::string(PATHLAB_SOURCE_DIR) + "/" + relative; }

const AgreementOptions kAgreement{1e-3, 1e-4};

// ---- without media: pt-mis ------------------------------------------------------------------

TEST(Volpath, WithoutMediaItIsPtMisBitForBit) {
    std::vector<SceneDescription> scenes;
    for (int s = 0; s < 8; ++s) scenes.push_back(make_builtin_scene(s));
    for (const char* f : {"scenes/materials/smooth.xml", "scenes/materials/roughdielectric.xml", "scenes/caustic.xml"})
        scenes.push_back(load_scene_file(source_path(f)));
    // The merged lights (envmap, spot, IES), and a thin-lens camera with a Gaussian filter and a
    // twosided pair of BSDFs (front, back) in the course box.
    for (const char* f : {"scenes/envmap-sky.xml", "scenes/spot.xml", "scenes/ies.xml"}) scenes.push_back(load_scene_file(source_path(f)));
    {
        std::string text;
        {
            std::ifstream in(source_path("scenes/2-ceiling-diffuse.xml"));
            text.assign(std::istreambuf_iterator<char>(in), {});
        }
        const auto replace = [&](const std::string& from, const std::string& to) {
            const size_t at = text.find(from);
            ASSERT_NE(at, std::string::npos) << from;
            text.replace(at, from.size(), to);
        };
        replace("<scene version=\"3.0.0\">", "<scene version=\"3.0.0\"><path value=\"" + source_path("scenes") + "\"/>");
        replace("<sensor type=\"perspective\">",
                "<sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"0.1\"/><float name=\"focus_distance\" value=\"3\"/>");
        replace("<film type=\"hdrfilm\">", "<film type=\"hdrfilm\"><rfilter type=\"gaussian\"/>");
        replace("<bsdf type=\"twosided\" id=\"floor\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.803921998, 0.803921998, 0.803921998\"/></bsdf></bsdf>",
                "<bsdf type=\"twosided\" id=\"floor\"><bsdf type=\"diffuse\"/><bsdf type=\"roughconductor\"/></bsdf>");
        const std::string file = testing::TempDir() + "volpath-thinlens.xml";
        std::ofstream(file) << text;
        scenes.push_back(load_scene_file(file));
    }
    const auto own_loop = make_volpath(IntegratorOptions{}, {true, false});
    for (const SceneDescription& d : scenes) {
        const RenderResult a = render_scene(d, "pt-mis", 16, 12, 4, 7), b = render_scene(d, "volpath", 16, 12, 4, 7);
        EXPECT_TRUE(bit_identical(a.film.mean(), b.film.mean())) << d.name;
        EXPECT_TRUE(bit_identical(a.film.standard_error(), b.film.standard_error())) << d.name;
        EXPECT_EQ(a.stats.rays, b.stats.rays) << d.name;
        // volpath's own loop (not pt-mis's, which it hands a scene without media to).
        const RenderResult c = render_integrator(d, *own_loop, 16, 12, 4, 7);
        EXPECT_TRUE(bit_identical(a.film.mean(), c.film.mean())) << d.name << ": volpath's own loop";
        EXPECT_TRUE(bit_identical(a.film.standard_error(), c.film.standard_error())) << d.name << ": volpath's own loop";
        EXPECT_EQ(a.stats.rays, c.stats.rays) << d.name << ": volpath's own loop";
    }
}

// ---- media that change nothing --------------------------------------------------------------

// Index-matched boundaries are Embree geometry with their own mask: the rays of every estimator
// that does not render media pass through them (meshes and spheres), so pt-mis renders a scene
// whose media are a vacuum as if the boundaries were not there (a scene with a medium that
// attenuates it refuses: test_scene_file_media.cpp; lt and bdpt follow media as volpath does).
TEST(Volpath, OtherEstimatorsDoNotSeeIndexMatchedBoundaries) {
    const SceneDescription plain = make_builtin_scene(2);
    SceneDescription with = plain;
    with.media.push_back(HomogeneousMedium{Rgb(0.0f), Rgb(0.0f), IsotropicPhase{}});
    MeshDesc box = cube_mesh();
    transform_mesh(box, Transform::scale({0.5, 0.5, 0.5}));
    box.media.interior = 0;
    box.media.index_matched = true;
    with.meshes.push_back(box);
    SphereDesc ball;
    ball.center = {0.2f, -0.6f, 0.1f};
    ball.radius = 0.3f;
    ball.media.interior = 0;
    ball.media.index_matched = true;
    with.spheres.push_back(ball);
    for (const char* a : {"pt-mis", "direct-light"}) {
        const RenderResult x = render_scene(plain, a, 16, 16, 4, 7), y = render_scene(with, a, 16, 16, 4, 7);
        EXPECT_TRUE(bit_identical(x.film.mean(), y.film.mean())) << a;
    }
    // volpath does see them when the medium is dense.
    with.media[0] = HomogeneousMedium{Rgb(2.0f), Rgb(1.0f), IsotropicPhase{}};
    const RenderResult x = render_scene(plain, "volpath", 16, 16, 4, 7), y = render_scene(with, "volpath", 16, 16, 4, 7);
    EXPECT_FALSE(bit_identical(x.film.mean(), y.film.mean()));
}

// Scene 2 (ceiling light) with an empty medium filling the box, and its blue sphere turned into
// glass filled with another empty medium: volpath crosses the boundaries, switches media at the
// glass, samples free flights that never end and ratio-tracks transmittances of 1.
SceneDescription empty_media_scene() {
    SceneDescription d = make_builtin_scene(2);
    d.media.push_back(HomogeneousMedium{Rgb(0.0f), Rgb(0.0f), HgPhase{0.5f}});
    d.media.push_back(HomogeneousMedium{Rgb(0.0f), Rgb(0.0f), IsotropicPhase{}});
    d.meshes.push_back(fog_box(0));
    make_last_sphere_glass(d, 1, 0);
    return d;
}

TEST(Volpath, AnIndexMatchedEmptyMediumAgreesWithPtMis) {
    const SceneDescription d = empty_media_scene();
    const RenderResult a = render_scene(d, "pt-mis", 16, 16, 1024, 3), b = render_scene(d, "volpath", 16, 16, 1024, 4);
    const AgreementResult r = test_agreement(b.film.mean(), b.film.standard_error(), a.film.mean(), a.film.standard_error(), kAgreement);
    EXPECT_TRUE(r.agree) << r.describe();
    // volpath traced the boundaries: more rays per sample than pt-mis.
    EXPECT_GT(b.stats.rays, a.stats.rays);
}

// ---- closed forms ---------------------------------------------------------------------------

// A sphere of radius 1 emitting Le inwards, black (it absorbs what reaches it), filled with
// `medium` in which the camera sits. With albedo 1 nothing is lost, so every pixel sees Le.
SceneDescription emitting_sphere(const Medium& medium, Rgb Le) {
    SceneDescription d;
    d.name = "medium-furnace";
    d.camera = Camera::look_along({0.1f, -0.2f, 0.05f}, {0.3f, 1.0f, 0.2f}, {0, 0, 1}, 70.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(0.0f))};
    SphereDesc s;
    s.radius = 1;
    s.flip_normals = true;
    s.emission = Le;
    s.media.interior = 0;
    d.spheres.push_back(s);
    d.media.push_back(medium);
    d.camera_medium = 0;
    return d;
}

// A 3-channel grid of densities between 0.2 and 2.7 filling [-0.8, 0.8]^3.
HeterogeneousMedium grid_medium(const Rgb& albedo) { return striped_grid_medium({{6, 5, 4}, 3, 0.2f, 0.5f, 6, 0.8, albedo, HgPhase{-0.3f}}); }

TEST(Volpath, AnAlbedoOneMediumInAnEmittingEnclosureStaysAtLe) {
    const Rgb Le(0.5f, 1.0f, 1.5f);
    const Medium homogeneous = HomogeneousMedium{Rgb(0.5f, 1.5f, 3.0f), Rgb(0.5f, 1.5f, 3.0f), HgPhase{0.6f}};
    for (const Medium& m : {homogeneous, Medium(grid_medium(Rgb(1.0f)))}) {
        const RenderResult r = render_scene(emitting_sphere(m, Le), "volpath", 8, 8, 2048, 5);
        const AgreementResult a =
            test_agreement(r.film.mean(), r.film.standard_error(), Image(8, 8, Le), Image(), kAgreement);
        EXPECT_TRUE(a.agree) << (std::holds_alternative<HomogeneousMedium>(m) ? "homogeneous: " : "grid: ") << a.describe();
    }
}

TEST(Volpath, AnAbsorbingMediumIsDetectedInTheFurnace) {
    // The test of the test: albedo 0.9 is not Le.
    const Rgb Le(1.0f);
    const Medium m = HomogeneousMedium{Rgb(1.0f), Rgb(0.9f), HgPhase{0.6f}};
    const RenderResult r = render_scene(emitting_sphere(m, Le), "volpath", 8, 8, 2048, 5);
    EXPECT_FALSE(test_agreement(r.film.mean(), r.film.standard_error(), Image(8, 8, Le), Image(), kAgreement).agree);
}

// Henyey-Greenstein written out here (not the code under test's).
double hg(double g, double cos_theta) { return (1 - g * g) / (4 * M_PI * std::pow(1 + g * g - 2 * g * cos_theta, 1.5)); }

// A slab 0 < z < thickness of a homogeneous medium (wide enough to be infinite here), lit by a
// directional light from above, seen from above. With one bounce the radiance along a camera
// ray of direction v (|v.z| = mu_v) is the single-scattering integral
//   L = sigma_s p(theta) E (1 - exp(-sigma_t d (1/mu_v + 1/mu_l))) / (sigma_t (1 + mu_v / mu_l)),
// theta between the light's direction of travel and -v, mu_l the light direction's |z|.
TEST(Volpath, SingleScatteringInAThinSlabMatchesTheClosedForm) {
    const float thickness = 0.2f, g = 0.4f;
    const HomogeneousMedium medium{Rgb(0.8f, 1.2f, 2.0f), Rgb(0.5f, 0.6f, 1.0f), HgPhase{g}};
    const Vec3f light_dir = normalize(Vec3f(0.3f, 0.2f, -1.0f));
    const Rgb E(1.0f, 2.0f, 3.0f);
    SceneDescription d;
    d.name = "slab";
    d.camera = Camera::look_at({0, -1.5f, 2}, {0, 0, 0.1f}, {0, 0, 1}, 1.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(0.5f))};
    MeshDesc slab = cube_mesh();
    transform_mesh(slab, Transform::translate({0, 0, thickness / 2}) * Transform::scale({50, 50, thickness / 2}));
    slab.media.interior = 0;
    slab.media.index_matched = true;
    d.meshes.push_back(slab);
    d.media.push_back(medium);
    d.lights.push_back(DirectionalLight{light_dir, E});

    constexpr int kSize = 4;
    IntegratorOptions o;
    o.max_depth = 1;
    const RenderResult r = render_scene(d, "volpath", kSize, kSize, 8192, 9, o);
    const PerspectiveCamera camera(d.camera, kSize, kSize);
    Image expected(kSize, kSize);
    const double mu_l = std::abs(light_dir.z);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const Vec3f v = normalize(camera.generate(float(x) + 0.5f, float(y) + 0.5f).d);
            const double mu_v = std::abs(v.z), p = hg(g, -dot(light_dir, v));
            for (int c = 0; c < 3; ++c) {
                const double st = medium.sigma_t[c], ss = medium.sigma_s[c];
                expected.at(x, y)[c] = float(ss * p * E[c] * (1 - std::exp(-st * thickness * (1 / mu_v + 1 / mu_l))) / (st * (1 + mu_v / mu_l)));
            }
        }
    const AgreementResult a = test_agreement(r.film.mean(), r.film.standard_error(), expected, Image(), kAgreement);
    EXPECT_TRUE(a.agree) << a.describe() << "\nexpected " << expected.at(0, 0).x << " " << expected.at(0, 0).y << " "
                         << expected.at(0, 0).z << ", got " << r.film.mean().at(0, 0).x << " " << r.film.mean().at(0, 0).y
                         << " " << r.film.mean().at(0, 0).z;
}

// ---- MIS, threads ---------------------------------------------------------------------------

TEST(Volpath, WithAndWithoutMisAgree) {
    SceneDescription d = make_builtin_scene(4);  // the light box: small and bright, MIS matters
    d.media.push_back(HomogeneousMedium{Rgb(0.4f, 0.5f, 0.6f), Rgb(0.3f, 0.4f, 0.5f), HgPhase{0.3f}});
    d.meshes.push_back(fog_box(0));
    IntegratorOptions o;
    o.max_depth = 4;
    const auto mis = make_volpath(o), no_mis = make_volpath(o, {false});
    const RenderResult a = render_integrator(d, *mis, 12, 12, 1024, 1), b = render_integrator(d, *no_mis, 12, 12, 1024, 2);
    const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), kAgreement);
    EXPECT_TRUE(r.agree) << r.describe();
}

// --mis power (Mitsuba 3's volpath weighs its light and phase/BSDF samples so): another
// estimator of the same image, in the medium and on the surfaces, not the balance heuristic's bytes.
TEST(Volpath, ThePowerHeuristicAgreesWithTheBalanceHeuristic) {
    SceneDescription d = make_builtin_scene(4);
    d.media.push_back(HomogeneousMedium{Rgb(0.4f, 0.5f, 0.6f), Rgb(0.3f, 0.4f, 0.5f), HgPhase{0.3f}});
    d.meshes.push_back(fog_box(0));
    IntegratorOptions o;
    o.max_depth = 4;
    IntegratorOptions p = o;
    p.mis_power = true;
    const auto balance = make_volpath(o), power = make_volpath(p);
    const RenderResult a = render_integrator(d, *balance, 12, 12, 1024, 1), b = render_integrator(d, *power, 12, 12, 1024, 2);
    const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), kAgreement);
    EXPECT_TRUE(r.agree) << r.describe();
    EXPECT_FALSE(bit_identical(render_integrator(d, *power, 12, 12, 64, 1).film.mean(), render_integrator(d, *balance, 12, 12, 64, 1).film.mean()));
}

TEST(Volpath, OneAndTwoThreadsGiveTheSameBytes) {
    for (const char* f : {"scenes/fog-box.xml", "scenes/smoke.xml"}) {
        const SceneDescription d = load_scene_file(source_path(f));
        const auto with_threads = [&](int threads) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
            return render_scene(d, "volpath", 24, 16, 4, 5);
        };
        const RenderResult one = with_threads(1), two = with_threads(2);
        EXPECT_TRUE(bit_identical(one.film.mean(), two.film.mean())) << f;
        EXPECT_TRUE(bit_identical(one.film.standard_error(), two.film.standard_error())) << f;
        EXPECT_EQ(one.stats.rays, two.stats.rays) << f;
    }
}

// The committed grid is the generator's (tools/make_smoke.cpp), up to float rounding of a
// different compiler.
TEST(Volpath, TheShippedSmokeIsTheGeneratorsGrid) {
    const VoxelGrid shipped = read_vol_file(source_path("scenes/volumes/smoke.vol")), made = tools::smoke_grid(32);
    ASSERT_EQ(shipped.res, made.res);
    ASSERT_EQ(shipped.data.size(), made.data.size());
    for (size_t i = 0; i < made.data.size(); ++i) ASSERT_NEAR(shipped.data[i], made.data[i], 1e-5f) << i;
}

}  // namespace
}  // namespace pathlab::test
