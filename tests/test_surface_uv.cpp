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
