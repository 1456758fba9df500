// Textured area emitters (<emitter type="area"><texture name="radiance">, Mitsuba 3's spatially
// varying area light; lights/triangle.hpp): seen directly, each pixel is the texel under it
// (closed form); the estimators that find the emitter by light sampling (its sampled point's
// uv), by BSDF sampling (the hit's uv), from the light (emission sampling) and in both
// directions agree by per-pixel z-tests, in RGB and spectral mode; and the reader refuses what
// it cannot render.
#include <gtest/gtest.h>

#include <filesystem>

#include "image/image_io.hpp"
#include "render_helpers.hpp"
#include "scratch_dir.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {


struct TextureDir : ScratchDir {
    TextureDir() : ScratchDir("pathlab-emitter-texture") {
        // 2 x 2 texels, as sRGB codes: top (230, 140, 60), (60, 140, 230); bottom (140, 230, 60),
        // (60, 230, 140).
        Image8 img;
        img.width = 2, img.height = 2;
        img.rgb = {230, 140, 60, 60, 140, 230, 140, 230, 60, 60, 230, 140};
        write_png8(img, path + "/sign.png");
    }
};

const char* kEmitter = R"(<emitter type="area"><texture type="bitmap" name="radiance"><string name="filename" value="sign.png"/>
    <string name="filter_type" value="nearest"/></texture></emitter>)";

// The camera looks along +z at the textured rectangle [-1, 1]^2 turned to face it at z = 2; its
// frame is 1 wide there (fov 2 atan(1/4) = 28.07 degrees on x): the rectangle's middle half.
SceneDescription facing(const std::string& dir) {
    return load_scene_text(std::string(R"(<scene version="3.0.0">
        <sensor type="perspective"><float name="fov" value="28.072486935852954"/><string name="fov_axis" value="x"/>
            <transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, 1" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film></sensor>
        <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="180"/><translate z="2"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>)") +
                               kEmitter + "</shape></scene>",
                           dir + "/facing.xml", dir);
}

TEST(TexturedEmitter, SeenDirectlyEachPixelIsItsTexel) {
    TextureDir dir;
    const SceneDescription d = facing(dir.path);
    // u = 1/2 and v = 1/2 (the texels' boundaries) lie on the image's middle boundaries: each
    // quarter shows one texel, exactly (nearest filtering, no light but the emitter's own).
    const Image img = render_scene(d, "pt-naive", 8, 8, 4, 1).film.mean();
    const auto texel = [](uint8_t r, uint8_t g, uint8_t b) { return Rgb(decode_srgb8(r), decode_srgb8(g), decode_srgb8(b)); };
    const Rgb texels[4] = {texel(230, 140, 60), texel(60, 140, 230), texel(140, 230, 60), texel(60, 230, 140)};
    const auto near = [](const Rgb& p, const Rgb& q) { return length(p - q) <= 1e-6f * length(q); };
    // The rectangle is turned about y to face the camera: which corner shows which texel depends
    // on its parameterisation; each quarter must show a different one, and every texel once.
    Rgb seen[4];
    int k = 0;
    for (int y : {1, 6})
        for (int x : {1, 6}) seen[k++] = img.at(x, y);
    for (int i = 0; i < 4; ++i) {
        int matches = 0;
        for (int j = 0; j < 4; ++j) matches += near(seen[i], texels[j]);
        EXPECT_EQ(matches, 1) << "quarter " << i << ": " << seen[i].x << " " << seen[i].y << " " << seen[i].z;
        for (int j = 0; j < i; ++j) EXPECT_FALSE(near(seen[i], seen[j])) << i << " " << j;
    }
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) EXPECT_TRUE(near(img.at(x, y), seen[(y < 4 ? 0 : 2) + (x < 4 ? 0 : 1)])) << x << "," << y;
}

// A diffuse floor lit by the textured rectangle above it, facing down and tilted away from the
// camera (which sees its unlit back).
SceneDescription lit_floor(const std::string& dir, bool spectral = false) {
    SceneDescription d = load_scene_text(std::string(R"(<scene version="3.0.0">
        <sensor type="perspective"><float name="fov" value="60"/>
            <transform name="to_world"><lookat origin="0, -2.6, 1.1" target="0, 0, 0" up="0, 0, 1"/></transform>
            <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/><rfilter type="box"/></film></sensor>
        <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></shape>
        <shape type="rectangle"><transform name="to_world"><scale x="1.2" y="0.8"/><rotate x="1" angle="200"/><translate z="1"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf>)") +
                                             kEmitter + "</shape></scene>",
                                         dir + "/floor.xml", dir);
    d.spectral = spectral;
    return d;
}

TEST(TexturedEmitter, LightBsdfAndEmissionSamplingAgree) {
    TextureDir dir;
    // direct-light finds the emitter by light sampling only, direct-brdf and pt-naive by BSDF
    // sampling only; lt and bdpt start at its sampled points.
    const SceneDescription d = lit_floor(dir.path);
    expect_estimators_agree(d, "direct-mis", {"direct-light", "direct-brdf"}, 12, 1024);  // direct light only
    expect_estimators_agree(d, "pt-mis", {"pt-naive", "lt", "bdpt"}, 12, 1024);
}

TEST(TexturedEmitter, SpectralModeAgreesWithRgbMode) {
    TextureDir dir;
    SceneDescription d = lit_floor(dir.path, true);
    expect_estimators_agree(d, "direct-mis", {"direct-light", "direct-brdf"}, 12, 1024);
    expect_estimators_agree(d, "pt-mis", {"bdpt"}, 12, 1024);
    const Image rgb = render_scene(lit_floor(dir.path), "pt-mis", 12, 12, 256, 5).film.mean();
    const Image spectral = render_scene(d, "pt-mis", 12, 12, 256, 5).film.mean();
    double a = 0, b = 0;
    for (size_t i = 0; i < rgb.pixel_count(); ++i) a += mean(rgb[i]), b += mean(spectral[i]);
    EXPECT_NEAR(b / a, 1.0, 0.05);  // upsampled emission, not the same numbers: means within 5%
}

void expect_refused(const std::string& shape, const std::string& words) {
    TextureDir dir;
    try {
        load_scene_text("<scene version=\"3.0.0\">" + shape + "</scene>", dir.path + "/bad.xml", dir.path);
        ADD_FAILURE() << "accepted: " << shape;
    } catch (const SceneFileError& e) {
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
}

TEST(TexturedEmitter, RefusesWhatItCannotRender) {
    expect_refused(std::string("<shape type=\"sphere\">") + kEmitter + "</shape>", "needs a mesh with texture coordinates");
    expect_refused(std::string("<shape type=\"disk\">") + kEmitter + "</shape>", "needs a mesh with texture coordinates");
    expect_refused(R"(<shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1"/>
        <texture type="bitmap" name="radiance"><string name="filename" value="sign.png"/></texture></emitter></shape>)",
                   "given twice");
    expect_refused(R"(<shape type="rectangle"><emitter type="area"><texture type="bitmap" name="irradiance">
        <string name="filename" value="sign.png"/></texture></emitter></shape>)",
                   "only nested plugin is its radiance");
}

}  // namespace
}  // namespace pathlab::test
