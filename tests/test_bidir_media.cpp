// Light tracing and bdpt in participating media (issue 37): every method agrees with volpath per
// pixel (z-tests at a stated false-alarm rate, judge/image_statistics.hpp) on homogeneous and
// heterogeneous fog with surfaces, with the camera and an emitter inside the medium, through a
// glass ball filled with another medium, and with the sky outside; the densities bdpt's random
// walks store are those of their definitions (phase, distance sampling, transmittance) and its
// MIS weights with medium vertices are those of the strategies' densities written out here; a
// connection without its transmittance, and weights without distance sampling's densities, fail
// those tests; 1 and 2 threads give the same bytes.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "geometry/shape_meshes.hpp"
#include "integrators/bidir/bdpt.hpp"
#include "integrators/bidir/light_tracer.hpp"
#include "integrators/photon/pm.hpp"
#include "integrators/photon/sppm.hpp"
#include "integrators/photon/vcm.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scene_helpers.hpp"
#include "spectral_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

std::string source_path(const std::string& relative) { return std::string(PATHLAB_SOURCE_DIR) + "/" + relative; }

// Per pixel and channel at 1e-3, the whole image's family at 1e-4 (the suite's usual rates).
const AgreementOptions kAgreement{1e-3, 1e-4};

// A 3-channel grid of densities between 0.1 and 1.35 filling [-0.9, 0.9]^3.
HeterogeneousMedium grid_medium() {
    return striped_grid_medium({{6, 5, 4}, 3, 0.1f, 0.25f, 6, 0.9, Rgb(0.9f, 0.8f, 0.7f), HgPhase{-0.3f}});
}

struct MediaScene {
    std::string name;
    SceneDescription d;
    bool light_tracer = true;  // lt renders it (no pixel sees a Dirac surface first)
};

std::vector<MediaScene> media_scenes() {
    std::vector<MediaScene> scenes;
    scenes.push_back({"light box in fog", light_box_in_fog()});
    {  // Glossy walls, the whole world a medium: the camera and the emitter (a small ball in place
       // of the course's point light: a point light in a scattering medium gives every estimator
       // infinite variance, the 1 / d^2 of the points around it, and no z-test can hold there).
        SceneDescription d = make_builtin_scene(1);
        d.lights.clear();
        d.light_ids.clear();
        SphereDesc lamp{{0.0f, -0.3f, 0.9f}, 0.25f, 0, false};
        lamp.emission = Rgb(50.0f / (4 * kPi) / (kPi * 0.0625f));  // the point light's intensity
        d.spheres.push_back(lamp);
        d.media.push_back(HomogeneousMedium{Rgb(0.3f, 0.35f, 0.4f), Rgb(0.25f, 0.3f, 0.3f), HgPhase{-0.2f}});
        d.camera_medium = 0;
        scenes.push_back({"camera and emitter in fog", d});
    }
    {  // A grid of smoke under the ceiling light, the blue ball turned to glass filled with ink.
        SceneDescription d = make_builtin_scene(2);
        d.media.push_back(grid_medium());
        d.media.push_back(HomogeneousMedium{Rgb(2.0f, 1.0f, 0.5f), Rgb(1.5f, 0.5f, 0.4f), IsotropicPhase{}});
        d.meshes.push_back(fog_box(0));
        make_last_sphere_glass(d, 1, 0);
        scenes.push_back({"smoke grid and a glass ball of ink", d, false});
    }
    {  // The sky through the open front, fog inside the box.
        SceneDescription d = make_builtin_scene(6);
        d.media.push_back(HomogeneousMedium{Rgb(0.4f), Rgb(0.35f), HgPhase{0.6f}});
        d.meshes.push_back(fog_box(0));
        scenes.push_back({"sky and fog", d});
    }
    return scenes;
}

constexpr int kSize = 10, kMaxDepth = 5;

IntegratorOptions depth_options() {
    IntegratorOptions o;
    o.max_depth = kMaxDepth;
    return o;
}

// volpath's renders of the scenes, each made once (when a test first needs it) for every test here.
const RenderResult& reference(size_t i) {
    static std::vector<std::optional<RenderResult>> refs(media_scenes().size());
    if (!refs[i]) refs[i] = render_scene(media_scenes()[i].d, "volpath", kSize, kSize, 4096, 11, depth_options());
    return *refs[i];
}

// volpath's spectral render of the first scene, made once.
const RenderResult& spectral_reference() {
    static const RenderResult ref = [] {
        IntegratorOptions o = depth_options();
        o.spectral = true;
        return render_integrator(media_scenes()[0].d, *find_integrator("volpath")->make(o), kSize, kSize, 4096, 31);
    }();
    return ref;
}

AgreementResult agreement(const RenderResult& a, const RenderResult& ref) {
    return test_agreement(a.film.mean(), a.film.standard_error(), ref.film.mean(), ref.film.standard_error(), kAgreement);
}

TEST(BidirMedia, BdptAndLightTracingAgreeWithVolpath) {
    const std::vector<MediaScene> scenes = media_scenes();
    for (size_t i = 0; i < scenes.size(); ++i) {
        const RenderResult& ref = reference(i);
        const RenderResult b = render_scene(scenes[i].d, "bdpt", kSize, kSize, 1024, 21, depth_options());
        const AgreementResult rb = agreement(b, ref);
        EXPECT_TRUE(rb.agree) << scenes[i].name << ", bdpt: " << rb.describe();
        if (!scenes[i].light_tracer) continue;
        const RenderResult l = render_scene(scenes[i].d, "lt", kSize, kSize, 2048, 22, depth_options());
        const AgreementResult rl = agreement(l, ref);
        EXPECT_TRUE(rl.agree) << scenes[i].name << ", lt: " << rl.describe();
    }
}

// vcm and bpm: merging at medium vertices (the 3D kernel) beside the connections, one MIS, from
// a radius of 3% of the scene's (as test_vcm.cpp: the default, two pixel footprints, is a
// large blur at 10 x 10 pixels, whose bias these z-tests resolve). bpm gets 4096 iterations:
// without connections, in-scattering from the light box in the fog is found only by phase
// sampling hitting the light or by rare merges with the few photons of 100 light paths in a
// small ball, a skewed estimate whose pixel means at 1024 still miss their normal z (4 seeds
// pass at 4096; at 1024 and 2048 the first did not).
TEST(BidirMedia, VcmAndBpmAgreeWithVolpath) {
    const std::vector<MediaScene> scenes = media_scenes();
    for (size_t i = 0; i < scenes.size(); ++i) {
        const RenderResult& ref = reference(i);
        IntegratorOptions o = depth_options();
        o.photon_radius = 0.03f * Scene::build(scenes[i].d)->scene_sphere().radius;
        for (const char* a : {"vcm", "bpm"}) {
            const bool bpm = std::string(a) == "bpm";
            const RenderResult r = render_integrator(scenes[i].d, *find_integrator(a)->make(o), kSize, kSize, bpm ? 4096 : 1024, 23);
            const AgreementResult res = agreement(r, ref);
            EXPECT_TRUE(res.agree) << scenes[i].name << ", " << a << ": " << res.describe();
        }
    }
}

// upbp: all its estimators, and the point-beam estimator alone (with s = 0, which every set
// keeps), on the scenes with homogeneous media (a grid is refused), radius 3% of the scene's.
// pb2d alone gets 4096 iterations, as bpm: in-scattering found only by rare gathers is a skewed
// estimate whose pixel means at 256 and 1024 iterations miss their normal z (3 seeds each: up to
// 10 outliers of 300 at 256, max |z| 6-8, 1 of 3 seeds failing at 1024; none at 4096, max |z|
// 2.2-3.6; pp3d alone, measured the same way, was worse: 5-10 outliers at 1024).
bool homogeneous(const SceneDescription& d) {
    for (const Medium& m : d.media)
        if (std::holds_alternative<HeterogeneousMedium>(m)) return false;
    return true;
}

RenderResult upbp_render(const SceneDescription& d, const std::string& estimators, uint64_t iterations, uint64_t seed, VcmFaults faults = {},
                         int64_t photon_beams = 0, float beam_fraction = 0.03f) {
    IntegratorOptions o = depth_options();
    o.photon_radius = 0.03f * Scene::build(d)->scene_sphere().radius;
    o.beam_radius = beam_fraction * Scene::build(d)->scene_sphere().radius;
    o.estimators = estimators;
    o.photon_beams = photon_beams;
    Vcm<RgbTransport> upbp(o, faults);
    return render_integrator(d, upbp, kSize, kSize, iterations, seed);
}

TEST(BidirMedia, UpbpAndEachBeamEstimatorAloneAgreeWithVolpath) {
    const std::vector<MediaScene> scenes = media_scenes();
    for (size_t i = 0; i < scenes.size(); ++i) {
        if (!homogeneous(scenes[i].d)) continue;
        for (const char* e : {"all", "pb2d", "bb1d"}) {
            const AgreementResult res = agreement(upbp_render(scenes[i].d, e, std::string(e) == "all" ? 1024 : 4096, 25), reference(i));
            EXPECT_TRUE(res.agree) << scenes[i].name << ", upbp --estimators " << e << ": " << res.describe();
        }
    }
    // Photon beams from 25 of the 100 light paths of an iteration (N in bb1d's kernel and MIS is 25).
    const AgreementResult few = agreement(upbp_render(scenes[0].d, "bpt,bb1d", 1024, 26, {}, 25), reference(0));
    EXPECT_TRUE(few.agree) << "upbp --estimators bpt,bb1d --photon-beams 25: " << few.describe();
    // The beams with a radius of their own (6% of the scene's against the points' 3%), and the
    // default, a quarter of the points'.
    const AgreementResult own = agreement(upbp_render(scenes[0].d, "all", 1024, 27, {}, 0, 0.06f), reference(0));
    EXPECT_TRUE(own.agree) << "upbp --beam-radius: " << own.describe();
    const AgreementResult quarter = agreement(upbp_render(scenes[0].d, "all", 1024, 28, {}, 0, 0.0f), reference(0));
    EXPECT_TRUE(quarter.agree) << "upbp, the default beam radius: " << quarter.describe();
}

// The tests of the test: pb2d without the beam's transmittance to the photon (its probability
// kept: in a grey medium T(s) / P(s) is 1 and a beam that leaves out both is right), and with the
// ball's normalisation in place of the disc's, and bb1d without the 1 / sin(theta) of its kernel;
// the same renders without the faults pass above.
TEST(BidirMedia, BeamGathersWithoutTransmittanceOrWithTheWrongKernelAreDetected) {
    const MediaScene s = media_scenes()[0];
    const AgreementResult no_T = agreement(upbp_render(s.d, "pb2d", 4096, 25, VcmFaults{.beam_without_transmittance = true}), reference(0));
    EXPECT_FALSE(no_T.agree) << no_T.describe();
    const AgreementResult ball = agreement(upbp_render(s.d, "pb2d", 1024, 25, VcmFaults{.beam_kernel_as_ball = true}), reference(0));
    EXPECT_FALSE(ball.agree) << ball.describe();
    const AgreementResult sine = agreement(upbp_render(s.d, "bb1d", 4096, 25, VcmFaults{.beam_beam_without_sine = true}), reference(0));
    EXPECT_FALSE(sine.agree) << sine.describe();
}


// sppm in media, both volume estimates: the beam radiance estimate along the camera rays (the
// default) from a radius of 5% of the scene's, and the 3D kernel at the camera path's first
// scattering point from 10% (it needs a photon within the ball around one sampled point: with
// fewer than one on average, as at 5% here, its pixel means are too skewed for these z-tests),
// 4096 photons per iteration, 256 iterations. (ppm is the same code through the pixel centres:
// its image is not volpath's pixel average; see OneAndTwoThreadsGiveTheSameBytes.)
RenderResult sppm_render(const SceneDescription& d, bool beams, float radius_fraction, SppmFaults faults = {}, int iterations = 256) {
    IntegratorOptions o = depth_options();
    o.photons = 4096;
    o.photon_radius = radius_fraction * Scene::build(d)->scene_sphere().radius;
    o.volume_beam = beams;
    Sppm<RgbTransport> sppm(o, faults);
    return render_integrator(d, sppm, kSize, kSize, uint64_t(iterations), 24);
}

TEST(BidirMedia, SppmAgreesWithVolpathByBeamsAndByPoints) {
    const std::vector<MediaScene> scenes = media_scenes();
    for (size_t i = 0; i < scenes.size(); ++i) {
        const RenderResult& ref = reference(i);
        for (const bool beams : {true, false}) {
            const AgreementResult res = agreement(sppm_render(scenes[i].d, beams, beams ? 0.05f : 0.1f), ref);
            EXPECT_TRUE(res.agree) << scenes[i].name << ", sppm " << (beams ? "beams" : "points") << ": " << res.describe();
        }
    }
}

// The tests of the test: beams without their transmittance, and points with the disc's kernel
// (64 iterations, at which the correct renders agree).
TEST(BidirMedia, SppmWithoutTheBeamsTransmittanceOrWithTheDiscKernelIsDetected) {
    const MediaScene s = media_scenes()[0];
    const AgreementResult beams = agreement(sppm_render(s.d, true, 0.05f, SppmFaults{.beam_without_transmittance = true}, 64), reference(0));
    EXPECT_FALSE(beams.agree) << beams.describe();
    const AgreementResult points = agreement(sppm_render(s.d, false, 0.1f, SppmFaults{.volume_kernel_as_disc = true}, 64), reference(0));
    EXPECT_FALSE(points.agree) << points.describe();
    // (and the same renders without the faults agree)
    for (const bool b : {true, false}) {
        const AgreementResult control = agreement(sppm_render(s.d, b, b ? 0.05f : 0.1f, {}, 64), reference(0));
        EXPECT_TRUE(control.agree) << (b ? "beams: " : "points: ") << control.describe();
    }
}

// pm in media (Jensen and Christensen's volume map), both volume estimates with the k nearest
// photons (pm's default). pm's maps are made once, so its image keeps their noise and bias
// however many camera samples it takes: the z-tests hold where the maps' error is below the
// camera samples' (beams: 64000 light paths, 256 samples per pixel; points, noisier per sample:
// 256000 and 1024), on the two scenes where the volume map has no boundary in view. Where it
// has (the fog box open to the sky: the balls of photons by the box's walls reach outside the
// fog, where there are none, and the estimate is too dark there), the bias must shrink as the
// photon count grows.
RenderResult pm_render(size_t scene, bool beams, int64_t photons, uint64_t spp, PmFaults faults = {}, bool spectral = false) {
    IntegratorOptions o = depth_options();
    o.photons = photons;
    o.volume_beam = beams;
    o.spectral = spectral;
    if (spectral) return render_integrator(media_scenes()[scene].d, *find_integrator("pm")->make(o), kSize, kSize, spp, 26);
    PhotonMapper<RgbTransport> pm(o, faults);
    return render_integrator(media_scenes()[scene].d, pm, kSize, kSize, spp, 25);
}

RenderResult pm_render(size_t scene, bool beams, PmFaults faults = {}) {
    return pm_render(scene, beams, beams ? 64000 : 256000, beams ? 256 : 1024, faults);
}

TEST(BidirMedia, PmAgreesWithVolpathByBeamsAndByPoints) {
    for (const size_t i : {0u, 1u}) {
        for (const bool beams : {true, false}) {
            const AgreementResult res = agreement(pm_render(i, beams), reference(i));
            EXPECT_TRUE(res.agree) << media_scenes()[i].name << ", pm " << (beams ? "beams" : "points") << ": " << res.describe();
        }
    }
}

// The tests of the test: beams without their transmittance, and points with the disc's kernel.
TEST(BidirMedia, PmWithoutTheBeamsTransmittanceOrWithTheDiscKernelIsDetected) {
    const AgreementResult beams = agreement(pm_render(0, true, PmFaults{.beam_without_transmittance = true}), reference(0));
    EXPECT_FALSE(beams.agree) << beams.describe();
    const AgreementResult points = agreement(pm_render(0, false, PmFaults{.volume_kernel_as_disc = true}), reference(0));
    EXPECT_FALSE(points.agree) << points.describe();
}

// The image mean's difference from volpath's, in standard errors of that difference.
double mean_bias_z(const RenderResult& a, const RenderResult& ref) {
    const Image m = a.film.mean(), se = a.film.standard_error(), rm = ref.film.mean(), rse = ref.film.standard_error();
    double d = 0, var = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x)
            for (int c = 0; c < 3; ++c) {
                d += double(m.at(x, y)[c]) - double(rm.at(x, y)[c]);
                var += double(se.at(x, y)[c]) * se.at(x, y)[c] + double(rse.at(x, y)[c]) * rse.at(x, y)[c];
            }
    return d / std::sqrt(var);
}

TEST(BidirMedia, PmBoundaryBiasShrinksAsThePhotonCountGrows) {
    for (const bool beams : {true, false}) {
        const double few = mean_bias_z(pm_render(3, beams, 16000, 256), reference(3));
        const double many = mean_bias_z(pm_render(3, beams, 256000, 256), reference(3));
        const std::string all = fmt::format("{}: the mean's bias in standard errors with 16000 light paths {:.1f}, 256000 {:.1f}",
                                            beams ? "beams" : "points", few, many);
        EXPECT_LT(few, -6.0) << "the boundary's bias must be seen: " << all;
        EXPECT_GT(many, 0.6 * few) << all;
        EXPECT_LT(many, 0.0) << all;
    }
}

// Spectral mode makes the maps anew in every pass at its wavelengths: the passes are independent,
// and 64 of them with 16000 light paths each agree with volpath's spectral image.
TEST(BidirMedia, PmInSpectralModeAgreesWithVolpath) {
    for (const bool beams : {true, false}) {
        const AgreementResult r = agreement(pm_render(0, beams, 16000, 64, {}, true), spectral_reference());
        EXPECT_TRUE(r.agree) << (beams ? "beams: " : "points: ") << r.describe();
    }
}

// The test of the test: merging in a medium with the surfaces' kernel (N pi r^2, in the estimate
// and the MIS) is too dark where merges carry weight.
TEST(BidirMedia, AMediumMergeWithTheDiscKernelIsDetected) {
    const MediaScene s = media_scenes()[0];
    IntegratorOptions o = depth_options();
    o.photon_radius = 0.03f * Scene::build(s.d)->scene_sphere().radius;
    o.vcm_connections = false;
    Vcm<RgbTransport> faulty(o, VcmFaults{.volume_kernel_as_disc = true});
    const RenderResult r = render_integrator(s.d, faulty, kSize, kSize, 1024, 23);
    const AgreementResult res = agreement(r, reference(0));
    EXPECT_FALSE(res.agree) << res.describe();
}

TEST(BidirMedia, BdptVcmUpbpAndSppmInSpectralModeAgreeWithVolpath) {
    const MediaScene s = media_scenes()[0];
    IntegratorOptions o = depth_options();
    o.spectral = true;
    const RenderResult& v = spectral_reference();
    o.photon_radius = 0.03f * Scene::build(s.d)->scene_sphere().radius;
    for (const char* a : {"bdpt", "vcm", "upbp"}) {
        const RenderResult b = render_integrator(s.d, *find_integrator(a)->make(o), kSize, kSize, 1024, 32);
        const AgreementResult r = agreement(b, v);
        EXPECT_TRUE(r.agree) << a << ": " << r.describe();
    }
    o.photons = 4096;
    o.photon_radius = 0.05f * Scene::build(s.d)->scene_sphere().radius;
    {
        const RenderResult b = render_integrator(s.d, *find_integrator("sppm")->make(o), kSize, kSize, 256, 33);
        const AgreementResult r = agreement(b, v);
        EXPECT_TRUE(r.agree) << "sppm: " << r.describe();
    }
}

// The test of the test: a connection that leaves out its transmittance is too bright.
TEST(BidirMedia, AConnectionWithoutItsTransmittanceIsDetected) {
    BdptFaults faults;
    faults.drop_connection_transmittance = true;
    Bdpt<RgbTransport> faulty(depth_options(), faults);
    const RenderResult b = render_integrator(media_scenes()[0].d, faulty, kSize, kSize, 1024, 21);
    EXPECT_FALSE(agreement(b, reference(0)).agree);
}

TEST(BidirMedia, MediaBehindScatteringBoundariesAreSealedFromTheOthers) {
    // Scene 3 of media_scenes: smoke inside an index-matched box (medium 0), ink in a glass ball (1).
    const auto scene = Scene::build(media_scenes()[2].d);
    EXPECT_TRUE(scene->media_separated(1, 0));   // ink | smoke: the glass between them
    EXPECT_TRUE(scene->media_separated(-1, 1));  // outside | ink
    EXPECT_FALSE(scene->media_separated(0, -1)); // smoke | outside: through the index-matched box
    EXPECT_FALSE(scene->media_separated(1, 1));
    EXPECT_FALSE(scene->media_separated(-1, -1));
}

// Connections inside a dense homogeneous medium are made with probability T / (1/64) when their
// transmittance T is below 1/64 in every channel (Bdpt::connect): the image is that of making
// them all. Paired renders (the same seeds make the same subpaths; only the roulette differs) of
// the marble block, whose 16 image means differ by d_k: a t-test of mean(d) = 0 (15 degrees of
// freedom, |t| < 4.07: false alarm 1e-3). Not dividing the survivors by their probability
// darkens the block (detected: t = -5.1 with these seeds).
TEST(BidirMedia, ConnectionRouletteChangesTheNoiseNotTheImage) {
    const SceneDescription d = load_scene_file(source_path("scenes/marble-block.xml"));
    BdptFaults every_connection, undivided;
    every_connection.no_connection_roulette = true;
    undivided.connection_roulette_undivided = true;
    Bdpt<RgbTransport> oracle(IntegratorOptions{}, every_connection), roulette(IntegratorOptions{}, BdptFaults{}),
        faulty(IntegratorOptions{}, undivided);
    const auto brightness = [](const RenderResult& r) {
        const ImageMean m = image_mean(r);
        return m.mean.x + m.mean.y + m.mean.z;
    };
    const auto t_statistic = [&](Integrator& candidate) {
        std::vector<double> diffs;
        for (uint64_t seed = 1; seed <= 16; ++seed)
            diffs.push_back(brightness(render_integrator(d, candidate, kSize, kSize, 128, seed)) -
                            brightness(render_integrator(d, oracle, kSize, kSize, 128, seed)));
        double mean = 0, var = 0;
        for (double x : diffs) mean += x / double(diffs.size());
        for (double x : diffs) var += (x - mean) * (x - mean) / double(diffs.size() - 1);
        return mean / std::sqrt(var / double(diffs.size()));
    };
    const double t = t_statistic(roulette);
    EXPECT_LT(std::abs(t), 4.07) << "roulette against every connection made: t = " << t;
    const double t_faulty = t_statistic(faulty);
    EXPECT_LT(t_faulty, -4.07) << "survivors not divided by their probability: t = " << t_faulty;
}

TEST(BidirMedia, OneAndTwoThreadsGiveTheSameBytes) {
    for (const char* f : {"scenes/fog-box.xml", "scenes/smoke.xml"}) {
        const SceneDescription d = load_scene_file(source_path(f));
        for (const char* a : {"bdpt", "lt", "vcm", "bpm", "upbp", "sppm", "ppm", "pm"}) {
            if (std::string(a) == "upbp" && std::string(f) == "scenes/smoke.xml") continue;  // a grid: refused
            const auto with_threads = [&](int threads) {
                tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
                return render_scene(d, a, 16, 12, 4, 5);
            };
            const RenderResult one = with_threads(1), two = with_threads(2);
            EXPECT_TRUE(bit_identical(one.film.mean(), two.film.mean())) << f << ", " << a;
            EXPECT_TRUE(bit_identical(one.film.standard_error(), two.film.standard_error())) << f << ", " << a;
        }
    }
}

// ---- densities and weights ---------------------------------------------------------------------

// A grey medium everywhere (sigma_t = 0.4, Henyey-Greenstein g = 0.3) around a diffuse floor and
// a downward area light, the camera in it: the densities below are written out for it.
constexpr float kSigma = 0.4f, kG = 0.3f;

SceneDescription medium_world() {
    SceneDescription d;
    d.name = "medium world";
    d.camera = Camera::look_at({0, -4, 1.5f}, {0, 0, 0.5f}, {0, 0, 1}, 60, FovAxis::X);
    d.width = d.height = 64;
    d.materials = {make_phong(Rgb(0.6f)), make_phong(Rgb(0.0f))};
    d.meshes.push_back(quad({0, 0, 0}, {3, 0, 0}, {0, 3, 0}, 0, Rgb(0.0f)));                 // floor, normal +z
    d.meshes.push_back(quad({0, 0.5f, 2.5f}, {0.5f, 0, 0}, {0, -0.5f, 0}, 1, Rgb(6.0f)));   // light, normal -z
    d.media.push_back(HomogeneousMedium{Rgb(kSigma), Rgb(0.8f * kSigma), HgPhase{kG}});
    d.camera_medium = 0;
    return d;
}

double hg(double cos_theta) { return (1 - kG * kG) / (4 * M_PI * std::pow(1 + kG * kG - 2 * kG * cos_theta, 1.5)); }

// A full path x_0 (the pinhole), ..., x_k (on the light), each inner point on the floor or in the medium.
struct MediumPath {
    std::string name;
    std::vector<Vec3f> p;
    std::vector<bool> in_medium;
};

class MediumMis {
public:
    explicit MediumMis(BdptFaults faults = {})
        : desc_(medium_world()), scene_(Scene::build(desc_)), camera_(scene_->camera(), 64, 64),
          ctx_{*scene_, camera_, 64, 64, 1, SamplerKind::Independent, 32}, bdpt_(IntegratorOptions{}, faults) {}

    int k(const MediumPath& f) const { return int(f.p.size()) - 1; }
    // |sin| of the angle between the path's two edges at inner vertex x_j.
    float sin_at(const MediumPath& f, int j) const { return length(cross(dir(f, j, j - 1), dir(f, j, j + 1))); }
    Vec3f dir(const MediumPath& f, int from, int to) const { return normalize(f.p[size_t(to)] - f.p[size_t(from)]); }
    Vec3f normal(const MediumPath& f, int j) const { return j == k(f) ? Vec3f(0, 0, -1) : Vec3f(0, 0, 1); }
    // The density at x_to of a direction chosen at x_from with solid-angle density pdfW: per unit
    // area (|cos| / d^2) at a surface, per unit volume (1 / d^2) in the medium, times distance
    // sampling's: exp(-sigma d), and sigma at a medium point.
    double density(const MediumPath& f, double pdfW, int from, int to) const {
        const Vec3f d = f.p[size_t(to)] - f.p[size_t(from)];
        const double dist = length(d);
        double p = pdfW / (dist * dist) * std::exp(-kSigma * dist);
        if (f.in_medium[size_t(to)]) p *= kSigma;
        else p *= std::abs(dot(normal(f, to), d / float(dist)));
        return p;
    }
    // The density at x_j (floor: cosine-weighted diffuse; medium: Henyey-Greenstein) of going on to x_next.
    double scatter_density(const MediumPath& f, int prev, int j, int next) const {
        const Vec3f wi = dir(f, j, prev), wo = dir(f, j, next);
        const double pdfW = f.in_medium[size_t(j)] ? hg(-dot(wi, wo)) : std::max(0.0f, dot(normal(f, j), wo)) / M_PI;
        return density(f, pdfW, j, next);
    }
    double light_origin() const { return 1.0 / 1.0; }  // one light of area 1
    double light_emission(const MediumPath& f) const {
        const int n = k(f);
        return density(f, std::max(0.0f, dot(normal(f, n), dir(f, n, n - 1))) / M_PI, n, n - 1);
    }
    double camera_density(const MediumPath& f) const { return density(f, camera_.pdf_direction(dir(f, 0, 1)), 0, 1); }
    double strategy_density(const MediumPath& f, int s) const {
        const int n = k(f), t = n + 1 - s;
        double p = 1;
        for (int j = 1; j < t; ++j) p *= j == 1 ? camera_density(f) : scatter_density(f, j - 2, j - 1, j);
        for (int i = 0; i < s; ++i) {
            const int j = n - i;
            p *= i == 0 ? light_origin() : i == 1 ? light_emission(f) : scatter_density(f, j + 2, j + 1, j);
        }
        return p;
    }
    // What the weights are made of: the strategies' densities, but for a light seen directly
    // (a path of one edge), where s = 1's counts (1 - T) times (Bdpt::seen_directly_weight).
    double weighed_density(const MediumPath& f, int s) const {
        if (k(f) != 1 || s != 1) return strategy_density(f, s);
        return (1 - std::exp(-kSigma * length(f.p[1] - f.p[0]))) * strategy_density(f, s);
    }
    double expected_weight(const MediumPath& f, int s) const {
        double sum = 0;
        for (int i = 0; i <= k(f); ++i) sum += weighed_density(f, i);  // (every strategy can make these paths)
        return weighed_density(f, s) / sum;
    }

    // The vertex bdpt's walk would have made of x_j on the camera side (reached from x_{j-1}) or the light side.
    PathVertex<RgbTransport> vertex(const MediumPath& f, int j, bool camera_side) const {
        PathVertex<RgbTransport> v;
        v.medium = 0;
        v.p = f.p[size_t(j)];
        const int n = k(f);
        if (j == 0 && camera_side) {
            v.kind = VertexKind::Camera;
            return v;
        }
        const int from = camera_side ? j - 1 : j + 1;
        if (j > 0 && j < n) v.T_in = float(std::exp(-kSigma * length(f.p[size_t(j)] - f.p[size_t(from)])));
        if (j == n && !camera_side) {
            v.kind = VertexKind::Light;
            v.light = 0;
            v.n = v.emitter_n = normal(f, n);
            return v;
        }
        if (j == n) v.T_in = float(std::exp(-kSigma * length(f.p[size_t(j)] - f.p[size_t(from)])));
        if (f.in_medium[size_t(j)]) {
            v.kind = VertexKind::Medium;
            v.dir = dir(f, j, from);
            v.sigma_mis = kSigma;
            v.sin_theta = sin_at(f, j);
            return v;
        }
        Intersection hit;
        const Vec3f w = dir(f, from, j), o = f.p[size_t(from)] + w * 1e-3f;
        EXPECT_TRUE(scene_->intersect(Ray{o, w, kInf}, hit));
        v.kind = VertexKind::Surface;
        v.sp = make_shading_point(*scene_, hit, dir(f, from, j), camera_side ? TransportMode::Radiance : TransportMode::Importance);
        v.n = v.sp.ng;
        v.emitter_n = hit.ng;
        v.light = hit.light;
        return v;
    }
    // The subpaths of strategy (s, t) with the densities of their definitions (NaN where the
    // connection must set them) and their running MIS quantities.
    void subpaths(const MediumPath& f, int s, std::vector<PathVertex<RgbTransport>>& light,
                  std::vector<PathVertex<RgbTransport>>& camera, const MergeMis* vm = nullptr) const {
        const int n = k(f), t = n + 1 - s;
        camera.clear(), light.clear();
        for (int j = 0; j < t; ++j) {
            PathVertex<RgbTransport> v = vertex(f, j, true);
            v.pdf_fwd = float(j == 0 ? 1 : j == 1 ? camera_density(f) : scatter_density(f, j - 2, j - 1, j));
            v.pdf_rev = j + 2 <= t - 1 ? float(scatter_density(f, j + 2, j + 1, j)) : NAN;
            camera.push_back(v);
        }
        for (int i = 0; i < s; ++i) {
            const int j = n - i;
            PathVertex<RgbTransport> v = vertex(f, j, false);
            v.pdf_fwd = float(i == 0 ? light_origin() : i == 1 ? light_emission(f) : scatter_density(f, j + 2, j + 1, j));
            v.pdf_rev = i + 2 <= s - 1 ? float(scatter_density(f, j - 2, j - 1, j)) : NAN;
            light.push_back(v);
        }
        set_running_mis(light.data(), int(light.size()), true, MisRules(false, vm));
        set_running_mis(camera.data(), int(camera.size()), false, MisRules(false, vm));
    }
    float bdpt_weight(const MediumPath& f, int s, const MergeMis* vm = nullptr) const {
        std::vector<PathVertex<RgbTransport>> light, camera;
        subpaths(f, s, light, camera, vm);
        const int n = k(f), t = n + 1 - s;
        PathVertex<RgbTransport> sampled = s == 1 && t > 1 ? vertex(f, n, false) : vertex(f, 0, true);
        if (s == 1 && t > 1) sampled.pdf_fwd = float(light_origin());
        EdgeDensities known;
        if (s >= 1) known.T = float(std::exp(-kSigma * length(f.p[size_t(t)] - f.p[size_t(t - 1)])));
        return bdpt_.mis_weight(ctx_, light, s, camera, t, sampled, known, vm);
    }
    // The light side's density of inner vertex x_j (from x_{j+1}).
    double light_density(const MediumPath& f, int j) const {
        return j + 1 == k(f) ? light_emission(f) : scatter_density(f, j + 2, j + 1, j);
    }
    // Merging at x_j: the connection with camera endpoint x_j, times the light side's density of
    // x_j, times eta (per unit area on the floor, per unit volume in the medium).
    double merge_density(const MediumPath& f, int j, const MergeMis& vm) const {
        return strategy_density(f, k(f) - j) * light_density(f, j) * (f.in_medium[size_t(j)] ? vm.eta_volume : vm.eta);
    }
    // The photon x_j of the light subpath x_k .. x_j merged at x_j of the camera subpath x_0 .. x_j,
    // by the running quantities and by the walk.
    std::pair<float, float> merge_weights(const Vcm<RgbTransport>& vcm, const MediumPath& f, int j, const MergeMis& vm) const {
        const int s = k(f) - j + 1;
        std::vector<PathVertex<RgbTransport>> light, camera, unused;
        subpaths(f, s, light, unused, &vm);
        subpaths(f, s - 1, unused, camera, &vm);
        return {vcm.merge_weight(*scene_, light.data(), s, camera, j + 1, vm),
                vcm.merge_weight_oracle(*scene_, light.data(), s, camera, j + 1, vm)};
    }

    // The photon x_j of the light subpath x_k .. x_j gathered by pb2d on the camera beam from
    // x_{j-1} towards x_j, at x_j: by the running quantities and by the walk.
    std::pair<float, float> beam_weights(const Vcm<RgbTransport>& vcm, const MediumPath& f, int j, const MergeMis& vm) const {
        const int s = k(f) - j + 1;
        std::vector<PathVertex<RgbTransport>> light, camera, unused;
        subpaths(f, s, light, unused, &vm);
        subpaths(f, s - 1, unused, camera, &vm);
        SubpathBeam<RgbTransport> beam;
        beam.from = j - 1;
        beam.o = f.p[size_t(j - 1)];
        beam.d = dir(f, j - 1, j);
        beam.medium = 0;
        const float along = length(f.p[size_t(j)] - beam.o);
        beam.length = along * 1.5f;
        beam.pdfW = float(j == 1 ? camera_.pdf_direction(beam.d)
                                 : density(f, 1.0, j - 1, j) > 0 ? scatter_density(f, j - 2, j - 1, j) / density(f, 1.0, j - 1, j) : 0.0);
        return {vcm.beam_merge_weight(*scene_, light.data(), s, camera, beam, along, vm, false),
                vcm.beam_merge_weight(*scene_, light.data(), s, camera, beam, along, vm, true)};
    }

    // bb1d at x_j: the light subpath's edge from x_{j+1} and the camera subpath's from x_{j-1}, both through x_j.
    std::pair<float, float> beam_beam_weights(const Vcm<RgbTransport>& vcm, const MediumPath& f, int j, const MergeMis& vm) const {
        const int s = k(f) - j + 1;
        std::vector<PathVertex<RgbTransport>> light, camera, unused;
        subpaths(f, s, light, unused, &vm);
        subpaths(f, s - 1, unused, camera, &vm);
        SubpathBeam<RgbTransport> cb, lb;
        cb.from = j - 1, lb.from = s - 2;
        cb.o = f.p[size_t(j - 1)], lb.o = f.p[size_t(j + 1)];
        cb.d = dir(f, j - 1, j), lb.d = dir(f, j + 1, j);
        cb.medium = lb.medium = 0;
        const float along_c = length(f.p[size_t(j)] - cb.o), along_l = length(f.p[size_t(j)] - lb.o);
        cb.length = 1.5f * along_c, lb.length = 1.5f * along_l;
        cb.pdfW = float(j == 1 ? camera_.pdf_direction(cb.d) : scatter_density(f, j - 2, j - 1, j) / density(f, 1.0, j - 1, j));
        lb.pdfW = float(j + 1 == k(f) ? std::max(0.0f, dot(normal(f, k(f)), lb.d)) / M_PI
                                      : scatter_density(f, j + 2, j + 1, j) / density(f, 1.0, j + 1, j));
        return {vcm.beam_beam_weight(*scene_, light.data(), lb, along_l, camera, cb, along_c, vm, false),
                vcm.beam_beam_weight(*scene_, light.data(), lb, along_l, camera, cb, along_c, vm, true)};
    }

    std::vector<MediumPath> paths() const {
        const Vec3f m1(0.3f, -1.0f, 1.2f), m2(-0.4f, 0.2f, 1.8f), floor(0.2f, 0.4f, 0.0f), on_light(0.1f, 0.45f, 2.5f);
        const Vec3f c = camera_.position();
        // (camera-light: the light seen through the medium, by the camera's ray (s = 0) and by
        // the emitter's point connected to the camera (s = t = 1), which a scene with media has.)
        return {{"camera-light", {c, on_light}, {false, false}},
                {"camera-medium-light", {c, m1, on_light}, {false, true, false}},
                {"camera-medium-floor-light", {c, m1, floor, on_light}, {false, true, false, false}},
                {"camera-floor-medium-light", {c, floor, m2, on_light}, {false, false, true, false}},
                {"camera-medium-medium-light", {c, m1, m2, on_light}, {false, true, true, false}},
                {"camera-medium-floor-medium-light", {c, m1, floor, m2, on_light}, {false, true, false, true, false}}};
    }

    const Bdpt<RgbTransport>& bdpt() const { return bdpt_; }
    const RenderContext& ctx() const { return ctx_; }
    const Scene& scene() const { return *scene_; }

private:
    SceneDescription desc_;
    std::unique_ptr<Scene> scene_;
    PerspectiveCamera camera_;
    RenderContext ctx_;
    Bdpt<RgbTransport> bdpt_;
};

// Hand-built paths with medium vertices: bdpt's weight of every strategy is the balance
// heuristic over the strategies' densities written out above (and so they sum to 1).
bool weights_match(const MediumMis& h, std::string& report) {
    bool ok = true;
    for (const MediumPath& f : h.paths()) {
        double sum = 0;
        for (int s = 0; s <= h.k(f); ++s) {
            const double expected = h.expected_weight(f, s), got = h.bdpt_weight(f, s);
            sum += got;
            if (std::abs(got - expected) > 1e-4 * std::max(1e-3, expected)) {
                ok = false;
                report += f.name + " s=" + std::to_string(s) + ": " + std::to_string(got) + " instead of " + std::to_string(expected) + "\n";
            }
        }
        if (std::abs(sum - 1) > 1e-4) {
            ok = false;
            report += f.name + ": the weights sum to " + std::to_string(sum) + "\n";
        }
    }
    return ok;
}

TEST(BidirMedia, WeightsWithMediumVerticesAreTheBalanceHeuristicOfTheDensities) {
    std::string report;
    EXPECT_TRUE(weights_match(MediumMis{}, report)) << report;
}

// vcm's weights on the same paths: every connection and a merge at every inner vertex (on the
// floor with eta = N pi r^2, in the medium with eta_volume = N 4/3 pi r^3: the point-point
// estimator of UPBP) get the balance heuristic of the densities written out above, by the
// running quantities and by the walk, and sum to 1; a medium merge weighed with the disc's eta
// is caught.
bool merge_weights_match(const MediumMis& h, VcmFaults faults, std::string& report) {
    Vcm<RgbTransport> vcm(IntegratorOptions{}, faults);
    bool ok = true;
    for (const double r : {0.02, 0.1, 0.4}) {
        const MergeMis vm = vcm.merge_mis(1000, r);
        // What the render assumes (the fault lives in merge_mis): the densities of the definition.
        MergeMis exact = vm;
        exact.eta_volume = 1000 * 4.0 / 3.0 * M_PI * r * r * r;
        for (const MediumPath& f : h.paths()) {
            double total = 0;
            for (int s = 0; s <= h.k(f); ++s) total += h.weighed_density(f, s);
            for (int j = 1; j < h.k(f); ++j) total += h.merge_density(f, j, exact);
            double sum = 0;
            const auto check = [&](const std::string& what, double got, double expected) {
                sum += got;
                if (std::abs(got - expected) > 1e-4 * std::max(1e-3, expected)) {
                    ok = false;
                    report += f.name + " r=" + std::to_string(r) + " " + what + ": " + std::to_string(got) + " instead of " +
                              std::to_string(expected) + "\n";
                }
            };
            for (int s = 0; s <= h.k(f); ++s) check("s=" + std::to_string(s), h.bdpt_weight(f, s, &vm), h.weighed_density(f, s) / total);
            for (int j = 1; j < h.k(f); ++j) {
                const auto [running, walk] = h.merge_weights(vcm, f, j, vm);
                if (std::abs(running - walk) > 1e-5 * walk + 1e-12) {
                    ok = false;
                    report += f.name + " merge at x_" + std::to_string(j) + ": running " + std::to_string(running) + ", walk " +
                              std::to_string(walk) + "\n";
                }
                check("merge at x_" + std::to_string(j), running, h.merge_density(f, j, exact) / total);
            }
            if (std::abs(sum - 1) > 1e-4) {
                ok = false;
                report += f.name + " r=" + std::to_string(r) + ": the weights sum to " + std::to_string(sum) + "\n";
            }
        }
    }
    return ok;
}

TEST(BidirMedia, VcmWeightsWithMediumVerticesAreTheBalanceHeuristicOfTheDensities) {
    std::string report;
    EXPECT_TRUE(merge_weights_match(MediumMis{}, {}, report)) << report;
    EXPECT_FALSE(merge_weights_match(MediumMis{}, VcmFaults{.volume_kernel_as_disc = true}, report));
}

// upbp's weights on the same paths, for several sets of estimators: every connection (bpt; s = 0
// always), a surface merge on the floor (surf), and at every medium vertex a point-point merge
// (pp3d, eta_volume), a point-beam gather (pb2d: the photon on the camera's edge into x_j,
// density that of the connection ending at x_j times the light side's density of x_j times
// N pi r^2 / sigma, the camera's distance density left out but for its transmittance) and a
// beam-beam gather (bb1d: the light's edge into x_j against the camera's, the same product times
// N 2r sin(theta_j) / sigma^2, neither side's distance density in it) get the balance heuristic of
// those densities, by the running quantities and by the walk, and sum to 1.
bool upbp_weights_match(const MediumMis& h, const std::string& estimators, std::string& report) {
    IntegratorOptions o;
    o.estimators = estimators;
    const Vcm<RgbTransport> upbp(o);
    const VcmEstimators& e = upbp.estimators();
    bool ok = true;
    for (const double r : {0.02, 0.1, 0.4}) {
        const MergeMis vm = upbp.merge_mis(1000, r);
        const double disc = 1000 * M_PI * r * r, ball = 1000 * 4.0 / 3.0 * M_PI * r * r * r,
                     beam1d = double(upbp.photon_beam_paths(1000)) * 2 * r;  // (the light paths that leave beams)
        for (const MediumPath& f : h.paths()) {
            const auto base = [&](int j) { return h.strategy_density(f, h.k(f) - j) * h.light_density(f, j); };
            double total = 0;
            for (int s = 0; s <= h.k(f); ++s)
                if (s == 0 || e.bpt) total += h.weighed_density(f, s);
            for (int j = 1; j < h.k(f); ++j) {
                if (!f.in_medium[size_t(j)]) total += e.surf ? base(j) * disc : 0.0;
                else
                    total += (e.pp3d ? base(j) * ball : 0.0) + (e.pb2d ? base(j) * disc / kSigma : 0.0) +
                             (e.bb1d ? base(j) * beam1d * h.sin_at(f, j) / (kSigma * kSigma) : 0.0);
            }
            double sum = 0;
            const auto check = [&](const std::string& what, double got, double expected) {
                sum += got;
                if (std::abs(got - expected) > 1e-4 * std::max(1e-3, expected)) {
                    ok = false;
                    report += estimators + " " + f.name + " r=" + std::to_string(r) + " " + what + ": " + std::to_string(got) +
                              " instead of " + std::to_string(expected) + "\n";
                }
            };
            const auto same = [&](const std::string& what, float running, float walk) {
                if (std::abs(running - walk) > 1e-5 * walk + 1e-12) {
                    ok = false;
                    report += estimators + " " + f.name + " " + what + ": running " + std::to_string(running) + ", walk " +
                              std::to_string(walk) + "\n";
                }
            };
            for (int s = 0; s <= h.k(f); ++s)
                if (s == 0 || e.bpt) check("s=" + std::to_string(s), h.bdpt_weight(f, s, &vm), h.weighed_density(f, s) / total);
            for (int j = 1; j < h.k(f); ++j) {
                const bool medium = f.in_medium[size_t(j)];
                if (medium ? e.pp3d : e.surf) {
                    const auto [running, walk] = h.merge_weights(upbp, f, j, vm);
                    same("merge at x_" + std::to_string(j), running, walk);
                    check("merge at x_" + std::to_string(j), running, base(j) * (medium ? ball : disc) / total);
                }
                if (medium && e.pb2d) {
                    const auto [running, walk] = h.beam_weights(upbp, f, j, vm);
                    same("pb2d at x_" + std::to_string(j), running, walk);
                    check("pb2d at x_" + std::to_string(j), running, base(j) * disc / kSigma / total);
                }
                if (medium && e.bb1d) {
                    const auto [running, walk] = h.beam_beam_weights(upbp, f, j, vm);
                    same("bb1d at x_" + std::to_string(j), running, walk);
                    check("bb1d at x_" + std::to_string(j), running, base(j) * beam1d * h.sin_at(f, j) / (kSigma * kSigma) / total);
                }
            }
            if (std::abs(sum - 1) > 1e-4) {
                ok = false;
                report += estimators + " " + f.name + " r=" + std::to_string(r) + ": the weights sum to " + std::to_string(sum) + "\n";
            }
        }
    }
    return ok;
}

TEST(BidirMedia, UpbpWeightsAreTheBalanceHeuristicOverEveryEstimator) {
    std::string report;
    for (const char* e : {"all", "pb2d", "bb1d", "bpt,pb2d", "bpt,bb1d", "pp3d,pb2d", "surf,pp3d"})
        EXPECT_TRUE(upbp_weights_match(MediumMis{}, e, report)) << report;
}

TEST(BidirMedia, WeightsWithoutDistanceSamplingAreDetected) {
    BdptFaults faults;
    faults.drop_distance_pdf = true;
    std::string report;
    EXPECT_FALSE(weights_match(MediumMis(faults), report));
}

// The densities bdpt's random walks store on real subpaths in the medium world are those of
// their definitions: pdf_fwd from the predecessor, pdf_rev from the successor.
bool walk_densities_match(const MediumMis& h, std::string& report, int& medium_vertices) {
    const auto pdfW_at = [&](const PathVertexBase& at, const PathVertexBase* from, const Vec3f& to) -> double {
        const Vec3f wo = normalize(to - at.p);
        if (at.kind == VertexKind::Camera) return h.ctx().camera.pdf_direction(wo);
        if (at.kind == VertexKind::Light) return std::max(0.0f, dot(at.emitter_n, wo)) / M_PI;
        const Vec3f wi = normalize(from->p - at.p);
        if (at.kind == VertexKind::Medium) return hg(-dot(wi, wo));
        // The floor's diffuse lobe, on the side it was reached from (the floor is seen from below too).
        const float cos_i = dot(Vec3f(0, 0, 1), wi), cos_o = dot(Vec3f(0, 0, 1), wo);
        return cos_i * cos_o > 0 ? std::abs(cos_o) / M_PI : 0.0;
    };
    const auto density = [&](const PathVertexBase& to, const PathVertexBase& from, double pdfW) {
        const Vec3f d = to.p - from.p;
        const double dist = length(d);
        double p = pdfW / (dist * dist) * std::exp(-kSigma * dist);
        return to.kind == VertexKind::Medium ? p * kSigma : p * std::abs(dot(to.n, d / float(dist)));
    };
    bool ok = true;
    medium_vertices = 0;
    std::vector<PathVertex<RgbTransport>> path;
    for (uint64_t i = 0; i < 200; ++i) {
        Sampler sampler(7, i, 0, SamplerKind::Independent);
        const RgbWavelengths wl{};
        const bool camera_side = i % 2 == 0;
        if (camera_side) h.bdpt().camera_subpath(h.ctx(), size_t(i * 37 % 4096), sampler, wl, path);
        else h.bdpt().light_subpath(h.ctx(), sampler, wl, path);
        for (size_t j = 1; j < path.size(); ++j) {
            const PathVertexBase& v = path[j];
            if (v.kind == VertexKind::Light) continue;  // (a camera ray that escaped)
            // Edges shorter than this from a surface are left out: the ray leaves the surface a
            // little off it (geometry/ray.hpp), which moves their 1 / d^2 by more than 1e-3.
            if (length(v.p - path[j - 1].p) < 0.2f || (j + 1 < path.size() && length(path[j + 1].p - v.p) < 0.2f)) continue;
            medium_vertices += v.kind == VertexKind::Medium;
            const double fwd = density(v, path[j - 1], pdfW_at(path[j - 1], j >= 2 ? &path[j - 2] : nullptr, v.p));
            if (std::abs(v.pdf_fwd - fwd) > 1e-3 * fwd) {
                ok = false;
                report += "subpath " + std::to_string(i) + " vertex " + std::to_string(j) + ": pdf_fwd " + std::to_string(v.pdf_fwd) +
                          " instead of " + std::to_string(fwd) + "\n";
            }
            if (j + 1 < path.size() && j >= 1 && path[j + 1].kind != VertexKind::Light) {
                const PathVertexBase& prev = path[j - 1];
                if (prev.kind == VertexKind::Camera) continue;
                const double rev = density(prev, v, pdfW_at(v, &path[j + 1], prev.p));
                const double stored = prev.pdf_rev;
                if (std::abs(stored - rev) > 1e-3 * rev) {
                    ok = false;
                    report += "subpath " + std::to_string(i) + " vertex " + std::to_string(j - 1) + ": pdf_rev " + std::to_string(stored) +
                              " instead of " + std::to_string(rev) + "\n";
                }
            }
        }
    }
    return ok;
}

TEST(BidirMedia, RandomWalksStoreTheDensitiesOfTheirDefinitions) {
    std::string report;
    int medium_vertices = 0;
    EXPECT_TRUE(walk_densities_match(MediumMis{}, report, medium_vertices)) << report;
    EXPECT_GT(medium_vertices, 50);
    BdptFaults faults;
    faults.drop_distance_pdf = true;
    EXPECT_FALSE(walk_densities_match(MediumMis(faults), report, medium_vertices));
}

}  // namespace
}  // namespace pathlab::test
