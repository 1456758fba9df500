// volpath in spectral mode (docs/spectral.md, "Spectral direct estimators, eyelight and
// volpath"): without media it is spectral pt-mis bit for bit; a grey medium under a white light
// agrees with RGB mode within the white's upsampling error; single scattering in a coloured
// slab (homogeneous, and a 3-channel grid tracked against its majorants) matches the closed form
// integrated against the observer by quadrature; two free-flight strategies agree on coloured
// media; the majorant bound of unbounded spectra; 1 and 2 threads give the same bytes.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>

#include "geometry/shape_meshes.hpp"
#include "media/spectral_medium.hpp"
#include "integrators/path/volpath.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scene_helpers.hpp"
#include "scenefile/scene_file.hpp"
#include "spectral_helpers.hpp"
#include "spectral/rgb_spectra.hpp"

namespace pathlab::test {
namespace {

std::string source_path(const std::string& relative) { return std::string(PATHLAB_SOURCE_DIR) + "/" + relative; }

const AgreementOptions kAgreement{1e-3, 1e-4};

RenderResult render_spectral(const SceneDescription& d, Integrator& integrator, int width, int height, uint64_t spp, uint64_t seed,
                             bool spectral = true) {
    const auto scene = Scene::build(d);
    RenderSettings rs;
    rs.width = width, rs.height = height, rs.spp = spp, rs.seed = seed;
    rs.spectral = spectral;
    return render(*scene, integrator, rs);
}

// volpath in spectral mode (RGB mode with spectral = false).
std::unique_ptr<Integrator> volpath(int max_depth = -1, VolpathSettings s = {}, bool spectral = true) {
    IntegratorOptions o;
    o.max_depth = max_depth;
    o.spectral = spectral;
    return make_volpath(o, s);
}

// ---- without media: spectral pt-mis ---------------------------------------------------------

TEST(SpectralVolpath, WithoutMediaItIsSpectralPtMisBitForBit) {
    std::vector<SceneDescription> scenes;
    for (int s = 0; s < 8; ++s) scenes.push_back(make_builtin_scene(s));
    // A dispersive glass: paths left with the hero alone.
    scenes.push_back(load_scene_file(source_path("scenes/dispersion-caustic.xml")));
    const auto pt = make_pixel_integrator<SpectralTransport>("pt-mis");
    const auto own_loop = volpath(-1, {true, false}), delegating = volpath();
    for (const SceneDescription& d : scenes) {
        const RenderResult a = render_spectral(d, *pt, 16, 12, 4, 7), b = render_spectral(d, *delegating, 16, 12, 4, 7);
        EXPECT_TRUE(bit_identical(a.film.mean(), b.film.mean())) << d.name;
        // volpath's own loop (what a scene with media runs), on a path that meets no medium.
        const RenderResult c = render_spectral(d, *own_loop, 16, 12, 4, 7);
        EXPECT_TRUE(bit_identical(a.film.mean(), c.film.mean())) << d.name << ": volpath's own loop";
        EXPECT_TRUE(bit_identical(a.film.standard_error(), c.film.standard_error())) << d.name << ": volpath's own loop";
        EXPECT_EQ(a.stats.rays, c.stats.rays) << d.name << ": volpath's own loop";
    }
}

// ---- a grey medium under a white light: RGB mode ------------------------------------------

// A one-channel grid of densities between 0.2 and 1.7 filling [-0.8, 0.8]^3.
HeterogeneousMedium grey_grid(float albedo) { return striped_grid_medium({{6, 5, 4}, 1, 0.2f, 0.3f, 6, 0.8, Rgb(albedo), HgPhase{-0.3f}}); }

// Spectral mode's expected colour of an RGB emitter, by quadrature every 0.25 nm (the film's
// expectation): its largest relative difference from the RGB over the channels.
double white_round_trip_error(const Rgb& e) {
    const RgbIlluminantSpectrum le(RgbToSpectrumTable::srgb(), e);
    Vec3d xyz(0.0);
    const double h = 0.25;
    for (double l = kVisibleMinWavelength + h / 2; l < kVisibleMaxWavelength; l += h) xyz += cie1931_xyz_bar(l) * (double(le(float(l))) * h);
    const Vec3d rgb = xyz_to_linear_srgb(xyz / cie_y_integral());
    double worst = 0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(rgb[c] - e[c]) / e[c]);
    return worst;
}


// Scene 4 (the light box: a white emitter) with every surface grey and a grey medium filling the
// box (homogeneous, or a one-channel grid). Every path's value is a product of grey factors
// (reflectances, albedos, transmittances: flat spectra, exactly the RGB's) times the white
// light's colour, and the media's random walks are the same in both modes (a grey medium
// leaves r = 1), so spectral mode's expectation is RGB mode's times the white's film colour:
// per channel within eps = white_round_trip_error of it. The test: the image means per channel,
// |spectral - rgb| <= eps rgb + 4 sigma; 2 media x 3 channels at z = 4, false alarms below 4e-4.
TEST(SpectralVolpath, GreyMediumUnderAWhiteLightAgreesWithRgbMode) {
    SceneDescription base = make_builtin_scene(4);
    for (Material& m : base.materials)
        if (auto* p = std::get_if<PhongMaterial>(&m.model)) {
            p->diffuse = Rgb(mean(p->diffuse));
            p->specular = Rgb(mean(p->specular));
        }
    double eps = 0;
    for (const SphereDesc& s : base.spheres)
        if (!is_black(s.emission)) eps = std::max(eps, white_round_trip_error(s.emission));
    for (const MeshDesc& m : base.meshes)
        if (!is_black(m.emission)) eps = std::max(eps, white_round_trip_error(m.emission));
    ASSERT_GT(eps, 0);  // the light box's emitter was found
    EXPECT_LT(eps, 2e-4);
    for (int variant = 0; variant < 2; ++variant) {
        SceneDescription d = base;
        if (variant == 0) {
            d.media.push_back(HomogeneousMedium{Rgb(0.6f), Rgb(0.45f), HgPhase{0.3f}});
        } else {
            d.media.push_back(grey_grid(0.8f));
        }
        d.meshes.push_back(fog_box(0));
        const ImageMean rgb = image_mean(render_spectral(d, *volpath(4, {}, false), 16, 16, 64, 31, false));
        const ImageMean spectral = image_mean(render_spectral(d, *volpath(4), 16, 16, 64, 32, true));
        for (int c = 0; c < 3; ++c) {
            const double sigma = std::hypot(rgb.se[c], spectral.se[c]);
            EXPECT_LE(std::abs(spectral.mean[c] - rgb.mean[c]), eps * rgb.mean[c] + 4 * sigma)
                << (variant == 0 ? "homogeneous" : "grid") << " channel " << c << ": spectral " << spectral.mean[c] << ", rgb "
                << rgb.mean[c] << ", eps " << eps << ", sigma " << sigma;
        }
    }
}

// ---- a coloured slab: the closed form at every wavelength -----------------------------------

double hg(double g, double cos_theta) { return (1 - g * g) / (4 * M_PI * std::pow(1 + g * g - 2 * g * cos_theta, 1.5)); }

// A slab 0 < z < thickness of a coloured medium (wide enough to be infinite), lit by a
// coloured directional light from above, seen from above, one bounce. At each wavelength the
// single-scattering radiance along a camera ray of direction v (|v.z| = mu_v) is
//   L(lambda) = sigma_s p(theta) E (1 - exp(-sigma_t d (1/mu_v + 1/mu_l))) / (sigma_t (1 + mu_v / mu_l))
// with sigma_t, sigma_s = albedo sigma_t and E the upsampled spectra (RgbUnboundedSpectrum,
// RgbAlbedoSpectrum, RgbIlluminantSpectrum) at lambda; the pixel's expectation is the film's
// colour of L, integrated here against the CIE observer by the midpoint rule every 1 nm. The
// medium is homogeneous (exact free flights, closed-form transmittance), or a 3-channel grid of
// that colour in every voxel (delta tracking, ratio tracking against the majorant grid times
// the unbounded-spectrum bound: sigma_t = (2, 0.05, 0.1) has a spectrum that rises far above 2, at long wavelengths).
TEST(SpectralVolpath, SingleScatteringInAColouredSlabMatchesTheQuadrature) {
    const float thickness = 0.3f, g = 0.4f;
    const Rgb sigma_t_rgb(2.0f, 0.05f, 0.1f), albedo_rgb(0.9f, 0.5f, 0.2f);
    const Vec3f light_dir = normalize(Vec3f(0.3f, 0.2f, -1.0f));
    const Rgb E(1.0f, 2.0f, 3.0f);
    const RgbToSpectrumTable& table = RgbToSpectrumTable::srgb();
    const RgbUnboundedSpectrum st_spec(table, sigma_t_rgb);
    const RgbAlbedoSpectrum albedo_spec(table, albedo_rgb);
    const RgbIlluminantSpectrum e_spec(table, E);
    ASSERT_GT(st_spec.max_value(), 1.5f * max_component(sigma_t_rgb));  // the case the majorant bound is for
    std::printf("sigma_t's spectrum: max %.4f for an RGB of max %.4f\n", st_spec.max_value(), max_component(sigma_t_rgb));

    SceneDescription d;
    d.name = "slab";
    d.camera = Camera::look_at({0, -1.5f, 2}, {0, 0, 0.1f}, {0, 0, 1}, 1.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(0.5f))};
    MeshDesc slab = cube_mesh();
    const Transform slab_to_world = Transform::translate({0, 0, thickness / 2}) * Transform::scale({50, 50, thickness / 2});
    transform_mesh(slab, slab_to_world);
    slab.media.interior = 0;
    slab.media.index_matched = true;
    d.meshes.push_back(slab);
    d.lights.push_back(DirectionalLight{light_dir, E});

    constexpr int kSize = 4;
    const PerspectiveCamera camera(d.camera, kSize, kSize);
    Image expected(kSize, kSize);
    const double mu_l = std::abs(light_dir.z);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const Vec3f v = normalize(camera.generate(float(x) + 0.5f, float(y) + 0.5f).d);
            const double mu_v = std::abs(v.z), p = hg(g, -dot(light_dir, v));
            Vec3d xyz(0.0);
            for (double l = kVisibleMinWavelength + 0.5; l < kVisibleMaxWavelength; l += 1) {
                const double st = st_spec(float(l)), ss = albedo_spec(float(l)) * st;
                const double L = ss * p * e_spec(float(l)) * (1 - std::exp(-st * thickness * (1 / mu_v + 1 / mu_l))) / (st * (1 + mu_v / mu_l));
                xyz += cie1931_xyz_bar(l) * L;
            }
            const Vec3d rgb = xyz_to_linear_srgb(xyz / cie_y_integral());
            expected.at(x, y) = Rgb(float(rgb.x), float(rgb.y), float(rgb.z));
        }

    HomogeneousMedium homogeneous{sigma_t_rgb, sigma_t_rgb * albedo_rgb, HgPhase{g}};
    HeterogeneousMedium grid;
    {
        VoxelGrid v;
        v.res = {2, 2, 2};
        v.channels = 3;
        for (int i = 0; i < 8; ++i)
            for (int c = 0; c < 3; ++c) v.data.push_back(sigma_t_rgb[c]);
        grid.sigma_t = Volume::of_grid(v, Transform::translate({-50, -50, -0.01}) * Transform::scale({100, 100, thickness + 0.02}));
        grid.albedo = Volume::constant_value(albedo_rgb);
        grid.phase = HgPhase{g};
        grid.prepare();
    }
    EXPECT_GT(spectral_majorant_factor(grid), 1.0f);
    EXPECT_EQ(spectral_majorant_factor(homogeneous), 1.0f);
    for (const Medium& m : {Medium(homogeneous), Medium(grid)}) {
        SceneDescription scene = d;
        scene.media.push_back(m);
        const auto integrator = volpath(1);
        const RenderResult r = render_spectral(scene, *integrator, kSize, kSize, 8192, 9);
        const AgreementResult a = test_agreement(r.film.mean(), r.film.standard_error(), expected, Image(), kAgreement);
        EXPECT_TRUE(a.agree) << (std::holds_alternative<HomogeneousMedium>(m) ? "homogeneous: " : "grid: ") << a.describe()
                             << "\nexpected " << expected.at(0, 0).x << " " << expected.at(0, 0).y << " " << expected.at(0, 0).z
                             << ", got " << r.film.mean().at(0, 0).x << " " << r.film.mean().at(0, 0).y << " "
                             << r.film.mean().at(0, 0).z;
    }
}

// ---- coloured media: two free-flight strategies ---------------------------------------------

// The fog box (a bluish homogeneous fog, coloured walls, full global illumination), scene 2 with
// a strongly coloured homogeneous fog (sigma_t (1.5, 0.4, 0.1)) and with a coloured 3-channel grid: exact free flights against delta and ratio tracking with
// the majorant inflated 2.5 times (null collisions); the same expectation: the per-pixel z-test
// (judge/image_statistics.hpp), and the image means per channel at z = 4 (6 two-sided tests,
// false alarms below 4e-4).
TEST(SpectralVolpath, FreeFlightStrategiesAgreeOnColouredMedia) {
    std::vector<SceneDescription> scenes;
    scenes.push_back(load_scene_file(source_path("scenes/fog-box.xml")));
    {
        // A strongly coloured homogeneous fog in scene 2 (its lanes' extinctions far apart).
        SceneDescription d = make_builtin_scene(2);
        d.media.push_back(HomogeneousMedium{Rgb(1.5f, 0.4f, 0.1f), Rgb(1.35f, 0.24f, 0.03f), HgPhase{0.3f}});
        d.meshes.push_back(fog_box(0));
        scenes.push_back(d);
    }
    {
        SceneDescription d = make_builtin_scene(2);
        d.media.push_back(striped_grid_medium({{5, 4, 3}, 3, 0.1f, 0.4f, 5, 0.8, Rgb(0.9f, 0.7f, 0.4f), HgPhase{0.5f}}));
        d.meshes.push_back(fog_box(0));
        scenes.push_back(d);
    }
    for (const SceneDescription& d : scenes) {
        // The majorant inflated: delta tracking with null collisions and ratio tracking in every
        // medium (homogeneous ones too), another free-flight strategy.
        const auto exact = volpath(4), inflated = volpath(4, {true, true, 2.5f});
        const RenderResult a = render_spectral(d, *exact, 12, 12, 256, 41), b = render_spectral(d, *inflated, 12, 12, 256, 42);
        const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), kAgreement);
        EXPECT_TRUE(r.agree) << d.name << ": " << r.describe();
        // The image means too (a small bias in every pixel adds up there): z = 4 per channel.
        const ImageMean ma = image_mean(a), mb = image_mean(b);
        for (int c = 0; c < 3; ++c)
            EXPECT_LE(std::abs(ma.mean[c] - mb.mean[c]), 4 * std::hypot(ma.se[c], mb.se[c]))
                << d.name << " channel " << c << ": exact " << ma.mean[c] << ", inflated majorant " << mb.mean[c];
    }
}

// ---- the majorant bound ---------------------------------------------------------------------

// unbounded_spectrum_bound() bounds every colour's unbounded spectrum (random colours, many of
// them saturated, at every nm), and is needed: some colours rise well above their largest channel.
TEST(SpectralVolpath, UnboundedSpectrumBoundHolds) {
    const float K = unbounded_spectrum_bound();
    EXPECT_GT(K, 1.0f);
    EXPECT_LE(K, 2.0f);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    float worst = 0;
    for (int i = 0; i < 4000; ++i) {
        Rgb c(u(rng), u(rng), u(rng));
        if (i % 2) c[i % 3] *= 0.02f;                // saturated: one channel near 0
        if (i % 3 == 0) c[(i + 1) % 3] *= 0.05f;     // and a second
        c = c * (0.1f + 20 * u(rng));                // any magnitude
        const RgbUnboundedSpectrum s(RgbToSpectrumTable::srgb(), c);
        const float m = max_component(c);
        for (int l = 360; l <= 830; ++l) {
            ASSERT_LE(s(float(l)), K * m) << c.x << " " << c.y << " " << c.z << " at " << l << " nm";
            worst = std::max(worst, s(float(l)) / m);
        }
    }
    EXPECT_GT(worst, 1.1f);  // a bound of 1 (the RGB majorant) would be wrong
    std::printf("unbounded spectrum bound K = %.5f; largest ratio over the random colours %.5f\n", K, worst);
    // Grey extinction is exact: a flat spectrum at the RGB's value.
    const SampledWavelengths wl = SampledWavelengths::sample_visible(0.3);
    const HomogeneousMedium grey{Rgb(0.7f), Rgb(0.35f), IsotropicPhase{}};
    const Medium medium = grey;
    const MediumCoefficientsOf<Spectrum4> c = MediumAtWavelengths{medium, wl}.coefficients(Vec3f(0.0f));
    for (int i = 0; i < kSpectrumLanes; ++i) {
        EXPECT_EQ(c.sigma_t[i], 0.7f);
        EXPECT_FLOAT_EQ(c.sigma_s[i], 0.35f);
    }
}

// ---- threads --------------------------------------------------------------------------------

TEST(SpectralVolpath, OneAndTwoThreadsGiveTheSameBytes) {
    for (const char* f : {"scenes/fog-box.xml", "scenes/smoke.xml"}) {
        const SceneDescription d = load_scene_file(source_path(f));
        const auto with_threads = [&](int threads) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
            const auto integrator = volpath();
            return render_spectral(d, *integrator, 24, 16, 4, 5);
        };
        const RenderResult one = with_threads(1), two = with_threads(2);
        EXPECT_TRUE(bit_identical(one.film.mean(), two.film.mean())) << f;
        EXPECT_TRUE(bit_identical(one.film.standard_error(), two.film.standard_error())) << f;
        EXPECT_EQ(one.stats.rays, two.stats.rays) << f;
    }
}

}  // namespace
}  // namespace pathlab::test
