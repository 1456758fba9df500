// principled and principledthin (bsdfs/principled.hpp, principledthin.hpp: Mitsuba 3's Disney
// BSDFs): their lobes against closed forms
// and against the BSDFs they reduce to (a white metal is the rough conductor of Fresnel 1, full
// specular transmission is the rough dielectric), reciprocity, the scene-file reader, and
// estimators agreeing on it (importance transport through its transmission included). Its
// sampling is chi-square tested with the other rough BSDFs (test_microfacet.cpp), its spectral
// values in test_spectral_materials.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "bsdfs/material.hpp"
#include "core/sampling.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scene_helpers.hpp"
#include "samplers/sampler.hpp"
#include "job/render_job.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

Material principled(const PrincipledMaterial& p) { return Material{p, false}; }

PrincipledMaterial everything() {
    PrincipledMaterial p;
    p.base_color = Rgb(0.7f, 0.4f, 0.2f);
    p.roughness = 0.4f, p.anisotropic = 0.5f, p.metallic = 0.3f, p.spec_tint = 0.4f, p.sheen = 0.6f, p.sheen_tint = 0.5f;
    p.clearcoat = 0.7f, p.clearcoat_gloss = 0.6f, p.flatness = 0.3f, p.eta = 1.45f;
    return p;
}

// The albedo of the reflection lobes for wi, by stratified cosine-weighted quadrature.
double albedo(const Material& m, const Vec3f& wi, int n = 512) {
    double sum = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const Vec3f wo = square_to_cosine_hemisphere(Vec2f(float((i + 0.5) / n), float((j + 0.5) / n)));
            sum += m.eval(wi, wo).x * kPi;  // f cos / (cos / pi)
        }
    return sum / (double(n) * n);
}

// At normal incidence with eta = 1 (specular 0: no specular reflection) the diffuse lobe's
// albedo is c (1 - 1/42 + 5 r / 84): (1 - Fo/2) loses 2 int (1 - mu)^5 mu dmu / 2 = 1/42, and
// the retro-reflection Rr Fo, Rr = 2 r cos_d^2 = r (1 + mu), adds 2 r int (1 + mu)(1 - mu)^5 mu dmu
// = 5 r / 84 (Burley's retro-reflection makes a rough surface reflect more than it receives).
// The error a scene file holding a sphere with this <bsdf> raises ("" when it loads).
std::string error_of(const std::string& bsdf) {
    try {
        load_scene_text("<scene version=\"3.0.0\"><shape type=\"sphere\">" + bsdf + "</shape></scene>", "bad.xml", ".");
    } catch (const SceneFileError& e) {
        return e.what();
    }
    return "";
}

TEST(Principled, DiffuseAlbedoAtNormalIncidenceIsTheClosedForm) {
    for (float r : {0.0f, 0.5f, 1.0f}) {
        PrincipledMaterial p;
        p.base_color = Rgb(0.8f);
        p.roughness = r;
        p.eta = 1;
        const double want = 0.8 * (1 - 1.0 / 42 + 5.0 * r / 84);
        EXPECT_NEAR(albedo(principled(p), Vec3f(0, 0, 1)), want, 2e-4) << "roughness " << r;
    }
}

// metallic = 1 with a white base: F_p = Schlick(1) = 1, i.e. the rough conductor whose Fresnel
// term is 1 (eta 0, k 1), with principled's GGX alphas.
TEST(Principled, WhiteMetalIsTheRoughConductorOfFresnelOne) {
    Sampler rng(7, 0, 0);
    for (const auto& [r, a] : {std::pair(0.3f, 0.0f), std::pair(0.6f, 0.7f)}) {
        PrincipledMaterial p;
        p.base_color = Rgb(1.0f);
        p.metallic = 1, p.roughness = r, p.anisotropic = a;
        const MicrofacetDistribution d = p.specular_distribution();
        const Material m = principled(p), twin = make_rough_conductor(d, {Rgb(0.0f), Rgb(1.0f)});
        long nonzero = 0;
        for (int i = 0; i < 5000; ++i) {
            const Vec3f wi = square_to_cosine_hemisphere(rng.next2d()), wo = square_to_cosine_hemisphere(rng.next2d());
            const float f = m.eval(wi, wo).x, g = twin.eval(wi, wo).x;
            ASSERT_NEAR(f, g, 1e-5f * std::max(1.0f, g)) << r << " " << a;
            nonzero += f > 0;
        }
        EXPECT_GT(nonzero, 4000);
    }
}

// spec_trans = 1 with a white base: the rough dielectric of index eta in vacuum, on both sides
// and for both lobes.
TEST(Principled, FullTransmissionIsTheRoughDielectric) {
    Sampler rng(8, 0, 0);
    PrincipledMaterial p;
    p.base_color = Rgb(1.0f);
    p.spec_trans = 1, p.transmits = true, p.roughness = 0.45f, p.eta = 1.5f;
    const Material m = principled(p), twin = make_rough_dielectric(p.specular_distribution(), 1.5f, 1.0f);
    long reflected = 0, transmitted = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f wi = square_to_uniform_sphere(rng.next2d()), wo = square_to_uniform_sphere(rng.next2d());
        const float f = m.eval(wi, wo).x, g = twin.eval(wi, wo).x;
        ASSERT_NEAR(f, g, 2e-4f * std::max(1.0f, g)) << wi.z << " " << wo.z;
        (wi.z * wo.z > 0 ? reflected : transmitted) += f > 0;
    }
    EXPECT_GT(reflected, 1000);
    EXPECT_GT(transmitted, 1000);
}

// Reflection is reciprocal; transmission obeys f(wi, wo) / eta_i^2 = f(wo, wi) / eta_o^2.
TEST(Principled, IsReciprocal) {
    Sampler rng(9, 0, 0);
    PrincipledMaterial glassy = everything();
    glassy.spec_trans = 0.6f, glassy.transmits = true;
    for (const PrincipledMaterial& p : {everything(), glassy}) {
        const Material m = principled(p);
        long nonzero = 0;
        for (int i = 0; i < 20000; ++i) {
            const Vec3f a = square_to_uniform_sphere(rng.next2d()), b = square_to_uniform_sphere(rng.next2d());
            const float ea = a.z > 0 ? 1.0f : p.eta, eb = b.z > 0 ? 1.0f : p.eta;
            const Rgb fab = m.eval(a, b) / (ea * ea), fba = m.eval(b, a) / (eb * eb);
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(fab[c], fba[c], 1e-4f * std::max(fab[c], fba[c]) + 1e-30f) << a.z << " " << b.z;
            nonzero += fab.x > 0;
        }
        EXPECT_GT(nonzero, 4000);
    }
}

// Without transmission the material is black from behind (Mitsuba's front-side lobes); with it,
// light from behind is reflected and refracted.
TEST(Principled, IsBlackFromBehindUnlessItTransmits) {
    const Material opaque = principled(everything());
    const Vec3f below = normalize(Vec3f(0.3f, 0.1f, -0.8f)), above = normalize(Vec3f(-0.2f, 0.3f, 0.9f));
    EXPECT_EQ(opaque.eval(below, reflect(below, Vec3f(0, 0, 1))), Rgb(0.0f));
    EXPECT_EQ(opaque.eval(below, above), Rgb(0.0f));
    EXPECT_FALSE(opaque.sample(below, Vec2f(0.3f, 0.6f)).has_value());
    EXPECT_FALSE(opaque.is_dielectric());
    PrincipledMaterial p = everything();
    p.spec_trans = 0.5f, p.transmits = true;
    const Material glass = principled(p);
    EXPECT_TRUE(glass.is_dielectric());
    EXPECT_GT(glass.eval(below, above).x, 0.0f);
    EXPECT_NE(glass.lobes() & kLobeTransmission, 0u);
}

// Without the diffuse lobe's retro-reflection and the sheen, the lobes together reflect and
// transmit at most what they receive: a white metal with a clearcoat, and white glass from
// outside (its transmitted energy counted as importance, without radiance's 1 / eta^2).
TEST(Principled, SpecularLobesDoNotCreateEnergy) {
    Sampler rng(10, 0, 0);
    PrincipledMaterial metal;
    metal.base_color = Rgb(1.0f), metal.metallic = 1, metal.roughness = 0.5f, metal.clearcoat = 1;
    PrincipledMaterial glass;
    glass.base_color = Rgb(1.0f), glass.spec_trans = 1, glass.transmits = true, glass.roughness = 0.5f;
    for (const PrincipledMaterial& p : {metal, glass})
        for (float theta : {0.0f, 45.0f, 80.0f}) {
            const Material m = principled(p);
            const Vec3f wi(std::sin(theta * kPi / 180), 0, std::cos(theta * kPi / 180));
            double sum = 0, sum2 = 0;
            const int n = 200000;
            for (int i = 0; i < n; ++i) {
                const auto s = m.sample(wi, rng.next2d());
                if (!s) continue;
                const double w = s->f.x * std::abs(s->wo.z) / s->pdfW * (s->wo.z < 0 ? p.eta * p.eta : 1.0f);
                sum += w, sum2 += w * w;
            }
            const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
            EXPECT_LT(mean, 1 + 4 * se) << "theta " << theta << (p.transmits ? " glass" : " metal");
            EXPECT_GT(mean, 0.7) << "theta " << theta << (p.transmits ? " glass" : " metal");
        }
}

TEST(Principled, SceneFilesReadItAsMitsubaDoes) {
    const SceneDescription d = load_scene_text(R"(<scene version="3.0.0">
  <shape type="sphere"><bsdf type="principled">
    <rgb name="base_color" value="0.2, 0.8, 0.1"/>
    <float name="roughness" value="0.15"/>
    <texture name="metallic" type="checkerboard"><float name="color0" value="0.7"/><float name="color1" value="0.1"/></texture>
    <texture name="spec_trans" type="checkerboard"><float name="color0" value="0.7"/><float name="color1" value="0.1"/></texture>
    <float name="specular" value="0.7"/>
  </bsdf></shape>
  <shape type="sphere"><bsdf type="principled"><float name="eta" value="1.33"/><float name="anisotropic" value="0.5"/></bsdf></shape>
  <shape type="sphere"><bsdf type="principled"/></shape>
</scene>)", "p.xml", ".");
    const Material& textured = d.materials[d.spheres[0].material];
    const auto& p = std::get<PrincipledMaterial>(textured.model);
    EXPECT_TRUE(p.transmits);  // a texture's largest value
    EXPECT_TRUE(textured.varies);
    EXPECT_TRUE(textured.is_dielectric());
    EXPECT_NEAR(p.eta, 2 / (1 - std::sqrt(0.08f * 0.7f)) - 1, 1e-6f);
    Material aniso = d.materials[d.spheres[1].material];
    EXPECT_FLOAT_EQ(std::get<PrincipledMaterial>(aniso.model).eta, 1.33f);
    aniso.prepare();  // (as Scene::build does)
    EXPECT_TRUE(aniso.tangent_frame);
    const auto& plain = std::get<PrincipledMaterial>(d.materials[d.spheres[2].material].model);
    EXPECT_FLOAT_EQ(plain.eta, 1.5f);  // specular 0.5
    EXPECT_FALSE(plain.transmits);
    EXPECT_FLOAT_EQ(plain.roughness, 0.5f);

    EXPECT_NE(error_of(R"(<bsdf type="principled"><float name="eta" value="1.3"/><float name="specular" value="0.3"/></bsdf>)")
                  .find("either eta or specular"),
              std::string::npos);
    EXPECT_NE(error_of(R"(<bsdf type="principled"><float name="metallic" value="1.5"/></bsdf>)").find("between 0 and 1"), std::string::npos);
    EXPECT_NE(error_of(R"(<bsdf type="principled"><float name="clearcoat_sampling_rate" value="0"/></bsdf>)").find("must be positive"),
              std::string::npos);
    EXPECT_NE(error_of(R"(<bsdf type="twosided"><bsdf type="principled"><float name="spec_trans" value="0.5"/></bsdf></bsdf>)")
                  .find("cannot be wrapped in twosided"),
              std::string::npos);
    EXPECT_EQ(error_of(R"(<bsdf type="twosided"><bsdf type="principled"><float name="metallic" value="0.5"/></bsdf></bsdf>)"), "");
}

// Estimators see the same principled surfaces: light sampling and BSDF sampling at the first
// hit, and bdpt against pt-mis, on an opaque sphere with every lobe, a glass-like one and a
// metal, under a glass-like sheet that covers part of the light (a single interface: bdpt's
// light subpaths cross it with importance's (eta_o / eta_i)^2, which a closed glass shape
// would cancel). Per-pixel z-tests at a 1e-3 false-alarm rate.
TEST(Principled, EstimatorsAgree) {
    PrincipledMaterial glass = everything();
    glass.spec_trans = 0.8f, glass.transmits = true, glass.clearcoat = 0, glass.anisotropic = 0;
    PrincipledMaterial metal = everything();
    metal.metallic = 0.9f, metal.roughness = 0.3f;
    SceneDescription d = material_scene({principled(everything()), principled(glass), principled(metal)});
    d.meshes.push_back(quad({0.5f, 0.5f, 2.2f}, {0.8f, 0, 0}, {0, 0.8f, 0}, 3));
    for (Material& m : d.materials) m.prepare();
    expect_estimators_agree(d, "direct-mis", {"direct-light", "direct-brdf"}, 12, 4096);
    expect_estimators_agree(d, "pt-mis", {"bdpt"}, 12, 4096);
}

// ---- principledthin (bsdfs/principledthin.hpp) -------------------------------------------------

Material thin(const PrincipledThinMaterial& p) { return Material{p, true}; }

PrincipledThinMaterial thin_everything() {
    PrincipledThinMaterial p;
    p.base_color = Rgb(0.7f, 0.4f, 0.2f);
    p.roughness = 0.4f, p.anisotropic = 0.5f, p.spec_trans = 0.6f, p.spec_tint = 0.4f, p.sheen = 0.6f, p.sheen_tint = 0.5f;
    p.flatness = 0.3f, p.diff_trans = 0.8f, p.eta = 1.4f;
    return p;
}

// Without the specular lobes, diff_trans splits the diffuse lobe: 0.5 diff_trans of it is
// Lambertian transmission c / pi, the rest Burley's diffuse reflection, whose albedo at normal
// incidence is c (1 - 1/42 + 5 r / 84) (see DiffuseAlbedoAtNormalIncidenceIsTheClosedForm).
TEST(PrincipledThin, DiffuseTransmissionIsLambertian) {
    PrincipledThinMaterial p;
    p.base_color = Rgb(0.8f, 0.5f, 0.2f), p.roughness = 0.6f, p.diff_trans = 0.5f;
    const Material m = thin(p);
    const Vec3f wi(0, 0, 1);
    for (const Vec3f& wo : {Vec3f(0, 0, -1), normalize(Vec3f(0.3f, -0.5f, -0.4f)), normalize(Vec3f(-0.9f, 0.1f, -0.05f))})
        EXPECT_NEAR(m.eval(wi, wo).x, 0.25f * 0.8f / kPi, 1e-6f);
    const double expected = 0.75 * (1 - 1.0 / 42 + 5 * 0.6 / 84);
    EXPECT_NEAR(albedo(m, wi) / 0.8, expected, 2e-3);
    p.diff_trans = 2;  // all transmitted
    EXPECT_EQ(thin(p).eval(wi, normalize(Vec3f(0.2f, 0.1f, 0.9f))).x, 0.0f);
    EXPECT_NEAR(thin(p).eval(wi, normalize(Vec3f(0.2f, 0.1f, -0.9f))).x, 0.8f / kPi, 1e-6f);
}

// A sheet has no front: mirroring both directions through it changes nothing.
TEST(PrincipledThin, IsTheSameFromBothSides) {
    const Material m = thin(thin_everything());
    Sampler rng(4, 0, 0);
    int nonzero = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3f wi = square_to_uniform_sphere(rng.next2d()), wo = square_to_uniform_sphere(rng.next2d());
        const Vec3f wi_m(wi.x, wi.y, -wi.z), wo_m(wo.x, wo.y, -wo.z);
        const Rgb f = m.eval(wi, wo), f_m = m.eval(wi_m, wo_m);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(f[c], f_m[c]) << i;
        EXPECT_EQ(m.pdf(wi, wo), m.pdf(wi_m, wo_m)) << i;
        nonzero += f.x > 0;
    }
    EXPECT_GT(nonzero, 1000);
}

// With 0.65 eta - 0.35 = 1 the transmission's microfacets are the reflection's: a white sheet
// then transmits, through the mirror direction of the reflection, (1 - F) where it reflects F.
TEST(PrincipledThin, SpecularTransmissionIsTheReflectionThroughTheSheet) {
    PrincipledThinMaterial p;
    p.base_color = Rgb(1.0f), p.spec_trans = 1, p.roughness = 0.45f, p.eta = 1.35f / 0.65f;
    const Material m = thin(p);
    Sampler rng(5, 0, 0);
    for (int i = 0; i < 200; ++i) {
        const Vec3f wi = square_to_cosine_hemisphere(rng.next2d()), wo = square_to_cosine_hemisphere(rng.next2d());
        const Vec3f h = normalize(wi + wo);
        const float F = fresnel_dielectric(dot(wi, h), p.eta);
        const float reflected = m.eval(wi, wo).x, transmitted = m.eval(wi, Vec3f(wo.x, wo.y, -wo.z)).x;
        if (transmitted == 0) continue;  // (the microfacet on the wrong side of the transmitted direction)
        EXPECT_NEAR(transmitted / (1 - F), reflected / F, 1e-4f * reflected / F) << i;
    }
}

// A white sheet of the specular lobes reflects and transmits at most what it receives (both
// lobes are a microfacet mirror, split by F and 1 - F).
TEST(PrincipledThin, SpecularLobesDoNotCreateEnergy) {
    Sampler rng(11, 0, 0);
    PrincipledThinMaterial p;
    p.base_color = Rgb(1.0f), p.spec_trans = 1, p.roughness = 0.5f, p.eta = 1.35f / 0.65f;
    const Material m = thin(p);
    for (float theta : {0.0f, 45.0f, 80.0f}) {
        const Vec3f wi(std::sin(theta * kPi / 180), 0, std::cos(theta * kPi / 180));
        double sum = 0, sum2 = 0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) {
            const auto s = m.sample(wi, rng.next2d());
            if (!s) continue;
            const double w = s->f.x * std::abs(s->wo.z) / s->pdfW;
            sum += w, sum2 += w * w;
        }
        const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
        EXPECT_LT(mean, 1 + 4 * se) << "theta " << theta;
        EXPECT_GT(mean, 0.7) << "theta " << theta;
    }
}

TEST(PrincipledThin, SceneFilesReadItAsMitsubaDoes) {
    SceneDescription d = load_scene_text(R"(<scene version="3.0.0">
  <shape type="rectangle"><bsdf type="principledthin">
    <rgb name="base_color" value="0.7, 0.1, 0.1"/>
    <texture name="diff_trans" type="checkerboard"><float name="color0" value="0.4"/><float name="color1" value="1.4"/></texture>
    <float name="spec_trans" value="0.5"/>
    <float name="eta" value="1.33"/>
    <float name="anisotropic" value="0.3"/>
  </bsdf></shape>
  <shape type="rectangle"><bsdf type="principledthin"/></shape>
</scene>)", "thin.xml", ".");
    Material& textured = d.materials[d.meshes[0].material];
    const auto& p = std::get<PrincipledThinMaterial>(textured.model);
    EXPECT_FLOAT_EQ(p.eta, 1.33f);
    EXPECT_FLOAT_EQ(p.spec_trans, 0.5f);
    EXPECT_TRUE(textured.varies);
    EXPECT_TRUE(textured.two_sided);
    EXPECT_FALSE(textured.is_dielectric());  // a sheet: no inside, no medium boundary
    textured.prepare();
    EXPECT_TRUE(textured.tangent_frame);
    const auto& plain = std::get<PrincipledThinMaterial>(d.materials[d.meshes[1].material].model);
    EXPECT_FLOAT_EQ(plain.eta, 1.5f);
    EXPECT_FLOAT_EQ(plain.roughness, 0.5f);
    EXPECT_FLOAT_EQ(plain.diff_trans, 0.0f);
    EXPECT_NE(error_of(R"(<bsdf type="principledthin"><float name="diff_trans" value="2.5"/></bsdf>)").find("between 0 and 2"), std::string::npos);
    EXPECT_NE(error_of(R"(<bsdf type="principledthin"><float name="metallic" value="0.5"/></bsdf>)").find("metallic"), std::string::npos);
    EXPECT_NE(error_of(R"(<bsdf type="principledthin"><float name="diffuse_transmittance_sampling_rate" value="0"/></bsdf>)")
                  .find("must be positive"),
              std::string::npos);
}

// Estimators see the same thin sheets: light sampling and BSDF sampling at the first hit, and
// bdpt against pt-mis, on spheres of principledthin (light through both of their walls) and under
// a sheet that covers part of the light. Per-pixel z-tests at a 1e-3 false-alarm rate.
TEST(PrincipledThin, EstimatorsAgree) {
    PrincipledThinMaterial leaf = thin_everything();
    PrincipledThinMaterial paper = thin_everything();
    paper.spec_trans = 0, paper.diff_trans = 1.2f, paper.anisotropic = 0;
    PrincipledThinMaterial pane = thin_everything();
    pane.spec_trans = 0.9f, pane.roughness = 0.2f, pane.diff_trans = 0.1f;
    SceneDescription d = material_scene({thin(leaf), thin(paper), thin(pane)});
    d.meshes.push_back(quad({0.5f, 0.5f, 2.2f}, {0.8f, 0, 0}, {0, 0.8f, 0}, 4));  // the pane
    for (Material& m : d.materials) m.prepare();
    expect_estimators_agree(d, "direct-mis", {"direct-light", "direct-brdf"}, 12, 4096);
    expect_estimators_agree(d, "pt-mis", {"pt-naive", "volpath"}, 12, 4096);
    // Without specular transmission the sheet is reciprocal, and the light-path methods see it
    // too (light through the sheets' diffuse transmission, which next-event estimation once
    // skipped behind every surface but glass: pt-mis was darker than bdpt, lt and pt-naive, bias
    // z up to 26).
    for (Material& m : d.materials)
        if (auto* t = std::get_if<PrincipledThinMaterial>(&m.model)) t->spec_trans = 0;
    expect_estimators_agree(d, "pt-mis", {"bdpt", "lt"}, 12, 4096);
}

// Mitsuba's specular transmission is not reciprocal (it asks the transmitted direction, not the
// incident one, to lie behind the microfacet), so the methods that scatter light paths with the
// adjoint BSDF refuse it, naming it and the integrators that render it.
TEST(PrincipledThin, LightPathMethodsRefuseItsSpecularTransmission) {
    PrincipledThinMaterial pane = thin_everything();
    const Material m = thin(pane);
    // Grazing in, near the normal out: the reverse path's transmitted direction is in front of
    // the microfacet, so f(wo, wi) has no specular part.
    const Vec3f grazing = normalize(Vec3f(0.995f, 0, 0.1f)), steep = normalize(Vec3f(0.1f, 0, -0.995f));
    EXPECT_GT(m.eval(grazing, steep).x, 1.2f * m.eval(steep, grazing).x);  // (0.045 and 0.036: the same diffuse part)
    SceneDescription d = material_scene({m});
    d.material_ids.assign(d.materials.size(), "");
    d.material_ids[2] = "pane";
    for (const char* name : {"lt", "bdpt", "pm", "sppm", "vcm"}) {
        const std::string why = integrator_refusal(*find_integrator(name), d, JobRequest{});
        EXPECT_NE(why.find("principledthin 'pane' has specular transmission"), std::string::npos) << name << ": " << why;
    }
    for (const char* name : {"pt-mis", "volpath", "ic"}) EXPECT_EQ(integrator_refusal(*find_integrator(name), d, JobRequest{}), "") << name;
    std::get<PrincipledThinMaterial>(d.materials[2].model).spec_trans = 0;
    EXPECT_EQ(integrator_refusal(*find_integrator("bdpt"), d, JobRequest{}), "");
}

}  // namespace
}  // namespace pathlab::test
