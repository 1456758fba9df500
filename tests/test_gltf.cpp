// glTF 2.0 scenes (scenefile/gltf_scene.hpp): the shipped scene renders bit for bit as its
// converted XML (and its .gltf twin as its .glb); closed forms on scenes written here: an
// emissive quad seen through the camera's yfov covers exactly the pixels it should, with
// emissiveFactor times emissive strength, also under a mirroring node (the winding reversed);
// lights in candela and lux (683 lm/W); a base colour factor times its texture baked linear;
// and what cannot be rendered is refused naming the file.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "image/image_io.hpp"
#include "lights/registry.hpp"
#include "core/input_file.hpp"
#include "render_helpers.hpp"
#include "scratch_dir.hpp"
#include "scenefile/gltf_scene.hpp"

namespace pathlab::test {
namespace {

using nlohmann::json;

const std::string kSource = PATHLAB_SOURCE_DIR;

struct TempDir : ScratchDir {
    TempDir() : ScratchDir("pathlab-gltf-test") {}
};

std::string base64(const std::string& bytes) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (i + 2 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 2]));
        out += k[(v >> 18) & 63];
        out += k[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? k[v & 63] : '=';
    }
    return out;
}

// A glTF document built in memory, its one buffer a data: URI.
struct Gltf {
    json doc = {{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", json::array()}}}}, {"nodes", json::array()},
                {"meshes", json::array()}, {"materials", json::array()}, {"accessors", json::array()}, {"bufferViews", json::array()}};
    std::string blob;

    int view(const std::string& bytes) {
        while (blob.size() % 4) blob.push_back('\0');
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", blob.size()}, {"byteLength", bytes.size()}});
        blob += bytes;
        return int(doc["bufferViews"].size()) - 1;
    }
    int accessor(const std::vector<float>& v, const char* type, int components) {
        doc["accessors"].push_back({{"bufferView", view(std::string(reinterpret_cast<const char*>(v.data()), v.size() * 4))},
                                    {"componentType", 5126},
                                    {"count", v.size() / size_t(components)},
                                    {"type", type}});
        return int(doc["accessors"].size()) - 1;
    }
    // The quad x in [x0, x1], y in [-h, h] at z, facing +z, as triangles (mode 4), a strip (5)
    // or a fan (6); returns its mesh index.
    int quad(float x0, float x1, float h, float z, int material, int mode = 4) {
        const std::vector<float> pos = {x0, -h, z, x1, -h, z, x1, h, z, x0, h, z};
        const std::vector<float> nrm = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
        const std::vector<float> uv = {0, 1, 1, 1, 1, 0, 0, 0};
        const std::vector<uint32_t> idx = mode == 5 ? std::vector<uint32_t>{0, 1, 3, 2}
                                          : mode == 6 ? std::vector<uint32_t>{0, 1, 2, 3}
                                                      : std::vector<uint32_t>{0, 1, 2, 0, 2, 3};
        doc["accessors"].push_back({{"bufferView", view(std::string(reinterpret_cast<const char*>(idx.data()), idx.size() * 4))},
                                    {"componentType", 5125},
                                    {"count", idx.size()},
                                    {"type", "SCALAR"}});
        const int indices = int(doc["accessors"].size()) - 1;
        json prim = {{"attributes", {{"POSITION", accessor(pos, "VEC3", 3)}, {"NORMAL", accessor(nrm, "VEC3", 3)}, {"TEXCOORD_0", accessor(uv, "VEC2", 2)}}},
                     {"indices", indices},
                     {"mode", mode}};
        if (material >= 0) prim["material"] = material;
        doc["meshes"].push_back({{"primitives", {prim}}});
        return int(doc["meshes"].size()) - 1;
    }
    int node(json n, bool root = true) {
        doc["nodes"].push_back(std::move(n));
        const int i = int(doc["nodes"].size()) - 1;
        if (root) doc["scenes"][0]["nodes"].push_back(i);
        return i;
    }
    int material(json m) {
        doc["materials"].push_back(std::move(m));
        return int(doc["materials"].size()) - 1;
    }
    // A camera at the origin looking down -z whose frame is 1 high and wide at distance 2 (yfov = 2 atan(1/2), aspect 1).
    void camera() {
        doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 2 * std::atan(0.5)}, {"aspectRatio", 1.0}, {"znear", 0.01}}}}};
        node({{"camera", 0}});
    }
    // Texture 0: `texels` as a PNG in the buffer (written through `dir`), bilinear or nearest.
    void texture(const Image8& texels, const std::string& dir, bool nearest = false) {
        write_png8(texels, dir + "/texture.png");
        const std::string png = read_input_file(dir + "/texture.png", 1 << 20);
        doc["images"] = {{{"mimeType", "image/png"}, {"bufferView", view(png)}}};
        doc["samplers"] = {{{"magFilter", nearest ? 9728 : 9729}}};
        doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
    }
    std::string write(const std::string& dir, const std::string& name = "scene.gltf") const {
        json d = doc;
        d["buffers"] = {{{"byteLength", blob.size()}, {"uri", "data:application/octet-stream;base64," + base64(blob)}}};
        const std::string path = dir + "/" + name;
        std::ofstream(path) << d.dump();
        return path;
    }
};

// A 2 x 1 image of the sRGB codes `rgb` (6 bytes).
Image8 two_texels(std::vector<uint8_t> rgb) {
    Image8 img;
    img.width = 2, img.height = 1;
    img.rgb = std::move(rgb);
    return img;
}

// A black quad emitting (0.5, 0.25, 1) x strength 4 = (2, 1, 4).
int lamp_material(Gltf& g) {
    return g.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                       {"emissiveFactor", {0.5, 0.25, 1}},
                       {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}}}});
}

// 8x8 pixels; the frame spans x in [-1, 1] at distance 2, so a quad x in [-1.5, -0.5] covers
// exactly the columns 0 and 1 (of 0..7).
void expect_columns_0_and_1_lit(const SceneDescription& d) {
    const Image img = render_scene(d, "pt-naive", 8, 8, 4, 1).film.mean();
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const Rgb want = x < 2 ? Rgb(2, 1, 4) : Rgb(0.0f);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.at(x, y)[c], want[c], 1e-5) << x << "," << y << " channel " << c;
        }
}

TEST(Gltf, AnEmissiveQuadCoversThePixelsTheCamerasYfovSays) {
    TempDir dir;
    Gltf g;
    g.camera();
    // The quad hangs under a parent node 2 m in front of the camera, given in the child's frame.
    const int child = g.node({{"mesh", g.quad(-1.5f, -0.5f, 1.5f, 0, lamp_material(g))}}, false);
    g.node({{"translation", {0, 0, -2}}, {"children", {child}}});
    expect_columns_0_and_1_lit(load_scene_file(g.write(dir.path)));
}

TEST(Gltf, AnOrthographicCameraSeesXmagByYmag) {
    // xmag 2, ymag 1: a 16 x 8 film spans x in [-2, 2], y in [-1, 1] (the film 640 x 320); the
    // quad x in [-2.5, -1], y in [-1, -0.5], 5 m in front of the camera, covers exactly the
    // columns 0-3 of the rows 6-7.
    TempDir dir;
    Gltf g;
    g.doc["cameras"] = {{{"type", "orthographic"}, {"orthographic", {{"xmag", 2}, {"ymag", 1}, {"znear", 0.01}, {"zfar", 100}}}}};
    g.node({{"camera", 0}, {"translation", {0, 0, 5}}});
    g.node({{"mesh", g.quad(-2.5f, -1, 0.25f, 0, lamp_material(g))}, {"translation", {0, -0.75, 0}}});
    const SceneDescription d = load_scene_file(g.write(dir.path));
    EXPECT_EQ(d.width, 640);
    EXPECT_EQ(d.height, 320);
    const Image img = render_scene(d, "pt-naive", 16, 8, 4, 1).film.mean();
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.at(x, y)[c], x < 4 && y >= 6 ? Rgb(2, 1, 4)[c] : 0.0f, 1e-5) << x << "," << y;
}

TEST(Gltf, AMirroringNodeKeepsTheFrontFaceTowardsTheCamera) {
    // The quad x in [0.5, 1.5] mirrored by scale x -1: glTF's spec makes its front face the
    // clockwise one, so it still emits towards the camera (without the reversed winding, the
    // one-sided emitter would face away and the image would be black).
    TempDir dir;
    Gltf g;
    g.camera();
    g.node({{"mesh", g.quad(0.5f, 1.5f, 1.5f, -2, lamp_material(g))}, {"scale", {-1, 1, 1}}});
    expect_columns_0_and_1_lit(load_scene_file(g.write(dir.path)));
}

TEST(Gltf, TriangleStripsAndFansMakeTheSameSurface) {
    for (int mode : {5, 6}) {
        SCOPED_TRACE(mode == 5 ? "strip" : "fan");
        TempDir dir;
        Gltf g;
        g.camera();
        g.node({{"mesh", g.quad(-1.5f, -0.5f, 1.5f, -2, lamp_material(g), mode)}});
        const SceneDescription d = load_scene_file(g.write(dir.path));
        ASSERT_EQ(d.meshes.size(), 1u);
        EXPECT_EQ(d.meshes[0].triangles.size(), 2u);
        expect_columns_0_and_1_lit(d);  // both triangles, both facing the camera
    }
}

TEST(Gltf, LightsAreReadInCandelaAndLuxAt683LumensPerWatt) {
    TempDir dir;
    Gltf g;
    g.camera();
    g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    g.doc["extensions"] = {{"KHR_lights_punctual",
                            {{"lights",
                              {{{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 683}},
                               {{"type", "directional"}, {"intensity", 1366}},
                               {{"type", "spot"}, {"intensity", 68.3}, {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}}}}}}};
    const double s = std::sqrt(0.5);  // a quarter turn about x: -z becomes +y
    g.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"translation", {1, 2, 3}}});
    g.node({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}, {"rotation", {s, 0, 0, s}}});
    g.node({{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}, {"rotation", {s, 0, 0, s}}, {"translation", {0, 1, 0}}});
    g.node({{"mesh", g.quad(-1, 1, 1, -2, -1)}});
    const SceneDescription d = load_scene_file(g.write(dir.path));
    ASSERT_EQ(d.lights.size(), 3u);
    const auto& point = std::get<PointLight>(d.lights[0]);
    EXPECT_NEAR(point.intensity.x, 1, 1e-6);
    EXPECT_NEAR(point.intensity.y, 0.5, 1e-6);
    EXPECT_NEAR(point.intensity.z, 0.25, 1e-6);
    EXPECT_NEAR(length(point.position - Vec3f(1, 2, 3)), 0, 1e-6);
    const auto& sun = std::get<DirectionalLight>(d.lights[1]);
    EXPECT_NEAR(sun.irradiance.y, 2, 1e-6);
    EXPECT_NEAR(length(sun.direction - Vec3f(0, 1, 0)), 0, 1e-6);
    const auto& spot = std::get<SpotLight>(d.lights[2]);
    EXPECT_NEAR(spot.intensity.x, 0.1, 1e-6);
    EXPECT_NEAR(spot.cutoff, 0.5, 1e-6);
    EXPECT_NEAR(spot.beam_width, 0.25, 1e-6);
    EXPECT_NEAR(length(spot.frame.n - Vec3f(0, 1, 0)), 0, 1e-6);
    EXPECT_NEAR(length(spot.position - Vec3f(0, 1, 0)), 0, 1e-6);
}

TEST(Gltf, ABaseColourFactorTimesItsTextureIsBakedAsLinearValues) {
    TempDir dir;
    const Image8 texels = two_texels({10, 128, 250, 255, 0, 77});
    Gltf g;
    g.camera();
    g.texture(texels, dir.path);
    const int m = g.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1, 0.25, 1}}, {"baseColorTexture", {{"index", 0}}}}}});
    g.node({{"mesh", g.quad(-1, 1, 1, -2, m)}});
    const GltfConversion c = convert_gltf_scene(g.write(dir.path), dir.path + "/out.xml");
    EXPECT_TRUE(c.warnings.empty());
    const Image baked = read_image(dir.path + "/out_files/base-color-0.exr");
    ASSERT_EQ(baked.width(), 2);
    const float factor[3] = {0.5f, 1.0f, 0.25f};
    for (int x = 0; x < 2; ++x)
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_FLOAT_EQ(baked.at(x, 0)[ch], factor[ch] * decode_srgb8(texels.at(x, 0, ch))) << x << " " << ch;
    EXPECT_NO_THROW(load_scene_file(dir.path + "/out.xml"));
}

TEST(Gltf, AnEmissiveTextureTimesItsFactorAndStrengthIsTheRadiance) {
    // A textured emissive quad filling the view: each half of the image shows one texel, times
    // emissiveFactor (0.5, 1, 1) times strength 2, of the texel's decoded sRGB value.
    TempDir dir;
    const Image8 texels = two_texels({200, 100, 50, 30, 90, 250});
    Gltf g;
    g.camera();
    g.texture(texels, dir.path, /*nearest=*/true);
    g.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    const int m = g.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                              {"emissiveFactor", {0.5, 1, 1}},
                              {"emissiveTexture", {{"index", 0}}},
                              {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 2}}}}}});
    g.node({{"mesh", g.quad(-1.2f, 1.2f, 1.2f, -2, m)}});
    const Image img = render_scene(load_scene_file(g.write(dir.path)), "pt-naive", 8, 8, 4, 1).film.mean();
    const float k[3] = {1, 2, 2};
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x)
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(img.at(x, y)[c], k[c] * decode_srgb8(texels.at(x < 4 ? 0 : 1, 0, c)), 1e-5) << x << "," << y << " channel " << c;
}

TEST(Gltf, KhrTextureTransformMovesTheLookup) {
    // The textured emissive quad filling the view, its texture scaled by (2, 1) (four stripes),
    // then offset by (1/4, 0) instead (the boundaries a quarter along): u' = T R S u, per column
    // of 8 (an offset of -1/4 would give another image).
    for (const bool offset : {false, true}) {
        SCOPED_TRACE(offset ? "offset" : "scale");
        TempDir dir;
        const Image8 texels = two_texels({200, 100, 50, 30, 90, 250});
        Gltf g;
        g.camera();
        g.texture(texels, dir.path, /*nearest=*/true);
        g.doc["extensionsUsed"] = {"KHR_texture_transform"};
        const json transform = offset ? json{{"offset", {0.25, 0}}} : json{{"scale", {2, 1}}};
        const int m = g.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                                  {"emissiveFactor", {1, 1, 1}},
                                  {"emissiveTexture", {{"index", 0}, {"extensions", {{"KHR_texture_transform", transform}}}}}});
        g.node({{"mesh", g.quad(-1, 1, 1.2f, -2, m)}});  // as wide as the view: u = (column + 1/2) / 8 at the centres
        const Image img = render_scene(load_scene_file(g.write(dir.path)), "pt-naive", 8, 8, 4, 1).film.mean();
        for (int x = 0; x < 8; ++x) {
            // the quad's u at the column's centre, then the lookup's
            const float u = (float(x) + 0.5f) / 8.0f;
            const float looked = offset ? u + 0.25f : 2 * u;
            const int texel = int(std::floor(looked * 2)) % 2;
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(img.at(x, 4)[c], decode_srgb8(texels.at(texel, 0, c)), 1e-5) << "column " << x << " channel " << c;
        }
    }
}

TEST(Gltf, TheShippedSceneRendersBitForBitAsItsConversionAndItsTextTwin) {
    TempDir dir;
    const std::string glb = kSource + "/scenes/gltf/room.glb", text = kSource + "/scenes/gltf/room.gltf";
    const GltfConversion c = convert_gltf_scene(glb, dir.path + "/room.xml");
    EXPECT_TRUE(c.warnings.empty());
    ASSERT_EQ(c.files, std::vector<std::string>{glb});
    const Image a = render_scene(load_scene_file(glb), "pt-mis", 40, 30, 2, 7).film.mean();
    const Image b = render_scene(load_scene_file(text), "pt-mis", 40, 30, 2, 7).film.mean();
    const Image x = render_scene(load_scene_file(dir.path + "/room.xml"), "pt-mis", 40, 30, 2, 7).film.mean();
    ASSERT_EQ(a.pixel_count(), x.pixel_count());
    EXPECT_EQ(std::memcmp(&a[0], &x[0], a.pixel_count() * sizeof(Rgb)), 0);
    EXPECT_EQ(std::memcmp(&a[0], &b[0], a.pixel_count() * sizeof(Rgb)), 0);
    // and the scene is what the script made: a camera, 8 meshes, one point light, one area light
    const SceneDescription d = load_scene_file(glb);
    EXPECT_EQ(d.meshes.size(), 8u);
    EXPECT_EQ(d.lights.size(), 1u);
    EXPECT_NEAR(d.camera.fov_degrees, 39.6, 1e-4);
    size_t emitting = 0;
    for (const MeshDesc& m : d.meshes) emitting += m.emission.x > 0;
    EXPECT_EQ(emitting, 1u);
}

void expect_refused(const std::function<void(Gltf&)>& edit, const std::string& words) {
    TempDir dir;
    Gltf g;
    g.camera();
    g.node({{"mesh", g.quad(-1, 1, 1, -2, -1)}});
    edit(g);
    const std::string path = g.write(dir.path);
    try {
        load_scene_file(path);
        ADD_FAILURE() << "accepted; expected a refusal mentioning: " << words;
    } catch (const SceneFileError& e) {
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("scene.gltf"), std::string::npos) << e.what();
    }
}

TEST(Gltf, RefusesWhatItCannotRenderNamingTheFile) {
    expect_refused([](Gltf& g) { g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }, "KHR_draco_mesh_compression");
    expect_refused([](Gltf& g) { g.doc["meshes"][0]["primitives"][0]["mode"] = 1; }, "mode 1");
    expect_refused([](Gltf& g) { g.doc["cameras"][0] = {{"type", "orthographic"}, {"orthographic", {{"xmag", 0}, {"ymag", 1}, {"znear", 0}, {"zfar", 1}}}}; },
                   "xmag 0 and ymag 1 must be positive");
    expect_refused([](Gltf& g) { g.doc["cameras"][0] = {{"type", "fisheye"}}; }, "\"perspective\" or \"orthographic\"");  // tinygltf's words
    expect_refused([](Gltf& g) { g.doc["scenes"][0]["nodes"] = {0, 5}; }, "node 5");
    expect_refused([](Gltf& g) { g.doc["accessors"][0]["count"] = 4000000000u; }, "indices: accessor 0 reaches past the end of its buffer");
    expect_refused([](Gltf& g) { g.doc["accessors"][1]["count"] = 5; }, "POSITION: accessor 1 reaches past the end of its buffer");
    expect_refused([](Gltf& g) { g.doc["bufferViews"][1]["byteOffset"] = 1u << 30; }, "reaches past the end of its buffer");
    expect_refused([](Gltf& g) { g.doc["nodes"][1]["children"] = {1}; }, "own ancestor");
    expect_refused(
        [](Gltf& g) {
            g.doc["images"] = {{{"uri", "missing-image.png"}}};
            g.doc["textures"] = {{{"source", 0}}};
            g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
            g.doc["meshes"][0]["primitives"][0]["material"] = 0;
        },
        "missing-image.png");
    expect_refused(
        [](Gltf& g) {
            g.doc["materials"] = {{{"name", "glow"}, {"emissiveFactor", {1, 1, 1}}, {"emissiveTexture", {{"index", 0}}}}};
            g.doc["textures"] = {{{"source", 0}}};
            g.doc["images"] = {{{"mimeType", "image/png"}, {"bufferView", 0}}};
            g.doc["meshes"][0]["primitives"][0]["material"] = 0;
            g.doc["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_0");
        },
        "material 'glow' has an emissive texture but the primitive has no TEXCOORD_0");
    TempDir dir;
    std::ofstream(dir.path + "/broken.gltf") << "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [";
    try {
        load_scene_file(dir.path + "/broken.gltf");
        ADD_FAILURE() << "a truncated file was accepted";
    } catch (const SceneFileError& e) {
        EXPECT_NE(std::string(e.what()).find("broken.gltf"), std::string::npos) << e.what();
    }
}

TEST(Gltf, SaysWhatItLeavesOut) {
    TempDir dir;
    Gltf g;
    g.camera();
    g.doc["extensionsUsed"] = {"KHR_materials_clearcoat"};
    const int m = g.material({{"alphaMode", "BLEND"}});
    g.node({{"mesh", g.quad(-1, 1, 1, -2, m)}});
    const GltfConversion c = convert_gltf_scene(g.write(dir.path), dir.path + "/out.xml");
    ASSERT_EQ(c.warnings.size(), 2u);
    EXPECT_NE(c.warnings[0].find("KHR_materials_clearcoat"), std::string::npos) << c.warnings[0];
    EXPECT_NE(c.warnings[1].find("BLEND"), std::string::npos) << c.warnings[1];
}

}  // namespace
}  // namespace pathlab::test
