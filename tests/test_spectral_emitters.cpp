// Emitters with a spectrum of their own in spectral mode (docs/spectral.md, "Emitters with a
// spectrum"): scene files' black bodies and tabulated spectra reach the scene for area, point,
// spot, constant and directional emitters, the emission of a light sample is that spectrum
// times the light's own factor (1/d^2, a scale), and renders see the spectrum itself, not its
// RGB colour upsampled.
#include <gtest/gtest.h>

#include <cmath>

#include "integrators/common/transport.hpp"
#include "scenefile/scene_file.hpp"
#include "spectral_helpers.hpp"

namespace pathlab::test {
namespace {

// One emitter of each kind, each given as a spectrum but the directional one.
const char* const kEmitters = R"(<scene version="3.0.0">
  <emitter type="point"><point name="position" x="0" y="0" z="4"/><blackbody name="intensity" temperature="4000K" scale="0.5"/></emitter>
  <emitter type="spot"><spectrum name="intensity" value="400:1, 700:2"/></emitter>
  <emitter type="constant"><spectrum name="radiance" value="2"/></emitter>
  <emitter type="directional"><rgb name="irradiance" value="1, 2, 3"/></emitter>
  <shape type="rectangle">
    <emitter type="area"><spectrum type="blackbody" name="radiance"><float name="temperature" value="2856"/></spectrum></emitter>
  </shape>
</scene>)";

TEST(SpectralEmitters, SceneFilesKeepTheirSpectra) {
    const SceneDescription d = load_scene_text(kEmitters, "emitters.xml", ".");
    const std::unique_ptr<Scene> scene = Scene::build(d);
    ASSERT_EQ(scene->lights().size(), 6u);  // point, spot, constant, directional, the rectangle's 2 triangles
    // Point: Planck's law at 4000 K times 0.5, W / (m^2 sr nm), at every whole nm.
    const EmissionSpectrum* point = scene->light_spectrum(0);
    ASSERT_NE(point, nullptr);
    for (float l : {400.0f, 550.0f, 700.0f}) EXPECT_NEAR(point->values(l), 0.5 * planck(l, 4000), 1e-6 * planck(l, 4000)) << l;
    // Its RGB is what the light was given (the light's own RGB code uses it).
    SampledSpectrum bb = blackbody_spectrum(4000);
    for (double& v : bb.values) v *= 0.5;
    const Vec3d rgb = spectrum_to_linear_srgb(bb, SpectrumUse::Illuminant);
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(point->rgb[c], float(rgb[c]));
    EXPECT_FLOAT_EQ(std::get<PointLight>(scene->lights()[0]).intensity.x, point->rgb.x);
    // Spot: the tabulated spectrum, linear between its knots.
    ASSERT_NE(scene->light_spectrum(1), nullptr);
    EXPECT_NEAR(scene->light_spectrum(1)->values(550), 1.5f, 1e-6f);
    // Constant: Mitsuba 3's uniform emitter spectrum is flat (illuminant E).
    ASSERT_NE(scene->light_spectrum(2), nullptr);
    EXPECT_EQ(scene->light_spectrum(2)->values(400), 2.0f);
    EXPECT_EQ(scene->light_spectrum(2)->values(800), 2.0f);
    // Directional: an RGB value, upsampled in spectral mode.
    EXPECT_EQ(scene->light_spectrum(3), nullptr);
    // Area: Mitsuba 3's <spectrum type="blackbody">, on both triangles of the rectangle.
    for (int i : {4, 5}) {
        ASSERT_NE(scene->light_spectrum(i), nullptr) << i;
        EXPECT_NEAR(scene->light_spectrum(i)->values(600), planck(600, 2856), 1e-6 * planck(600, 2856));
    }
    EXPECT_EQ(scene->light_spectrum(6), nullptr);  // past the end
}

TEST(SpectralEmitters, LightSampleEmissionIsTheSpectrumTimesTheLightsFactor) {
    const SceneDescription d = load_scene_text(kEmitters, "emitters.xml", ".");
    const std::unique_ptr<Scene> scene = Scene::build(d);
    const SampledWavelengths wl = SampledWavelengths::sample_visible(0.37);
    // The point light seen from the origin, 4 away: intensity / 16.
    const auto ls = sample_light(scene->lights()[0], Vec3f(0.0f), Vec2f(0.5f, 0.5f));
    ASSERT_TRUE(ls);
    const Spectrum4 L = light_colour(*scene, 0, ls->Le, wl);
    for (int i = 0; i < kSpectrumLanes; ++i)
        EXPECT_NEAR(L[i], 0.5 * planck(wl[i], 4000) / 16, 2e-5 * planck(wl[i], 4000) / 16) << "lane " << i << " at " << wl[i] << " nm";
    // The environment's flat spectrum, and an RGB emitter (no spectrum) upsampled as before.
    const Spectrum4 sky = escaped_radiance(*scene, Vec3f(0, 0, 1), wl);
    for (int i = 0; i < kSpectrumLanes; ++i) EXPECT_FLOAT_EQ(sky[i], 2.0f);
    const Rgb e(1, 2, 3);
    EXPECT_EQ(light_colour(*scene, 3, e, wl), illuminant_spectrum(e, wl));
    // A coloured factor (a spot's projected texture) multiplies the spectrum by its upsampled
    // unbounded spectrum; a black one gives black.
    const EmissionSpectrum& spot = *scene->light_spectrum(1);
    const Rgb tint(0.2f, 0.5f, 0.9f);
    const Spectrum4 tinted = light_colour(*scene, 1, spot.rgb * tint, wl);
    const Spectrum4 want = spot.values.sample(wl) * unbounded_spectrum(tint, wl);
    for (int i = 0; i < kSpectrumLanes; ++i) EXPECT_NEAR(tinted[i], want[i], 1e-4f * want[i]) << i;
    EXPECT_TRUE(light_colour(*scene, 1, Rgb(0.0f), wl).is_black());
}

TEST(SpectralEmitters, MalformedSpectraNameTheirLine) {
    const auto error = [](const std::string& spectrum) -> std::string {
        const std::string text = "<scene version=\"3.0.0\">\n<emitter type=\"constant\">\n" + spectrum + "\n</emitter>\n<shape type=\"sphere\"/></scene>";
        try {
            load_scene_text(text, "bad.xml", ".");
        } catch (const SceneFileError& e) {
            return e.what();
        }
        return "loaded";
    };
    const std::string unknown = error(R"(<spectrum type="regular" name="radiance"/>)");
    EXPECT_NE(unknown.find("bad.xml:3"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("unsupported spectrum type 'regular'; supported: blackbody"), std::string::npos) << unknown;
    const std::string missing = error(R"(<spectrum type="blackbody" name="radiance"/>)");
    EXPECT_NE(missing.find("needs <float name=\"temperature\""), std::string::npos) << missing;
    const std::string cold = error(R"(<spectrum type="blackbody" name="radiance"><float name="temperature" value="20"/></spectrum>)");
    EXPECT_NE(cold.find("temperature must be 100 K to 1e6 K, got 20"), std::string::npos) << cold;
    const std::string other = error(R"(<spectrum type="blackbody" name="radiance"><float name="scale" value="2"/></spectrum>)");
    EXPECT_NE(other.find("takes one parameter"), std::string::npos) << other;
}

// ---- renders see the spectrum ----------------------------------------------------------------

// A diffuse sphere filling the view under a constant environment, direct illumination: every
// pixel's expectation is the film colour of rho(lambda) L(lambda) (the convex sphere sees the
// whole sky over its hemisphere).
const char* const kSkyLitSphere = R"(<scene version="3.0.0">
  <default name="mode" value="spectral"/>
  <sensor type="perspective"><float name="fov" value="10"/>
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant">SKY</emitter>
  <shape type="sphere"><float name="radius" value="1"/><bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.2, 0.1"/></bsdf></shape>
</scene>)";

// A narrow band of green light on an orange surface: spectral mode sees the band's product with
// the surface's upsampled reflectance; the band's RGB colour (out of gamut, clamped) upsampled
// would give a very different colour (the test prints it).
TEST(SpectralEmitters, ANarrowBandSkyIsSeenWithItsSpectrum) {
    const std::string band = R"(<spectrum name="radiance" value="500:0, 530:0, 545:20, 560:0, 600:0"/>)";
    std::string text = kSkyLitSphere;
    text.replace(text.find("SKY"), 3, band);
    const SceneDescription d = load_scene_text(text, "band.xml", ".");
    const RgbAlbedoSpectrum rho(RgbToSpectrumTable::srgb(), Rgb(0.8f, 0.2f, 0.1f));
    const auto sky = [](double l) { return l <= 530 || l >= 560 ? 0.0 : l < 545 ? 20 * (l - 530) / 15 : 20 * (560 - l) / 15; };
    const Vec3d want = film_colour([&](double l) { return double(rho(float(l))) * sky(l); });
    const Rgb sky_rgb = Scene::build(d)->light_spectrum(0)->rgb;
    const RgbIlluminantSpectrum upsampled(RgbToSpectrumTable::srgb(), sky_rgb);
    const Vec3d rgb_way = film_colour([&](double l) { return double(rho(float(l))) * upsampled(float(l)); });
    const ImageMean m = image_mean(render_mode(d, true, 16, 64, 11, 1, "direct-mis"));
    // z = 4 per channel (3 two-sided tests: a false-alarm rate below 2e-4); the quadrature's
    // error (0.25 nm midpoint rule of a piecewise-linear product) is below 1e-4 relative.
    for (int c = 0; c < 3; ++c)
        EXPECT_LE(std::abs(m.mean[c] - want[c]), 4 * m.se[c] + 1e-4 * std::abs(want[c]))
            << "channel " << c << ": " << m.mean[c] << " +- " << m.se[c] << ", the spectrum gives " << want[c]
            << ", its RGB upsampled would give " << rgb_way[c];
}

// A point light of a black body's intensity on a diffuse sphere, direct illumination: the image
// is the geometry (cos / (pi d^2), the same in both modes for the same seed) times the colour,
// so the ratio of the two modes' image means per channel is the film colour of rho I over RGB
// mode's rho I_rgb (which the black body's in-gamut colour makes the same up to the
// upsampled reflectance's error, stated below). This pins the light's 1/d^2 factor.
TEST(SpectralEmitters, ABlackBodyPointLightAgreesWithRgbMode) {
    const std::string text = R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="1" y="2" z="4"/>
    <spectrum type="blackbody" name="intensity"><float name="temperature" value="3500"/></spectrum></emitter>
  <shape type="sphere"><float name="radius" value="1"/><bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
</scene>)";
    const SceneDescription d = load_scene_text(text, "point.xml", ".");
    const ImageMean rgb = image_mean(render_mode(d, false, 16, 16, 5, 1, "direct-light"));
    const ImageMean spectral = image_mean(render_mode(d, true, 16, 16, 5, 1, "direct-light"));
    // The black body's colour and the spectrum's film colour: equal where in gamut (grey rho 0.5 is exact).
    const EmissionSpectrum& own = *Scene::build(d)->light_spectrum(0);
    const Vec3d film = film_colour([&](double l) { return double(own.values(float(l))); });
    for (int c = 0; c < 3; ++c) {
        ASSERT_GT(rgb.mean[c], 0.01) << "the light reaches the sphere";
        ASSERT_GT(film[c], 0) << "3500 K lies in the sRGB gamut";
        const double want = rgb.mean[c] * film[c] / own.rgb[c];
        // z = 4 (3 tests), plus the DenseSpectrum's 1 nm interpolation of Planck's law (< 1e-5).
        EXPECT_LE(std::abs(spectral.mean[c] - want), 4 * std::hypot(spectral.se[c], rgb.se[c] * film[c] / own.rgb[c]) + 1e-4 * want)
            << "channel " << c << ": spectral " << spectral.mean[c] << " rgb " << rgb.mean[c];
    }
}

}  // namespace
}  // namespace pathlab::test
