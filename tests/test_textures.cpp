// Textures on their own: the sRGB decode, bilinear weights and values, the wrap modes against
// an independent statement of each, nearest lookups, the uv transform, the checkerboard, the
// gradient bump maps use; and reading them from files (PNG, JPEG, EXR) and scene files,
// including every refusal (a clear message naming the file and line, never a crash).
#include <gtest/gtest.h>

#include <stb_image_write.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "cli_runner.hpp"
#include "image/image_io.hpp"
#include "scenefile/scene_file.hpp"
#include "textures/registry.hpp"
#include "textures/srgb.hpp"
#include "integrators/common/shading.hpp"
#include "job/render_job.hpp"
#include "job/usage_error.hpp"
#include "scene/scene.hpp"

namespace pathlab {
namespace {

namespace fs = std::filesystem;

// A texture of w x h texels whose values are their indices (distinct, grey).
BitmapTexture indexed(int w, int h, FilterType f = FilterType::Bilinear, WrapMode m = WrapMode::Repeat, UvTransform t = {}) {
    std::vector<Rgb> texels;
    for (int i = 0; i < w * h; ++i) texels.push_back(Rgb(float(i)));
    return BitmapTexture(w, h, std::move(texels), f, m, t);
}

TEST(Textures, SrgbDecodeIsTheStandardCurveAndInvertsTheEncoder) {
    const auto& t = srgb8_to_linear_table();
    EXPECT_EQ(t[0], 0.0f);
    EXPECT_EQ(t[255], 1.0f);
    EXPECT_FLOAT_EQ(t[10], float(10 / 255.0 / 12.92));                            // the linear segment
    EXPECT_FLOAT_EQ(t[128], float(std::pow((128 / 255.0 + 0.055) / 1.055, 2.4)));  // 0.2158605
    EXPECT_NEAR(t[128], 0.2158605f, 1e-6f);
    for (int v = 0; v < 256; ++v) {
        EXPECT_EQ(encode_srgb8(t[size_t(v)]), v) << v;  // pathlab's PNG writer's curve, inverted
        if (v > 0) {
            EXPECT_GT(t[size_t(v)], t[size_t(v - 1)]);
        }
    }
}

TEST(Textures, BilinearWeightsAndValues) {
    // 4 x 3 texels: texel (i, j) holds i + 4 j.
    const BitmapTexture tex = indexed(4, 3);
    // At a texel's centre: that texel, with weight 1 (up to the rounding of (j + 1/2) / 3).
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec2f uv((i + 0.5f) / 4, (j + 0.5f) / 3);
            EXPECT_NEAR(tex.eval(uv).x, float(i + 4 * j), 1e-5f);
            const TexelFootprint f = tex.footprint(uv);
            const int k = int(std::max_element(f.weight.begin(), f.weight.end()) - f.weight.begin());
            EXPECT_EQ(f.index[size_t(k)], uint32_t(i + 4 * j));
            EXPECT_NEAR(f.weight[size_t(k)], 1.0f, 1e-6f);
        }
    EXPECT_EQ(tex.eval({0.625f, 0.5f}).x, 6.0f);  // (2.5 / 4, 1.5 / 3) exactly: texel (2, 1) alone
    // A quarter of the way from texel (1, 0) to (2, 0) and a half from row 0 to row 1:
    // x = u 4 - 1/2 = 1.25, y = v 3 - 1/2 = 0.5.
    const Vec2f uv(1.75f / 4, 1.0f / 3);
    const TexelFootprint f = tex.footprint(uv);
    ASSERT_EQ(f.count, 4);
    const uint32_t want_index[4] = {1, 2, 5, 6};
    const float want_weight[4] = {0.75f * 0.5f, 0.25f * 0.5f, 0.75f * 0.5f, 0.25f * 0.5f};
    float sum = 0, value = 0;
    for (int k = 0; k < 4; ++k) {
        EXPECT_EQ(f.index[size_t(k)], want_index[k]);
        EXPECT_NEAR(f.weight[size_t(k)], want_weight[k], 1e-6f);
        sum += f.weight[size_t(k)];
        value += f.weight[size_t(k)] * float(f.index[size_t(k)]);
    }
    EXPECT_NEAR(sum, 1.0f, 1e-6f);
    EXPECT_NEAR(tex.eval(uv).x, 0.375f * 1 + 0.125f * 2 + 0.375f * 5 + 0.125f * 6, 1e-5f);  // 3.25
    EXPECT_NEAR(tex.eval(uv).x, value, 1e-5f);
    // Equal texels give exactly their value at every position (0.1f is not a sum of halves).
    const BitmapTexture flat(3, 2, std::vector<Rgb>(6, Rgb(0.1f, 0.7f, 0.3f)));
    for (float u = -1.3f; u < 2; u += 0.0731f)
        for (float v = -0.7f; v < 2; v += 0.1173f) EXPECT_EQ(flat.eval({u, v}), Rgb(0.1f, 0.7f, 0.3f));
}

// Each wrap mode against its plain statement on a row of n = 4 texels.
TEST(Textures, WrapModes) {
    const int n = 4;
    for (int i = -13; i <= 13; ++i) {
        const int repeat = ((i % n) + n) % n;
        const int period = ((i % (2 * n)) + 2 * n) % (2 * n);  // 0 1 2 3 3 2 1 0, repeated
        const int mirror = period < n ? period : 2 * n - 1 - period;
        const int clamp = std::clamp(i, 0, n - 1);
        EXPECT_EQ(indexed(n, 1, FilterType::Nearest, WrapMode::Repeat).wrap(i, n), repeat) << i;
        EXPECT_EQ(indexed(n, 1, FilterType::Nearest, WrapMode::Mirror).wrap(i, n), mirror) << i;
        EXPECT_EQ(indexed(n, 1, FilterType::Nearest, WrapMode::Clamp).wrap(i, n), clamp) << i;
    }
    // Lookups outside [0, 1]: texel i holds i.
    struct Case {
        float u;
        float repeat, mirror, clamp;
    };
    for (const Case& c : {Case{-0.1f, 3, 0, 0}, Case{1.1f, 0, 3, 3}, Case{1.9f, 3, 0, 3}, Case{2.1f, 0, 0, 3}, Case{-1.1f, 3, 3, 0}}) {
        EXPECT_EQ(indexed(n, 1, FilterType::Nearest, WrapMode::Repeat).eval({c.u, 0.5f}).x, c.repeat) << c.u;
        EXPECT_EQ(indexed(n, 1, FilterType::Nearest, WrapMode::Mirror).eval({c.u, 0.5f}).x, c.mirror) << c.u;
        EXPECT_EQ(indexed(n, 1, FilterType::Nearest, WrapMode::Clamp).eval({c.u, 0.5f}).x, c.clamp) << c.u;
    }
    // Bilinear at u = 0: halfway between texel -1 and texel 0.
    EXPECT_FLOAT_EQ(indexed(n, 1, FilterType::Bilinear, WrapMode::Repeat).eval({0.0f, 0.5f}).x, 1.5f);  // (3 + 0) / 2
    EXPECT_FLOAT_EQ(indexed(n, 1, FilterType::Bilinear, WrapMode::Mirror).eval({0.0f, 0.5f}).x, 0.0f);  // (0 + 0) / 2
    EXPECT_FLOAT_EQ(indexed(n, 1, FilterType::Bilinear, WrapMode::Clamp).eval({0.0f, 0.5f}).x, 0.0f);
    // Non-finite and enormous coordinates stay inside the image.
    for (const WrapMode m : {WrapMode::Repeat, WrapMode::Mirror, WrapMode::Clamp})
        for (const float u : {kInf, -kInf, std::nanf(""), 3e38f, -3e38f}) {
            const Rgb v = indexed(n, 1, FilterType::Bilinear, m).eval({u, u});
            EXPECT_TRUE(v.x >= 0 && v.x <= n - 1) << u;
        }
}

TEST(Textures, NearestLookupAndTheUvTransform) {
    // Nearest: texel (floor(u w), floor(v h)); row 0 is the top of the image, at small v.
    const BitmapTexture tex = indexed(4, 2, FilterType::Nearest);
    EXPECT_EQ(tex.eval({0.01f, 0.01f}).x, 0.0f);
    EXPECT_EQ(tex.eval({0.99f, 0.01f}).x, 3.0f);
    EXPECT_EQ(tex.eval({0.26f, 0.51f}).x, 5.0f);
    EXPECT_EQ(tex.footprint({0.26f, 0.51f}).count, 1);
    // to_uv from a <transform>: scale by 2 in u, then translate by 0.25 (a 4x4 matrix: its
    // upper-left 2x2 block and its translation column are kept).
    const Transform t = Transform::translate({0.25, 0, 7}) * Transform::scale({2, 1, 5});
    const UvTransform to_uv = UvTransform::from(t);
    EXPECT_EQ(to_uv.apply({0.1f, 0.3f}), Vec2f(0.45f, 0.3f));
    const BitmapTexture moved = indexed(4, 2, FilterType::Nearest, WrapMode::Repeat, to_uv);
    EXPECT_EQ(moved.eval({0.1f, 0.3f}).x, 1.0f);  // u' = 0.45: texel 1
}

TEST(Textures, CheckerboardSquares) {
    CheckerboardTexture c;
    c.color0 = Rgb(1, 0, 0), c.color1 = Rgb(0, 0, 1);
    EXPECT_EQ(c.eval({0.25f, 0.25f}), c.color0);
    EXPECT_EQ(c.eval({0.75f, 0.75f}), c.color0);
    EXPECT_EQ(c.eval({0.75f, 0.25f}), c.color1);
    EXPECT_EQ(c.eval({0.25f, 0.75f}), c.color1);
    EXPECT_EQ(c.eval({-0.25f, 0.25f}), c.color1);  // the pattern repeats
    c.to_uv = UvTransform::from(Transform::scale({4, 4, 1}));  // 8 x 8 squares
    EXPECT_EQ(c.eval({0.1f, 0.1f}), c.color0);
    EXPECT_EQ(c.eval({0.2f, 0.1f}), c.color1);
    // Scalars: a grey colour's value, else its luminance, with the colours' squares swapped as
    // Mitsuba 3's eval_1 swaps them.
    CheckerboardTexture g;
    g.color0 = Rgb(0.3f), g.color1 = Rgb(0.2f, 0.4f, 0.6f);
    EXPECT_EQ(g.eval_1({0.75f, 0.25f}), 0.3f);
    EXPECT_EQ(g.eval_1({0.25f, 0.25f}), luminance(g.color1));
}

// bumpmap's gradient: that of the bilinear interpolant, through the uv transform (against
// central differences inside one cell, where the interpolant is smooth).
TEST(Textures, ScalarGradientIsTheInterpolantsDerivative) {
    std::vector<Rgb> texels;
    for (int i = 0; i < 16; ++i) texels.push_back(Rgb(float((i * 7) % 5), float(i % 3), float(i % 4)));  // colours: luminance
    const UvTransform to_uv = UvTransform::from(Transform::rotate({0, 0, 1}, 30) * Transform::scale({1.5, 0.7, 1}));
    const BitmapTexture tex(4, 4, texels, FilterType::Bilinear, WrapMode::Repeat, to_uv);
    EXPECT_FALSE(tex.monochrome());
    for (const Vec2f uv : {Vec2f(0.31f, 0.42f), Vec2f(0.77f, 0.13f), Vec2f(0.52f, 0.61f)}) {
        const Vec2f g = tex.eval_1_grad(uv);
        const float h = 1e-3f;
        const float du = (tex.eval_1({uv.x + h, uv.y}) - tex.eval_1({uv.x - h, uv.y})) / (2 * h);
        const float dv = (tex.eval_1({uv.x, uv.y + h}) - tex.eval_1({uv.x, uv.y - h})) / (2 * h);
        EXPECT_NEAR(g.x, du, 2e-2f * (1 + std::abs(du))) << uv.x << " " << uv.y;
        EXPECT_NEAR(g.y, dv, 2e-2f * (1 + std::abs(dv))) << uv.x << " " << uv.y;
    }
    EXPECT_EQ(indexed(4, 4, FilterType::Nearest).eval_1_grad({0.3f, 0.3f}), Vec2f(0.0f, 0.0f));
}

// ---- files and scene files ---------------------------------------------------------------

class TextureFiles : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-textures-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    void write(const std::string& name, const std::string& bytes) const { std::ofstream(path(name), std::ios::binary) << bytes; }
    // An 8-bit image whose texel (x, y) holds (x * sx, y * sy, 200).
    static Image8 pattern8(int w, int h, int sx = 40, int sy = 60) {
        Image8 img{w, h, std::vector<uint8_t>(size_t(w * h * 3))};
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                uint8_t* p = &img.rgb[size_t(y * w + x) * 3];
                p[0] = uint8_t(x * sx), p[1] = uint8_t(y * sy), p[2] = 200;
            }
        return img;
    }
    void write_jpeg(const std::string& name, const Image8& img, int quality = 100) const {
        ASSERT_TRUE(stbi_write_jpg(path(name).c_str(), img.width, img.height, 3, img.rgb.data(), quality));
    }
    // A scene with one sphere whose BSDF is `bsdf`, after the top-level elements `before`.
    SceneDescription load(const std::string& bsdf, const std::string& before = "") const {
        return load_scene_text("<scene version=\"3.0.0\">" + before + "<shape type=\"sphere\">" + bsdf + "</shape></scene>",
                               path("scene.xml"), dir_.string());
    }
    // The message of the SceneFileError the scene raises (empty if it loads).
    std::string error_of(const std::string& bsdf, const std::string& before = "") const {
        try {
            load(bsdf, before);
        } catch (const SceneFileError& e) {
            return e.what();
        }
        return "";
    }
    fs::path dir_;
};

TEST_F(TextureFiles, PngIsDecodedFromSrgbUnlessRaw) {
    write_png8(pattern8(4, 3), path("p.png"));
    const BitmapTexture srgb = load_bitmap_texture(path("p.png"), false, FilterType::Nearest);
    const BitmapTexture raw = load_bitmap_texture(path("p.png"), true, FilterType::Nearest);
    ASSERT_EQ(srgb.width(), 4);
    ASSERT_EQ(srgb.height(), 3);
    const auto& table = srgb8_to_linear_table();
    // Texel (2, 1): (80, 60, 200).
    EXPECT_EQ(srgb.texels()[6], Rgb(table[80], table[60], table[200]));
    EXPECT_EQ(raw.texels()[6], Rgb(80 / 255.0f, 60 / 255.0f, 200 / 255.0f));
    EXPECT_TRUE(srgb.colour());
    EXPECT_FALSE(raw.colour());
}

TEST_F(TextureFiles, JpegAndExrAreRead) {
    write_jpeg("p.jpg", pattern8(16, 8, 10, 20));
    const BitmapTexture j = load_bitmap_texture(path("p.jpg"), true);
    EXPECT_EQ(j.width(), 16);
    EXPECT_EQ(j.height(), 8);
    // Lossy, but close at quality 100 (smooth ramps): texel (5, 3) is (50, 60, 200).
    EXPECT_NEAR(j.texels()[size_t(3 * 16 + 5)].x, 50 / 255.0f, 0.03f);
    EXPECT_NEAR(j.texels()[size_t(3 * 16 + 5)].y, 60 / 255.0f, 0.03f);
    EXPECT_NEAR(j.texels()[size_t(3 * 16 + 5)].z, 200 / 255.0f, 0.03f);
    Image img(3, 2);
    img.at(2, 1) = Rgb(7.5f, -0.25f, 0.125f);
    write_image(img, path("e.exr"));
    const BitmapTexture e = load_bitmap_texture(path("e.exr"), false);
    EXPECT_EQ(e.texels()[5], Rgb(7.5f, -0.25f, 0.125f));  // float images: as stored, raw or not
    EXPECT_EQ(e.min_value(), Rgb(0.0f, -0.25f, 0.0f));
}

TEST_F(TextureFiles, BmpIsReadAsStored) {
    // Mitsuba's test scenes use .bmp textures: 24 bits (stb_image_write's) read back exactly.
    const Image8 p = pattern8(5, 3, 10, 20);
    ASSERT_TRUE(stbi_write_bmp(path("p.bmp").c_str(), p.width, p.height, 3, p.rgb.data()));
    const BitmapTexture b = load_bitmap_texture(path("p.bmp"), true);
    ASSERT_EQ(b.width(), 5);
    ASSERT_EQ(b.height(), 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x)
            for (int c = 0; c < 3; ++c) EXPECT_EQ(b.texels()[size_t(y * 5 + x)][c], p.at(x, y, c) / 255.0f) << x << "," << y;
}

TEST_F(TextureFiles, UnreadableTruncatedAndUnsupportedImagesNameTheFile) {
    write_png8(pattern8(8, 8), path("good.png"));
    std::ifstream in(path("good.png"), std::ios::binary);
    const std::string png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    write("cut.png", png.substr(0, png.size() / 2));
    write_jpeg("good.jpg", pattern8(32, 32));
    std::ifstream jin(path("good.jpg"), std::ios::binary);
    const std::string jpg((std::istreambuf_iterator<char>(jin)), std::istreambuf_iterator<char>());
    write("cut.jpg", jpg.substr(0, jpg.size() - 40));
    write("fake.jpg", "not a jpeg at all");
    write("image.bmp", "BM....");
    write("image.tga", "......");
    const std::pair<const char*, const char*> cases[] = {
        {"missing.png", "missing.png"},
        {"cut.png", "cut.png: cannot read PNG"},
        {"cut.jpg", "cut.jpg: cannot read JPEG: truncated"},
        {"fake.jpg", "fake.jpg: cannot read JPEG: not a JPEG file"},
        {"image.bmp", "image.bmp: cannot read BMP: not a BMP file (it is 6 bytes long)"},
        {"image.tga", "unsupported texture image '.tga' (supported: .png, .jpg, .jpeg, .bmp, .exr, .hdr, .pfm)"},
    };
    for (const auto& [file, needle] : cases) {
        const std::string e = error_of(std::string("<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"") +
                                       file + "\"/></texture></bsdf>");
        EXPECT_NE(e.find("scene.xml:1:"), std::string::npos) << e;  // the file and line of the element
        EXPECT_NE(e.find("cannot read the texture"), std::string::npos) << e;
        EXPECT_NE(e.find(needle), std::string::npos) << file << ": " << e;
    }
    // The command line: exit code 2 and the message.
    std::ofstream(path("cli.xml")) << "<scene version=\"3.0.0\"><shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" "
                                      "name=\"reflectance\"><string name=\"filename\" value=\"cut.jpg\"/></texture></bsdf></shape></scene>";
    const test::CliResult r = test::run({"--scene", path("cli.xml"), "--spp", "1", "-q", "-o", path("out.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(test::contains(r.err, "cut.jpg: cannot read JPEG: truncated")) << r.err;
}

TEST_F(TextureFiles, TexturesAreBoundToBsdfParameters) {
    write_png8(pattern8(4, 4), path("wall.png"));
    const SceneDescription d = load(
        R"(<bsdf type="roughconductor"><ref name="specular_reflectance" id="wall"/>
             <texture type="checkerboard" name="alpha_u"><float name="color0" value="0.05"/><float name="color1" value="0.4"/></texture>
             <float name="alpha_v" value="0.2"/></bsdf>)",
        R"(<texture type="bitmap" id="wall"><string name="filename" value="wall.png"/><string name="filter_type" value="nearest"/>
             <string name="wrap_mode" value="clamp"/><boolean name="raw" value="true"/>
             <transform name="to_uv"><scale x="2" y="3"/></transform></texture>)");
    ASSERT_EQ(d.materials.size(), 1u);
    const Material& m = d.materials[0];
    ASSERT_TRUE(m.textures);
    EXPECT_TRUE(m.varies);
    EXPECT_TRUE(m.tangent_frame);  // alpha_u textured: anisotropic
    ASSERT_EQ(m.textures->bindings.size(), 2u);
    EXPECT_EQ(m.textures->bindings[0].param, "specular_reflectance");
    EXPECT_FALSE(m.textures->bindings[0].scalar);
    EXPECT_EQ(m.textures->bindings[1].param, "alpha_u");
    EXPECT_TRUE(m.textures->bindings[1].scalar);
    const auto& bitmap = std::get<BitmapTexture>(m.textures->bindings[0].texture->model());
    EXPECT_EQ(bitmap.filter(), FilterType::Nearest);
    EXPECT_EQ(bitmap.wrap_mode(), WrapMode::Clamp);
    EXPECT_FALSE(bitmap.colour());
    EXPECT_EQ(bitmap.to_uv().apply({0.5f, 0.5f}), Vec2f(1.0f, 1.5f));
    // The constant model holds the textures' largest values (its lobe flags follow them).
    const auto& rc = std::get<RoughConductorMaterial>(m.model);
    EXPECT_EQ(rc.distribution.alpha_u, 0.4f);
    EXPECT_EQ(rc.distribution.alpha_v, 0.2f);
    // At a hit: the values there (uv (0.3, 0.1): a colour's color0 square, so a float's color1,
    // as Mitsuba's eval_1 swaps them).
    const auto at = std::get<RoughConductorMaterial>(m.model_at({0.3f, 0.1f}));
    EXPECT_EQ(at.distribution.alpha_u, 0.4f);
    EXPECT_EQ(at.distribution.alpha_v, 0.2f);
    // uv' = (0.6, 0.3) -> clamped nearest texel (2, 1) of the raw image: (80, 60, 200) / 255.
    EXPECT_EQ(at.specular_reflectance, Rgb(80 / 255.0f, 60 / 255.0f, 200 / 255.0f));

    // normalmap and bumpmap wrap a BSDF (in either order with twosided) and give it a frame.
    const SceneDescription n = load(
        R"(<bsdf type="twosided"><bsdf type="normalmap"><texture type="bitmap" name="normalmap"><string name="filename" value="wall.png"/>
             <boolean name="raw" value="true"/></texture><bsdf type="diffuse"><ref name="reflectance" id="wall"/></bsdf></bsdf></bsdf>)",
        R"(<texture type="bitmap" id="wall"><string name="filename" value="wall.png"/></texture>)");
    const Material& nm = n.materials[0];
    EXPECT_TRUE(nm.two_sided);
    EXPECT_TRUE(nm.perturbed());
    EXPECT_TRUE(nm.tangent_frame);
    EXPECT_EQ(nm.textures->perturbation, FramePerturbation::NormalMap);
    EXPECT_EQ(nm.textures->bindings.size(), 1u);
    // Models with derived values recompute them: a rough plastic textured at 0.2 where the
    // texture is 0.2 is the rough plastic of 0.2 (its base rho' / (pi eta^2) and lobe weight).
    const SceneDescription rp = load(R"(<bsdf type="roughplastic"><texture type="checkerboard" name="diffuse_reflectance">
             <rgb name="color0" value="0.2, 0.3, 0.4"/><rgb name="color1" value="0.8"/></texture></bsdf>)");
    const SceneDescription rp_constant = load(R"(<bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.2, 0.3, 0.4"/></bsdf>)");
    const auto rp_at = std::get<RoughPlasticMaterial>(rp.materials[0].model_at({0.25f, 0.25f}));
    const auto& rp_want = std::get<RoughPlasticMaterial>(rp_constant.materials[0].model);
    EXPECT_EQ(rp_at.coat.base, rp_want.coat.base);
    EXPECT_EQ(rp_at.coat.specular_weight, rp_want.coat.specular_weight);
    EXPECT_NE(std::get<RoughPlasticMaterial>(rp.materials[0].model).coat.base, rp_want.coat.base);  // the 0.8 placeholder's
    const SceneDescription bm = load(
        R"(<bsdf type="bumpmap"><float name="scale" value="0.25"/><bsdf type="twosided"><bsdf type="roughplastic"/></bsdf>
             <texture type="checkerboard" name="whatever"/></bsdf>)");
    EXPECT_EQ(bm.materials[0].textures->perturbation, FramePerturbation::BumpMap);
    EXPECT_EQ(bm.materials[0].textures->bump_scale, 0.25f);
    EXPECT_TRUE(bm.materials[0].two_sided);
}

// Mitsuba 3's normalmap options, on by default (material_textures.hpp): the shadowing term in
// closed form, the flip of a tilted normal that the incoming direction sees from behind, and the
// BSDF they give; off, the reciprocal map of before. A rectangle in the xy plane (n = z, dp/du
// along x) whose map tilts the normal to n' = (0, -0.6, 0.8).
TEST_F(TextureFiles, NormalMapFlipsInvalidNormalsAndShadowsAsMitsuba) {
    // G = 2 / (1 + sqrt(1 + a^2 tan^2 theta_o)), a^2 = min(tan^2 theta_p / 8, 1).
    EXPECT_FLOAT_EQ(bump_shadowing(1.0f, 0.3f), 1.0f);  // an untilted normal: no shadowing
    EXPECT_FLOAT_EQ(bump_shadowing(0.6f, 1.0f), 1.0f);  // wo along the normal
    EXPECT_NEAR(bump_shadowing(std::sqrt(0.5f), 0.5f), 2 / (1 + std::sqrt(1 + 0.125 * 3)), 1e-6);
    EXPECT_NEAR(bump_shadowing(0.2f, 0.5f), 2 / (1 + std::sqrt(1 + 1.0 * 3)), 1e-6);  // a^2 capped at 1
    const auto scene_of = [&](const std::string& options) {
        return Scene::build(load_scene_text(R"(<scene version="3.0.0"><shape type="rectangle"><bsdf type="normalmap">
            <texture type="rawconstant" name="normalmap"><vector name="value" value="0.5, 0.2, 0.9"/></texture>)" + options +
                                                R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></bsdf></shape></scene>)",
                                            path("scene.xml"), dir_.string()));
    };
    const auto mitsuba = scene_of(""), flip_only = scene_of(R"(<boolean name="use_shadowing_function" value="false"/>)"),
               reciprocal = scene_of(R"(<boolean name="flip_invalid_normals" value="false"/><boolean name="use_shadowing_function" value="false"/>)");
    const Vec3f tilted = normalize(Vec3f(0, -0.6f, 0.8f)), mirrored = normalize(Vec3f(0, 0.6f, 0.8f));
    const auto at = [](const Scene& scene, const Vec3f& wi) {
        Intersection hit;
        EXPECT_TRUE(scene.intersect(Ray{wi * 2.0f, -wi}, hit));
        return make_shading_point(scene, hit, -wi);
    };
    // Seen from (0, 0.9, 0.3): above the surface, behind n' (wi.n' < 0), so n' is mirrored about n.
    const Vec3f wi = normalize(Vec3f(0, 0.9f, 0.3f)), wo = normalize(Vec3f(0.8f, 0.3f, 0.3f));
    for (const auto* s : {mitsuba.get(), flip_only.get()}) {
        const ShadingPoint sp = at(*s, wi);
        EXPECT_NEAR(dot(sp.frame.n, mirrored), 1, 1e-5);
    }
    EXPECT_NEAR(dot(at(*reciprocal, wi).frame.n, tilted), 1, 1e-5);
    // Seen from (0, -0.9, 0.3): in front of n' too, no flip.
    EXPECT_NEAR(dot(at(*mitsuba, normalize(Vec3f(0, -0.9f, 0.3f))).frame.n, tilted), 1, 1e-5);
    // The BSDF at the flipped frame: the diffuse's 0.5 / pi, times G(n'.n, wo.n) with the shadowing term.
    const ShadingPoint m = at(*mitsuba, wi), f = at(*flip_only, wi);
    const float G = bump_shadowing(0.8f, wo.z);
    EXPECT_NEAR(m.material->eval(m, m.wi, m.frame.to_local(wo)).x, 0.5f / kPi * G, 1e-6);
    EXPECT_NEAR(f.material->eval(f, f.wi, f.frame.to_local(wo)).x, 0.5f / kPi, 1e-6);
    EXPECT_LT(G, 0.9f);  // (a grazing wo: a real attenuation)
    // A direction above n' but below n (Mitsuba's rule: both must see it on one side) is black.
    const Vec3f below = normalize(Vec3f(0, 0.9f, -0.1f));
    ASSERT_GT(dot(below, m.frame.n), 0);
    EXPECT_EQ(m.material->eval(m, m.wi, m.frame.to_local(below)).x, 0.0f);
    // Sampling carries the same factor: f cos / pdf of the diffuse is its albedo, times G.
    Sampler sampler(7, 0, 0);
    for (int i = 0; i < 64; ++i) {
        const auto s = m.material->sample(m, m.wi, sampler.next2d());
        if (!s) continue;
        const Vec3f w = m.frame.to_world(s->wo);
        EXPECT_NEAR(s->f.x * s->wo.z / s->pdfW, 0.5f * bump_shadowing(0.8f, w.z), 1e-5);
    }
    // Not reciprocal: the integrators that scatter light paths with the adjoint BSDF refuse it.
    const auto refusal = [&](const std::string& algorithm, const std::string& options) {
        JobRequest r;
        r.algorithm = algorithm;
        try {
            RenderJob job(scene_choice_of(load_scene_text(R"(<scene version="3.0.0"><sensor type="perspective"/><shape type="rectangle">
              <bsdf type="normalmap" id="wall"><texture type="rawconstant" name="normalmap"><vector name="value" value="0.5, 0.2, 0.9"/></texture>)" +
                                                              options + R"(<bsdf type="diffuse"/></bsdf></shape></scene>)",
                                                          path("scene.xml"), dir_.string())),
                          r);
        } catch (const UsageError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(refusal("bdpt", "").find("'wall' has a normalmap with Mitsuba's flip_invalid_normals"), std::string::npos) << refusal("bdpt", "");
    EXPECT_NE(refusal("lt", R"(<boolean name="flip_invalid_normals" value="false"/>)").find("not reciprocal"), std::string::npos);
    EXPECT_EQ(refusal("bdpt", R"(<boolean name="flip_invalid_normals" value="false"/><boolean name="use_shadowing_function" value="false"/>)"), "");
    EXPECT_EQ(refusal("pt-mis", ""), "");
}

// Mitsuba 3's rawconstant (the identity normal map of its render tests) and bitmap's storage
// format (accepted: pathlab stores floats).
TEST_F(TextureFiles, RawConstantAndBitmapFormat) {
    write_png8(pattern8(2, 2), path("t.png"));
    const SceneDescription n = load(
        R"(<bsdf type="normalmap"><texture type="rawconstant" name="normalmap"><vector name="value" value="0.5, 0.5, 1"/></texture>
             <bsdf type="diffuse"/></bsdf>)");
    ASSERT_TRUE(n.materials[0].textures);
    EXPECT_EQ(n.materials[0].textures->perturbation, FramePerturbation::NormalMap);
    const SceneDescription f = load(R"(<bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/>
             <string name="format" value="variant"/></texture></bsdf>)");
    const SceneDescription plain = load(R"(<bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/>
             </texture></bsdf>)");
    EXPECT_EQ(std::get<PhongMaterial>(f.materials[0].model_at({0.3f, 0.7f})).diffuse,
              std::get<PhongMaterial>(plain.materials[0].model_at({0.3f, 0.7f})).diffuse);
}

TEST_F(TextureFiles, RefusalsSayWhatIsWrongAndWhere) {
    write_png8(pattern8(2, 2), path("t.png"));
    Image negative(2, 2, Rgb(0.5f));
    negative.at(1, 1) = Rgb(0.5f, -1.0f, 0.5f);
    write_image(negative, path("neg.exr"));
    const std::string bitmap = R"(<texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/></texture>)";
    const std::string checker = R"(<texture type="checkerboard" name="NAME"/>)";
    const auto checker_as = [&](const std::string& name) { return std::string(checker).replace(checker.find("NAME"), 4, name); };
    struct Case {
        std::string bsdf, before, needle;
    };
    const std::vector<Case> cases = {
        {"<bsdf type=\"dielectric\">" + checker_as("int_ior") + "</bsdf>", "",
         "parameter 'int_ior' of <bsdf type=\"dielectric\"> cannot be a texture; those that can: none"},
        {"<bsdf type=\"roughplastic\">" + checker_as("alpha") + "</bsdf>", "",
         "parameter 'alpha' of <bsdf type=\"roughplastic\"> cannot be a texture; those that can: diffuse_reflectance, specular_reflectance"},
        {"<bsdf type=\"diffuse\">" + checker_as("colour") + "</bsdf>", "", "parameter 'colour' of <bsdf type=\"diffuse\"> cannot be a texture"},
        {"<bsdf type=\"diffuse\"><texture type=\"checkerboard\"/></bsdf>", "", "needs the name of the parameter it gives (reflectance)"},
        {"<bsdf type=\"diffuse\"><texture type=\"noise\" name=\"reflectance\"/></bsdf>", "",
         "unsupported texture type 'noise'; supported: bitmap, checkerboard, rawconstant, mesh_attribute"},
        {"<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"/></bsdf>", "", "needs <string name=\"filename\""},
        {"<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t.png\"/>"
         "<string name=\"filter_type\" value=\"trilinear\"/></texture></bsdf>",
         "", "unsupported filter_type 'trilinear'; supported: bilinear, nearest"},
        {"<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t.png\"/>"
         "<string name=\"wrap_mode\" value=\"border\"/></texture></bsdf>",
         "", "unsupported wrap_mode 'border'; supported: repeat, mirror, clamp"},
        {"<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t.png\"/>"
         "<string name=\"format\" value=\"half\"/></texture></bsdf>",
         "", "unsupported format 'half'; supported: auto, variant, fixed"},
        {"<bsdf type=\"normalmap\"><texture type=\"rawconstant\" name=\"normalmap\"/><bsdf type=\"diffuse\"/></bsdf>", "",
         "needs <vector name=\"value\""},
        {"<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t.png\"/>"
         "<float name=\"gamma\" value=\"2\"/></texture></bsdf>",
         "", "unsupported parameter 'gamma' for <texture type=\"bitmap\">; supported: filename, filter_type, wrap_mode, raw, format, to_uv"},
        {"<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"neg.exr\"/></texture></bsdf>",
         "", "the texture for 'reflectance' has negative values (down to -1); it must not be negative"},
        {"<bsdf type=\"diffuse\">" + bitmap + "<rgb name=\"reflectance\" value=\"0.5\"/></bsdf>", "", "parameter 'reflectance' is given twice"},
        {"<bsdf type=\"diffuse\"><ref name=\"reflectance\" id=\"nowhere\"/></bsdf>", "", "no <texture> with id 'nowhere' is declared"},
        {"<bsdf type=\"diffuse\"><ref name=\"reflectance\" id=\"m\"/></bsdf>", "<bsdf type=\"diffuse\" id=\"m\"/>", "'m' is a <bsdf> (declared at"},
        {"<ref id=\"t\"/>", "<texture type=\"checkerboard\" id=\"t\"/>", "'t' is a <texture>; a shape refers to a <bsdf>"},
        {"<bsdf type=\"diffuse\"/>", "<texture type=\"checkerboard\"/>", "a top-level <texture> needs an id"},
        {"<bsdf type=\"diffuse\"/>", "<texture type=\"checkerboard\" id=\"a\"/><bsdf type=\"diffuse\" id=\"a\"/>", "the id 'a' is already used"},
        {"<bsdf type=\"diffuse\"><texture type=\"checkerboard\" name=\"reflectance\"><texture type=\"checkerboard\" name=\"color0\"/></texture></bsdf>",
         "", "<texture type=\"checkerboard\"> has no nested plugins (its colours are constants)"},
        {"<bsdf type=\"normalmap\"><bsdf type=\"diffuse\"/></bsdf>", "", "<bsdf type=\"normalmap\"> needs a texture"},
        {"<bsdf type=\"normalmap\">" + checker_as("height") + "<bsdf type=\"diffuse\"/></bsdf>", "",
         "the texture of a normalmap must be named \"normalmap\""},
        {"<bsdf type=\"bumpmap\">" + checker_as("h") + "</bsdf>", "", "<bsdf type=\"bumpmap\"> wraps exactly one nested <bsdf>"},
        {"<bsdf type=\"bumpmap\">" + checker_as("h") + "<bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/></bsdf>", "",
         "<bsdf type=\"bumpmap\"> wraps exactly one nested <bsdf>"},
        {"<bsdf type=\"bumpmap\">" + checker_as("h") + checker_as("g") + "<bsdf type=\"diffuse\"/></bsdf>", "",
         "<bsdf type=\"bumpmap\"> takes exactly one texture"},
        {"<bsdf type=\"bumpmap\">" + checker_as("h") + "<bsdf type=\"bumpmap\">" + checker_as("h") + "<bsdf type=\"diffuse\"/></bsdf></bsdf>",
         "", "this BSDF already has a normal or bump map"},
        {"<bsdf type=\"twosided\">" + checker_as("h") + "<bsdf type=\"diffuse\"/></bsdf>", "", "unsupported element <texture> in <bsdf type=\"twosided\">"},
        {"<bsdf type=\"mask\"><ref id=\"d\"/></bsdf>", "<bsdf type=\"normalmap\" id=\"d\">" + checker_as("normalmap") + "<bsdf type=\"diffuse\"/></bsdf>",
         "a normal or bump map inside mask is not supported"},
        {"<bsdf type=\"diffuse\"><bsdf type=\"diffuse\"/></bsdf>", "", "<bsdf type=\"diffuse\"> has no nested <bsdf>; its parameters that may be textures: reflectance"},
    };
    for (const Case& c : cases) {
        const std::string e = error_of(c.bsdf, c.before);
        EXPECT_NE(e.find(c.needle), std::string::npos) << c.bsdf << "\n  gave: " << e << "\n  expected: " << c.needle;
        EXPECT_NE(e.find("scene.xml:1:"), std::string::npos) << e;
    }
    // A twosided BSDF may wrap a declared one by reference, and a bumpmap a declared texture.
    EXPECT_EQ(error_of("<bsdf type=\"bumpmap\"><ref id=\"h\"/><ref id=\"d\"/></bsdf>",
                       "<bsdf type=\"diffuse\" id=\"d\"/><texture type=\"checkerboard\" id=\"h\"/>"),
              "");
}


// ---- mesh attributes ----------------------------------------------------------------------

// Mitsuba 3's mesh_attribute: a PLY's extra vertex and face properties, named as Mitsuba names
// them, spread to the corners of the triangles its polygons become, and looked up at a hit with
// its barycentrics (closed forms on a quad).
TEST_F(TextureFiles, MeshAttributesFromPlyPropertiesAreLookedUpAtTheHit) {
    write("quad.ply", R"(ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property float color_0
property float color_1
property float color_2
element face 1
property list uchar int vertex_indices
property float weight_0
property uchar r
property uchar g
property uchar b
end_header
0 0 0 0.1 0.2 0.3
1 0 0 0.4 0.5 0.6
1 1 0 0.7 0.8 0.9
0 1 0 1.0 0.0 0.5
4 0 1 2 3 0.25 51 102 255
)");
    const auto scene_with = [&](const std::string& bsdf) {
        return load_scene_text(R"(<scene version="3.0.0"><shape type="ply"><string name="filename" value="quad.ply"/>)" + bsdf +
                                   "</shape></scene>",
                               path("scene.xml"), dir_.string());
    };
    const SceneDescription d = scene_with(R"(<bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance">
        <string name="name" value="vertex_color"/></texture></bsdf>)");
    ASSERT_EQ(d.meshes.size(), 1u);
    const MeshAttributes& a = d.meshes[0].attributes;
    ASSERT_EQ(a.size(), 3u);
    EXPECT_EQ(a[0].name, "vertex_color");
    EXPECT_FALSE(a[0].per_face);
    EXPECT_EQ(a[0].channels, 3);
    // Triangles (0, 1, 2) and (0, 2, 3): their corners' colours.
    EXPECT_EQ(a[0].values, (std::vector<float>{0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f,  //
                                               0.1f, 0.2f, 0.3f, 0.7f, 0.8f, 0.9f, 1.0f, 0.0f, 0.5f}));
    EXPECT_EQ(a[1].name, "face_color");  // r, g, b of unsigned chars, over 255
    EXPECT_EQ(a[1].values, (std::vector<float>{0.2f, 0.4f, 1.0f, 0.2f, 0.4f, 1.0f}));
    EXPECT_EQ(a[2].name, "face_weight");
    EXPECT_TRUE(a[2].per_face);
    EXPECT_EQ(a[2].values, (std::vector<float>{0.25f, 0.25f}));

    // At (0.75, 0.25) in triangle (0, 1, 2): barycentrics 0.25, 0.5, 0.25, colour (0.4, 0.5, 0.6).
    const auto reflectance_at = [](const SceneDescription& desc, float x, float y) {
        const std::unique_ptr<Scene> scene = Scene::build(desc);
        Intersection hit;
        EXPECT_TRUE(scene->intersect(Ray{Vec3f(x, y, 1), Vec3f(0, 0, -1)}, hit));
        const ShadingPoint sp = make_shading_point(*scene, hit, Vec3f(0, 0, -1));
        return std::get<PhongMaterial>(sp.material->model_at(sp.uv)).diffuse;
    };
    const SceneDescription constant = scene_with(R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.4, 0.5, 0.6"/></bsdf>)");
    const Rgb expected = std::get<PhongMaterial>(constant.materials[0].model).diffuse, got = reflectance_at(d, 0.75f, 0.25f);
    EXPECT_NEAR(got.x, expected.x, 1e-6f);
    EXPECT_NEAR(got.y, expected.y, 1e-6f);
    EXPECT_NEAR(got.z, expected.z, 1e-6f);
    // The face's own value, times scale, anywhere on it: a blend's weight.
    const SceneDescription blend = scene_with(R"(<bsdf type="blendbsdf"><texture type="mesh_attribute" name="weight">
        <string name="name" value="face_weight"/><float name="scale" value="0.5"/></texture><bsdf type="diffuse"/><bsdf type="conductor"/></bsdf>)");
    const std::unique_ptr<Scene> scene = Scene::build(blend);
    for (const Vec2f at : {Vec2f(0.75f, 0.25f), Vec2f(0.1f, 0.8f)}) {
        Intersection hit;
        ASSERT_TRUE(scene->intersect(Ray{Vec3f(at.x, at.y, 1), Vec3f(0, 0, -1)}, hit));
        const ShadingPoint sp = make_shading_point(*scene, hit, Vec3f(0, 0, -1));
        EXPECT_FLOAT_EQ(std::get<BlendMaterial>(sp.material->model_at(sp.uv)).weight, 0.125f);
    }
    // What a shape must have for its BSDF's mesh_attribute textures.
    const auto error_with = [&](const std::string& scene) -> std::string {
        try {
            load_scene_text("<scene version=\"3.0.0\">" + scene + "</scene>", path("scene.xml"), dir_.string());
        } catch (const SceneFileError& e) {
            return e.what();
        }
        return "";
    };
    const std::string ply = R"(<shape type="ply"><string name="filename" value="quad.ply"/>)";
    const std::string tex = R"(<texture type="mesh_attribute" name="reflectance"><string name="name" value="NAME"/></texture>)";
    const auto tex_of = [&](const std::string& n) { return std::string(tex).replace(tex.find("NAME"), 4, n); };
    for (const auto& [scene, message] : std::vector<std::pair<std::string, std::string>>{
             {ply + "<bsdf type=\"diffuse\">" + tex_of("vertex_normal") + "</bsdf></shape>",
              "reads the mesh attribute 'vertex_normal' (mesh_attribute), which mesh 'quad.ply' does not have; it has: vertex_color, "
              "face_color, face_weight"},
             {"<shape type=\"sphere\"><bsdf type=\"diffuse\">" + tex_of("vertex_color") + "</bsdf></shape>", "and a sphere has none"},
             {"<shape type=\"rectangle\"><bsdf type=\"diffuse\">" + tex_of("vertex_color") + "</bsdf></shape>",
              "it has: none (only PLY files give attributes)"},
             {ply + R"(<bsdf type="blendbsdf"><texture type="mesh_attribute" name="weight"><string name="name" value="vertex_color"/></texture>
                  <bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)",
              "the mesh attribute 'vertex_color' has 3 channels, and the parameter reading it takes one value"},
             {"<bsdf type=\"diffuse\" id=\"m\">" + tex_of("vertex_color") + "</bsdf><shape type=\"shapegroup\" id=\"g\">" + ply +
                  "<ref id=\"m\"/></shape></shape>",
              "which an instance's mesh does not keep"},
             {"<bsdf type=\"diffuse\">" + tex_of("color") + "</bsdf>", "a mesh attribute's name starts with vertex_ or face_, not 'color'"},
         }) {
        const std::string e = error_with(scene);
        EXPECT_NE(e.find(message), std::string::npos) << e;
        EXPECT_NE(e.find("scene.xml:1:"), std::string::npos) << e;
    }
    write("bright.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float "
                        "glow\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0\n1 0 0 2\n0 1 0 1\n3 0 1 2\n");
    const std::string e = error_with(R"(<shape type="ply"><string name="filename" value="bright.ply"/><bsdf type="diffuse">)" +
                                     tex_of("vertex_glow") + "</bsdf></shape>");
    EXPECT_NE(e.find("the mesh attribute 'vertex_glow' of mesh 'bright.ply' has values from 0 to 2"), std::string::npos) << e;
}

}  // namespace
}  // namespace pathlab
