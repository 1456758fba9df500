#include "geometry/shape_plugins.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "core/file_search.hpp"
#include "geometry/mesh_files.hpp"
#include "geometry/shape_meshes.hpp"

namespace pathlab {
namespace {

const ParamInfo kToWorld{"to_world", ParamType::Transform, "", "placement: translate, rotate, scale, matrix, lookat", "toWorld"};
const ParamInfo kFlipNormals{"flip_normals", ParamType::Boolean, "false", "the shape faces the other way", "flipNormals"};
const ParamInfo kFaceNormals{"face_normals", ParamType::Boolean, "false", "flat shading: ignore vertex normals", "faceNormals"};
const ParamInfo kFilename{"filename", ParamType::String, "", "the file: relative names are searched in the scene file's folder and its <path> folders"};

// A mesh file's name, resolved (PropertyError when files are disabled or it is missing).
std::string mesh_path(Properties& p, const ShapeContext& ctx) {
    if (!p.has("filename")) p.fail(fmt::format("<shape type=\"{}\"> needs <string name=\"filename\" value=\"...\"/>", p.plugin().type));
    if (!ctx.allow_files) p.fail(fmt::format("this loader does not read files ({} shapes are disabled)", p.plugin().type));
    return ctx.resolve(p.get_string("filename"));
}

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
    static const PluginInfo info{"shape", "obj", "a Wavefront OBJ mesh (tinyobjloader, triangulated; vertex normals used when every face has them; materials (mtllib, usemtl) ignored: the scene file's BSDF counts)",
                                 {kFilename, kToWorld, kFlipNormals, kFaceNormals,
                                  {"flip_tex_coords", ParamType::Boolean, "true", "v' = 1 - v (only true is supported)", "flipTexCoords"},
                                  {"collapse", ParamType::Boolean, "false", "accepted (Mitsuba 0.6): the file's objects always become one mesh"},
                                  {"max_smooth_angle", ParamType::Float, "", "refused: pathlab does not compute smoothed normals", "maxSmoothAngle"}}};
    return info;
}
ShapeDesc read_obj(Properties& p, const ShapeContext& ctx) {
    const std::filesystem::path path(mesh_path(p, ctx));
    const std::string filename = p.get_string("filename");
    if (p.has("flip_tex_coords") && !p.get_bool("flip_tex_coords"))
        p.fail("flip_tex_coords", "flip_tex_coords false is not supported: pathlab flips v (v' = 1 - v) as Mitsuba does by default");
    if (p.has("collapse")) p.get_bool("collapse");
    if (p.has("max_smooth_angle")) p.fail("max_smooth_angle", "max_smooth_angle is not supported: pathlab uses the file's normals, or face_normals");
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
    static const PluginInfo info{"shape", "rectangle", "[-1, 1]^2 in the z = 0 plane, normal +z", {kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_rectangle(Properties& p, const ShapeContext&) { return finish_mesh(rectangle_mesh(), p); }

const PluginInfo& cube_plugin() {
    static const PluginInfo info{"shape", "cube", "[-1, 1]^3, outward normals", {kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_cube(Properties& p, const ShapeContext&) { return finish_mesh(cube_mesh(), p); }

const PluginInfo& disk_plugin() {
    static const PluginInfo info{"shape", "disk", "the unit disk in the z = 0 plane, normal +z (a fan of 128 triangles, 0.04% less area)",
                                 {kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_disk(Properties& p, const ShapeContext&) { return finish_mesh(disk_mesh(), p); }

const PluginInfo& sphere_plugin() {
    static const PluginInfo info{"shape", "sphere", "an exact sphere (intersected in double precision, not tessellated)",
                                 {{"center", ParamType::Point, "0, 0, 0", "centre"},
                                  {"radius", ParamType::Float, "1", "radius"},
                                  {"to_world", ParamType::Transform, "", "may only translate, rotate and scale uniformly", "toWorld"},
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
    return s;
}

const PluginInfo& ply_plugin() {
    static const PluginInfo info{"shape", "ply", "a PLY mesh, binary or ASCII (Assimp; polygons as fans; vertex normals and u, v used when present)",
                                 {kFilename, kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_ply(Properties& p, const ShapeContext& ctx) {
    const std::string path = mesh_path(p, ctx);
    MeshDesc m;
    try {
        m = load_ply_mesh(path);
    } catch (const MeshLoadError& e) {
        p.fail("filename", e.what());
    }
    m.name = p.get_string("filename");
    return finish_mesh(std::move(m), p);
}

const PluginInfo& serialized_plugin() {
    static const PluginInfo info{"shape", "serialized", "one shape of a Mitsuba .serialized file (zlib-compressed; format versions 3 and 4)",
                                 {kFilename, {"shape_index", ParamType::Integer, "0", "which shape of the file, from 0", "shapeIndex"},
                                  kToWorld, kFlipNormals, kFaceNormals,
                                  {"max_smooth_angle", ParamType::Float, "", "refused: pathlab does not compute smoothed normals", "maxSmoothAngle"}}};
    return info;
}
ShapeDesc read_serialized(Properties& p, const ShapeContext& ctx) {
    const std::string path = mesh_path(p, ctx);
    if (p.has("max_smooth_angle")) p.fail("max_smooth_angle", "max_smooth_angle is not supported: pathlab uses the file's normals, or face_normals");
    const int index = p.get_int("shape_index");
    MeshDesc m;
    try {
        m = load_serialized_mesh(path, index);
    } catch (const MeshLoadError& e) {
        p.fail("filename", e.what());
    }
    m.name = fmt::format("{}#{}", p.get_string("filename"), index);
    return finish_mesh(std::move(m), p);
}

const PluginInfo& cylinder_plugin() {
    static const PluginInfo info{"shape", "cylinder", "an open tube from p0 to p1 (no caps), outward normals; 128 flat sides with smooth vertex normals (0.01% less area)",
                                 {{"p0", ParamType::Point, "0, 0, 0", "centre of one end"},
                                  {"p1", ParamType::Point, "0, 0, 1", "centre of the other end"},
                                  {"radius", ParamType::Float, "1", "radius"},
                                  kToWorld, kFlipNormals, kFaceNormals}};
    return info;
}
ShapeDesc read_cylinder(Properties& p, const ShapeContext&) {
    const Vec3d p0(p.get_point("p0")), p1(p.get_point("p1"));
    const double r = p.get_float("radius");
    if (!(r > 0)) p.fail("radius", "a cylinder's radius must be positive");
    const Vec3d axis = p1 - p0;
    const double h = length(axis);
    if (!(h > 0)) p.fail("a cylinder's p0 and p1 must differ");
    // The unit tube (radius 1, z from 0 to 1) placed by a frame whose z is the axis.
    const Vec3d z = axis / h;
    const Vec3d x = normalize(std::abs(z.x) > 0.9 ? cross(Vec3d(0, 1, 0), z) : cross(Vec3d(1, 0, 0), z));
    const Vec3d y = cross(z, x);
    Transform frame;
    for (int i = 0; i < 3; ++i) frame.m[size_t(i)] = {x[i] * r, y[i] * r, z[i] * h, p0[i]};
    MeshDesc m = cylinder_mesh();
    transform_mesh(m, frame);
    return finish_mesh(std::move(m), p);
}

}  // namespace

std::string ShapeContext::resolve(const std::string& name) const {
    return find_in_dirs(name, search_dirs.empty() ? std::vector<std::string>{base_dir} : search_dirs);
}

const std::vector<ShapePlugin>& shape_plugins() {
    static const std::vector<ShapePlugin> table = {
        {obj_plugin, read_obj},   {ply_plugin, read_ply},       {serialized_plugin, read_serialized}, {rectangle_plugin, read_rectangle},
        {cube_plugin, read_cube}, {disk_plugin, read_disk}, {cylinder_plugin, read_cylinder},     {sphere_plugin, read_sphere},
    };
    return table;
}

const ShapePlugin* find_shape_plugin(const std::string& type) {
    for (const ShapePlugin& s : shape_plugins())
        if (s.info().type == type) return &s;
    return nullptr;
}

}  // namespace pathlab
