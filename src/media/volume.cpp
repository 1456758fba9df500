#include "media/volume.hpp"

#include <filesystem>

#include <fmt/format.h>

namespace pathlab {

Transform affine_inverse(const Transform& t) {
    const auto& a = t.m;
    const double det = t.determinant();
    Transform r;
    // The inverse of the linear part: its adjugate over the determinant.
    r.m[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) / det;
    r.m[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
    r.m[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
    r.m[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) / det;
    r.m[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
    r.m[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
    r.m[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) / det;
    r.m[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
    r.m[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
    // The translation: -A^-1 b.
    for (int i = 0; i < 3; ++i) r.m[size_t(i)][3] = -(r.m[size_t(i)][0] * a[0][3] + r.m[size_t(i)][1] * a[1][3] + r.m[size_t(i)][2] * a[2][3]);
    return r;
}

Volume Volume::of_grid(VoxelGrid g, const Transform& unit_to_world) {
    Volume v;
    v.grid = std::make_shared<const VoxelGrid>(std::move(g));
    v.to_world = unit_to_world;
    v.to_unit = affine_inverse(unit_to_world);
    return v;
}

Volume read_constvolume(Properties& p) {
    // Mitsuba 3 bounds a heterogeneous medium by its volume's box, and a constvolume's box is the
    // unit cube its to_world places (mitsuba3 src/volumes/const.cpp: bbox() of to_world's unit
    // cube); without to_world pathlab's constant fills the medium's shape. Placed, it is a grid of
    // one voxel: the value inside the cube, 0 outside (VoxelGrid::lookup).
    const Rgb value = p.get_rgb("value");
    const std::optional<Transform> to_world = p.get_transform("to_world");
    if (!to_world) return Volume::constant_value(value);
    VoxelGrid one;
    one.res = {1, 1, 1};
    one.channels = 3;
    one.data = {value.x, value.y, value.z};
    return Volume::of_grid(std::move(one), *to_world);
}

Volume read_gridvolume(Properties& p, const std::string& base_dir, bool allow_files, std::vector<std::string>* files_read) {
    if (!p.has("filename")) p.fail("<volume type=\"gridvolume\"> needs <string name=\"filename\" value=\"...\"/>");
    if (!allow_files) p.fail("this loader does not read files (gridvolume is disabled)");
    std::filesystem::path file(p.get_string("filename"));
    if (file.is_relative()) file = std::filesystem::path(base_dir) / file;
    const std::string path = file.string();
    const std::string filter = p.get_string("filter_type");
    if (filter != "trilinear" && filter != "nearest")
        p.fail("filter_type", fmt::format("unsupported filter_type '{}'; supported: trilinear, nearest", filter));
    const std::string grid_name = p.has("grid") ? p.get_string("grid") : "";
    if (p.get_bool("use_grid_bbox"))
        p.fail("use_grid_bbox", "use_grid_bbox = true is not supported: pathlab places the grid's unit cube with to_world (give the "
                                "file's bounding box as a scale and translate there)");
    const Transform to_world = p.get_transform("to_world").value_or(Transform{});
    const bool vdb = path.size() >= 4 && path.compare(path.size() - 4, 4, ".vdb") == 0;
    if (!vdb && p.has("grid")) p.fail("grid", "only .vdb files have named grids");
    VoxelGrid grid;
    Transform unit_to_world = to_world;
    try {
        if (vdb) {
            VdbGrid g = read_vdb_file(path, grid_name);
            grid = std::move(g.grid);
            unit_to_world = to_world * g.unit_to_world;
        } else {
            grid = read_vol_file(path);
        }
    } catch (const GridFileError& e) {
        p.fail("filename", e.what());
    }
    grid.nearest = filter == "nearest";
    if (files_read) files_read->push_back(path);
    return Volume::of_grid(std::move(grid), unit_to_world);
}

}  // namespace pathlab
