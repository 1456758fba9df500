// Scene files: transforms, $parameters, the 8 course scenes as XML + OBJ twins of the built-ins
// (bit-identical renders), a glass furnace described in XML, and errors with file:line:column.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"
#include "core/transform.hpp"

namespace pathlab {
namespace {

std::string source_path(const std::string& relative) { return std::string(PATHLAB_SOURCE_DIR) + "/" + relative; }

void expect_near(const Vec3d& a, const Vec3d& b, double tol = 1e-12) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

// A minimal valid scene around `body` (which may add a sensor, more shapes, ...).
std::string scene_with(const std::string& body) {
    return "<scene version=\"3.0.0\">\n" + body + "\n<shape type=\"sphere\"/>\n</scene>\n";
}
SceneDescription load(const std::string& text, const SceneDefines& defines = {}) {
    return load_scene_text(text, "test.xml", ".", defines);
}

// ---- transforms -----------------------------------------------------------------------------

TEST(Transform, EachOperationAgainstHandComputedMatrices) {
    expect_near(Transform::translate({1, 2, 3}).point({1, 1, 1}), {2, 3, 4});
    expect_near(Transform::translate({1, 2, 3}).vector({1, 1, 1}), {1, 1, 1});
    expect_near(Transform::scale({2, 3, 4}).point({1, 1, 1}), {2, 3, 4});
    // 90 degrees about +z takes +x to +y (right-handed).
    expect_near(Transform::rotate({0, 0, 1}, 90).point({1, 0, 0}), {0, 1, 0});
    expect_near(Transform::rotate({1, 0, 0}, 90).point({0, 1, 0}), {0, 0, 1});
    // About (1,1,1) by 120 degrees the axes cycle x -> y -> z.
    expect_near(Transform::rotate({1, 1, 1}, 120).point({1, 0, 0}), {0, 1, 0}, 1e-12);
    // Normals use the inverse transpose: a plane x = y stays perpendicular after a squash.
    const Transform s = Transform::scale({1, 2, 1});
    const Vec3d n = s.normal({1, -1, 0}), t = s.vector({1, 1, 0});
    EXPECT_NEAR(dot(n, t), 0, 1e-12);
}

TEST(Transform, LookAtFollowsMitsuba) {
    // From (0,0,5) towards the origin with up +y: +z (camera forward) maps to -z,
    // +x (camera left) maps to cross(up, dir) = (1,0,0) x ... = +x here... check with the formula.
    const auto t = Transform::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0});
    ASSERT_TRUE(t);
    expect_near(t->point({0, 0, 0}), {0, 0, 5});
    expect_near(t->vector({0, 0, 1}), {0, 0, -1});
    expect_near(t->vector({1, 0, 0}), cross(Vec3d(0, 1, 0), Vec3d(0, 0, -1)));  // left = up x dir = (-1, 0, 0)
    expect_near(t->vector({0, 1, 0}), {0, 1, 0});
    EXPECT_FALSE(Transform::look_at({0, 0, 0}, {0, 0, 0}, {0, 1, 0}));
    EXPECT_FALSE(Transform::look_at({0, 0, 0}, {0, 1, 0}, {0, 1, 0}));
}

TEST(SceneFile, TransformElementsComposeInDocumentOrder) {
    // Scale by 2, then translate by (1,0,0), then rotate 90 degrees about z: the sphere's centre
    // (0,0,0) -> (0,0,0) -> (1,0,0) -> (0,1,0), radius 2.
    const SceneDescription d = load(
        "<scene version=\"3.0.0\"><shape type=\"sphere\"><transform name=\"to_world\">"
        "<scale value=\"2\"/><translate x=\"1\"/><rotate z=\"1\" angle=\"90\"/></transform></shape></scene>");
    ASSERT_EQ(d.spheres.size(), 1u);
    EXPECT_NEAR(d.spheres[0].center.x, 0, 1e-6);
    EXPECT_NEAR(d.spheres[0].center.y, 1, 1e-6);
    EXPECT_NEAR(d.spheres[0].radius, 2, 1e-6);
    // A matrix and a rectangle: the canonical [-1,1]^2 corners move with it.
    const SceneDescription r = load(
        "<scene version=\"3.0.0\"><shape type=\"rectangle\"><transform name=\"to_world\">"
        "<matrix value=\"1 0 0 10  0 1 0 20  0 0 1 30  0 0 0 1\"/></transform></shape></scene>");
    ASSERT_EQ(r.meshes.size(), 1u);
    EXPECT_EQ(r.meshes[0].positions[0], Vec3f(9, 19, 30));
    EXPECT_EQ(r.meshes[0].positions[2], Vec3f(11, 21, 30));
}

TEST(SceneFile, CameraAxesMatchMitsubaConventions) {
    // Looking down -z from +z with up +y: image right is world +x.
    const SceneDescription d = load(scene_with(
        "<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/><string name=\"fov_axis\" value=\"y\"/>"
        "<transform name=\"to_world\"><lookat origin=\"0,0,5\" target=\"0,0,0\" up=\"0,1,0\"/></transform>"
        "<film type=\"hdrfilm\"><integer name=\"width\" value=\"64\"/><integer name=\"height\" value=\"32\"/><rfilter type=\"box\"/></film>"
        "</sensor>"));
    EXPECT_EQ(d.camera.position, Vec3f(0, 0, 5));
    EXPECT_EQ(d.camera.forward, Vec3f(0, 0, -1));
    EXPECT_NEAR(d.camera.right.x, 1, 1e-6);
    EXPECT_NEAR(d.camera.up.y, 1, 1e-6);
    EXPECT_EQ(d.camera.fov_axis, FovAxis::Y);
    EXPECT_EQ(d.width, 64);
    EXPECT_EQ(d.height, 32);
    // The same camera through a general transform (rotate + translate) instead of <lookat>.
    const SceneDescription g = load(scene_with(
        "<sensor type=\"perspective\"><transform name=\"to_world\"><rotate y=\"1\" angle=\"180\"/>"
        "<translate z=\"5\"/></transform></sensor>"));
    EXPECT_NEAR(g.camera.forward.z, -1, 1e-6);
    EXPECT_NEAR(g.camera.right.x, 1, 1e-6);  // Mitsuba's camera +x is left: rotated to -x, so right is +x
    EXPECT_NEAR(g.camera.position.z, 5, 1e-6);
}

TEST(SceneFile, DefaultsAndCommandLineDefines) {
    const std::string text = "<scene version=\"3.0.0\"><default name=\"spp\" value=\"16\"/><default name=\"r\" value=\"0.25\"/>"
                             "<integrator type=\"path\"><integer name=\"max_depth\" value=\"$depth\"/></integrator>"
                             "<sensor type=\"perspective\"><sampler type=\"independent\">"
                             "<integer name=\"sample_count\" value=\"$spp\"/></sampler></sensor>"
                             "<shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape></scene>";
    const SceneDescription a = load(text, {{"depth", "5"}});
    EXPECT_EQ(a.spp, 16);
    EXPECT_EQ(a.max_depth, 4);  // Mitsuba's depth 5 = pathlab's 4 bounces
    EXPECT_EQ(a.algorithm, "pt-mis");
    EXPECT_EQ(a.spheres[0].radius, 0.25f);
    const SceneDescription b = load(text, {{"depth", "-1"}, {"spp", "7"}});  // -D wins over <default>
    EXPECT_EQ(b.spp, 7);
    EXPECT_EQ(b.max_depth, -1);
    EXPECT_THROW(load(text), SceneFileError);  // $depth undefined
}

TEST(SceneFile, MaterialsAndLights) {
    const SceneDescription d = load(
        "<scene version=\"3.0.0\">"
        "<bsdf type=\"twosided\" id=\"w\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.1, 0.2, 0.3\"/></bsdf></bsdf>"
        "<shape type=\"cube\"><ref id=\"w\"/></shape>"
        "<shape type=\"disk\"><bsdf type=\"conductor\"/><emitter type=\"area\"><rgb name=\"radiance\" value=\"4\"/></emitter></shape>"
        "<shape type=\"sphere\"><bsdf type=\"dielectric\"><float name=\"int_ior\" value=\"1.33\"/></bsdf></shape>"
        "<emitter type=\"point\"><point name=\"position\" x=\"1\" y=\"2\" z=\"3\"/><rgb name=\"intensity\" value=\"5\"/></emitter>"
        "<emitter type=\"directional\"><vector name=\"direction\" value=\"0,0,-2\"/><rgb name=\"irradiance\" value=\"2\"/></emitter>"
        "</scene>");
    ASSERT_EQ(d.meshes.size(), 2u);
    EXPECT_EQ(d.meshes[0].triangles.size(), 12u);
    const Material& white = d.materials[d.meshes[0].material];
    EXPECT_TRUE(white.two_sided);
    EXPECT_EQ(std::get<PhongMaterial>(white.model).diffuse, Rgb(0.1f, 0.2f, 0.3f));
    EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(d.materials[d.meshes[1].material].model));
    EXPECT_FALSE(d.materials[d.meshes[1].material].two_sided);
    EXPECT_EQ(d.meshes[1].emission, Rgb(4.0f));
    EXPECT_EQ(std::get<DielectricMaterial>(d.materials[d.spheres[0].material].model).int_ior, 1.33f);
    ASSERT_EQ(d.lights.size(), 2u);
    EXPECT_EQ(std::get<PointLight>(d.lights[0]).position, Vec3f(1, 2, 3));
    EXPECT_EQ(std::get<DirectionalLight>(d.lights[1]).direction, Vec3f(0, 0, -1));
}

TEST(SceneFile, MicrofacetAndFresnelMaterials) {
    const SceneDescription d = load(R"(<scene version="3.0.0">
        <shape type="sphere"><bsdf type="roughconductor"/></shape>
        <shape type="sphere"><bsdf type="roughconductor"><string name="distribution" value="ggx"/>
            <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.3"/><string name="material" value="Au"/>
            <rgb name="specular_reflectance" value="0.9"/><boolean name="sample_visible" value="true"/></bsdf></shape>
        <shape type="sphere"><bsdf type="twosided"><bsdf type="roughconductor"><float name="alphaU" value="0.2"/>
            <float name="alphaV" value="0.1"/><rgb name="specularReflectance" value="0.5"/></bsdf></bsdf></shape>
        <shape type="sphere"><bsdf type="conductor"><rgb name="eta" value="0.2, 0.9, 1.1"/><rgb name="k" value="3.9, 2.4, 2.1"/></bsdf></shape>
        <shape type="sphere"><bsdf type="conductor"><string name="material" value="Cu"/></bsdf></shape>
        <shape type="sphere"><bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.3"/>
            <string name="intIOR" value="water"/><float name="extIOR" value="1"/></bsdf></shape>
        <shape type="sphere"><bsdf type="plastic"/></shape>
        <shape type="sphere"><bsdf type="roughplastic"><string name="distribution" value="ggx"/><float name="alpha" value="0.25"/>
            <rgb name="diffuseReflectance" value="0.1, 0.2, 0.3"/><float name="int_ior" value="1.6"/>
            <boolean name="nonlinear" value="true"/></bsdf></shape>
        </scene>)");
    ASSERT_EQ(d.spheres.size(), 8u);
    const auto model = [&](size_t i) -> const MaterialModel& { return d.materials[d.spheres[i].material].model; };
    const auto& rc0 = std::get<RoughConductorMaterial>(model(0));  // Mitsuba's defaults: beckmann, 0.1, none
    EXPECT_EQ(rc0.distribution.type, MicrofacetType::Beckmann);
    EXPECT_EQ(rc0.distribution.alpha_u, 0.1f);
    EXPECT_EQ(rc0.distribution.alpha_v, 0.1f);
    EXPECT_EQ(rc0.eta, Rgb(0.0f));
    EXPECT_EQ(rc0.k, Rgb(1.0f));
    EXPECT_FALSE(d.materials[d.spheres[0].material].two_sided);
    const auto& rc1 = std::get<RoughConductorMaterial>(model(1));
    EXPECT_EQ(rc1.distribution.type, MicrofacetType::GGX);
    EXPECT_EQ(rc1.distribution.alpha_u, 0.05f);
    EXPECT_EQ(rc1.distribution.alpha_v, 0.3f);
    EXPECT_EQ(rc1.eta, named_conductor("Au")->eta);
    EXPECT_EQ(rc1.specular_reflectance, Rgb(0.9f));
    const auto& rc2 = std::get<RoughConductorMaterial>(model(2));  // camelCase spellings
    EXPECT_EQ(rc2.distribution.alpha_u, 0.2f);
    EXPECT_EQ(rc2.distribution.alpha_v, 0.1f);
    EXPECT_EQ(rc2.specular_reflectance, Rgb(0.5f));
    EXPECT_TRUE(d.materials[d.spheres[2].material].two_sided);
    EXPECT_EQ(std::get<ConductorMaterial>(model(3)).eta, Rgb(0.2f, 0.9f, 1.1f));
    EXPECT_EQ(std::get<ConductorMaterial>(model(3)).k, Rgb(3.9f, 2.4f, 2.1f));
    EXPECT_EQ(std::get<ConductorMaterial>(model(4)).k, named_conductor("Cu")->k);
    const auto& rd = std::get<RoughDielectricMaterial>(model(5));
    EXPECT_EQ(rd.int_ior, 1.333f);
    EXPECT_EQ(rd.ext_ior, 1.0f);
    EXPECT_EQ(rd.distribution.alpha_u, 0.3f);
    const auto& pl = std::get<PlasticMaterial>(model(6)).coat;  // defaults: polypropylene in air, linear
    EXPECT_EQ(pl.diffuse_reflectance, Rgb(0.5f));
    EXPECT_EQ(pl.specular_reflectance, Rgb(1.0f));
    EXPECT_FLOAT_EQ(pl.eta, 1.49f / 1.000277f);
    EXPECT_FALSE(pl.nonlinear);
    const auto& rp = std::get<RoughPlasticMaterial>(model(7));
    EXPECT_EQ(rp.distribution.type, MicrofacetType::GGX);
    EXPECT_EQ(rp.distribution.alpha_u, 0.25f);
    EXPECT_EQ(rp.coat.diffuse_reflectance, Rgb(0.1f, 0.2f, 0.3f));
    EXPECT_FLOAT_EQ(rp.coat.eta, 1.6f / 1.000277f);
    EXPECT_TRUE(rp.coat.nonlinear);
}

TEST(SceneFileErrors, MicrofacetAndFresnelParameters) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"(<bsdf type="roughconductor"><string name="material" value="Unobtainium"/></bsdf>)",
         "unknown conductor material 'Unobtainium'; known: none, Au, Ag, Cu, Al, Cr, a-C"},
        {R"(<bsdf type="conductor"><string name="material" value="Au"/><rgb name="eta" value="1"/></bsdf>)",
         "either material or eta and k"},
        {R"(<bsdf type="roughconductor"><float name="alpha" value="0.1"/><float name="alpha_u" value="0.1"/>
            <float name="alpha_v" value="0.1"/></bsdf>)", "either alpha or alpha_u and alpha_v"},
        {R"(<bsdf type="roughconductor"><float name="alpha_u" value="0.1"/></bsdf>)", "needs both alpha_u and alpha_v"},
        {R"(<bsdf type="roughplastic"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.2"/></bsdf>)",
         "is isotropic: give alpha"},
        {R"(<bsdf type="roughdielectric"><string name="distribution" value="phong"/></bsdf>)",
         "unsupported distribution 'phong'; supported: beckmann, ggx"},
        {R"(<bsdf type="roughconductor"><float name="alpha" value="-0.1"/></bsdf>)", "alpha must be between 0 and 10"},
        {R"(<bsdf type="plastic"><rgb name="specular_reflectance" value="1"/><rgb name="specularReflectance" value="1"/></bsdf>)",
         "'specular_reflectance' and 'specularReflectance' are the same parameter"},
        {R"(<bsdf type="twosided"><bsdf type="roughdielectric"/></bsdf>)", "a roughdielectric cannot be wrapped in twosided"},
        {R"(<bsdf type="roughplastic"><float name="alpha_x" value="0.1"/></bsdf>)",
         "unsupported parameter 'alpha_x' for <bsdf type=\"roughplastic\">; supported: distribution, alpha"},
        {R"(<bsdf type="roughdielectric"><float name="int_ior" value="1.3"/><float name="ext_ior" value="1.3"/></bsdf>)",
         "are equal"},
    };
    for (const auto& [bsdf, message] : cases) {
        const std::string text = "<scene version=\"3\">\n<shape type=\"sphere\">" + bsdf + "</shape></scene>";
        try {
            load_scene_text(text, "bad.xml", ".");
            ADD_FAILURE() << "no error for " << bsdf;
        } catch (const SceneFileError& e) {
            EXPECT_EQ(e.line, 2) << e.what();
            EXPECT_NE(e.message.find(message), std::string::npos) << e.what();
        }
    }
}

// ---- the 8 course scenes as files ------------------------------------------------------------

class CourseSceneFile : public ::testing::TestWithParam<int> {};

TEST_P(CourseSceneFile, RendersBitIdenticallyToItsBuiltInTwin) {
    const int index = GetParam();
    const BuiltinSceneInfo& info = builtin_scenes()[size_t(index)];
    const SceneDescription file =
        load_scene_file(source_path(fmt::format("scenes/{}-{}.xml", index, info.name)));
    const SceneDescription builtin = make_builtin_scene(index);
    EXPECT_EQ(file.width, builtin.width);
    for (const char* algorithm : {"direct-light", "pt-mis"}) {
        const RenderResult a = test::render_scene(file, algorithm, 24, 24, 4, 99);
        const RenderResult b = test::render_scene(builtin, algorithm, 24, 24, 4, 99);
        EXPECT_TRUE(test::bit_identical(a.film.mean(), b.film.mean())) << info.name << " with " << algorithm;
        EXPECT_EQ(a.stats.rays, b.stats.rays);
    }
}
INSTANTIATE_TEST_SUITE_P(Scenes, CourseSceneFile, ::testing::Range(0, 8));

TEST(CourseSceneFile, ADifferentSceneIsNotIdentical) {
    // Test of the test: the twin of scene 2 differs from built-in scene 3.
    const SceneDescription file = load_scene_file(source_path("scenes/2-ceiling-diffuse.xml"));
    EXPECT_FALSE(test::bit_identical(test::render_scene(file, "direct-light", 24, 24, 4, 99).film.mean(),
                               test::render_scene(make_builtin_scene(3), "direct-light", 24, 24, 4, 99).film.mean()));
}

// ---- a glass furnace written as a scene file ----------------------------------------------------

TEST(SceneFile, GlassSphereInAWhiteFurnaceStaysUniform) {
    const std::string text = R"(<scene version="3.0.0">
        <sensor type="perspective"><float name="fov" value="30"/>
            <transform name="to_world"><lookat origin="0,-5,0" target="0,0,0" up="0,0,1"/></transform></sensor>
        <shape type="sphere"><float name="radius" value="1"/><bsdf type="dielectric"><string name="int_ior" value="bk7"/></bsdf></shape>
        <shape type="sphere"><point name="center" value="0,0,-0.3"/><float name="radius" value="0.4"/>
            <bsdf type="dielectric"><float name="int_ior" value="1.0"/><float name="ext_ior" value="1.5046"/></bsdf></shape>
        <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter></scene>)";
    const SceneDescription d = load(text);
    for (const char* algorithm : {"pt-naive", "pt-mis"}) {
        const RenderResult r = test::render_scene(d, algorithm, 12, 12, 1024, 4);
        const AgreementResult a = test_agreement(r.film.mean(), r.film.standard_error(), Image(12, 12, Rgb(0.5f)), Image());
        EXPECT_TRUE(a.agree) << algorithm << ": " << a.describe();
        EXPECT_EQ(r.stats.invalid_samples, 0u);
    }
}

// ---- errors ------------------------------------------------------------------------------------

struct BadFile {
    std::string text;
    int line, column;
    std::string message;  // a substring of the message
};

TEST(SceneFileErrors, NameFileLineColumnAndTheProblem) {
    const std::vector<BadFile> cases = {
        {"<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n</scene>", 3, 3, "malformed XML"},
        {"", 1, 1, "malformed XML"},
        {"<scene>\n<shape type=\"sphere\"/></scene>", 1, 1, "version"},
        {"<scenery version=\"3\"/>", 1, 1, "root element must be <scene>"},
        {"<scene version=\"3\">\n\n  <shape type=\"teapot\"/></scene>", 3, 3, "unsupported shape type 'teapot'; supported: obj"},
        {"<scene version=\"3\">\n<volume/></scene>", 2, 1, "unsupported element <volume>"},
        {"<scene version=\"3\"><shape type=\"sphere\">\n <float name=\"radius\" value=\"abc\"/></shape></scene>", 2, 2,
         "'abc' is not a finite number"},
        {"<scene version=\"3\"><shape type=\"sphere\">\n <float name=\"radius\" value=\"-1\"/></shape></scene>", 1, 20,
         "radius must be positive"},
        {"<scene version=\"3\"><shape type=\"sphere\">\n <float name=\"radiu\" value=\"1\"/></shape></scene>", 2, 2,
         "unsupported parameter 'radiu' for <shape type=\"sphere\">; supported: center, radius"},
        {"<scene version=\"3\"><shape type=\"sphere\"><ref id=\"nope\"/></shape></scene>", 1, 41, "no <bsdf> with id 'nope'"},
        {"<scene version=\"3\"><bsdf type=\"hair\" id=\"p\"/><shape type=\"sphere\"/></scene>", 1, 20,
         "unsupported bsdf type 'hair'; supported: diffuse, phong, conductor, roughconductor, dielectric, "
         "roughdielectric, plastic, roughplastic, principled, principledthin, thindielectric, twosided, blendbsdf, mask"},
        {"<scene version=\"3\"><shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape></scene>", 1, 41,
         "undefined parameter $r"},
        {"<scene version=\"3\"><shape type=\"obj\"><string name=\"filename\" value=\"missing.obj\"/></shape></scene>", 1, 38,
         "missing.obj"},
        {"<scene version=\"3\"><shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"0\"/></transform></shape></scene>",
         1, 44, "not invertible"},
        {"<scene version=\"3\"><shape type=\"sphere\"><transform name=\"to_world\"><scale x=\"1\" y=\"2\"/></transform></shape></scene>",
         1, 20, "scale uniformly"},
        {"<scene version=\"3\"><emitter type=\"area\"/><shape type=\"sphere\"/></scene>", 1, 20, "inside a <shape>"},
        {"<scene version=\"3\"/>", 0, 0, "no shapes"},
        {"<scene version=\"3\"><bsdf type=\"twosided\" id=\"a\"><bsdf type=\"twosided\"><bsdf type=\"diffuse\"/></bsdf></bsdf></scene>",
         1, 49, "cannot wrap another twosided"},
        {"<scene version=\"3\"><sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"2147483647\"/></film></sensor></scene>",
         1, 68, "at most 1e9 in magnitude, got 2147483647"},
    };
    for (const BadFile& c : cases) {
        try {
            load_scene_text(c.text, "bad.xml", source_path("tests/data"));
            ADD_FAILURE() << "no error for:\n" << c.text;
        } catch (const SceneFileError& e) {
            EXPECT_EQ(e.file, "bad.xml");
            EXPECT_EQ(e.line, c.line) << e.what();
            EXPECT_EQ(e.column, c.column) << e.what();
            EXPECT_NE(e.message.find(c.message), std::string::npos) << e.what();
            if (c.line > 0) {
                EXPECT_EQ(std::string(e.what()).rfind(fmt::format("bad.xml:{}:{}: error: ", c.line, c.column), 0), 0u);
            }
        }
    }
}

TEST(SceneFileErrors, BadMeshesAreNamed) {
    const std::string dir = ::testing::TempDir() + "/pathlab_meshes";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/empty.obj") << "# nothing\nv 0 0 0\n";
    std::ofstream(dir + "/nan.obj") << "v 0 0 0\nv 1 0 0\nv 1e999 1 0\nf 1 2 3\n";  // overflows to inf
    std::filesystem::create_directories(dir + "/folder.obj");  // a directory (like /dev/zero) must not hang the reader
    for (const auto& [file, message] : {std::pair{"empty.obj", "has no faces"}, std::pair{"nan.obj", "not finite"},
                                        std::pair{"folder.obj", "not a regular file"}}) {
        const std::string text = fmt::format(
            "<scene version=\"3\"><shape type=\"obj\"><string name=\"filename\" value=\"{}\"/></shape></scene>", file);
        try {
            load_scene_text(text, "m.xml", dir);
            ADD_FAILURE() << file;
        } catch (const SceneFileError& e) {
            EXPECT_NE(e.message.find(file), std::string::npos) << e.what();
            EXPECT_NE(e.message.find(message), std::string::npos) << e.what();
        }
    }
}

// Hostile inputs (out-of-range numbers, NaN, degenerate transforms and cameras, deep nesting,
// self-references, truncated or binary files), plus any input a fuzzer ever finds crashing:
// each must load or fail with a SceneFileError/SceneError, never crash or hang.
TEST(SceneFileErrors, FuzzRegressionCorpus) {
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(source_path("tests/data/xml_regressions"))) {
        std::ifstream in(entry.path(), std::ios::binary);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        try {
            const SceneDescription d = load_scene_text(text, entry.path().filename().string(), ".", {}, false);
            (void)Scene::build(d);
        } catch (const SceneFileError&) {
        } catch (const SceneError&) {
        }
        ++files;
    }
    EXPECT_GT(files, 0);
}

}  // namespace
}  // namespace pathlab
