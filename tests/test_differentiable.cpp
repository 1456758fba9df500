// Differentiable rendering (src/diff/, docs/differentiable.md): parameters by name, path replay
// gradients against central finite differences with common random numbers, forward against
// reverse mode, the worked example's recovery, and the command line.
//
// The finite-difference test, per parameter direction t (all components of one parameter):
// the loss is linear, Loss = sum_p w(p) . I(p) with fixed weights w, so that each pass k (one
// sample per pixel, sample index k) gives an independent pair
//   X_k  = t . dLoss/dtheta from the path replay,
//   FD_k = (Loss_k(theta + h t) - Loss_k(theta - h t)) / 2h from two primal renders of pass k
// (the same random numbers: common random numbers). Both are unbiased for t . dE[Loss]/dtheta
// (FD up to its O(h^2) truncation, estimated by Richardson's comparison with step 2h). Their
// paired differences d_k = X_k - FD_k have mean zero; the test is a z-test of that mean
// against its standard error (plus the truncation estimate), |z| < 3.89: a false alarm rate of
// 1e-4 per parameter. It must also fail with each fault switch of DiffFaults.
#include <gtest/gtest.h>

#include <map>
#include <optional>
#include <tbb/task_arena.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_runner.hpp"
#include "diff/bsdf_derivatives.hpp"
#include "diff/loss.hpp"
#include "diff/optimizer.hpp"
#include "diff/parameters.hpp"
#include "diff/path_replay.hpp"
#include "diff/scene_file_update.hpp"
#include "image/image_io.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab {
namespace {

constexpr double kZ = 3.89;  // two-sided, false alarm rate 1e-4

// Fixed loss weights: a smooth ramp, so that every pixel counts and none the same.
Image loss_weights(int w, int h) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) img.at(x, y) = Rgb(1.0f + float(x) / float(w), 1.5f, 1.0f + float(y) / float(h)) / float(w * h);
    return img;
}

double weighted_sum(const Image& img, const Image& w) {
    double s = 0;
    for (size_t i = 0; i < img.pixel_count(); ++i) s += double(dot(img[i], w[i]));
    return s;
}

struct FdResult {
    double reverse = 0, fd = 0;  // means
    double z = 0;                // of the paired difference
    double se_reverse = 0;       // standard error of the reverse estimate
};

// The z-test above for parameter `name` of scene description d.
FdResult check_direction_against_fd(const SceneDescription& d, const std::vector<std::string>& names, DiffSettings s, int passes, double h_rel,
                          const DiffFaults& faults = {}, const Image* weights = nullptr, const std::vector<float>* direction = nullptr) {
    const ParameterSet set = ParameterSet::choose(d, names);
    const std::vector<float> theta = set.values(d);
    double scale = 0;
    for (float v : theta) scale = std::max(scale, double(std::abs(v)));
    const double h = h_rel;
    // The direction: all the parameters scaled together (theta / max |theta|), which keeps the
    // ratios that choose BSDF lobes (Phong's, plastic's) when two reflectances move together;
    // or the one given (texels).
    std::vector<float> t(theta.size());
    for (size_t i = 0; i < t.size(); ++i) t[i] = direction ? (*direction)[i] : float(theta[i] / scale);
    const Image w = weights ? *weights : loss_weights(s.width, s.height);
    const auto scene_at = [&](double step) {
        SceneDescription e = d;
        std::vector<float> th = theta;
        for (size_t i = 0; i < th.size(); ++i) th[i] = float(th[i] + step * t[i]);
        set.set_values(e, th);
        return Scene::build(e);
    };
    const auto base = scene_at(0), plus = scene_at(h), minus = scene_at(-h), plus2 = scene_at(2 * h), minus2 = scene_at(-2 * h);
    double sum_d = 0, sum_d2 = 0, sum_x = 0, sum_x2 = 0, sum_fd = 0, sum_fd2h = 0, sum_abs_loss = 0;
    s.spp = 1;
    for (int k = 0; k < passes; ++k) {
        s.first_pass = uint64_t(k);
        DiffSettings sf = s;
        sf.faults = faults;
        const std::vector<double> g = gradient(*base, set, sf, w);
        double x = 0;
        for (size_t i = 0; i < g.size(); ++i) x += g[i] * t[i];
        const double lp = weighted_sum(render_primal(*plus, s), w), lm = weighted_sum(render_primal(*minus, s), w);
        const double fd = (lp - lm) / (2 * h);
        sum_abs_loss += std::abs(lp) + std::abs(lm);
        const double fd2 = (weighted_sum(render_primal(*plus2, s), w) - weighted_sum(render_primal(*minus2, s), w)) / (4 * h);
        const double dk = x - fd;
        sum_d += dk, sum_d2 += dk * dk, sum_x += x, sum_x2 += x * x, sum_fd += fd, sum_fd2h += fd2;
    }
    const double n = passes;
    FdResult r;
    r.reverse = sum_x / n;
    r.fd = sum_fd / n;
    const double var_d = (sum_d2 - sum_d * sum_d / n) / (n - 1);
    const double truncation = std::abs(sum_fd2h / n - r.fd) / 3;  // Richardson: FD(2h) - FD(h) = 3 x its O(h^2) error
    // The float rounding of the renders' difference (8 ulps of the loss, over 2h): where both
    // estimates are exact per sample (a linear parameter) it is all that separates them.
    const double rounding = 1e-6 * sum_abs_loss / n / (2 * h);
    r.z = (sum_d / n) / std::sqrt(var_d / n + truncation * truncation + rounding * rounding + 1e-300);
    r.se_reverse = std::sqrt((sum_x2 - sum_x * sum_x / n) / (n - 1) / n);
    return r;
}

FdResult check_against_fd(const SceneDescription& d, const std::string& name, DiffSettings s, int passes, double h_rel,
                          const DiffFaults& faults = {}, const Image* weights = nullptr) {
    return check_direction_against_fd(d, std::vector<std::string>{name}, s, passes, h_rel, faults, weights);
}

DiffSettings tiny_settings() {
    DiffSettings s;
    s.width = s.height = 12;
    s.seed = 77;
    s.max_depth = 3;
    s.rr_depth = -1;  // Russian roulette decisions would differ between theta +- h
    return s;
}

// The course's scene 2 (ceiling light, diffuse) or 3 (glossy).
SceneDescription course(int index) { return make_builtin_scene(index); }

// scenes/fog-box.xml: the course's scene 4 in a homogeneous fog (medium 'fog', HG g 0.3).
SceneDescription fog_box() { return load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/fog-box.xml"); }

// Scene 1 (point light, glossy) with a broad floor lobe (n = 8): a strong exponent derivative.
SceneDescription broad_gloss() {
    SceneDescription d = make_builtin_scene(1);
    std::get<PhongMaterial>(d.materials[2].model).exponent = 8;
    return d;
}

// Weights that see parameter `name` best: the sign of dI/dtheta from an independent forward
// render (16 spp, another seed). The normalised Phong lobe keeps its energy as n changes, so a
// uniform weighting barely sees the exponent; these weights see the highlights sharpen.
Image signed_weights(const SceneDescription& d, const std::string& name, const DiffSettings& s) {
    DiffSettings r = s;
    r.spp = 16;
    r.seed = 4242;
    const ParameterSet set = ParameterSet::choose(d, {name});
    Image w = forward_gradient(*Scene::build(d), set, r, parameter_tangent(set, 0));
    for (size_t i = 0; i < w.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) w[i][c] = float((w[i][c] > 0) - (w[i][c] < 0)) / float(w.pixel_count());
    return w;
}

// Scene 2 with the right sphere rough metal, the left one plastic and the left wall roughplastic.
SceneDescription metals() {
    SceneDescription d = make_builtin_scene(2);
    d.materials[7] = make_rough_conductor(MicrofacetDistribution(MicrofacetType::GGX, 0.25f, 0.25f), {Rgb(0.2f), Rgb(3.0f)}, Rgb(0.9f));
    d.materials[6] = make_plastic(Rgb(0.6f, 0.5f, 0.2f), Rgb(0.8f));
    d.materials[3] = make_rough_plastic(MicrofacetDistribution(MicrofacetType::Beckmann, 0.3f, 0.3f), Rgb(0.2f, 0.7f, 0.2f), Rgb(0.5f));
    return d;
}

void expect_agreement(const FdResult& r, const std::string& what) {
    EXPECT_LT(std::abs(r.z), kZ) << what << ": reverse " << r.reverse << " fd " << r.fd;
    // Not a vacuous pass: the gradient itself is clearly non-zero.
    EXPECT_GT(std::abs(r.reverse), 5 * r.se_reverse) << what;
}

}  // namespace

TEST(DiffParameters, CourseScenesNameTheirMaterialsAndLights) {
    const std::vector<SceneParameter> p2 = scene_parameters(course(2));
    std::vector<std::string> names;
    for (const auto& p : p2) names.push_back(p.name);
    EXPECT_EQ(names, (std::vector<std::string>{"floor.reflectance.value", "green.reflectance.value", "red.reflectance.value",
                                               "back.reflectance.value", "yellow.reflectance.value", "blue.reflectance.value",
                                               "light.emitter.radiance.value"}));
    const std::vector<SceneParameter> p3 = scene_parameters(course(3));
    EXPECT_EQ(p3[0].name, "floor.diffuse_reflectance.value");
    EXPECT_EQ(p3[2].name, "floor.exponent");
    EXPECT_EQ(scene_parameters(course(0)).back().name, "light.intensity.value");
    EXPECT_EQ(scene_parameters(course(6)).back().name, "light.radiance.value");
    // The scene files name them alike.
    for (int i : {0, 2, 4, 6}) {
        const std::vector<SceneParameter> a = scene_parameters(course(i));
        std::string file;
        for (const auto& e : std::filesystem::directory_iterator(std::string(PATHLAB_SOURCE_DIR) + "/scenes"))
            if (e.path().filename().string().rfind(std::to_string(i) + "-", 0) == 0) file = e.path().string();
        const std::vector<SceneParameter> b = scene_parameters(load_scene_file(file));
        ASSERT_EQ(a.size(), b.size()) << file;
        for (size_t k = 0; k < a.size(); ++k) {
            EXPECT_EQ(a[k].name, b[k].name) << file;
            EXPECT_EQ(parameter_value(course(i), a[k]), parameter_value(load_scene_file(file), b[k])) << file;
        }
    }
}

// A homogeneous medium's sigma_t and albedo (Mitsuba's names), set and read back (sigma_s
// follows, the albedo kept when sigma_t moves), clamped to their ranges, and written back to the
// scene file as sigma_t and albedo whatever form it gave (here sigma_a, sigma_s and a scale).
TEST(DiffParameters, MediaAreParameters) {
    namespace fs = std::filesystem;
    SceneDescription fog = fog_box();
    const ParameterSet set = ParameterSet::choose(fog, {"fog.sigma_t.value", "fog.albedo.value"});
    EXPECT_EQ(set.params[0].kind(), "medium");
    const std::vector<float> v = set.values(fog);
    const std::vector<float> want = {0.3f, 0.35f, 0.4f, 0.8f, 0.85f, 0.9f};
    for (size_t k = 0; k < want.size(); ++k) EXPECT_NEAR(v[k], want[k], 1e-6f) << k;
    std::vector<float> theta = {0.5f, -1.0f, 0.2f, 0.5f, 1.5f, 0.25f};
    set.clamp(theta);
    EXPECT_EQ(theta, (std::vector<float>{0.5f, 1e-6f, 0.2f, 0.5f, 1.0f, 0.25f}));
    set.set_values(fog, theta);
    const auto& h = std::get<HomogeneousMedium>(fog.media[0]);
    EXPECT_EQ(h.sigma_s, Rgb(0.25f, 1e-6f, 0.05f));
    const ParameterSet sigma = ParameterSet::choose(fog, {"fog.sigma_t.value"});
    sigma.set_values(fog, {1.0f, 2.0f, 4.0f});  // the albedo stays
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::get<HomogeneousMedium>(fog.media[0]).sigma_s[k], (Rgb(0.5f, 2.0f, 1.0f))[k], 1e-6f) << k;

    const fs::path dir = fs::temp_directory_path() / ("pathlab-medium-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string file = (dir / "milk.xml").string();
    std::ofstream(file) << R"(<scene version="3.0.0">
<medium type="homogeneous" id="milk"><rgb name="sigma_a" value="0.1"/><rgb name="sigma_s" value="0.3, 0.2, 0.1"/><float name="scale" value="2"/>
    <phase type="hg"><float name="g" value="0.5"/></phase></medium>
<shape type="sphere"><bsdf type="null"/><ref name="interior" id="milk"/></shape>
<shape type="sphere" id="lamp"><point name="center" value="0, 0, 4"/><emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>
</scene>)";
    SceneDescription milk = load_scene_file(file);
    const ParameterSet both = ParameterSet::choose(milk, {"milk.albedo.value", "milk.phase_function.g"});
    EXPECT_NEAR(both.values(milk)[0], 0.75f, 1e-6f);
    EXPECT_EQ(both.values(milk)[3], 0.5f);
    const std::vector<float> albedo = {0.5f, 0.6f, 0.7f, -0.25f};
    both.set_values(milk, albedo);
    std::ofstream(dir / "written.xml") << scene_file_with_values(file, both, albedo, {}, &milk);
    const SceneDescription written = load_scene_file((dir / "written.xml").string());
    const auto& a = std::get<HomogeneousMedium>(milk.media[0]);
    const auto& b = std::get<HomogeneousMedium>(written.media[0]);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(a.sigma_t[k], b.sigma_t[k], 1e-6f) << k;
        EXPECT_NEAR(a.sigma_s[k], b.sigma_s[k], 1e-6f) << k;
    }
    EXPECT_EQ(std::get<HgPhase>(b.phase).g, -0.25f);
    std::vector<float> g = {0.0f, 0.0f, 0.0f, 1.5f};
    both.clamp(g);
    EXPECT_EQ(g[3], 0.99f);
    fs::remove_all(dir);
}

TEST(DiffParameters, SetGetClampAndUnknownNames) {
    SceneDescription d = metals();
    const ParameterSet set = ParameterSet::choose(d, {"red.reflectance.value", "blue.alpha", "light.emitter.radiance.value"});
    EXPECT_EQ(set.size, 7);
    std::vector<float> theta = {1.5f, -0.2f, 0.5f, 0.0f, 2.0f, 0.0f, 3.0f};
    set.clamp(theta);
    EXPECT_EQ(theta, (std::vector<float>{1.0f, 0.0f, 0.5f, 1e-3f, 2.0f, 1e-6f, 3.0f}));
    set.set_values(d, theta);
    EXPECT_EQ(set.values(d), theta);
    // The light's triangles are bound to the radiance (Scene::build's order: meshes' triangles).
    const auto scene = Scene::build(d);
    ASSERT_EQ(set.lights.size(), scene->lights().size());
    for (size_t i = 0; i < set.lights.size(); ++i) EXPECT_EQ(set.lights[i], 4);
    try {
        ParameterSet::choose(d, {"red.albedo"});
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("red.reflectance.value"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("blue.alpha"), std::string::npos) << e.what();
    }
}

// Roughness by Mitsuba's names: alpha (isotropic, roughplastic's too), alpha_u and alpha_v
// (anisotropic); written back to the scene file under the names it read (a file's equal alpha_u
// and alpha_v, one alpha, as alpha); a roughplastic's new alpha rebuilds its coating's tables.
TEST(DiffParameters, RoughnessNamesAndSceneFile) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("pathlab-rough-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string file = (dir / "rough.xml").string();
    std::ofstream(file) << R"(<scene version="3.0.0">
<bsdf type="roughconductor" id="brushed"><float name="alphaU" value="0.1"/><float name="alpha_v" value="0.4"/></bsdf>
<bsdf type="roughconductor" id="even"><float name="alpha_u" value="0.3"/><float name="alpha_v" value="0.3"/></bsdf>
<bsdf type="roughplastic" id="coat"><float name="alpha" value="0.2"/><rgb name="diffuse_reflectance" value="0.1, 0.5, 0.2"/></bsdf>
<bsdf type="roughdielectric" id="ice"><float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.2"/></bsdf>
<shape type="rectangle"><ref id="brushed"/></shape>
<shape type="rectangle"><ref id="even"/></shape>
<shape type="rectangle"><ref id="coat"/></shape>
<shape type="rectangle"><ref id="ice"/></shape>
<shape type="sphere" id="lamp"><point name="center" value="0, 0, 4"/><emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>
</scene>)";
    SceneDescription d = load_scene_file(file);
    const std::vector<std::string> names = {"brushed.alpha_u", "brushed.alpha_v", "even.alpha", "coat.alpha", "ice.alpha_u", "ice.alpha_v", "ice.eta"};
    const ParameterSet set = ParameterSet::choose(d, names);
    EXPECT_EQ(set.values(d), (std::vector<float>{0.1f, 0.4f, 0.3f, 0.2f, 0.05f, 0.2f, set.values(d)[6]}));
    for (const std::string bad : {"brushed.alpha", "even.alpha_u", "coat.alpha_u"}) EXPECT_THROW(ParameterSet::choose(d, {bad}), std::invalid_argument) << bad;
    const std::vector<float> theta = {0.15f, 0.35f, 0.25f, 0.4f, 0.07f, 0.3f, 1.4f};
    const RoughPlasticMaterial before = std::get<RoughPlasticMaterial>(d.materials[2].model);
    set.set_values(d, theta);
    EXPECT_EQ(set.values(d), theta);
    const RoughPlasticMaterial& after = std::get<RoughPlasticMaterial>(d.materials[2].model);
    EXPECT_EQ(after.coat.diffuse_reflectance, before.coat.diffuse_reflectance);
    EXPECT_EQ(after.transmittance, RoughPlasticMaterial(after.distribution, before.coat).transmittance);
    EXPECT_NE(after.transmittance, before.transmittance);
    EXPECT_NE(after.coat.fdr, before.coat.fdr);
    std::ofstream(dir / "written.xml") << scene_file_with_values(file, set, theta, {});
    const SceneDescription written = load_scene_file((dir / "written.xml").string());
    const std::vector<float> back = set.values(written);
    for (size_t i = 0; i < theta.size(); ++i) EXPECT_NEAR(back[i], theta[i], 1e-6f) << names[i];
    fs::remove_all(dir);
}

// Each BSDF's df/dtheta against a central difference of eval() (deterministic: no Monte Carlo),
// over directions spread on the hemisphere.
TEST(DiffBsdf, JacobianMatchesDifferencesOfEval) {
    SceneDescription d = metals();
    d.materials[5] = make_phong(Rgb(0.3f, 0.4f, 0.5f), Rgb(0.4f), 12);  // back: glossy Phong
    d.material_ids[5] = "back";
    SceneDescription beck = d;
    beck.materials[7] = make_rough_conductor(MicrofacetDistribution(MicrofacetType::Beckmann, 0.3f, 0.3f), {Rgb(0.2f), Rgb(3.0f)});
    beck.materials[3] = make_rough_plastic(MicrofacetDistribution(MicrofacetType::GGX, 0.2f, 0.2f), Rgb(0.2f, 0.7f, 0.2f), Rgb(0.5f));
    // Anisotropic metal (alpha_u, alpha_v), GGX and Beckmann.
    SceneDescription aniso = d, aniso_beck = d;
    aniso.materials[7] = make_rough_conductor(MicrofacetDistribution(MicrofacetType::GGX, 0.15f, 0.45f), {Rgb(0.2f), Rgb(3.0f)});
    aniso_beck.materials[7] = make_rough_conductor(MicrofacetDistribution(MicrofacetType::Beckmann, 0.4f, 0.2f), {Rgb(0.2f), Rgb(3.0f)});
    // Materials only (set_values copies the description per evaluation).
    for (SceneDescription* full : {&d, &beck, &aniso, &aniso_beck}) full->meshes.clear(), full->spheres.clear(), full->lights.clear();
    const std::vector<std::string> isotropic = {"back.diffuse_reflectance.value", "back.specular_reflectance.value", "back.exponent", "blue.alpha",
                                                "blue.specular_reflectance.value", "yellow.diffuse_reflectance.value",
                                                "green.diffuse_reflectance.value", "green.specular_reflectance.value", "green.alpha"};
    const std::vector<std::string> anisotropic = {"blue.alpha_u", "blue.alpha_v", "blue.specular_reflectance.value"};
    for (const SceneDescription* desc : {&d, &beck, &aniso, &aniso_beck})
        for (const std::string& name : desc == &aniso || desc == &aniso_beck ? anisotropic : isotropic) {
            const ParameterSet set = ParameterSet::choose(*desc, {name});
            const uint32_t mi = set.params[0].index;
            const std::vector<float> theta = set.values(*desc);
            // A roughplastic's alpha moves its tables too.
            std::optional<RoughCoatingDerivative> coating;
            if (const auto* r = std::get_if<RoughPlasticMaterial>(&desc->materials[mi].model); r && set.materials[mi].alpha >= 0) coating.emplace(*r);
            for (int c = 0; c < set.params[0].size; ++c) {
                const auto material_at = [&](float step) {
                    SceneDescription e = *desc;
                    std::vector<float> th = theta;
                    th[size_t(c)] += step;
                    set.set_values(e, th);
                    return e.materials[mi];
                };
                // A roughplastic's alpha: its tables' quadratures are smooth in alpha only to the
                // scale of their nodes (their slopes over steps of 0.2-4% of alpha spread by 2%:
                // bsdf_derivatives.hpp), so the step is 1%, and the tables' share of the derivative
                // (what a coating derivative of zeros leaves out) is known to 2%.
                std::optional<RoughCoatingDerivative> none;
                if (coating) none = *coating, none->dT.fill(0.0f), none->dfdr = 0;
                const float h = coating ? 1e-2f * theta[0] : 3e-3f * std::max(theta[size_t(c)], 0.1f);
                const Material m0 = material_at(0), mp = material_at(h), mm = material_at(-h);
                for (int k = 0; k < 20; ++k) {
                    const float a = 0.1f + 1.3f * float(k % 5) / 5, b = 0.2f + 1.2f * float(k / 5) / 4;
                    const Vec3f wi = normalize(Vec3f(std::sin(a), 0.1f, std::cos(a)));
                    const Vec3f wo = normalize(Vec3f(-std::sin(b) * std::cos(float(k)), std::sin(b) * std::sin(float(k)), std::cos(b)));
                    const Rgb f0 = m0.eval(wi, wo), fd = (mp.eval(wi, wo) - mm.eval(wi, wo)) / (2 * h);
                    Rgb an(0.0f), an_without_tables(0.0f);
                    bsdf_jacobian(desc->materials[mi], set.materials[mi], coating ? &*coating : nullptr, wi, wo, false, [&](int off, const Rgb& df) {
                        if (off == c) an += df;
                    });
                    if (none)
                        bsdf_jacobian(desc->materials[mi], set.materials[mi], &*none, wi, wo, false, [&](int off, const Rgb& df) {
                            if (off == c) an_without_tables += df;
                        });
                    for (int ch = 0; ch < 3; ++ch)
                        // Truncation O(h^2) (relative 2e-3), eval's float rounding over 2h, the tables' 2%.
                        EXPECT_NEAR(an[ch], fd[ch], 2e-3 * (std::abs(fd[ch]) + std::abs(an[ch])) + 4 * 6e-8 * std::abs(f0[ch]) / h + 1e-7 +
                                                        (none ? 0.02 * std::abs(an[ch] - an_without_tables[ch]) : 0.0))
                            << name << " k " << k << " c " << c;
                }
            }
        }
}

namespace {

// Frosted glass: the left sphere of metals() a rough dielectric, seen, lit and looked through.
SceneDescription frosted(float alpha, MicrofacetType type = MicrofacetType::GGX) {
    SceneDescription d = metals();
    d.materials[6] = make_rough_dielectric(MicrofacetDistribution(type, alpha, alpha), 1.5f);  // yellow
    return d;
}

}  // namespace

// A rough dielectric's alpha and eta: wi and wo on either side (reflection and refraction, from outside
// and from inside), GGX and Beckmann, against central differences of eval.
TEST(DiffBsdf, RoughDielectricAlphaAndEtaMatchDifferencesOfEval) {
    for (const std::string name : {"yellow.alpha", "yellow.eta", "yellow.alpha_u", "yellow.alpha_v", "anisotropic yellow.eta"})
    for (const MicrofacetType type : {MicrofacetType::GGX, MicrofacetType::Beckmann}) {
        const bool aniso = name.find("_u") != std::string::npos || name.find("_v") != std::string::npos || name.rfind("anisotropic", 0) == 0;
        SceneDescription d = frosted(0.3f, type);
        if (aniso) d.materials[6] = make_rough_dielectric(MicrofacetDistribution(type, 0.2f, 0.45f), 1.5f);
        d.meshes.clear(), d.spheres.clear(), d.lights.clear();
        const ParameterSet set = ParameterSet::choose(d, {name.substr(name.find(' ') + 1)});
        const std::vector<float> theta = set.values(d);
        int compared = 0, nonzero = 0;
        for (int k = 0; k < 80; ++k) {
            const float a = 0.1f + 1.3f * float(k % 5) / 5, b = 0.1f + 1.2f * float((k / 5) % 4) / 4;
            Vec3f wi = normalize(Vec3f(std::sin(a), 0.1f, std::cos(a)));
            // Reflection (wo on wi's side) and refraction (the other side), nearly opposite wi's
            // tangent part so that refraction's half vector is valid.
            Vec3f wo = normalize(Vec3f(-std::sin(b) * std::cos(0.3f * float(k)), std::sin(b) * std::sin(0.3f * float(k)), std::cos(b)));
            if (k % 2 == 1) wo.z = -wo.z;
            if (k >= 40) wi.z = -wi.z, wo.z = -wo.z;  // from inside
            const auto eval_at = [&](float step) {
                SceneDescription e = d;
                set.set_values(e, {theta[0] + step});
                return e.materials[6].eval(wi, wo);
            };
            const float h = 3e-3f * theta[0];
            // Near the edge of the refraction lobe's support (where the half vector stops seeing
            // wi or wo) f vanishes with a kink, which a central difference cannot straddle.
            const Rgb f_m2 = eval_at(-2 * h), f_p2 = eval_at(2 * h);
            if (f_m2.x == 0 || f_p2.x == 0) continue;
            // Richardson's five-point difference (truncation O(h^4)): far in Beckmann's tail, where
            // f varies over a few hundredths of eta, the central difference's O(h^2) is 3% at this h.
            const Rgb f0 = eval_at(0), fd = ((eval_at(h) - eval_at(-h)) * 8.0f - (f_p2 - f_m2)) / (12 * h);
            Rgb an(0.0f);
            bsdf_jacobian(d.materials[6], set.materials[6], nullptr, wi, wo, false, [&](int off, const Rgb& df) {
                if (off == 0) an += df;
            });
            ++compared;
            nonzero += std::abs(fd.x) > 1e-4f;
            for (int ch = 0; ch < 3; ++ch)  // (the rounding of 18 / 12 evaluations' worth of f over h)
                EXPECT_NEAR(an[ch], fd[ch], 2e-3 * (std::abs(fd[ch]) + std::abs(an[ch])) + 6 * 6e-8 * std::abs(f0[ch]) / h + 1e-7)
                    << name << " k " << k << " wi " << wi.z << " wo " << wo.z;
        }
        EXPECT_GT(compared, 40) << name;
        EXPECT_GT(nonzero, 30) << name << ": most directions compared must have a derivative";
    }
}

// The primal pass is pt-mis's estimator: the same image as the renderer's pt-mis; in a scene with
// media, volpath's.
TEST(DiffGradients, PrimalIsPtMisOrVolpath) {
    const SceneDescription fog = fog_box();
    for (const auto& [d, integrator] : {std::pair{course(3), "pt-mis"}, std::pair{fog, "volpath"}}) {
        const auto scene = Scene::build(d);
        DiffSettings s;
        s.width = s.height = 16;
        s.spp = 3;
        const Image a = render_primal(*scene, s);
        const PerspectiveCamera cam(scene->camera(), 16, 16);
        const auto renderer = find_integrator(integrator)->make(IntegratorOptions{});
        Film film(16, 16);
        RenderContext ctx{*scene, cam, 16, 16, s.seed};
        renderer->render_passes(ctx, film, 0, 3, {});
        const Image m = film.mean();
        for (size_t i = 0; i < a.pixel_count(); ++i)
            for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(a[i][c], m[i][c]) << integrator << " " << i;
    }
}

TEST(DiffGradients, DiffuseAlbedoAgreesWithFiniteDifferences) {
    expect_agreement(check_against_fd(course(2), "red.reflectance.value", tiny_settings(), 48, 1e-2), "red albedo");
}

TEST(DiffGradients, EmitterRadianceAgreesWithFiniteDifferences) {
    expect_agreement(check_against_fd(course(2), "light.emitter.radiance.value", tiny_settings(), 32, 1e-2), "area radiance");
    expect_agreement(check_against_fd(course(0), "light.intensity.value", tiny_settings(), 32, 1e-2), "point intensity");
    expect_agreement(check_against_fd(course(6), "light.radiance.value", tiny_settings(), 32, 1e-2), "environment");
}

TEST(DiffGradients, PhongAgreesWithFiniteDifferences) {
    expect_agreement(check_against_fd(course(3), "back.diffuse_reflectance.value", tiny_settings(), 48, 1e-2), "phong diffuse");
    // rho_d and rho_s scaled together: the lobe selection probability stays, so do the paths.
    expect_agreement(check_direction_against_fd(course(1), {"floor.diffuse_reflectance.value", "floor.specular_reflectance.value"}, tiny_settings(), 48, 1e-2),
                     "phong diffuse + specular");
    const Image hw = signed_weights(broad_gloss(), "floor.exponent", tiny_settings());
    expect_agreement(check_against_fd(broad_gloss(), "floor.exponent", tiny_settings(), 512, 2e-2, {}, &hw), "phong exponent");
}

TEST(DiffGradients, RoughConductorAndPlasticAgreeWithFiniteDifferences) {
    // Uniform weights see mostly the energy the roughness loses (G2's derivative; D's integrates
    // to nearly 0 over a smooth surrounding): D's derivative is checked by DiffBsdf.JacobianMatchesDifferencesOfEval.
    expect_agreement(check_against_fd(metals(), "blue.alpha", tiny_settings(), 192, 1e-2), "roughconductor alpha");
    expect_agreement(check_against_fd(metals(), "blue.specular_reflectance.value", tiny_settings(), 48, 1e-2), "roughconductor R");
    expect_agreement(check_against_fd(metals(), "yellow.diffuse_reflectance.value", tiny_settings(), 48, 1e-2), "plastic diffuse");
    expect_agreement(check_against_fd(metals(), "yellow.specular_reflectance.value", tiny_settings(), 48, 1e-2), "plastic coating");
    expect_agreement(check_against_fd(metals(), "green.diffuse_reflectance.value", tiny_settings(), 48, 1e-2), "roughplastic base");
    expect_agreement(check_against_fd(metals(), "green.specular_reflectance.value", tiny_settings(), 48, 1e-2), "roughplastic coating");
    // (8192 passes: reverse -0.0880 +- 0.0005, finite differences -0.0886, z 0.36.)
    expect_agreement(check_against_fd(metals(), "green.alpha", tiny_settings(), 2048, 1e-2), "roughplastic alpha");
    SceneDescription brushed = metals();  // the right sphere brushed metal
    brushed.materials[7] = make_rough_conductor(MicrofacetDistribution(MicrofacetType::GGX, 0.2f, 0.5f), {Rgb(0.2f), Rgb(3.0f)}, Rgb(0.9f));
    // Uniform weights barely see an anisotropic roughness: weights that see its highlight. (8192
    // passes: alpha_u reverse 0.00351 +- 0.00056, finite differences 0.00317, z 0.30; alpha_v
    // 0.0199 +- 0.00024 against 0.0209, z -0.98.)
    for (const auto& [name, passes] : {std::pair{"blue.alpha_u", 8192}, std::pair{"blue.alpha_v", 2048}}) {
        const Image w = signed_weights(brushed, name, tiny_settings());
        expect_agreement(check_against_fd(brushed, name, tiny_settings(), passes, 1e-2, {}, &w), std::string("roughconductor ") + name);
    }
}

namespace {

// Scene 2 with its floor frosted glass (GGX, alpha 0.2) of index ratio eta, over nothing: what
// the camera sees of it is its reflection, which grows with eta (the Fresnel term); the light it
// lets through is lost below.
SceneDescription frosted_floor(float eta) {
    SceneDescription d = course(2);
    const auto floor = std::find(d.material_ids.begin(), d.material_ids.end(), "floor");
    if (floor == d.material_ids.end()) {
        ADD_FAILURE() << "scene 2 has no material 'floor'";
        return d;
    }
    d.materials[size_t(floor - d.material_ids.begin())] =
        make_rough_dielectric(MicrofacetDistribution(MicrofacetType::GGX, 0.2f, 0.2f), eta * 1.000277f);  // ext_ior: air
    return d;
}

}  // namespace

TEST(DiffGradients, RoughDielectricAlphaAgreesWithFiniteDifferences) {
    // (65536 passes: reverse -0.0463 +- 0.0017, finite differences -0.0490, z 1.13.)
    expect_agreement(check_against_fd(frosted(0.1f), "yellow.alpha", tiny_settings(), 8192, 1e-2), "roughdielectric alpha");
}

TEST(DiffGradients, RoughDielectricEtaAgreesWithFiniteDifferences) {
    const FdResult u = check_against_fd(frosted_floor(1.5f), "floor.eta", tiny_settings(), 2048, 1e-2);
    // (reverse 0.01727 +- 0.00019, finite differences 0.01669, z 0.52.)
    expect_agreement(u, "roughdielectric eta");
}

// Tests of the test: each fault makes the same comparison fail.
TEST(DiffGradients, FiniteDifferenceTestCatchesFaults) {
    DiffFaults lobe;
    lobe.drop_glossy_lobe = true;
    const Image hw = signed_weights(broad_gloss(), "floor.exponent", tiny_settings());
    EXPECT_GT(std::abs(check_direction_against_fd(course(1), {"floor.diffuse_reflectance.value", "floor.specular_reflectance.value"}, tiny_settings(),
                                        48, 1e-2, lobe).z),
              kZ);
    DiffFaults rng;
    rng.replay_other_numbers = true;
    EXPECT_GT(std::abs(check_against_fd(course(2), "red.reflectance.value", tiny_settings(), 48, 1e-2, rng).z), kZ);
    DiffFaults cont;
    cont.drop_continuation = true;
    EXPECT_GT(std::abs(check_against_fd(course(2), "red.reflectance.value", tiny_settings(), 48, 1e-2, cont).z), kZ);
}

// Forward mode (one image per parameter) and reverse mode compute the same derivative of the
// same paths: sum_p w(p) . dI(p)/dtheta equals t . dLoss/dtheta up to float rounding.
TEST(DiffGradients, ForwardAgreesWithReverse) {
    const SceneDescription fog = fog_box();
    for (const auto& [d, names] :
         {std::pair{metals(), std::vector<std::string>{"red.reflectance.value", "blue.alpha", "yellow.diffuse_reflectance.value",
                                                        "light.emitter.radiance.value"}},
          std::pair{fog, std::vector<std::string>{"fog.sigma_t.value", "fog.albedo.value", "fog.phase_function.g", "red.reflectance.value"}}}) {
        const ParameterSet set = ParameterSet::choose(d, names);
        const auto scene = Scene::build(d);
        DiffSettings s;
        s.width = s.height = 12;
        s.spp = 2;
        const Image w = loss_weights(12, 12);
        const std::vector<double> g = gradient(*scene, set, s, w);
        for (size_t i = 0; i < set.params.size(); ++i) {
            const std::vector<float> t = parameter_tangent(set, i);
            const double fwd = weighted_sum(forward_gradient(*scene, set, s, t), w);
            double rev = 0;
            for (size_t k = 0; k < g.size(); ++k) rev += g[k] * t[k];
            EXPECT_NEAR(fwd, rev, 1e-3 * (std::abs(fwd) + std::abs(rev)) + 1e-9) << set.params[i].name;
            EXPECT_NE(rev, 0.0) << set.params[i].name;
        }
    }
}

// In fog: the medium's extinction and albedo, and a wall seen through it and lit through it
// (volpath's estimator: free flights, phase samples, shadow rays' transmittance).
TEST(DiffGradients, MediaAgreeWithFiniteDifferences) {
    const SceneDescription fog = fog_box();
    expect_agreement(check_against_fd(fog, "fog.sigma_t.value", tiny_settings(), 2048, 1e-2), "medium sigma_t");
    expect_agreement(check_against_fd(fog, "fog.albedo.value", tiny_settings(), 512, 1e-2), "medium albedo");
    // g moves light between directions: weights that see where it goes; one scattering (depth 1),
    // where the finite differences are least noisy (g moves the phase samples themselves). (Without
    // the phase sample's d log p/d g z = -5.8; with the sign of mu wrong z = 62.)
    DiffSettings single = tiny_settings();
    single.max_depth = 1;
    const Image gw = signed_weights(fog, "fog.phase_function.g", single);
    expect_agreement(check_against_fd(fog, "fog.phase_function.g", single, 16384, 5e-2, {}, &gw), "medium phase g");
    expect_agreement(check_against_fd(fog, "red.reflectance.value", tiny_settings(), 128, 1e-2), "diffuse albedo in fog");
}

TEST(DiffGradients, SameBytesWithAnyThreadCount) {
    const SceneDescription fog = fog_box();
    for (const auto& [d, names] : {std::pair{course(3), std::vector<std::string>{"red.diffuse_reflectance.value", "blue.exponent"}},
                                   std::pair{fog, std::vector<std::string>{"fog.sigma_t.value", "red.reflectance.value"}}}) {
        const ParameterSet set = ParameterSet::choose(d, names);
        const auto scene = Scene::build(d);
        DiffSettings s;
        s.width = s.height = 16;
        const Image w = loss_weights(16, 16);
        std::vector<double> one, many;
        {
            tbb::task_arena a(1);
            a.execute([&] { one = gradient(*scene, set, s, w); });
        }
        {
            tbb::task_arena a(4);
            a.execute([&] { many = gradient(*scene, set, s, w); });
        }
        EXPECT_EQ(one, many) << names[0];
    }
}

namespace {

// Adam from theta towards the parameters that render `target` (the L2 loss; the gradient's
// replay with the next seed), `steps` steps of learning rate lr, the values clamped to their ranges.
std::vector<float> adam_fit(const SceneDescription& start, const ParameterSet& set, std::vector<float> theta, DiffSettings s,
                            const Image& target, double lr, int steps, bool seed_per_iteration = false) {
    SceneDescription d = start;
    Optimizer opt(OptimizerKind::Adam, lr, theta.size());
    const uint64_t seed = s.seed;
    for (int it = 0; it < steps; ++it) {
        set.set_values(d, theta);
        const auto scene = Scene::build(d);
        if (seed_per_iteration) s.seed = seed + 2 * uint64_t(it);
        DiffSettings gs = s;
        gs.seed = s.seed + 1;
        opt.step(theta, gradient(*scene, set, gs, loss_adjoint(render_primal(*scene, s), target, Loss{})));
        set.clamp(theta);
    }
    return theta;
}

}  // namespace

// The worked example (docs/differentiable.md): scene 2's wall colours and the light's radiance
// perturbed, recovered from a target rendered with the same seed and spp (so the true values are
// an exact fixed point of the loss) to within 2% in 120 Adam steps.
TEST(DiffOptimize, WorkedExampleRecoversWallsAndLight) {
    const SceneDescription truth = course(2);
    const std::vector<std::string> names = {"red.reflectance.value", "green.reflectance.value", "light.emitter.radiance.value"};
    const ParameterSet set = ParameterSet::choose(truth, names);
    const std::vector<float> want = set.values(truth);
    DiffSettings s;
    s.width = s.height = 24;
    s.spp = 4;
    s.max_depth = 4;
    const Image target = render_primal(*Scene::build(truth), s);
    const std::vector<float> theta = adam_fit(truth, set, {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 2.0f, 2.0f, 2.0f}, s, target, 0.03, 120);
    for (size_t i = 0; i < theta.size(); ++i) EXPECT_NEAR(theta[i], want[i], 0.02 * want[i]) << i;
}

// A hidden index of refraction recovered: the frosted-glass floor of scene 2 (over nothing, seen
// by its reflection) rendered at eta 1.7 as the target, optimised from 1.35 to within 1%; the
// scene file written back holds the ratio as int_ior (ext_ior 1) and reads as the same eta.
TEST(DiffOptimize, RecoversAHiddenEta) {
    const SceneDescription truth = frosted_floor(1.7f);
    const ParameterSet set = ParameterSet::choose(truth, {"floor.eta"});
    const float want = set.values(truth)[0];
    DiffSettings s;
    s.width = s.height = 16;
    s.spp = 4;
    s.max_depth = 3;
    const Image target = render_primal(*Scene::build(truth), s);
    const std::vector<float> theta = adam_fit(truth, set, {1.35f}, s, target, 0.01, 200);
    EXPECT_NEAR(theta[0], want, 0.01 * want);

    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("pathlab-eta-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string file = (dir / "glass.xml").string();
    std::ofstream(file) << R"(<scene version="3.0.0">
<bsdf type="roughdielectric" id="glass"><float name="alpha" value="0.2"/><string name="int_ior" value="bk7"/><string name="ext_ior" value="air"/></bsdf>
<shape type="rectangle"><ref id="glass"/></shape>
<shape type="sphere" id="lamp"><point name="center" value="0, 0, 4"/><emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>
</scene>)";
    const ParameterSet glass = ParameterSet::choose(load_scene_file(file), {"glass.eta"});
    std::ofstream(dir / "written.xml") << scene_file_with_values(file, glass, {1.7f}, {});
    const SceneDescription written = load_scene_file((dir / "written.xml").string());
    EXPECT_NEAR(glass.values(written)[0], 1.7f, 1e-6f);
    fs::remove_all(dir);
}

// A hidden fog recovered: fog-box.xml's medium rendered (256 spp) at its sigma_t (0.3, 0.35,
// 0.4) as the target, sigma_t optimised from (0.15, 0.15, 0.15) to within 5% (measured: 0.293,
// 0.343, 0.392). New seeds at every step, as `optimize` draws them: a medium's gradient is
// heavy-tailed (a rare scattering event weighs 1 / sigma_t), and one fixed set of samples can be
// far off its mean (+0.38 against a mean of -0.08 at sigma_t 0.15, which drove sigma_t to 0).
// (The albedo's gradient is right, its sign changing at the truth at 256 spp, but at 4 spp its
// noise is 100x its mean here: Adam moves it from 0.5 to 0.55-0.7 in 500 steps.)
TEST(DiffOptimize, RecoversAHiddenFog) {
    const SceneDescription truth = fog_box();
    DiffSettings s;
    s.width = s.height = 16;
    s.spp = 4;
    s.max_depth = 3;
    DiffSettings t = s;
    t.spp = 256;
    t.seed = 4711;
    const Image target = render_primal(*Scene::build(truth), t);
    const ParameterSet set = ParameterSet::choose(truth, {"fog.sigma_t.value"});
    const std::vector<float> want = set.values(truth);
    std::vector<float> theta = adam_fit(truth, set, {0.15f, 0.15f, 0.15f}, s, target, 0.02, 300, true);
    s.seed += 10000;  // then smaller steps: Adam's steps at a fixed rate jitter by about the rate
    theta = adam_fit(truth, set, theta, s, target, 0.004, 200, true);
    for (size_t k = 0; k < want.size(); ++k) EXPECT_NEAR(theta[k], want[k], 0.05 * want[k]) << k;
}

// The command line: params lists names that optimize accepts; an unknown name is refused with
// the list (exit code 2); optimize writes its outputs and a scene file with the new values.
TEST(DiffCli, ParamsNamesAreAcceptedByOptimize) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("pathlab-diff-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string scene = std::string(PATHLAB_SOURCE_DIR) + "/scenes/2-ceiling-diffuse.xml";
    const test::CliResult params = test::run({"params", scene, "--json"});
    ASSERT_EQ(params.code, 0) << params.err;
    EXPECT_TRUE(test::contains(params.out, "\"red.reflectance.value\""));
    const std::string target = (dir / "target.exr").string();
    write_image(render_primal(*Scene::build(load_scene_file(scene)), DiffSettings{8, 8, 5, 2}), target);
    const std::string out = (dir / "opt").string();
    const test::CliResult ok = test::run({"optimize", "--scene", scene, "--target", target, "--params",
                                          "red.reflectance.value,light.emitter.radiance.value", "--set", "red.reflectance.value=0.5",
                                          "--iterations", "3", "--lr", "0.05", "--spp", "2", "--out", out, "-q"});
    EXPECT_EQ(ok.code, 0) << ok.err;
    for (const char* f : {"loss.json", "loss.svg", "params.json", "final.exr", "scene.xml", "iteration_0000.png"})
        EXPECT_TRUE(fs::exists(dir / "opt" / f)) << f;
    // The rewritten scene file loads, with the optimised value in place.
    const SceneDescription written = load_scene_file(out + "/scene.xml");
    const std::vector<SceneParameter> all = scene_parameters(written);
    EXPECT_NE(parameter_value(written, find_parameter(all, "red.reflectance.value"))[1], 0.152941f);
    const test::CliResult bad = test::run({"optimize", "--scene", scene, "--target", target, "--params", "red.albedo", "--out", out});
    EXPECT_EQ(bad.code, 2);
    EXPECT_TRUE(test::contains(bad.err, "unknown parameter 'red.albedo'")) << bad.err;
    EXPECT_TRUE(test::contains(bad.err, "green.reflectance.value")) << bad.err;
    // A scene with fog: differentiated with volpath's estimator (params says so).
    // empty; params lists its parameters and says so.
    const std::string fog = std::string(PATHLAB_SOURCE_DIR) + "/scenes/fog-box.xml";
    const test::CliResult listed = test::run({"params", fog});
    EXPECT_EQ(listed.code, 0) << listed.err;
    EXPECT_TRUE(test::contains(listed.out, "fog.sigma_t.value")) << listed.out;
    EXPECT_TRUE(test::contains(listed.out, "differentiate volpath's estimator")) << listed.out;
    const test::CliResult foggy = test::run({"gradient", "--scene", fog, "--params", "fog.sigma_t.value", "--resolution", "8x8", "--spp", "1",
                                             "--out", (dir / "fog").string()});
    EXPECT_EQ(foggy.code, 0) << foggy.err;
    // --out naming the folder of a file they read (optimize's scene.xml was written over the
    // scene, final.exr over a target of that name) is refused, and the file is left as it was.
    // (opt/scene.xml is the scene optimize wrote above: a scene file like any other.)
    const std::string before = [&] {
        std::ifstream in(dir / "opt" / "scene.xml");
        return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }();
    for (const std::string command : {"optimize", "gradient"}) {
        auto args = [&](const std::string& scene_file, const std::string& target_file) {
            std::vector<std::string> a = {command, "--scene", scene_file, "--target", target_file, "--params", "red.reflectance.value",
                                          "--spp", "1", "--out", out};
            if (command == "optimize") a.insert(a.end(), {"--iterations", "1", "-q"});
            return a;
        };
        const test::CliResult over = test::run(args(out + "/scene.xml", target));
        EXPECT_EQ(over.code, 2) << command;
        EXPECT_TRUE(test::contains(over.err, "--out " + out + " holds " + out + "/scene.xml, which " + command + " reads")) << over.err;
        const test::CliResult target_there = test::run(args(scene, out + "/final.exr"));
        EXPECT_EQ(target_there.code, 2) << command;
        EXPECT_TRUE(test::contains(target_there.err, "holds " + out + "/final.exr")) << target_there.err;
    }
    std::ifstream in(dir / "opt" / "scene.xml");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()), before);
    fs::remove_all(dir);
}

// -D sets a scene file's $parameters for params, gradient and optimize as for a render (a name
// the scene does not use is refused), and gradient gives the same bytes with 1 and 2 --threads.
TEST(DiffCli, DefinesAndThreadsAsForARender) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("pathlab-diff-d-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string scene = (dir / "wall.xml").string();
    std::ofstream(scene) << "<scene version=\"3.0.0\"><default name=\"refl\" value=\"0.5\"/>"
                            "<bsdf type=\"diffuse\" id=\"wall\"><rgb name=\"reflectance\" value=\"$refl\"/></bsdf>"
                            "<shape type=\"rectangle\"><ref id=\"wall\"/></shape><emitter type=\"constant\"/></scene>\n";
    const test::CliResult params = test::run({"params", scene, "-D", "refl=0.25", "--json"});
    ASSERT_EQ(params.code, 0) << params.err;
    EXPECT_TRUE(test::contains(params.out, "0.25")) << params.out;
    const auto gradient_files = [&](const std::string& threads) {
        const std::string out = (dir / ("g" + threads)).string();
        const test::CliResult r = test::run({"gradient", "--scene", std::string(PATHLAB_SOURCE_DIR) + "/scenes/2-ceiling-diffuse.xml",
                                             "--params", "red.reflectance.value", "--spp", "2", "--resolution", "16x12", "--threads", threads,
                                             "--out", out});
        EXPECT_FALSE(test::contains(r.out, "[0, 0, 0]")) << r.out;
        EXPECT_EQ(r.code, 0) << r.err;
        std::map<std::string, std::string> files;
        for (const auto& e : fs::directory_iterator(out)) {
            std::ifstream in(e.path(), std::ios::binary);
            files[e.path().filename().string()] = std::string(std::istreambuf_iterator<char>(in), {});
        }
        return files;
    };
    const auto one = gradient_files("1"), two = gradient_files("2");
    EXPECT_FALSE(one.empty());
    EXPECT_TRUE(one == two) << "the gradient's files differ between 1 and 2 threads";
    EXPECT_EQ(test::run({"gradient", "--scene", scene, "-D", "nothere=1", "--params", "wall.reflectance.value"}).code, 2);
    fs::remove_all(dir);
}

// ---- texels (a bitmap texture's, as <id>.reflectance.data) ------------------------------

namespace {

const char* kTextureScene = "/scenes/diff-texture.xml";

SceneDescription texture_scene() { return load_scene_file(std::string(PATHLAB_SOURCE_DIR) + kTextureScene); }

// The texture scene with an n x n texture of fixed pseudo-random colours in [0.2, 0.8] on the
// back wall (bilinear, clamped at the edges): texels a few pixels wide on a tiny image.
SceneDescription small_texture_scene(int n) {
    SceneDescription d = texture_scene();
    const ParameterSet set = ParameterSet::choose(d, {"back.reflectance.data"});
    Material& m = d.materials[set.params[0].index];
    std::vector<Rgb> texels(size_t(n * n));
    uint64_t state = 12345;
    const auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return 0.2f + 0.6f * float(state >> 40) / float(1 << 24);
    };
    for (Rgb& t : texels) t = Rgb(next(), next(), next());
    MaterialTextures t = *m.textures;
    t.bindings[0].texture = std::make_shared<const Texture>(BitmapTexture(n, n, texels, FilterType::Bilinear, WrapMode::Clamp));
    m.set_textures(std::move(t));
    // Through the parameter once, so that the model's constant follows the new texels.
    const std::vector<SceneParameter> all = scene_parameters(d);
    const SceneParameter& p = find_parameter(all, "back.reflectance.data");
    set_parameter_value(d, p, parameter_value(d, p));
    return d;
}

// The direction that moves texels `which` (all three channels) by 1.
std::vector<float> texel_direction(const SceneDescription& d, const std::vector<int>& which) {
    const ParameterSet set = ParameterSet::choose(d, {"back.reflectance.data"});
    std::vector<float> t(size_t(set.size), 0.0f);
    for (int k : which)
        for (int c = 0; c < 3; ++c) t[size_t(3 * k + c)] = 1;
    return t;
}

}  // namespace

TEST(DiffTexels, ListedSetAndClamped) {
    SceneDescription d = texture_scene();
    const std::vector<SceneParameter> all = scene_parameters(d);
    std::vector<std::string> names;
    for (const auto& p : all) names.push_back(p.name);
    EXPECT_EQ(names, (std::vector<std::string>{"floor.reflectance.value", "green.reflectance.value", "red.reflectance.value",
                                               "back.reflectance.data", "light.emitter.radiance.value"}));
    const SceneParameter& p = find_parameter(all, "back.reflectance.data");
    EXPECT_EQ(p.size, 32 * 32 * 3);
    EXPECT_EQ(p.kind(), "texture");
    EXPECT_EQ(p.range(), "[0, 1]");
    // The texels are the linear values pathlab keeps (the PNG's sRGB decoded once at load):
    // texel (0, 0) is the top-left quadrant's sRGB (214, 96, 77).
    const std::vector<float> v = parameter_value(d, p);
    EXPECT_NEAR(v[0], std::pow((214 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
    EXPECT_NEAR(v[2], std::pow((77 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
    // Set, get, clamp; the model's constant (the largest texel) follows.
    const ParameterSet set = ParameterSet::choose(d, {"back.reflectance.data"});
    std::vector<float> theta(size_t(set.size), 0.25f);
    theta[7] = 1.5f, theta[8] = -0.5f;
    set.clamp(theta);
    EXPECT_EQ(theta[7], 1.0f);
    EXPECT_EQ(theta[8], 0.0f);
    set.set_values(d, theta);
    EXPECT_EQ(set.values(d), theta);
    EXPECT_EQ(std::get<PhongMaterial>(d.materials[p.index].model).diffuse, Rgb(0.25f, 1.0f, 0.25f));
    // The material's binding points at the texels.
    EXPECT_EQ(set.materials[p.index].diffuse_texels.offset, 0);
    EXPECT_EQ(set.materials[p.index].diffuse, -1);
    // The textured parameter has no `.value`; asking for it lists the `.data`.
    try {
        ParameterSet::choose(d, {"back.reflectance.value"});
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("back.reflectance.data"), std::string::npos) << e.what();
    }
}

// The gradient with respect to one texel, and to a 2 x 2 block, against central finite
// differences with common random numbers (the z-test at the top, false alarm rate 1e-4 each),
// on a 4 x 4 texture whose texels are about 2 pixels wide on the 12 x 12 image.
TEST(DiffTexels, GradientAgreesWithFiniteDifferences) {
    const SceneDescription d = small_texture_scene(4);
    const std::vector<float> one = texel_direction(d, {5});  // texel (1, 1)
    // Loss weights that follow the texel's own footprint on the image (an independent forward
    // render of it): they weigh the pixels near the texel's centre more than those at its
    // neighbours' centres, so that the bilinear weights' shape matters, not only their mean.
    DiffSettings r = tiny_settings();
    r.spp = 64;
    r.seed = 4242;
    const ParameterSet set = ParameterSet::choose(d, {"back.reflectance.data"});
    Image w = forward_gradient(*Scene::build(d), set, r, one);
    for (size_t i = 0; i < w.pixel_count(); ++i) w[i] = w[i] / float(w.pixel_count());
    expect_agreement(check_direction_against_fd(d, {"back.reflectance.data"}, tiny_settings(), 48, 1e-2, {}, &w, &one), "texel 5");
    const std::vector<float> block = texel_direction(d, {9, 10, 13, 14});  // texels (1..2, 2..3)
    expect_agreement(check_direction_against_fd(d, {"back.reflectance.data"}, tiny_settings(), 48, 1e-2, {}, nullptr, &block), "2x2 block");
    // It fails when each texel gets the weight of the opposite corner of the bilinear cell.
    DiffFaults corner;
    corner.texel_weights_wrong_corner = true;
    const FdResult wrong = check_direction_against_fd(d, {"back.reflectance.data"}, tiny_settings(), 48, 1e-2, corner, &w, &one);
    EXPECT_GT(std::abs(wrong.z), kZ) << "reverse " << wrong.reverse << " fd " << wrong.fd;
}

// Forward mode for one texel and for the whole texture equals reverse mode on the same paths;
// the texel gradient is the same bytes with 1 and 4 threads.
TEST(DiffTexels, ForwardAgreesWithReverseAndThreadsAgree) {
    const SceneDescription d = small_texture_scene(4);
    const ParameterSet set = ParameterSet::choose(d, {"back.reflectance.data", "light.emitter.radiance.value"});
    const auto scene = Scene::build(d);
    DiffSettings s;
    s.width = s.height = 12;
    s.spp = 2;
    const Image w = loss_weights(12, 12);
    std::vector<double> g;
    {
        tbb::task_arena a(1);
        a.execute([&] { g = gradient(*scene, set, s, w); });
    }
    std::vector<double> many;
    {
        tbb::task_arena a(4);
        a.execute([&] { many = gradient(*scene, set, s, w); });
    }
    EXPECT_EQ(g, many);
    std::vector<float> texel5(size_t(set.size), 0.0f);
    for (int c = 0; c < 3; ++c) texel5[size_t(15 + c)] = 1;
    for (const std::vector<float>& t : {texel5, parameter_tangent(set, 0), parameter_tangent(set, 1)}) {
        const double fwd = weighted_sum(forward_gradient(*scene, set, s, t), w);
        double rev = 0;
        for (size_t k = 0; k < g.size(); ++k) rev += g[k] * t[k];
        EXPECT_NE(rev, 0.0);
        EXPECT_NEAR(fwd, rev, 1e-3 * (std::abs(fwd) + std::abs(rev)) + 1e-9);
    }
}

// The texture half of the worked example, small: an 8 x 8 texture recovered from flat grey
// (0.5) at 24 x 24 pixels, 4 spp, the target rendered with the optimisation's seed (the true
// texels are an exact fixed point), 150 Adam steps.
TEST(DiffTexels, WorkedExampleRecoversTexture) {
    const SceneDescription truth = small_texture_scene(8);
    const ParameterSet set = ParameterSet::choose(truth, {"back.reflectance.data"});
    const std::vector<float> want = set.values(truth);
    DiffSettings s;
    s.width = s.height = 24;
    s.spp = 4;
    s.max_depth = 3;
    const Image target = render_primal(*Scene::build(truth), s);
    SceneDescription d = truth;
    std::vector<float> theta(want.size(), 0.5f);
    Optimizer opt(OptimizerKind::Adam, 0.02, theta.size());
    const auto rms_error = [&] {
        double e = 0;
        for (size_t i = 0; i < theta.size(); ++i) e += (theta[i] - want[i]) * (theta[i] - want[i]);
        return std::sqrt(e / double(theta.size()));
    };
    const double start = rms_error();
    for (int it = 0; it < 150; ++it) {
        set.set_values(d, theta);
        const auto scene = Scene::build(d);
        const Image img = render_primal(*scene, s);
        DiffSettings gs = s;
        gs.seed = s.seed + 1;
        opt.step(theta, gradient(*scene, set, gs, loss_adjoint(img, target, Loss{})));
        set.clamp(theta);
    }
    const double end = rms_error();
    std::printf("texel rms error: start %.4f, after 150 steps %.4f\n", start, end);
    EXPECT_LT(end, 0.1 * start);
}

// A texture that two BSDFs share (a top-level <texture id> given by <ref>) is one parameter,
// listed under the first BSDF, bound for both, and moved for both; the rewritten scene file
// points the top-level texture at the written EXR.
TEST(DiffTexels, SharedTextureIsOneParameter) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("pathlab-shared-texels-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string scenes = std::string(PATHLAB_SOURCE_DIR) + "/scenes";
    const std::string file = (dir / "shared.xml").string();
    std::ofstream(file) << "<scene version=\"3.0.0\">\n<path value=\"" << scenes << "\"/>\n"
                        << R"(<texture type="bitmap" id="pic"><string name="filename" value="textures/letters.png"/></texture>
<bsdf type="diffuse" id="left"><ref name="reflectance" id="pic"/></bsdf>
<bsdf type="twosided" id="right"><bsdf type="diffuse"><ref name="reflectance" id="pic"/></bsdf></bsdf>
<shape type="rectangle"><ref id="left"/></shape>
<shape type="rectangle"><transform name="to_world"><translate x="3"/></transform><ref id="right"/></shape>
<shape type="sphere" id="lamp"><point name="center" value="0, 0, 4"/><emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>
</scene>)";
    SceneDescription d = load_scene_file(file);
    std::vector<std::string> names;
    for (const auto& p : scene_parameters(d)) names.push_back(p.name);
    EXPECT_EQ(names, (std::vector<std::string>{"left.reflectance.data", "lamp.emitter.radiance.value"}));
    const ParameterSet set = ParameterSet::choose(d, {"left.reflectance.data"});
    int bound = 0;
    for (const MaterialBinding& b : set.materials) bound += b.diffuse_texels.offset == 0;
    EXPECT_EQ(bound, 2);
    std::vector<float> theta(size_t(set.size), 0.3f);
    set.set_values(d, theta);
    int moved = 0;
    for (const Material& m : d.materials)
        if (m.textures) moved += std::get<BitmapTexture>(m.textures->bindings[0].texture->model()).texels()[0] == Rgb(0.3f);
    EXPECT_EQ(moved, 2);
    const std::string written = scene_file_with_values(file, set, theta, {{"left.reflectance.data", "left.reflectance.data.exr"}});
    EXPECT_NE(written.find("value=\"left.reflectance.data.exr\""), std::string::npos) << written;
    EXPECT_EQ(written.find("letters.png"), std::string::npos) << written;
    fs::remove_all(dir);
}

// The command line: params lists the texels (compactly; --json with their shape), optimize
// accepts them and writes the texture as an EXR that the written scene file reads, gradient
// takes one texel by index.
TEST(DiffTexels, CommandLine) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("pathlab-texels-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string scene = std::string(PATHLAB_SOURCE_DIR) + kTextureScene;
    const test::CliResult params = test::run({"params", scene});
    ASSERT_EQ(params.code, 0) << params.err;
    EXPECT_TRUE(test::contains(params.out, "back.reflectance.data")) << params.out;
    EXPECT_TRUE(test::contains(params.out, "32x32 texels, mean")) << params.out;
    const test::CliResult json = test::run({"params", scene, "--json"});
    EXPECT_TRUE(test::contains(json.out, "\"shape\"")) << json.out.substr(0, 400);
    const std::string target = (dir / "target.exr").string();
    write_image(render_primal(*Scene::build(load_scene_file(scene)), DiffSettings{8, 8, 5, 2}), target);
    const std::string out = (dir / "opt").string();
    const test::CliResult ok = test::run({"optimize", "--scene", scene, "--target", target, "--params", "back.reflectance.data", "--set",
                                          "back.reflectance.data=0.5", "--iterations", "2", "--lr", "0.05", "--spp", "2", "--out", out, "-q"});
    ASSERT_EQ(ok.code, 0) << ok.err;
    for (const char* f : {"back.reflectance.data.exr", "back.reflectance.data.png", "back.reflectance.data_0000.png", "scene.xml"})
        EXPECT_TRUE(fs::exists(dir / "opt" / f)) << f;
    // The written scene reads the written texels.
    const SceneDescription written = load_scene_file(out + "/scene.xml");
    const std::vector<SceneParameter> all = scene_parameters(written);
    const std::vector<float> v = parameter_value(written, find_parameter(all, "back.reflectance.data"));
    const Image exr = read_image(out + "/back.reflectance.data.exr");
    ASSERT_EQ(v.size(), exr.pixel_count() * 3);
    for (size_t i = 0; i < exr.pixel_count(); ++i) EXPECT_EQ(v[3 * i], exr[i].x) << i;
    EXPECT_TRUE(std::any_of(v.begin(), v.end(), [](float x) { return x != 0.5f; }));  // moved from the start
    const test::CliResult grad = test::run({"gradient", "--scene", scene, "--params", "back.reflectance.data[100]", "--spp", "1",
                                            "--resolution", "8x8", "--out", (dir / "grad").string()});
    EXPECT_EQ(grad.code, 0) << grad.err;
    EXPECT_TRUE(fs::exists(dir / "grad" / "d_back.reflectance.data[100].exr"));
    const test::CliResult range = test::run({"gradient", "--scene", scene, "--params", "back.reflectance.data[1024]", "--out", (dir / "grad").string()});
    EXPECT_EQ(range.code, 2);
    EXPECT_TRUE(test::contains(range.err, "32x32 = 1024 texels")) << range.err;
    const test::CliResult bad = test::run({"optimize", "--scene", scene, "--target", target, "--params", "back.reflectance.value", "--out", out});
    EXPECT_EQ(bad.code, 2);
    EXPECT_TRUE(test::contains(bad.err, "back.reflectance.data")) << bad.err;
    fs::remove_all(dir);
}

}  // namespace pathlab
