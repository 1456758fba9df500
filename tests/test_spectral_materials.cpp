// Spectral values of the material models (docs/spectral.md, "Materials in spectral mode"),
// checked against an oracle that does not share their code: RGB mode's own eval() and sample()
// of a copy of the material whose colour parameters are replaced by their spectra's values at
// three of the four wavelengths (then the fourth). Every model's value is channel-wise in its
// colour parameters, so that copy's RGB value is the spectral value at those wavelengths.
// Also: the measured metals, the importance-transport factor, a rough dispersive dielectric,
// and renders of plastic against RGB mode.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>

#include "integrators/common/transport.hpp"
#include "scenefile/scene_file.hpp"
#include "spectral/dispersion.hpp"
#include "spectral/metals.hpp"
#include "spectral_helpers.hpp"

namespace pathlab::test {
namespace {

// A material built from its colours: the function gives each colour parameter's value.
using ColourLanes = std::function<Rgb(const Rgb& colour)>;  // a colour parameter -> its substitute
using MaterialOf = std::function<Material(const ColourLanes&)>;

const SampledWavelengths kWl = SampledWavelengths::sample_visible(0.61);

// Reflectances and unbounded values (eta, k) as spectra at lanes (a, b, c) of kWl.
ColourLanes lanes(int a, int b, int c, bool unbounded = false) {
    return [=](const Rgb& colour) {
        const Spectrum4 s = unbounded ? unbounded_spectrum(colour, kWl) : reflectance_spectrum(colour, kWl);
        return Rgb(s[a], s[b], s[c]);
    };
}

ShadingPoint point_on(const Material& m, const Vec3f& wi, TransportMode mode, const Vec3f& shading_normal = Vec3f(0, 0, 1)) {
    ShadingPoint sp;
    sp.material = &m;
    sp.frame = Frame(shading_normal);
    sp.ng = Vec3f(0, 0, 1);
    sp.mode = mode;
    sp.wi = sp.frame.to_local(wi);
    return sp;
}

struct Case {
    const char* name;
    MaterialOf make;
};

MicrofacetDistribution rough(float alpha) { return MicrofacetDistribution(MicrofacetType::Beckmann, alpha, alpha); }

std::vector<Case> cases() {
    return {
        {"phong", [](const ColourLanes& L) { return make_phong(L({0.7f, 0.3f, 0.1f}), L({0.2f, 0.4f, 0.3f}), 20); }},
        {"plastic", [](const ColourLanes& L) { return make_plastic(L({0.1f, 0.6f, 0.8f}), L({0.9f, 0.8f, 0.7f})); }},
        {"plastic nonlinear", [](const ColourLanes& L) { return make_plastic(L({0.1f, 0.6f, 0.8f}), Rgb(1.0f), 1.6f, 1.000277f, true); }},
        {"roughplastic", [](const ColourLanes& L) { return make_rough_plastic(rough(0.3f), L({0.8f, 0.5f, 0.1f}), L({0.5f, 0.9f, 0.6f})); }},
        {"roughplastic nonlinear",
         [](const ColourLanes& L) { return make_rough_plastic(rough(0.2f), L({0.8f, 0.5f, 0.1f}), Rgb(1.0f), 1.5f, 1.000277f, true); }},
        {"principled",  // without the tints, whose luminance is the RGB colour's (principled.hpp)
         [](const ColourLanes& L) {
             PrincipledMaterial p;
             p.base_color = L({0.7f, 0.4f, 0.2f});
             p.roughness = 0.4f, p.metallic = 0.3f, p.spec_trans = 0.4f, p.transmits = true, p.sheen = 0.5f, p.clearcoat = 0.6f;
             return Material{p, false};
         }},
        {"principledthin",  // without the tints, as principled
         [](const ColourLanes& L) {
             PrincipledThinMaterial p;
             p.base_color = L({0.3f, 0.6f, 0.2f});
             p.roughness = 0.35f, p.spec_trans = 0.5f, p.diff_trans = 0.7f, p.sheen = 0.4f, p.eta = 1.3f;
             return Material{p, true};
         }},
        {"blendbsdf",
         [](const ColourLanes& L) {
             Material m{BlendMaterial{std::make_shared<const Material>(make_phong(L({0.7f, 0.2f, 0.2f}))),
                                      std::make_shared<const Material>(make_plastic(L({0.1f, 0.3f, 0.9f}))), 0.3f}};
             m.prepare();
             return m;
         }},
        {"mask",
         [](const ColourLanes& L) {
             Material m{MaskMaterial{std::make_shared<const Material>(make_rough_plastic(rough(0.3f), L({0.2f, 0.8f, 0.4f}))), 0.6f}};
             m.prepare();
             return m;
         }},
    };
}

// The spectral value against the oracle over directions of both hemispheres, in radiance and
// importance transport, with the shading normal tilted from the geometric one.
TEST(SpectralMaterials, NonDeltaValuesMatchRgbEvaluationOfTheSpectra) {
    for (const Case& c : cases()) {
        const Material m = c.make([](const Rgb& x) { return x; });
        const Material low = c.make(lanes(0, 1, 2)), high = c.make(lanes(3, 3, 3));
        for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance})
            for (const Vec3f& n : {Vec3f(0, 0, 1), normalize(Vec3f(0.2f, -0.1f, 1))})
                for (int k = 0; k < 24; ++k) {
                    const Vec3f wi = normalize(Vec3f(std::cos(k * 0.7f), std::sin(k * 1.3f), 0.3f + 0.03f * k));
                    const Vec3f wo_world = normalize(Vec3f(std::sin(k * 2.1f), std::cos(k * 0.4f), k % 5 == 0 ? -0.2f : 0.2f + 0.04f * k));
                    const ShadingPoint sp = point_on(m, wi, mode, n);
                    const Vec3f wo = sp.frame.to_local(wo_world);
                    SampledWavelengths wl = kWl;
                    float pdf = 0, pdf_rgb = 0;
                    const Spectrum4 f = bsdf_eval(sp, wo, wl, pdf);
                    const ShadingPoint a = point_on(low, wi, mode, n), b = point_on(high, wi, mode, n);
                    const Rgb f_low = low.eval_and_pdf(a, a.wi, wo, pdf_rgb), f_high = high.eval(b, b.wi, wo);
                    m.eval_and_pdf(sp, sp.wi, wo, pdf_rgb);
                    EXPECT_EQ(pdf, pdf_rgb) << c.name << ": the density is RGB mode's";
                    const float want[4] = {f_low.x, f_low.y, f_low.z, f_high.x};
                    for (int i = 0; i < kSpectrumLanes; ++i)
                        EXPECT_NEAR(f[i], want[i], 2e-5f * std::max(1.0f, std::abs(want[i])))
                            << c.name << " lane " << i << " direction " << k << (mode == TransportMode::Importance ? " importance" : " radiance");
                }
    }
}

// The Dirac lobes: a sample's value against the oracle's sample drawn with the same u.
TEST(SpectralMaterials, DeltaValuesMatchRgbSamplesOfTheSpectra) {
    const ComplexIor gold = [] {
        ComplexIor i = *named_conductor("Au");
        i.measured = nullptr;  // the RGB eta, k upsampled (the measured ones: the next test)
        return i;
    }();
    const std::vector<std::pair<Case, Vec2f>> delta = {
        {{"conductor", [&](const ColourLanes& L) { return make_conductor(gold, L({0.9f, 0.8f, 0.6f})); }}, Vec2f(0.5f, 0.5f)},
        {{"plastic's coating", [](const ColourLanes& L) { return make_plastic(L({0.1f, 0.6f, 0.8f}), L({0.9f, 0.6f, 0.7f})); }},
         Vec2f(0.0f, 0.5f)},
        {{"blendbsdf's conductor",
          [&](const ColourLanes& L) {
              Material m{BlendMaterial{std::make_shared<const Material>(make_conductor(gold, L({0.5f, 0.9f, 0.9f}))),
                                       std::make_shared<const Material>(make_phong(L({0.3f, 0.3f, 0.9f}))), 0.3f}};
              m.prepare();
              return m;
          }},
         Vec2f(0.8f, 0.5f)},
        {{"mask's inner conductor",
          [&](const ColourLanes& L) {
              Material m{MaskMaterial{std::make_shared<const Material>(make_conductor(gold, L({0.9f, 0.4f, 0.2f}))), 0.6f}};
              m.prepare();
              return m;
          }},
         Vec2f(0.3f, 0.5f)},
        {{"mask's pass-through",
          [&](const ColourLanes& L) {
              Material m{MaskMaterial{std::make_shared<const Material>(make_conductor(gold, L({0.9f, 0.4f, 0.2f}))), 0.6f}};
              m.prepare();
              return m;
          }},
         Vec2f(0.9f, 0.5f)},
    };
    const Vec3f wi = normalize(Vec3f(0.3f, -0.2f, 0.8f));
    for (const auto& [c, u] : delta)
        for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
            const Material m = c.make([](const Rgb& x) { return x; });
            const ShadingPoint sp = point_on(m, wi, mode, normalize(Vec3f(0.1f, 0.1f, 1)));
            SampledWavelengths wl = kWl;
            const auto s = bsdf_sample(sp, u, wl);
            ASSERT_TRUE(s && s->delta) << c.name;
            const Spectrum4 f = bsdf_sample_colour(sp, *s, wl);
            // The oracle: the gold's eta and k are fixed RGB here, so substitute them by hand.
            const auto oracle = [&](int a, int b, int cc) {
                const ColourLanes colour = lanes(a, b, cc);
                Material o = c.make(colour);
                const auto fix = [&](MaterialModel& model) {
                    if (auto* k = std::get_if<ConductorMaterial>(&model)) {
                        k->eta = lanes(a, b, cc, true)(gold.eta);
                        k->k = lanes(a, b, cc, true)(gold.k);
                    }
                };
                fix(o.model);
                if (auto* bl = std::get_if<BlendMaterial>(&o.model)) {
                    Material first = *bl->first;
                    fix(first.model);
                    bl->first = std::make_shared<const Material>(first);
                }
                if (auto* mk = std::get_if<MaskMaterial>(&o.model)) {
                    Material inner = *mk->inner;
                    fix(inner.model);
                    mk->inner = std::make_shared<const Material>(inner);
                }
                const ShadingPoint op = point_on(o, wi, mode, normalize(Vec3f(0.1f, 0.1f, 1)));
                const auto os = o.sample(op, op.wi, u);
                EXPECT_TRUE(os && os->delta && os->wo == s->wo) << c.name;
                return os ? os->f : Rgb(0.0f);
            };
            const Rgb low = oracle(0, 1, 2), high = oracle(3, 3, 3);
            const float want[4] = {low.x, low.y, low.z, high.x};
            for (int i = 0; i < kSpectrumLanes; ++i) EXPECT_NEAR(f[i], want[i], 2e-5f * std::max(1.0f, want[i])) << c.name << " lane " << i;
        }
}

// Named metals use their measured eta(lambda), k(lambda) (spectral/metals.hpp), not the RGB
// registry's averages: the smooth and rough conductors' values per lane against the Fresnel
// reflectance of the published data interpolated by core's spectrum_value.
TEST(SpectralMaterials, NamedMetalsUseTheirMeasuredIndices) {
    const std::string text = R"(<scene version="3.0.0">
  <bsdf type="conductor" id="smooth"><string name="material" value="$metal"/></bsdf>
  <bsdf type="roughconductor" id="rough"><string name="material" value="$metal"/><float name="alpha" value="0.2"/></bsdf>
  <shape type="sphere"><ref id="smooth"/></shape>
  <shape type="sphere"><ref id="rough"/><point name="center" x="3" y="0" z="0"/></shape>
</scene>)";
    for (const char* metal : {"Au", "Ag", "Cu", "Al", "Cr", "a-C"}) {
        const SceneDescription d = load_scene_text(text, "metals.xml", ".", {{"metal", metal}});
        const MeasuredConductor* data = measured_conductor(metal);
        ASSERT_EQ(std::get<ConductorMaterial>(d.materials[0].model).measured, data) << metal;
        ASSERT_EQ(std::get<RoughConductorMaterial>(d.materials[1].model).measured, data) << metal;
        const Vec3f wi = normalize(Vec3f(0.4f, 0.1f, 0.7f));
        // Smooth: F(cos_i) / cos per lane.
        const ShadingPoint sp = point_on(d.materials[0], wi, TransportMode::Radiance);
        SampledWavelengths wl = kWl;
        const auto s = bsdf_sample(sp, Vec2f(0.5f, 0.5f), wl);
        ASSERT_TRUE(s);
        const Spectrum4 f = bsdf_sample_colour(sp, *s, wl);
        // Rough: R F(wi.h) D G / (4 cos cos); its scalar part from the RGB model with F = 1.
        const ShadingPoint rp = point_on(d.materials[1], wi, TransportMode::Radiance);
        const Vec3f wo = normalize(Vec3f(-0.3f, 0.0f, 0.9f));
        float pdf;
        const Spectrum4 fr = bsdf_eval(rp, wo, wl, pdf);
        RoughConductorMaterial white = std::get<RoughConductorMaterial>(d.materials[1].model);
        white.eta = Rgb(0.0f), white.k = Rgb(1.0f);
        const float g = white.eval(rp.wi, wo).x;
        for (int i = 0; i < kSpectrumLanes; ++i) {
            const float eta = float(spectrum_value(data->eta, kWl[i])), k = float(spectrum_value(data->k, kWl[i]));
            EXPECT_NEAR(f[i], fresnel_conductor(sp.wi.z, eta, k) / sp.wi.z, 1e-4f) << metal << " lane " << i;
            EXPECT_NEAR(fr[i], fresnel_conductor(dot(rp.wi, normalize(rp.wi + wo)), eta, k) * g, 1e-4f * std::max(1.0f, g))
                << metal << " rough, lane " << i;
        }
    }
}

// ---- the rough dispersive dielectric ------------------------------------------------------

TEST(SpectralMaterials, RoughDielectricDispersesAtTheHeroWavelength) {
    const std::string text = R"(<scene version="3.0.0">
  <shape type="sphere"><bsdf type="roughdielectric"><string name="int_ior" value="bk7-sellmeier"/><float name="alpha" value="0.2"/></bsdf></shape>
</scene>)";
    const SceneDescription d = load_scene_text(text, "rough.xml", ".");
    const auto& glass = std::get<RoughDielectricMaterial>(d.materials[0].model);
    ASSERT_TRUE(glass.dispersion);
    EXPECT_NEAR(glass.int_ior, 1.5168f, 1e-4f);  // N-BK7's n_d in RGB mode
    const Vec3f wi = normalize(Vec3f(0.3f, 0.2f, 0.9f));
    const ShadingPoint sp = point_on(d.materials[0], wi, TransportMode::Radiance);
    for (float u_wl : {0.05f, 0.5f, 0.95f}) {
        const SampledWavelengths start = SampledWavelengths::sample_visible(u_wl);
        RoughDielectricMaterial hero = glass;
        hero.int_ior = float((*glass.dispersion)(start[0]));
        const Material at_hero{hero, false};
        for (const Vec2f u : {Vec2f(0.9f, 0.3f), Vec2f(0.2f, 0.7f)}) {  // refraction, reflection
            SampledWavelengths wl = start;
            const auto s = bsdf_sample(sp, u, wl);
            const auto want = at_hero.sample(sp.wi, u);
            ASSERT_EQ(bool(s), bool(want));
            EXPECT_TRUE(wl.secondary_terminated());
            EXPECT_EQ(wl.pdf(0), start.pdf(0) / 4);
            if (!s) continue;
            EXPECT_EQ(s->wo, want->wo) << "the hero's index refracts";
            EXPECT_EQ(s->pdfW, want->pdfW);
            // Evaluation (light sampling's) terminates too, and is the hero's.
            SampledWavelengths wl2 = start;
            float pdf;
            const Spectrum4 f = bsdf_eval(sp, s->wo, wl2, pdf);
            EXPECT_TRUE(wl2.secondary_terminated());
            float pdf_hero;
            EXPECT_FLOAT_EQ(f[0], at_hero.eval_and_pdf(sp.wi, s->wo, pdf_hero).x);
            EXPECT_FLOAT_EQ(pdf, pdf_hero);
        }
    }
}

// A rough glass ball whose "dispersive" index is constant (Cauchy 1.5 + 0 / l^2) against the same
// ball with int_ior 1.5, both in spectral mode: the first takes the hero-only path at every
// hit (terminate_secondary, the material copied at the hero's index), the second not; the
// images' means agree within noise (z = 4 per channel, 3 two-sided tests: false alarms below 2e-4).
TEST(SpectralMaterials, HeroOnlyRoughGlassAgreesWithTheConstantIndex) {
    const std::string text = R"(<scene version="3.0.0">
  <default name="mode" value="spectral"/>
  <sensor type="perspective"><float name="fov" value="25"/>
    <transform name="to_world"><lookat origin="0, 1, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="0.3, 0.5, 0.9"/></emitter>
  <shape type="sphere"><point name="center" x="0" y="3" z="1"/><float name="radius" value="0.5"/>
    <emitter type="area"><rgb name="radiance" value="8, 6, 3"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/><translate y="-1"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.4, 0.3"/></bsdf></shape>
  <shape type="sphere"><bsdf type="roughdielectric"><float name="alpha" value="0.15"/>IOR</bsdf></shape>
</scene>)";
    const auto with = [&](const std::string& ior) {
        std::string t = text;
        t.replace(t.find("IOR"), 3, ior);
        return load_scene_text(t, "glass.xml", ".");
    };
    const SceneDescription dispersive = with(R"(<string name="cauchy" value="1.5, 0"/>)");
    const SceneDescription constant = with(R"(<float name="int_ior" value="1.5"/>)");
    ASSERT_TRUE(std::get<RoughDielectricMaterial>(dispersive.materials.back().model).dispersion);
    const ImageMean a = image_mean(render_mode(dispersive, true, 16, 128, 21, 6));
    const ImageMean b = image_mean(render_mode(constant, true, 16, 128, 22, 6));
    for (int c = 0; c < 3; ++c)
        EXPECT_LE(std::abs(a.mean[c] - b.mean[c]), 4 * std::hypot(a.se[c], b.se[c]))
            << "channel " << c << ": hero-only " << a.mean[c] << " +- " << a.se[c] << ", constant " << b.mean[c] << " +- " << b.se[c];
}

// ---- reflectances given as spectra ----------------------------------------------------------

// A diffuse sphere filling the view whose reflectance the file gives as a spectrum, under a sky of
// a 2000 K black body, direct illumination: every pixel's expectation is the film colour of
// rho(lambda) S(lambda) (the convex sphere sees the whole sky). The reflectance's RGB (its
// colour under D65) upsampled would give another colour under this light (the test prints it).
TEST(SpectralMaterials, ReflectanceSpectraAreUsedAsGiven) {
    const std::string text = R"(<scene version="3.0.0">
  <default name="mode" value="spectral"/>
  <sensor type="perspective"><float name="fov" value="10"/>
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><blackbody name="radiance" temperature="2000K" scale="0.2"/></emitter>
  <shape type="sphere"><float name="radius" value="1"/>
    <bsdf type="diffuse"><spectrum name="reflectance" value="400:0.9, 480:0.05, 560:0.9, 640:0.05, 720:0.9"/></bsdf></shape>
</scene>)";
    const SceneDescription d = load_scene_text(text, "reflectance.xml", ".");
    ASSERT_TRUE(d.materials[0].spectra && d.materials[0].spectra->diffuse);
    EXPECT_FALSE(d.materials[0].spectra->specular);
    const auto rho = [](double l) {
        const double knots[5][2] = {{400, 0.9}, {480, 0.05}, {560, 0.9}, {640, 0.05}, {720, 0.9}};
        if (l < 400 || l > 720) return 0.0;
        for (int k = 0; k < 4; ++k)
            if (l <= knots[k + 1][0])
                return knots[k][1] + (knots[k + 1][1] - knots[k][1]) * (l - knots[k][0]) / (knots[k + 1][0] - knots[k][0]);
        return 0.9;
    };
    const auto sky = [](double l) { return 0.2 * planck(l, 2000); };
    const Vec3d want = film_colour([&](double l) { return rho(l) * sky(l); });
    const Rgb rho_rgb = std::get<PhongMaterial>(d.materials[0].model).diffuse;
    const RgbAlbedoSpectrum upsampled(RgbToSpectrumTable::srgb(), rho_rgb);
    const Vec3d rgb_way = film_colour([&](double l) { return double(upsampled(float(l))) * sky(l); });
    const ImageMean m = image_mean(render_mode(d, true, 16, 64, 41, 1, "direct-mis"));
    // z = 4 per channel (3 two-sided tests: false alarms below 2e-4); the black body's 1 nm
    // tabulation and the quadrature: below 1e-4 relative.
    for (int c = 0; c < 3; ++c)
        EXPECT_LE(std::abs(m.mean[c] - want[c]), 4 * m.se[c] + 1e-4 * std::abs(want[c]))
            << "channel " << c << ": " << m.mean[c] << " +- " << m.se[c] << ", the spectrum gives " << want[c]
            << ", its RGB upsampled would give " << rgb_way[c];
}

// Which parameters keep their spectra: diffuse's reflectance, plastic's two, a conductor's
// specular_reflectance; RGB values keep none.
TEST(SpectralMaterials, MaterialsKeepTheirReflectanceSpectra) {
    const std::string text = R"(<scene version="3.0.0">
  <bsdf type="plastic" id="a"><spectrum name="diffuse_reflectance" value="400:0.2, 700:0.8"/>
    <spectrum name="specular_reflectance" value="400:1, 700:0.5"/></bsdf>
  <bsdf type="conductor" id="b"><spectrum name="specular_reflectance" value="400:0.5, 700:1"/></bsdf>
  <bsdf type="roughplastic" id="c"><rgb name="diffuse_reflectance" value="0.2, 0.3, 0.4"/></bsdf>
  <shape type="sphere"><ref id="a"/></shape>
</scene>)";
    const SceneDescription d = load_scene_text(text, "kept.xml", ".");
    ASSERT_EQ(d.materials.size(), 3u);
    ASSERT_TRUE(d.materials[0].spectra && d.materials[0].spectra->diffuse && d.materials[0].spectra->specular);
    EXPECT_NEAR((*d.materials[0].spectra->diffuse)(550), 0.5f, 1e-6f);
    EXPECT_NEAR((*d.materials[0].spectra->specular)(550), 0.75f, 1e-6f);
    ASSERT_TRUE(d.materials[1].spectra && d.materials[1].spectra->specular);
    EXPECT_FALSE(d.materials[1].spectra->diffuse);
    EXPECT_FALSE(d.materials[2].spectra);
}

// ---- plastic renders as in RGB mode where colour cannot differ ---------------------------------

// Grey plastics (smooth and rough, linear and not) under white light, full global illumination:
// every path's value is a product of grey factors and the light's white, whose spectral colour
// differs from RGB's by at most 9e-5 (D65's white through the film), so the two modes' images
// agree within noise plus that. z = 4 per channel over 4 scenes (12 two-sided tests: a
// false-alarm rate below 1e-3).
TEST(SpectralMaterials, GreyPlasticsAgreeWithRgbMode) {
    const std::string text = R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="20"/>
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><point name="center" x="2" y="2" z="1"/><float name="radius" value="0.5"/>
    <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>
  <shape type="sphere"><bsdf type="$type"><rgb name="diffuse_reflectance" value="0.6"/><float name="alpha" value="0.2"/>
    <boolean name="nonlinear" value="$nonlinear"/></bsdf></shape>
</scene>)";
    for (const char* type : {"plastic", "roughplastic"})
        for (const char* nonlinear : {"false", "true"}) {
            std::string t = text;
            if (std::string(type) == "plastic") t.replace(t.find(R"(<float name="alpha" value="0.2"/>)"), 33, "");
            const SceneDescription d = load_scene_text(t, "p.xml", ".", {{"type", type}, {"nonlinear", nonlinear}});
            const ImageMean rgb = image_mean(render_mode(d, false, 16, 64, 31, 4));
            const ImageMean spectral = image_mean(render_mode(d, true, 16, 64, 32, 4));
            for (int c = 0; c < 3; ++c)
                EXPECT_LE(std::abs(spectral.mean[c] - rgb.mean[c]), 4 * std::hypot(spectral.se[c], rgb.se[c]) + 1e-4 * rgb.mean[c])
                    << type << " nonlinear " << nonlinear << " channel " << c << ": spectral " << spectral.mean[c] << " rgb " << rgb.mean[c];
        }
}

}  // namespace
}  // namespace pathlab::test
