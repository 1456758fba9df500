// Volumes: a quantity (density, albedo) as a function of the position in world space, Mitsuba
// 3's `constvolume` and `gridvolume`.
//
//   constvolume  one value everywhere
//   gridvolume   a VoxelGrid (voxel_grid.hpp) read from a .vol or .vdb file, filling the unit
//                cube that `to_world` places in the scene; 0 outside it. For a .vdb file the
//                grid first goes where the file's own transform puts it, then to_world.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "core/properties.hpp"
#include "core/transform.hpp"
#include "media/grid_files.hpp"

namespace pathlab {

// The inverse of an affine, invertible transform.
Transform affine_inverse(const Transform& t);

struct Volume {
    Rgb constant{0.0f};                     // the value, when there is no grid
    std::shared_ptr<const VoxelGrid> grid;  // shared: scene descriptions are copied
    Transform to_unit;                      // world space to the grid's unit cube
    Transform to_world;                     // the unit cube to world space

    bool is_constant() const { return !grid; }
    Vec3f unit_point(const Vec3f& p) const { return Vec3f(to_unit.point(Vec3d(p))); }
    Rgb eval(const Vec3f& p) const { return grid ? grid->lookup(unit_point(p)) : constant; }
    float max_value() const { return grid ? grid->max_value() : max_component(constant); }

    static Volume constant_value(const Rgb& v) {
        Volume vol;
        vol.constant = v;
        return vol;
    }
    // A grid filling the unit cube moved by unit_to_world.
    static Volume of_grid(VoxelGrid g, const Transform& unit_to_world);
};

inline const PluginInfo& constvolume_plugin() {
    static const PluginInfo info{"volume", "constvolume", "the same value everywhere",
                                 {{"value", ParamType::Rgb, "1", "the value (a float or an RGB triple)"},
                                  {"to_world", ParamType::Transform, "",
                                   "bounds the medium to the unit cube it places (Mitsuba 3's convention; 0 outside); without it the value fills the medium's shape"}}};
    return info;
}
inline const PluginInfo& gridvolume_plugin() {
    static const PluginInfo info{
        "volume", "gridvolume", "a voxel grid from a Mitsuba .vol file or an OpenVDB .vdb file, trilinearly interpolated",
        {{"filename", ParamType::String, "", "the .vol or .vdb file, relative to the scene file"},
         {"to_world", ParamType::Transform, "", "places the grid's unit cube [0, 1]^3 (a .vdb grid: its own world space) in the scene"},
         {"filter_type", ParamType::String, "trilinear", "trilinear or nearest"},
         {"grid", ParamType::String, "", "a .vdb file's grid by name (default: 'density', or the file's only grid)"},
         {"use_grid_bbox", ParamType::Boolean, "false",
          "Mitsuba 3's choice of the .vol file's own bounding box instead of the unit cube: false only (true is refused: give the box as to_world)"}},
        "The grid is 0 outside its box. A .vol file's own bounding box is ignored, as Mitsuba 3 does. Values must be finite and "
        "not negative."};
    return info;
}
// Reads a volume plugin's properties; a relative file name is resolved against `base_dir`
// (the scene file's directory); allow_files = false refuses to read files (the fuzzer). Throws
// PropertyError (a grid file's problems name the file).
Volume read_constvolume(Properties& p);
// `files_read`, if given, gets the grid file's path (SceneChoice::files: the scene hash, outputs that may not overwrite it).
Volume read_gridvolume(Properties& p, const std::string& base_dir, bool allow_files, std::vector<std::string>* files_read = nullptr);

}  // namespace pathlab
