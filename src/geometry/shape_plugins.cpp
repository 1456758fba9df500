#include "geometry/shape_plugins.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "geometry/shape_meshes.hpp"

namespace pathlab {
namespace {

const ParamInfo kToWorld{"to_world", ParamType::Transform, "", "placement: translate, rotate, scale, matrix, lookat"};
const ParamInfo kFlipNormals{"flip_normals", ParamType::Boolean, "false", "the shape faces the other way"};
const ParamInfo kFaceNormals{"face_normals", ParamType::Boolean, "false", "flat shading: ignore vertex normals"};

// What every mesh does after it is made: flat shading, placement, facing, finite vertices.
MeshDesc finish_mesh(MeshDesc m, Properties& p) {
    if (p.get_bool("face_normals")) use_face_normals(m);
    if (const auto t = p.get_transform("to_world")) transform_mesh(m, *t);
    if (p.get_bool("flip_normals")) flip_mesh_normals(m);
    for (const Vec3f& v : m.positions)
        if (!is_finite(v)) p.fail("the shape has a non-finite vertex after its transform");
    return m;
}

const PluginInfo& obj_plugin() {
    static const PluginInfo info{"shape", "obj", "a Wavefront OBJ mesh (tinyobjloader, triangulated; vertex normals used when every face has them)",
                                 {{"filename", ParamType::String, "", "the file, relative to the scene file"},
                                  kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_obj(Properties& p, const ShapeContext& ctx) {
    if (!p.has("filename")) p.fail("<shape type=\"obj\"> needs <string name=\"filename\" value=\"...\"/>");
    if (!ctx.allow_files) p.fail("this loader does not read files (obj shapes are disabled)");
    const std::string filename = p.get_string("filename");
    std::filesystem::path path(filename);
    if (path.is_relative()) path = std::filesystem::path(ctx.base_dir) / path;
    MeshDesc m;
    try {
        m = load_obj_mesh(path.string());
    } catch (const MeshLoadError& e) {
        p.fail("filename", e.what());
    }
    m.name = filename;
    return finish_mesh(std::move(m), p);
}

const PluginInfo& rectangle_plugin() {
    static const PluginInfo info{"shape", "rectangle", "[-1, 1]^2 in the z = 0 plane, normal +z; uv = ((x + 1) / 2, (y + 1) / 2)",
                                 {kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_rectangle(Properties& p, const ShapeContext&) { return finish_mesh(rectangle_mesh(), p); }

const PluginInfo& cube_plugin() {
    static const PluginInfo info{"shape", "cube", "[-1, 1]^3, outward normals; each face mapped onto [0, 1]^2 in uv (as Mitsuba 3)",
                                 {kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_cube(Properties& p, const ShapeContext&) { return finish_mesh(cube_mesh(), p); }

const PluginInfo& disk_plugin() {
    static const PluginInfo info{"shape", "disk",
                                 "the unit disk in the z = 0 plane, normal +z (a fan of 128 triangles, 0.04% less area); uv = (r, phi / 2 pi), exact",
                                 {kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_disk(Properties& p, const ShapeContext&) { return finish_mesh(disk_mesh(), p); }

const PluginInfo& sphere_plugin() {
    static const PluginInfo info{"shape", "sphere",
                                 "an exact sphere (intersected in double precision, not tessellated); uv = (phi / 2 pi, theta / pi) about its z axis",
                                 {{"center", ParamType::Point, "0, 0, 0", "centre"},
                                  {"radius", ParamType::Float, "1", "radius"},
                                  {"to_world", ParamType::Transform, "", "may only translate, rotate and scale uniformly"},
                                  kFlipNormals}};
    return info;
}
ShapeDesc read_sphere(Properties& p, const ShapeContext&) {
    const bool flip = p.get_bool("flip_normals");
    const std::optional<Transform> to_world = p.get_transform("to_world");
    Vec3d center(p.get_point("center"));
    double radius = p.get_float("radius");
    if (!(radius > 0)) p.fail("a sphere's radius must be positive");
    if (to_world) {
        const Transform& t = *to_world;
        const Vec3d a = t.vector({1, 0, 0}), b = t.vector({0, 1, 0}), c = t.vector({0, 0, 1});
        const double la = length(a), lb = length(b), lc = length(c);
        const double tol = 1e-5 * std::max({la, lb, lc});
        if (std::abs(la - lb) > tol || std::abs(la - lc) > tol || std::abs(dot(a, b)) > tol * la ||
            std::abs(dot(a, c)) > tol * la || std::abs(dot(b, c)) > tol * lb)
            p.fail("a sphere's to_world may only translate, rotate and scale uniformly (spheres are exact, not meshes)");
        center = t.point(center);
        radius *= la;
    }
    SphereDesc s;
    s.center = Vec3f(center);
    s.radius = float(radius);
    s.flip_normals = flip;
    if (to_world)
        for (int i = 0; i < 3; ++i) s.axes[size_t(i)] = Vec3f(normalize(to_world->vector(Vec3d(i == 0, i == 1, i == 2))));
    return s;
}

}  // namespace

const std::vector<ShapePlugin>& shape_plugins() {
    static const std::vector<ShapePlugin> table = {
        {obj_plugin, read_obj},   {rectangle_plugin, read_rectangle}, {cube_plugin, read_cube},
        {disk_plugin, read_disk}, {sphere_plugin, read_sphere},
    };
    return table;
}

const ShapePlugin* find_shape_plugin(const std::string& type) {
    for (const ShapePlugin& s : shape_plugins())
        if (s.info().type == type) return &s;
    return nullptr;
}

}  // namespace pathlab
