// --aovs: the auxiliary images from the render's own camera samples, against their closed forms:
// the normal, albedo and position of a plane seen directly; the albedo, normal and path length
// of a diffuse wall seen through a 45-degree mirror; a dense medium's albedo; the same bytes with
// 1 and 2 threads; variance and sample-count from the film; and integrators without camera
// samples refused for the first-vertex AOVs.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "cli_runner.hpp"
#include "image/image_io.hpp"
#include "job/extra_channels.hpp"
#include "job/render_job.hpp"
#include "job/usage_error.hpp"
#include "scene_helpers.hpp"
#include "scratch_dir.hpp"

namespace pathlab::test {
namespace {

// A camera at the origin looking along +z with a narrow field of view; a quad light behind it.
SceneDescription facing_scene() {
    SceneDescription d;
    d.name = "aovs";
    d.width = 12, d.height = 10;
    d.camera = Camera::look_along({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 20.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(0.0f)), make_phong(Rgb(0.2f, 0.4f, 0.6f)), make_mirror()};
    d.meshes.push_back(quad({0, 0, -1}, {1, 0, 0}, {0, 1, 0}, 0, Rgb(5.0f)));  // the light, facing +z
    return d;
}

struct Rendered {
    RenderResult result;
    AovFilm aovs;
};

Rendered render_aovs(const SceneDescription& d, const std::string& algorithm, uint64_t spp, std::vector<std::string> aovs) {
    JobRequest r;
    r.algorithm = algorithm;
    r.spp = spp;
    r.seed = 5;
    r.aovs = std::move(aovs);
    RenderJob job(scene_choice_of(d), r);
    Rendered out{job.run(), {}};
    if (job.aov_film()) out.aovs = *job.aov_film();
    return out;
}

TEST(Aovs, PlaneSeenDirectly) {
    SceneDescription d = facing_scene();
    // A diffuse plane at z = 4 facing the camera.
    d.meshes.push_back(quad({0, 0, 4}, {0, 10, 0}, {10, 0, 0}, 1));
    const Rendered r = render_aovs(d, "pt-mis", 8, {"albedo", "normal", "position", "depth"});
    ASSERT_EQ(r.aovs.pixel_count(), 120u);
    for (size_t p = 0; p < r.aovs.pixel_count(); ++p) {
        EXPECT_EQ(r.aovs.count(p), 8u);
        // Every sample sees the same albedo, normal and z: their mean is exact.
        EXPECT_EQ(r.aovs.mean(p, 0), 0.2f);
        EXPECT_EQ(r.aovs.mean(p, 1), 0.4f);
        EXPECT_EQ(r.aovs.mean(p, 2), 0.6f);
        EXPECT_EQ(r.aovs.mean(p, 3), 0.0f);
        EXPECT_EQ(r.aovs.mean(p, 4), 0.0f);
        EXPECT_EQ(r.aovs.mean(p, 5), -1.0f);  // facing the camera
        EXPECT_FLOAT_EQ(r.aovs.mean(p, 8), 4.0f);
        // Depth: 4 / cos(angle to the axis), between 4 and the corner's.
        const float x = r.aovs.mean(p, 6), y = r.aovs.mean(p, 7);
        EXPECT_NEAR(r.aovs.mean(p, 9), std::sqrt(16 + x * x + y * y), 2e-3f) << p;
    }
}

TEST(Aovs, DiffuseWallThroughAMirror) {
    SceneDescription d = facing_scene();
    // A mirror at z = 2 turning +z into +y (normal (0, 1, -1)/sqrt 2), and a wall at y = 3 facing -y.
    const float h = float(1 / std::sqrt(2.0));
    d.meshes.push_back(quad({0, 0, 2}, {1, 0, 0}, {0, 1 * h, 1 * h}, 2));
    d.meshes.back().triangles = {{0, 2, 1}, {0, 3, 2}};  // normal towards the camera and the wall
    d.meshes.push_back(quad({0, 3, 2}, {5, 0, 0}, {0, 0, 5}, 1));
    const Rendered r = render_aovs(d, "pt-mis", 8, {"albedo", "normal", "depth"});
    for (size_t p = 0; p < r.aovs.pixel_count(); ++p) {
        EXPECT_EQ(r.aovs.mean(p, 0), 0.2f) << p;
        EXPECT_EQ(r.aovs.mean(p, 1), 0.4f);
        EXPECT_EQ(r.aovs.mean(p, 2), 0.6f);
        EXPECT_EQ(r.aovs.mean(p, 4), -1.0f);  // the wall's normal, not the mirror's
        // The path's length: camera to mirror to wall, 2 + 3 = 5 on the axis; the same at each
        // pixel as the unfolded (virtual) ray's distance to the wall's mirror image.
        const float x = r.aovs.mean(p, 6), yz = r.aovs.mean(p, 8) - 2;
        EXPECT_NEAR(r.aovs.mean(p, 9), std::sqrt(25 + x * x + yz * yz), 0.02f) << p;
    }
    // pt-naive sees the same first vertex through the mirror; the estimators whose camera path
    // ends at the first surface (direct illumination, eyelight) find none, as their images show.
    EXPECT_EQ(render_aovs(d, "pt-naive", 8, {"albedo"}).aovs.mean(37, 2), 0.6f);
    for (const char* direct : {"direct-mis", "eyelight"}) EXPECT_EQ(render_aovs(d, direct, 8, {"albedo"}).aovs.mean(37, 2), 0.0f) << direct;
}

TEST(Aovs, AlbedoOfADenseMedium) {
    SceneDescription d = light_box_in_fog();
    d.width = d.height = 8;
    d.media[0] = HomogeneousMedium{Rgb(2000.0f, 1000.0f, 500.0f), Rgb(1000.0f, 800.0f, 100.0f), HgPhase{0.0f}};
    const Rendered r = render_aovs(d, "volpath", 4, {"albedo", "normal"});
    // The central pixels look into the fog box, where every sample scatters at once.
    for (int y = 3; y <= 4; ++y)
        for (int x = 3; x <= 4; ++x) {
            const size_t p = size_t(y * 8 + x);
            EXPECT_EQ(r.aovs.mean(p, 0), 0.5f);
            EXPECT_EQ(r.aovs.mean(p, 1), 0.8f);
            EXPECT_EQ(r.aovs.mean(p, 2), 0.2f);
            EXPECT_EQ(r.aovs.mean(p, 3), 0.0f);  // no normal in a medium
        }
}

TEST(Aovs, SameBytesWithOneAndTwoThreads) {
    const SceneDescription d = make_builtin_scene(3);
    SceneDescription small = d;
    small.width = small.height = 24;
    Rendered one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = render_aovs(small, "pt-mis", 6, {"albedo", "normal", "depth", "position"});
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = render_aovs(small, "pt-mis", 6, {"albedo", "normal", "depth", "position"});
    }
    EXPECT_TRUE(one.aovs.identical(two.aovs));
    EXPECT_TRUE(one.result.film.identical(two.result.film));
}

TEST(Aovs, VarianceAndSampleCountFromTheFilm) {
    SceneDescription d = make_builtin_scene(3);
    d.width = d.height = 16;
    // Also for an integrator that splats (each pass a sample of every pixel).
    for (const char* algorithm : {"pt-mis", "lt"}) {
        const Rendered r = render_aovs(d, algorithm, 5, {"variance", "sample-count"});
        const std::vector<ExrChannel> c = render_aov_channels({"variance", "sample-count"}, r.result.film, nullptr);
        ASSERT_EQ(c.size(), 4u);
        EXPECT_EQ(c[0].name, "Variance.R");
        EXPECT_EQ(c[3].name, "SampleCount");
        const Image se = r.result.film.standard_error();
        for (size_t p = 0; p < r.result.film.pixel_count(); ++p) {
            EXPECT_EQ(c[3].values[p], 5.0f);
            // The variance of one sample = n x the squared standard error of the mean.
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[size_t(k)].values[p], 5 * se[p][k] * se[p][k], 1e-4f + 1e-4f * c[size_t(k)].values[p]) << algorithm;
        }
    }
}

TEST(Aovs, LightTracersRefuseTheFirstVertexAovs) {
    JobRequest r;
    r.algorithm = "lt";
    r.aovs = {"albedo"};
    try {
        RenderJob job(builtin_scene_choice(3), r);
        FAIL() << "lt took --aovs albedo";
    } catch (const UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("pt-mis"), std::string::npos) << e.what();
    }
    r.algorithm = "pt-mis";
    r.aovs = {"albedo", "shadow"};
    EXPECT_THROW(RenderJob(builtin_scene_choice(3), r), UsageError);
    r.aovs = {"albedo", "albedo"};
    EXPECT_THROW(RenderJob(builtin_scene_choice(3), r), UsageError);
}

TEST(Aovs, CommandLineWritesTheLayers) {
    ScratchDir dir("pathlab-aovs");
    const std::string exr = dir.path + "/a.exr";
    const CliResult ok = run({"3", "--resolution", "8x8", "--spp", "2", "--aovs", "albedo,depth,sample-count", "-o", exr, "-q"});
    ASSERT_EQ(ok.code, 0) << ok.err;
    const CliResult info = run({"info", exr});
    for (const char* want : {"Albedo.R (float)", "Albedo.G (float)", "Albedo.B (float)", "Z (float)", "SampleCount (float)"})
        EXPECT_TRUE(contains(info.out, want)) << want << "\n" << info.out;
    ExrExtras extras;
    read_exr(exr, extras);
    const auto albedo = std::find_if(extras.layers.begin(), extras.layers.end(), [](const auto& l) { return l.first == "Albedo"; });
    ASSERT_NE(albedo, extras.layers.end());
    EXPECT_EQ(albedo->second.width(), 8);
    EXPECT_EQ(run({"3", "--aovs", "albedo", "-o", dir.path + "/a.png", "-q"}).code, 2);
    // -a all renders the integrators that record them, and leaves out the others, saying why.
    const CliResult all = run({"3", "-a", "all", "--aovs", "normal", "--spp", "1", "--resolution", "4x4", "-o", dir.path + "/{algorithm}.exr"});
    EXPECT_EQ(all.code, 0) << all.err;
    EXPECT_TRUE(std::filesystem::exists(dir.path + "/pt-mis.exr"));
    EXPECT_FALSE(std::filesystem::exists(dir.path + "/lt.exr"));
    EXPECT_TRUE(contains(all.err, "left out")) << all.err;
    const CliResult unknown = run({"3", "-a", "lt", "--aovs", "shadow", "-o", exr, "-q"});
    EXPECT_EQ(unknown.code, 2);
    EXPECT_NE(unknown.err.find("sample-count"), std::string::npos) << unknown.err;
}

}  // namespace
}  // namespace pathlab::test
