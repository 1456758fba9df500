// Textured materials inside the estimators: a texture whose texels all equal a constant
// renders bit for bit like that constant (every BSDF parameter that may be textured, in
// radiance and importance transport); a white textured diffuse stays invisible in a white
// furnace; a flat normal map and a constant bump map are no normal or bump map at all (the
// frame they give, and the image, by a per-pixel z-test), while a tilted one is seen.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <random>

#include <unistd.h>

#include "image/image_io.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

namespace fs = std::filesystem;

class TextureRendering : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-texture-rendering-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    // An EXR file of 3 x 2 texels all equal to `v` (float: exactly v).
    std::string constant_exr(const std::string& name, const Rgb& v) const {
        const std::string p = (dir_ / name).string();
        write_image(Image(3, 2, v), p);
        return name;
    }
    SceneDescription load(const std::string& body) const {
        return load_scene_text("<scene version=\"3.0.0\">" + body + "</scene>", (dir_ / "scene.xml").string(), dir_.string());
    }
    fs::path dir_;
};

// A floor, spheres in two rows and a rectangle light under a dim sky; BSDF i of `bsdfs` on
// sphere i (the floor has bsdfs[0] too).
std::string spheres_scene(const std::vector<std::string>& bsdfs) {
    std::string s = R"(<sensor type="perspective"><float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, -6, 2.5" target="0, 0, 0.4" up="0, 0, 1"/></transform></sensor>
        <emitter type="constant"><rgb name="radiance" value="0.1, 0.12, 0.15"/></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="0.8"/><rotate x="1" angle="180"/><translate z="3"/></transform>
            <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform><bsdf type="twosided">)" +
                    bsdfs[0] + "</bsdf></shape>\n";
    for (size_t i = 0; i < bsdfs.size(); ++i)
        s += "<shape type=\"sphere\"><point name=\"center\" value=\"" + std::to_string(-1.5 + double(i % 4)) + ", " +
             std::to_string(1.2 * double(i / 4)) + ", 0.45\"/><float name=\"radius\" value=\"0.45\"/>" + bsdfs[i] + "</shape>\n";
    return s;
}

std::string bitmap(const std::string& param, const std::string& file) {
    return "<texture type=\"bitmap\" name=\"" + param + "\"><string name=\"filename\" value=\"" + file + "\"/></texture>";
}
std::string checker(const std::string& param, const std::string& value) {
    return "<texture type=\"checkerboard\" name=\"" + param + "\"><rgb name=\"color0\" value=\"" + value + "\"/><rgb name=\"color1\" value=\"" +
           value + "\"/></texture>";
}

TEST_F(TextureRendering, ConstantTexelsRenderBitForBitLikeTheConstant) {
    const std::string c1 = constant_exr("c1.exr", Rgb(0.3f, 0.5f, 0.7f)), c2 = constant_exr("c2.exr", Rgb(0.9f, 0.8f, 0.7f));
    const std::string w = constant_exr("w.exr", Rgb(0.3f));
    const std::string a = constant_exr("a.exr", Rgb(0.2f)), au = constant_exr("au.exr", Rgb(0.08f)), av = constant_exr("av.exr", Rgb(0.35f));
    const std::vector<std::string> constant = {
        R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.3, 0.5, 0.7"/></bsdf>)",
        R"(<bsdf type="phong"><rgb name="diffuse_reflectance" value="0.3, 0.5, 0.7"/><rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/>
             <float name="exponent" value="20"/></bsdf>)",
        R"(<bsdf type="roughconductor"><string name="material" value="Cu"/><rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/>
             <float name="alpha" value="0.2"/></bsdf>)",
        R"(<bsdf type="roughconductor"><string name="distribution" value="ggx"/><float name="alpha_u" value="0.08"/><float name="alpha_v" value="0.35"/></bsdf>)",
        R"(<bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.3, 0.5, 0.7"/><rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/></bsdf>)",
        R"(<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.3, 0.5, 0.7"/></bsdf>)",
        R"(<bsdf type="roughdielectric"><float name="alpha" value="0.2"/></bsdf>)",
        R"(<bsdf type="conductor"><rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/></bsdf>)",
        R"(<bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"><rgb name="reflectance" value="0.3, 0.5, 0.7"/></bsdf>
             <bsdf type="conductor"><rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/></bsdf></bsdf>)",
        R"(<bsdf type="mask"><float name="opacity" value="0.6"/><bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.3, 0.5, 0.7"/></bsdf></bsdf>)",
    };
    const std::vector<std::string> textured = {
        "<bsdf type=\"diffuse\">" + bitmap("reflectance", c1) + "</bsdf>",
        "<bsdf type=\"phong\">" + checker("diffuse_reflectance", "0.3, 0.5, 0.7") + bitmap("specular_reflectance", c2) +
            "<texture type=\"checkerboard\" name=\"exponent\"><float name=\"color0\" value=\"20\"/><float name=\"color1\" value=\"20\"/></texture></bsdf>",
        "<bsdf type=\"roughconductor\"><string name=\"material\" value=\"Cu\"/>" + bitmap("specular_reflectance", c2) + bitmap("alpha", a) + "</bsdf>",
        "<bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/>" + bitmap("alpha_u", au) + bitmap("alpha_v", av) + "</bsdf>",
        "<bsdf type=\"roughplastic\">" + bitmap("diffuse_reflectance", c1) + checker("specular_reflectance", "0.9, 0.8, 0.7") + "</bsdf>",
        "<bsdf type=\"plastic\">" + bitmap("diffuse_reflectance", c1) + "</bsdf>",
        "<bsdf type=\"roughdielectric\">" + bitmap("alpha", a) + "</bsdf>",
        "<bsdf type=\"conductor\">" + bitmap("specular_reflectance", c2) + "</bsdf>",
        "<bsdf type=\"blendbsdf\">" + bitmap("weight", w) + "<bsdf type=\"diffuse\">" + bitmap("reflectance", c1) +
            "</bsdf><bsdf type=\"conductor\">" + bitmap("specular_reflectance", c2) + "</bsdf></bsdf>",
        "<bsdf type=\"mask\">" + checker("opacity", "0.6") + "<bsdf type=\"roughplastic\">" + bitmap("diffuse_reflectance", c1) +
            "</bsdf></bsdf>",
    };
    const SceneDescription plain = load(spheres_scene(constant)), tex = load(spheres_scene(textured));
    EXPECT_EQ(std::count_if(tex.materials.begin(), tex.materials.end(), [](const Material& m) { return m.varies; }),
              long(textured.size() + 1));  // the floor's and the spheres' (the light has the default material)
    // pt-mis (radiance mode), bdpt (importance mode and reverse pdfs on the light subpaths).
    for (const char* algorithm : {"pt-mis", "bdpt"}) {
        const RenderResult a0 = render_scene(plain, algorithm, 24, 16, 4, 11);
        const RenderResult a1 = render_scene(tex, algorithm, 24, 16, 4, 11);
        EXPECT_TRUE(bit_identical(a0.film.mean(), a1.film.mean())) << algorithm;
        double sum = 0;
        for (size_t i = 0; i < a0.film.mean().pixel_count(); ++i) sum += luminance(a0.film.mean()[i]);
        EXPECT_GT(sum, 0.0) << algorithm;  // not two black images
    }
}

// blendbsdf's weight and mask's opacity follow their textures, and the BSDFs nested in them are
// evaluated at the same uv (a checkerboard weight of 0.2 / 0.9 over a textured diffuse and a
// conductor; a checkerboard opacity of 0.25 / 1 over a textured diffuse).
TEST_F(TextureRendering, BlendWeightAndMaskOpacityFollowTheirTexturesAtTheHitsUv) {
    const auto two = [](const std::string& param, const std::string& c0, const std::string& c1) {
        return "<texture type=\"checkerboard\" name=\"" + param + "\"><rgb name=\"color0\" value=\"" + c0 + "\"/><rgb name=\"color1\" value=\"" +
               c1 + "\"/></texture>";
    };
    const SceneDescription d = load(R"(<bsdf type="blendbsdf" id="blend">)" + two("weight", "0.2", "0.9") + R"(<bsdf type="diffuse">)" +
                                    two("reflectance", "0.1, 0.2, 0.3", "0.6, 0.5, 0.4") +
                                    R"(</bsdf><bsdf type="conductor"/></bsdf>
        <bsdf type="mask" id="mask">)" + two("opacity", "0.25", "1") + R"(<bsdf type="diffuse">)" +
                                    two("reflectance", "0.1, 0.2, 0.3", "0.6, 0.5, 0.4") + R"(</bsdf></bsdf>
        <shape type="sphere"><ref id="blend"/></shape>)");
    ASSERT_EQ(d.materials.size(), 2u);
    const Material &blend = d.materials[0], &mask = d.materials[1];
    EXPECT_TRUE(blend.varies && mask.varies);
    EXPECT_TRUE(blend.lobes() & kLobeSpecular);  // the conductor's, whatever the weight
    const Vec3f wi = normalize(Vec3f(0.3f, -0.2f, 0.9f)), wo = normalize(Vec3f(-0.4f, 0.1f, 0.8f));
    // A colour's color0 at [0, 1/2]^2 and [1/2, 1]^2, color1 elsewhere; a scalar's the other way
    // round (Mitsuba 3's eval_1, checkerboard.hpp).
    const struct {
        Vec2f uv;
        float weight, opacity;
        Rgb rho;
    } at[] = {{Vec2f(0.25f, 0.25f), 0.9f, 1.0f, Rgb(0.1f, 0.2f, 0.3f)}, {Vec2f(0.75f, 0.25f), 0.2f, 0.25f, Rgb(0.6f, 0.5f, 0.4f)}};
    for (const auto& x : at) {
        const MaterialModel bm = blend.model_at(x.uv);
        EXPECT_FLOAT_EQ(std::get<BlendMaterial>(bm).weight, x.weight);
        // The conductor adds nothing off its mirror direction: the blend is (1 - w) rho / pi.
        const Rgb f = std::visit([&](const auto& m) { return m.eval(wi, wo); }, bm);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], (1 - x.weight) * x.rho[k] / float(M_PI), 1e-6f) << k;
        const MaterialModel mm = mask.model_at(x.uv);
        EXPECT_FLOAT_EQ(std::get<MaskMaterial>(mm).opacity, x.opacity);
        const Rgb g = std::visit([&](const auto& m) { return m.eval(wi, wo); }, mm);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(g[k], x.opacity * x.rho[k] / float(M_PI), 1e-6f) << k;
        // Sampling passes straight through with probability 1 - opacity.
        const auto through = std::visit([&](const auto& m) { return m.sample(wi, Vec2f(0.999f, 0.5f)); }, mm);
        EXPECT_EQ(bool(through && through->delta), x.opacity < 1);
    }
    // Values outside [0, 1] and normal maps inside a blend are refused.
    const auto fails = [&](const std::string& body, const std::string& text) {
        try {
            load(body + R"(<shape type="sphere"/>)");
            ADD_FAILURE() << "accepted: " << body;
        } catch (const SceneFileError& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    };
    fails(R"(<bsdf type="mask">)" + two("opacity", "0.5", "1.5") + R"(<bsdf type="diffuse"/></bsdf>)", "between 0 and 1");
    fails(R"(<bsdf type="blendbsdf">)" + two("weight", "0.5", "1") +
              R"(<bsdf type="normalmap"><bsdf type="diffuse"/><texture type="checkerboard" name="normalmap"/></bsdf><bsdf type="diffuse"/></bsdf>)",
          "not supported");
    fails(R"(<bsdf type="mask">)" + two("alpha", "0.5", "1") + R"(<bsdf type="diffuse"/></bsdf>)", "must be named \"opacity\"");
}

// A white textured diffuse (a white PNG, sRGB 255 = 1; a white checkerboard) on a floor and a
// sphere in a constant environment: L = Le everywhere (per-pixel z-test at a 1e-3 family-wise
// false-alarm rate, as the other furnace tests).
TEST_F(TextureRendering, AWhiteTexturedDiffuseStaysInvisibleInAWhiteFurnace) {
    Image8 white{5, 4, std::vector<uint8_t>(5 * 4 * 3, 255)};
    write_png8(white, (dir_ / "white.png").string());
    const std::string scene = R"(<sensor type="perspective"><float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, -4, 1.5" target="0, 0, 0.4" up="0, 0, 1"/></transform></sensor>
        <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform>
          <bsdf type="twosided"><bsdf type="diffuse">)" + bitmap("reflectance", "white.png") + R"(</bsdf></bsdf></shape>
        <shape type="sphere"><point name="center" value="0, 0, 0.6"/><float name="radius" value="0.5"/>
          <bsdf type="diffuse">)" + checker("reflectance", "1") + R"(</bsdf></shape>)";
    const SceneDescription d = load(scene);
    ASSERT_TRUE(d.materials[0].varies);
    const RenderResult r = render_scene(d, "pt-mis", 12, 12, 1024, 8);
    const AgreementResult a = test_agreement(r.film.mean(), r.film.standard_error(), Image(12, 12, Rgb(0.5f)), Image());
    EXPECT_TRUE(a.agree) << a.describe();
    EXPECT_EQ(r.stats.invalid_samples, 0u);
}

// The frames: a normal map of (0.5, 0.5, 1) and a bump map of a constant height give the
// tangent frame itself.
TEST(TextureFrames, AFlatNormalMapAndAConstantBumpMapLeaveTheFrame) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1, 1);
    for (const FramePerturbation kind : {FramePerturbation::NormalMap, FramePerturbation::BumpMap}) {
        MaterialTextures t;
        t.perturbation = kind;
        t.perturbation_texture = std::make_shared<const Texture>(
            kind == FramePerturbation::NormalMap
                ? Texture(BitmapTexture(2, 2, std::vector<Rgb>(4, Rgb(0.5f, 0.5f, 1.0f))))
                : Texture(BitmapTexture(2, 2, std::vector<Rgb>(4, Rgb(0.7f)))));
        t.bump_scale = 3;
        for (int i = 0; i < 200; ++i) {
            const Vec3f n = normalize(Vec3f(u(rng), u(rng), u(rng)));
            const Vec3f dpdu = Vec3f(u(rng), u(rng), u(rng)) * 3.0f, dpdv = cross(n, dpdu) * 0.5f + n * u(rng);
            const Frame base = tangent_frame(n, dpdu);
            const Frame f = perturbed_frame(t, n, n, dpdu, dpdv, Vec2f(u(rng), u(rng)));
            for (const auto& [a, b] : {std::pair{f.n, base.n}, std::pair{f.s, base.s}, std::pair{f.t, base.t}})
                EXPECT_LT(length(a - b), 1e-5f) << int(kind) << " " << i;
            EXPECT_NEAR(dot(base.s, base.n), 0.0f, 1e-5f);
            EXPECT_NEAR(dot(base.s, normalize(dpdu - n * dot(n, dpdu))), 1.0f, 1e-5f);  // s along dp/du
        }
    }
}

// Mitsuba's tangent space: a normal map's red tilts the normal towards s (along dp/du), its
// green towards t = n x s, and blue 1 is the normal itself.
TEST(TextureFrames, NormalMapChannelsAreTheTangentFrame) {
    const Vec3f n = normalize(Vec3f(0.2f, -0.3f, 0.9f)), dpdu(1, 2, 0.5f);
    const Frame base = tangent_frame(n, dpdu);
    for (const Rgb& c : {Rgb(0.9f, 0.5f, 0.8f), Rgb(0.5f, 0.2f, 0.8f), Rgb(0.3f, 0.7f, 0.6f)}) {
        MaterialTextures t;
        t.perturbation = FramePerturbation::NormalMap;
        t.perturbation_texture = std::make_shared<const Texture>(ConstantTexture{c});
        const Frame f = perturbed_frame(t, n, n, dpdu, cross(n, dpdu), {0, 0});
        const Vec3f want = normalize(base.s * (2 * c.x - 1) + base.t * (2 * c.y - 1) + base.n * (2 * c.z - 1));
        EXPECT_LT(length(f.n - want), 1e-5f);
        EXPECT_NEAR(dot(f.s, f.n), 0.0f, 1e-6f);
        EXPECT_NEAR(dot(f.s, base.s), std::sqrt(1 - std::pow(dot(base.s, f.n), 2.0f)), 1e-5f);  // s: dp/du's direction, made orthogonal
    }
}

// The images: a diffuse floor with a flat normal map, and with a constant bump map, against
// the plain one (per-pixel z-tests, 1e-3 family-wise); a tilted normal map must be told apart.
TEST_F(TextureRendering, AFlatNormalMapRendersLikeNoNormalMap) {
    Image flat(2, 2, Rgb(0.5f, 0.5f, 1.0f)), tilted(2, 2, Rgb(0.85f, 0.5f, 0.86f));
    write_image(flat, (dir_ / "flat.exr").string());
    write_image(tilted, (dir_ / "tilted.exr").string());
    const auto scene = [&](const std::string& bsdf) {
        return load(R"(<sensor type="perspective"><float name="fov" value="45"/>
            <transform name="to_world"><lookat origin="0, -3, 2" target="0, 0, 0" up="0, 0, 1"/></transform></sensor>
            <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="180"/><translate x="1" z="1.5"/></transform>
                <emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
            <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate z="1" angle="30"/></transform>)" +
                    bsdf + "</shape>");
    };
    const std::string diffuse = R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf>)";
    const auto normalmap = [&](const std::string& file) {
        return "<bsdf type=\"normalmap\"><texture type=\"bitmap\" name=\"normalmap\"><string name=\"filename\" value=\"" + file +
               "\"/></texture>" + diffuse + "</bsdf>";
    };
    write_image(Image(3, 3, Rgb(0.4f)), (dir_ / "height.exr").string());
    const std::string bump = "<bsdf type=\"bumpmap\"><float name=\"scale\" value=\"5\"/>" + bitmap("height", "height.exr") + diffuse + "</bsdf>";
    const RenderResult plain = render_scene(scene(diffuse), "pt-mis", 16, 16, 256, 5);
    const auto agrees = [&](const std::string& bsdf) {
        const RenderResult r = render_scene(scene(bsdf), "pt-mis", 16, 16, 256, 6);
        const AgreementResult a = test_agreement(r.film.mean(), r.film.standard_error(), plain.film.mean(), plain.film.standard_error());
        return std::pair{a.agree, a.describe()};
    };
    const auto [flat_agrees, flat_why] = agrees(normalmap("flat.exr"));
    EXPECT_TRUE(flat_agrees) << flat_why;
    const auto [bump_agrees, bump_why] = agrees(bump);
    EXPECT_TRUE(bump_agrees) << bump_why;
    // Test of the test: a normal tilted by 45 degrees changes the image.
    const auto [tilted_agrees, tilted_why] = agrees(normalmap("tilted.exr"));
    EXPECT_FALSE(tilted_agrees) << tilted_why;
}

}  // namespace
}  // namespace pathlab::test
