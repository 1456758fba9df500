// The photon methods in spectral mode (docs/spectral.md "Spectral photon mapping"): sppm and pm
// agree with spectral pt-mis on a diffuse course scene, a glass ball's caustic and the caustic of
// a dispersive ball (per pixel, and on the image mean with block standard errors); on a grey
// scene under white light spectral pm, ppm and sppm agree with their RGB modes within the (tiny)
// upsampling error; images are the same bytes with 1 and 2 threads and when the passes are split;
// RGB mode renders as before; the merge counts hero-only photons 4 times against 4-lane paths.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <optional>

#include <fmt/format.h>

#include "integrators/integrators.hpp"
#include "integrators/photon/pm.hpp"
#include "integrators/photon/photon.hpp"
#include "integrators/photon/sppm.hpp"
#include "job/render_job.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"
#include "spectral_helpers.hpp"
#include "spectral/rgb_spectra.hpp"
#include "spectral/rgb_to_spectrum.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab::test {
namespace {

// An integrator by name in either mode (its factory sees IntegratorOptions::spectral).
RenderResult render_with(const Scene& scene, const std::string& name, IntegratorOptions o, bool spectral, int width, int height,
                         uint64_t spp, uint64_t seed, uint64_t first = 0, SamplerKind sampler = SamplerKind::Independent) {
    o.spectral = spectral;
    const std::unique_ptr<Integrator> integrator = find_integrator(name)->make(o);
    RenderSettings rs;
    rs.width = width, rs.height = height, rs.spp = spp, rs.seed = seed, rs.spectral = spectral, rs.first_sample = first;
    rs.sampler = sampler;
    return render(scene, *integrator, rs);
}

// A glass ball (constant index 1.5) on a floor, lit by a sphere light and a constant sky: a
// caustic under the ball that pt-mis also resolves (the sky and the light are large). `floor`,
// `light` and `sky` are rgb values.
std::unique_ptr<Scene> glass_scene(const std::string& floor, const std::string& light, const std::string& sky,
                                   const std::string& glass = R"(<float name="int_ior" value="1.5"/>)") {
    const std::string text = fmt::format(R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0, -3, 1.2" target="0, 0, 0.5" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film></sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="{}"/></bsdf></shape>
  <shape type="sphere"><point name="center" value="0, 0, 0.5"/><float name="radius" value="0.5"/>
    <bsdf type="dielectric">{}</bsdf></shape>
  <shape type="sphere"><point name="center" value="-1.2, 0.3, 1.4"/><float name="radius" value="0.4"/>
    <emitter type="area"><rgb name="radiance" value="{}"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="{}"/></emitter>
</scene>)",
                                         floor, glass, light, sky);
    return Scene::build(load_scene_text(text, "glass.xml", "."));
}

// ---- (a) agreement with spectral pt-mis ----------------------------------------------------

// A photon method at a small fixed or initial radius (5% of the scene's radius) with many
// photons per pass, whose photon bias is then far below its noise (test_sppm.cpp's
// SppmConsistency, whose parameters these are, at half the photons), against a spectral pt-mis
// reference (8x8, 16384 spp), two ways:
//  - per pixel and channel, test_agreement's outlier count (false alarms 1e-4 for the image,
//    binomial over its 192 tests), and the largest |z| at most 5.5 (Bonferroni over the 192:
//    7e-6 false alarms if the pixels' errors were normal; pt-mis's caustic pixels have heavier
//    tails, hence the margin over the 5.0 of 1e-4): a pixel's passes are independent (each draws its own
//    wavelengths and photons), so the films' standard errors are valid per pixel. Its pooled
//    bias test is not used: the pixels of one pass share the pass's wavelengths (and photons),
//    so their errors are correlated (a tint of the whole pass) and the pooled standard error
//    assuming independent pixels is too small (a first version failed it in blue, bias z -4.7 to
//    -7.7, on all three scenes with the same seed, i.e. the same 256 pass wavelengths);
//  - the image mean per channel, |photon - pt-mis| <= 4.5 sigma, with the photon method's sigma
//    from the spread of the means of 16 blocks of consecutive passes (one render split by
//    first_sample: each block is independent of the others; the blocks' different radii only
//    widen the spread, so sigma is conservative) and pt-mis's from its pixels' standard errors
//    (its samples draw their own wavelengths: independent pixels). t with 15 degrees of
//    freedom at 4.5: 4e-4 false alarms per channel.
struct PhotonAgreement {
    AgreementResult pixels;
    Vec3d z{0.0};
    bool agree() const {
        return pixels.outliers <= pixels.allowed_outliers && pixels.max_abs_z <= 5.5 && std::abs(z[0]) <= 4.5 && std::abs(z[1]) <= 4.5 &&
               std::abs(z[2]) <= 4.5;
    }
    std::string describe() const {
        return fmt::format("{} outliers (allowed {}) of {}, max |z| {:.2f} (limit 5.5); image mean z = ({:.2f}, {:.2f}, {:.2f}) (limit 4.5)", pixels.outliers,
                           pixels.allowed_outliers, pixels.pixels, pixels.max_abs_z, z[0], z[1], z[2]);
    }
};

Vec3d image_average(const Image& m) {
    Vec3d sum(0.0);
    for (size_t i = 0; i < m.pixel_count(); ++i) sum += Vec3d(m[i]);
    return sum / double(m.pixel_count());
}

PhotonAgreement against_spectral_pt_mis(const Scene& scene, const RenderResult& ref, const std::string& method, int passes_per_block) {
    IntegratorOptions o;
    o.photons = 8192;
    o.photon_radius = 0.05f * scene.scene_sphere().radius;
    constexpr int kBlocks = 16;
    std::vector<Vec3d> block_means;
    std::optional<Film> all;
    for (int k = 0; k < kBlocks; ++k) {
        const RenderResult r = render_with(scene, method, o, true, 8, 8, uint64_t(passes_per_block), 8, uint64_t(k * passes_per_block));
        block_means.push_back(image_average(r.film.mean()));
        if (!all) all = r.film;
        else all->merge(r.film);
    }
    PhotonAgreement out;
    out.pixels = test_agreement(all->mean(), all->standard_error(), ref.film.mean(), ref.film.standard_error(), AgreementOptions{1e-3, 1e-4});
    const Image ref_mean = ref.film.mean(), ref_se = ref.film.standard_error();
    const Vec3d ref_avg = image_average(ref_mean);
    for (int c = 0; c < 3; ++c) {
        double mean = 0, var = 0, ref_var = 0;
        for (const Vec3d& m : block_means) mean += m[c] / kBlocks;
        for (const Vec3d& m : block_means) var += (m[c] - mean) * (m[c] - mean) / (kBlocks - 1);
        for (size_t i = 0; i < ref_se.pixel_count(); ++i) ref_var += double(ref_se[i][c]) * ref_se[i][c];
        ref_var /= double(ref_se.pixel_count()) * double(ref_se.pixel_count());
        out.z[c] = (mean - ref_avg[c]) / std::sqrt(var / kBlocks + ref_var);
    }
    return out;
}

// The scenes of (a): the diffuse course scene 2, the glass ball's caustic, and the same ball of
// a strongly dispersive glass (Cauchy n = 1.5 + 0.02 / lambda^2, about five times N-BK7's
// dispersion): photons through it are hero-only and count 4 times against camera paths of 4
// lanes (the factor 4 of terminate_secondary, once for the whole path); camera paths through the
// ball are hero-only themselves.
class SpectralPhotonAgreement : public ::testing::TestWithParam<int> {
protected:
    static void SetUpTestSuite() {
        scenes_ = new std::vector<std::unique_ptr<Scene>>;
        refs_ = new std::vector<RenderResult>;
        scenes_->push_back(Scene::build(make_builtin_scene(2)));
        scenes_->push_back(glass_scene("0.7, 0.5, 0.3", "6, 4, 1.5", "0.3, 0.45, 0.6"));
        scenes_->push_back(glass_scene("0.7, 0.5, 0.3", "6, 4, 1.5", "0.3, 0.45, 0.6", R"(<string name="cauchy" value="1.5, 0.02"/>)"));
        for (const auto& s : *scenes_) refs_->push_back(render_with(*s, "pt-mis", {}, true, 8, 8, 16384, 4));
    }
    static void TearDownTestSuite() { delete scenes_, delete refs_; }
    static std::vector<std::unique_ptr<Scene>>* scenes_;
    static std::vector<RenderResult>* refs_;
};
std::vector<std::unique_ptr<Scene>>* SpectralPhotonAgreement::scenes_ = nullptr;
std::vector<RenderResult>* SpectralPhotonAgreement::refs_ = nullptr;

TEST_P(SpectralPhotonAgreement, SppmAgreesWithSpectralPtMis) {
    const PhotonAgreement r = against_spectral_pt_mis(*(*scenes_)[size_t(GetParam())], (*refs_)[size_t(GetParam())], "sppm", 16);
    std::printf("sppm: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.agree()) << r.describe();
}

// pm with a fixed radius (--radius: the same disc for every estimate instead of the 50 nearest
// photons) of 5% of the scene's radius and 8192 light paths per pass: its bias (the final
// gathering's blur, the caustic map's) is then below the noise of 128 passes.
TEST_P(SpectralPhotonAgreement, PmAgreesWithSpectralPtMis) {
    const PhotonAgreement r = against_spectral_pt_mis(*(*scenes_)[size_t(GetParam())], (*refs_)[size_t(GetParam())], "pm", 8);
    std::printf("pm: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.agree()) << r.describe();
}

INSTANTIATE_TEST_SUITE_P(SpectralPhoton, SpectralPhotonAgreement, ::testing::Values(0, 1, 2), [](const ::testing::TestParamInfo<int>& i) {
    return std::string(i.param == 0 ? "CeilingDiffuse" : i.param == 1 ? "GlassCaustic" : "DispersiveGlassCaustic");
});

// ---- (b) spectral against RGB photon mapping on a grey scene under white light ------------


// Image means per channel over R independent runs (seeds), and their standard error from the
// runs' spread: valid although the pixels of one pass share photons (and, in spectral mode,
// wavelengths), and although RGB pm's passes share one photon map per run.
struct RunsMean {
    Vec3d mean{0.0}, se{0.0};
};
RunsMean runs_mean(const Scene& scene, const std::string& name, const IntegratorOptions& o, bool spectral, int runs, uint64_t spp,
                   uint64_t seed0) {
    std::vector<Vec3d> means;
    for (int k = 0; k < runs; ++k) {
        const Image m = render_with(scene, name, o, spectral, 16, 16, spp, seed0 + uint64_t(k), 0, SamplerKind::Sobol).film.mean();
        Vec3d sum(0.0);
        for (size_t i = 0; i < m.pixel_count(); ++i) sum += Vec3d(m[i]);
        means.push_back(sum / double(m.pixel_count()));
    }
    RunsMean out;
    for (const Vec3d& x : means) out.mean += x / double(runs);
    for (const Vec3d& x : means)
        for (int c = 0; c < 3; ++c) out.se[c] += (x[c] - out.mean[c]) * (x[c] - out.mean[c]) / double(runs - 1);
    for (int c = 0; c < 3; ++c) out.se[c] = std::sqrt(out.se[c] / double(runs));
    return out;
}

// Every surface grey (a grey reflectance upsamples exactly: the table's closed form), glass of
// constant index (grey Fresnel factors), the light and the sky white: every path's value is a
// grey product times the emitter's spectrum, D65 at unit luminance in spectral mode, whose film
// colour is white within eps = 2e-4 (docs/spectral.md: (1.00009, 0.99998, 0.99991)); the photon
// positions, radii and Russian roulette's odds are RGB mode's (grey throughputs). So each
// method's expected image is its RGB mode's within eps, bias included. The z-test: 12 runs per
// mode (seeds), image means, |spectral - rgb| <= eps rgb + 5 sigma per channel, sigma from the
// runs' spread (11 degrees of freedom each: about 5e-4 false alarms per comparison, 5e-3 for
// the 9 comparisons).
TEST(SpectralPhotonGrey, SpectralAgreesWithRgbModeForPmPpmAndSppm) {
    const auto scene = glass_scene("0.6", "5, 5, 5", "0.4, 0.4, 0.4");
    const Vec3d white = film_colour([](double l) {
        const RgbIlluminantSpectrum e(RgbToSpectrumTable::srgb(), Rgb(1.0f));
        return double(e(float(l)));
    });
    double eps = 0;
    for (int c = 0; c < 3; ++c) eps = std::max(eps, std::abs(white[c] - 1));
    ASSERT_LT(eps, 2e-4);
    struct Case {
        const char* name;
        int64_t photons;
        uint64_t spp;
    };
    for (const Case& k : {Case{"sppm", 512, 64}, Case{"ppm", 512, 64}, Case{"pm", 512, 64}}) {
        IntegratorOptions o;
        o.photons = k.photons;
        const RunsMean rgb = runs_mean(*scene, k.name, o, false, 12, k.spp, 100);
        const RunsMean spectral = runs_mean(*scene, k.name, o, true, 12, k.spp, 200);
        for (int c = 0; c < 3; ++c) {
            const double sigma = std::hypot(rgb.se[c], spectral.se[c]);
            std::printf("%s channel %d: spectral %.5f (se %.5f), rgb %.5f (se %.5f)\n", k.name, c, spectral.mean[c], spectral.se[c], rgb.mean[c], rgb.se[c]);
            EXPECT_LE(std::abs(spectral.mean[c] - rgb.mean[c]), eps * rgb.mean[c] + 5 * sigma)
                << k.name << " channel " << c << ": spectral " << spectral.mean[c] << ", rgb " << rgb.mean[c] << ", sigma " << sigma;
            EXPECT_GT(rgb.mean[c], 10 * sigma) << k.name << ": the test must resolve the image";
        }
    }
}

// ---- (c) determinism -----------------------------------------------------------------------

TEST(SpectralPhotonDeterminism, OneAndTwoThreadsGiveTheSameBytes) {
    const auto scene = glass_scene("0.7, 0.5, 0.3", "6, 4, 1.5", "0.3, 0.45, 0.6");
    for (const char* name : {"pm", "ppm", "sppm"}) {
        IntegratorOptions o;
        o.photons = 3000;
        RenderResult runs[2];
        for (const int threads : {1, 2}) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
            runs[threads - 1] = render_with(*scene, name, o, true, 24, 16, 3, 9);
        }
        EXPECT_TRUE(bit_identical(runs[0].film.mean(), runs[1].film.mean())) << name;
        EXPECT_EQ(runs[0].stats.rays, runs[1].stats.rays) << name;
    }
}

// pm owns its pass loop in spectral mode and reproduces the tile loop's lens sample and
// reconstruction filter (a lattice per pass at filter_shift, filtered into the film): through a
// thin lens with a Gaussian filter it renders the same bytes with 1 and 2 threads, a finite
// image that is not black. (Only this smoke check: its agreement is not tested.)
TEST(SpectralPhotonDeterminism, PmThroughALensWithAFilter) {
    const std::string text = R"(<scene version="3.0.0">
  <sensor type="thinlens"><float name="fov" value="50"/><float name="aperture_radius" value="0.05"/><float name="focus_distance" value="3"/>
    <transform name="to_world"><lookat origin="0, -3, 1.2" target="0, 0, 0.5" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/><rfilter type="gaussian"/></film></sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.5, 0.3"/></bsdf></shape>
  <shape type="sphere"><point name="center" value="-1.2, 0.3, 1.4"/><float name="radius" value="0.4"/>
    <emitter type="area"><rgb name="radiance" value="6, 4, 1.5"/></emitter></shape>
</scene>)";
    const SceneDescription d = load_scene_text(text, "lens.xml", ".");
    RenderResult runs[2];
    for (const int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        JobRequest request;
        request.algorithm = "pm";
        request.spp = 3;
        request.width = 24, request.height = 16;
        request.seed = 3;
        request.photons = 2000;
        request.spectral = true;
        RenderJob job(scene_choice_of(d), request);
        runs[threads - 1] = job.run();
    }
    const Image m = runs[0].film.mean();
    EXPECT_TRUE(bit_identical(m, runs[1].film.mean()));
    double sum = 0;
    for (size_t i = 0; i < m.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            ASSERT_TRUE(std::isfinite(m[i][c]));
            sum += m[i][c];
        }
    EXPECT_GT(sum, 0.0);
    EXPECT_EQ(runs[0].stats.invalid_samples, 0u);
}

// A pass is a function of its index alone: passes 0-2 and 3-5 rendered apart and merged give the
// sums of passes 0-5 rendered at once (to the order of the additions).
TEST(SpectralPhotonDeterminism, ARenderSplitIntoPartsEqualsTheOneShotRender) {
    const auto scene = Scene::build(make_builtin_scene(3));
    for (const char* name : {"pm", "sppm"}) {
        IntegratorOptions o;
        o.photons = 2000;
        const RenderResult whole = render_with(*scene, name, o, true, 16, 12, 6, 5);
        Film merged = render_with(*scene, name, o, true, 16, 12, 3, 5).film;
        merged.merge(render_with(*scene, name, o, true, 16, 12, 3, 5, 3).film);
        for (size_t i = 0; i < merged.pixel_count(); ++i) {
            ASSERT_EQ(merged.count(i), whole.film.count(i));
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(merged.sum(i)[c], whole.film.sum(i)[c], 1e-12 * std::max(1.0, std::abs(whole.film.sum(i)[c]))) << name;
        }
    }
}

// ---- (d) RGB mode unchanged ----------------------------------------------------------------

// RGB mode's factories still make the RGB integrators: the same image as PhotonMapper and Sppm
// made directly. (That their images are main's before this work was checked with the command
// line, docs/spectral.md "Spectral photon mapping".)
TEST(SpectralPhotonRgb, RgbModeRendersAsBefore) {
    const auto scene = Scene::build(make_builtin_scene(3));
    IntegratorOptions o;
    o.photons = 2000;
    RenderSettings rs;
    rs.width = 16, rs.height = 12, rs.spp = 3, rs.seed = 7;
    PhotonMapper<RgbTransport> pm(o);
    Sppm<RgbTransport> sppm(o), ppm(o, SppmFaults{}, CameraRays::PixelCentres);
    const Image direct[3] = {render(*scene, pm, rs).film.mean(), render(*scene, ppm, rs).film.mean(), render(*scene, sppm, rs).film.mean()};
    const char* names[3] = {"pm", "ppm", "sppm"};
    for (int i = 0; i < 3; ++i) {
        const Image by_name = render_with(*scene, names[i], o, false, 16, 12, 3, 7).film.mean();
        EXPECT_TRUE(bit_identical(by_name, direct[i])) << names[i];
    }
}

// ---- the merge rule and the refusal --------------------------------------------------------

// docs: a hero-only photon's lane 0 counts 4 times against a camera path of 4 lanes, once against
// a hero-only one; photons of 4 lanes count as they are.
TEST(SpectralPhotonMerge, HeroOnlyPhotonsCountFourTimesOnceForTheWholePath) {
    SampledWavelengths four = SampledWavelengths::sample_visible(0.3), hero = four;
    hero.terminate_secondary();
    MergeSum<SpectralTransport> sum;
    sum.add(Spectrum4(1.0f) * Spectrum4(1, 2, 3, 4), false);
    sum.add(Spectrum4(2.0f) * Spectrum4(0.5f, 0, 0, 0), true);
    EXPECT_EQ(sum.total(four), Spectrum4(1 + 4 * 1.0f, 2, 3, 4));
    EXPECT_EQ(sum.total(hero), Spectrum4(1 + 1.0f, 2, 3, 4));
    // The film's estimate of the hero-only part alone is f(l0) / p(l0) with either camera path.
    MergeSum<SpectralTransport> only;
    only.add(Spectrum4(1.0f) * Spectrum4(0.8f, 0, 0, 0), true);
    const Vec3d a = spectral_sample_to_xyz(only.total(four), four), b = spectral_sample_to_xyz(only.total(hero), hero);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6 * std::abs(b[c]) + 1e-12);
}

}  // namespace
}  // namespace pathlab::test
