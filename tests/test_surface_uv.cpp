// Surface coordinates reach the shading context: an OBJ mesh's texture coordinates are
// interpolated at the hit (v flipped, as Mitsuba reads OBJ), and shapes without them give
// (0, 0).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "integrators/common/shading.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab {
namespace {

TEST(SurfaceUv, ObjTextureCoordinatesAreInterpolatedAtTheHit) {
    const auto dir = std::filesystem::temp_directory_path() / ("pathlab-uv-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "quad.obj") << "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                       "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    const std::string scene_text = "<scene version=\"3.0.0\"><shape type=\"obj\"><string name=\"filename\" value=\"quad.obj\"/></shape>"
                                   "<shape type=\"sphere\"><point name=\"center\" value=\"10, 10, 0\"/></shape></scene>";
    const auto scene = Scene::build(load_scene_text(scene_text, "uv.xml", dir.string()));
    Intersection hit;
    ASSERT_TRUE(scene->intersect(Ray{{1.5f, 0.5f, 1.0f}, {0, 0, -1}, kInf}, hit));
    EXPECT_NEAR(hit.uv.x, 0.75f, 1e-5f);
    EXPECT_NEAR(hit.uv.y, 1 - 0.25f, 1e-5f);  // v flipped
    const ShadingPoint sp = make_shading_point(*scene, hit, {0, 0, -1});
    EXPECT_EQ(sp.uv, hit.uv);
    // A shape without coordinates: (0, 0).
    ASSERT_TRUE(scene->intersect(Ray{{10, 10, 5}, {0, 0, -1}, kInf}, hit));
    EXPECT_EQ(hit.uv, Vec2f(0.0f, 0.0f));
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pathlab

// ---- the built-in shapes' parameterisations (Mitsuba 3's), and dp/du, dp/dv ------------------

namespace pathlab {
namespace {

// A checkerboard-textured BSDF (the shapes' coordinates are the same without it).
const char* kTextured = R"(<bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf>)";

std::unique_ptr<Scene> one_shape(const std::string& shape) {
    return Scene::build(load_scene_text("<scene version=\"3.0.0\">" + shape + "</scene>", "shapes.xml", "."));
}

// The surface coordinates of the hit of a ray from `from` towards `to`.
Scene::SurfaceCoordinates hit_towards(const Scene& scene, const Vec3d& from, const Vec3d& to) {
    Intersection hit;
    const Vec3d d = normalize(to - from);
    EXPECT_TRUE(scene.intersect(Ray{Vec3f(from), Vec3f(d), kInf}, hit));
    return scene.surface_coordinates(hit);
}

void expect_near(const Vec3f& a, const Vec3d& b, double tol, const std::string& what) {
    EXPECT_LT(length(Vec3d(a) - b), tol * std::max(1.0, length(b))) << what << ": " << a.x << " " << a.y << " " << a.z << " vs " << b.x
                                                                     << " " << b.y << " " << b.z;
}

const Transform kPlace = Transform::translate({0.3, -0.2, 0.5}) * Transform::rotate({1, 2, 3}, 40) * Transform::scale({1.5, 1.5, 1.5});
const char* kPlaceXml = R"(<transform name="to_world"><scale value="1.5"/><rotate x="1" y="2" z="3" angle="40"/><translate x="0.3" y="-0.2" z="0.5"/></transform>)";

TEST(SurfaceUv, RectangleMapsOntoTheUnitSquare) {
    const auto scene = one_shape(std::string("<shape type=\"rectangle\">") + kPlaceXml + kTextured + "</shape>");
    const Vec3d n = normalize(kPlace.normal({0, 0, 1}));
    for (const auto& [x, y] : {std::pair{-0.8, -0.6}, std::pair{0.3, 0.9}, std::pair{0.95, -0.1}}) {
        const Vec3d p = kPlace.point({x, y, 0});
        const Scene::SurfaceCoordinates hit = hit_towards(*scene, p + n * 2.0, p);
        EXPECT_NEAR(hit.uv.x, (x + 1) / 2, 1e-5);
        EXPECT_NEAR(hit.uv.y, (y + 1) / 2, 1e-5);
        expect_near(hit.dpdu, kPlace.vector({2, 0, 0}), 1e-5, "rectangle dp/du");
        expect_near(hit.dpdv, kPlace.vector({0, 2, 0}), 1e-5, "rectangle dp/dv");
    }
}

// Mitsuba 3's cube: its 24 vertices and their texture coordinates (src/shapes/cube.cpp), four
// per face. A point near each vertex, inside its face, has the uv interpolated towards it.
TEST(SurfaceUv, CubeFacesMapOntoTheUnitSquareAsMitsubas) {
    const double v[24][3] = {{1, -1, -1}, {1, -1, 1},  {-1, -1, 1}, {-1, -1, -1}, {1, 1, -1},  {-1, 1, -1}, {-1, 1, 1},  {1, 1, 1},
                             {1, -1, -1}, {1, 1, -1},  {1, 1, 1},   {1, -1, 1},   {1, -1, 1},  {1, 1, 1},   {-1, 1, 1},  {-1, -1, 1},
                             {-1, -1, 1}, {-1, 1, 1},  {-1, 1, -1}, {-1, -1, -1}, {1, 1, -1},  {1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}};
    const double t[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};  // the same for every face
    const auto scene = one_shape(std::string("<shape type=\"cube\">") + kPlaceXml + kTextured + "</shape>");
    for (int face = 0; face < 6; ++face) {
        Vec3d centre(0.0);
        for (int k = 0; k < 4; ++k) centre = centre + Vec3d(v[face * 4 + k][0], v[face * 4 + k][1], v[face * 4 + k][2]) * 0.25;
        for (int k = 0; k < 4; ++k) {
            const Vec3d corner(v[face * 4 + k][0], v[face * 4 + k][1], v[face * 4 + k][2]);
            const Vec3d local = centre + (corner - centre) * 0.8;
            const Vec3d p = kPlace.point(local);
            const Scene::SurfaceCoordinates hit = hit_towards(*scene, kPlace.point(local + centre * 2.0), p);
            EXPECT_NEAR(hit.uv.x, 0.5 + (t[k][0] - 0.5) * 0.8, 1e-5) << face << " " << k;
            EXPECT_NEAR(hit.uv.y, 0.5 + (t[k][1] - 0.5) * 0.8, 1e-5) << face << " " << k;
        }
    }
}

TEST(SurfaceUv, DiskIsPolar) {
    const auto scene = one_shape(std::string("<shape type=\"disk\">") + kPlaceXml + kTextured + "</shape>");
    const Vec3d n = normalize(kPlace.normal({0, 0, 1}));
    for (const auto& [r, phi] : {std::pair{0.5, 0.3}, std::pair{0.9, 2.5}, std::pair{0.2, 4.0}, std::pair{0.7, 6.0}}) {
        const Vec3d p = kPlace.point({r * std::cos(phi), r * std::sin(phi), 0});
        const Scene::SurfaceCoordinates hit = hit_towards(*scene, p + n * 2.0, p);
        EXPECT_NEAR(hit.uv.x, r, 1e-5);
        EXPECT_NEAR(hit.uv.y, phi / (2 * M_PI), 1e-5);
        // p(u, v) = to_world (u cos 2 pi v, u sin 2 pi v, 0)
        expect_near(hit.dpdu, kPlace.vector({std::cos(phi), std::sin(phi), 0}), 1e-4, "disk dp/du");
        expect_near(hit.dpdv, kPlace.vector({-2 * M_PI * r * std::sin(phi), 2 * M_PI * r * std::cos(phi), 0}), 1e-4, "disk dp/dv");
    }
}

TEST(SurfaceUv, SphereFollowsItsAxes) {
    const auto scene = one_shape(std::string("<shape type=\"sphere\"><float name=\"radius\" value=\"0.4\"/>") + kPlaceXml + kTextured + "</shape>");
    // p(u, v) = c + 0.6 R (sin theta cos phi, sin theta sin phi, cos theta), theta = pi v, phi = 2 pi u
    const auto p_of = [](double u, double v) {
        const double th = M_PI * v, ph = 2 * M_PI * u;
        return kPlace.point(Vec3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)) * 0.4);
    };
    const Vec3d c = kPlace.point({0, 0, 0});
    for (const auto& [u, v] : {std::pair{0.1, 0.3}, std::pair{0.45, 0.7}, std::pair{0.8, 0.5}, std::pair{0.6, 0.12}}) {
        const Vec3d p = p_of(u, v);
        const Scene::SurfaceCoordinates hit = hit_towards(*scene, c + (p - c) * 3.0, p);
        EXPECT_NEAR(hit.uv.x, u, 1e-5);
        EXPECT_NEAR(hit.uv.y, v, 1e-5);
        const double h = 1e-5;
        expect_near(hit.dpdu, (p_of(u + h, v) - p_of(u - h, v)) / (2 * h), 1e-4, "sphere dp/du");
        expect_near(hit.dpdv, (p_of(u, v + h) - p_of(u, v - h)) / (2 * h), 1e-4, "sphere dp/dv");
    }
}

TEST(SurfaceUv, MeshDerivativesFollowItsTextureCoordinates) {
    const auto dir = std::filesystem::temp_directory_path() / ("pathlab-uv-d-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "quad.obj") << "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    const auto scene = Scene::build(load_scene_text(std::string("<scene version=\"3.0.0\"><shape type=\"obj\"><string name=\"filename\" "
                                                                "value=\"quad.obj\"/>") + kTextured + "</shape></scene>",
                                                    "uv.xml", dir.string()));
    Intersection hit;
    ASSERT_TRUE(scene->intersect(Ray{{0.5f, 1.5f, 1.0f}, {0, 0, -1}, kInf}, hit));
    const Scene::SurfaceCoordinates c = scene->surface_coordinates(hit);
    expect_near(c.dpdu, {2, 0, 0}, 1e-6, "dp/du");
    expect_near(c.dpdv, {0, -2, 0}, 1e-6, "dp/dv (v flipped)");
    EXPECT_EQ(c.uv, hit.uv);
    std::filesystem::remove_all(dir);
}

// The shading frame of an anisotropic material follows dp/du.
TEST(SurfaceUv, AnisotropicShadingFrameFollowsTheTangent) {
    const auto scene = one_shape(std::string("<shape type=\"rectangle\">") + kPlaceXml +
                                 R"(<bsdf type="roughconductor"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.4"/></bsdf></shape>)");
    const Vec3d n = normalize(kPlace.normal({0, 0, 1}));
    const Vec3d p = kPlace.point({0.2, 0.1, 0});
    Intersection hit;
    ASSERT_TRUE(scene->intersect(Ray{Vec3f(p + n * 2.0), Vec3f(-n), kInf}, hit));
    const ShadingPoint sp = make_shading_point(*scene, hit, Vec3f(-n));
    expect_near(sp.frame.s, normalize(kPlace.vector({1, 0, 0})), 1e-5, "s");
    expect_near(sp.frame.n, n, 1e-5, "n");
}

}  // namespace
}  // namespace pathlab
