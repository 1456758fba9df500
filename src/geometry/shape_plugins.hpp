// The shape plugins of scene files: obj, rectangle, cube, disk (triangle meshes) and sphere
// (exact). Each declares its parameters and reads them into a MeshDesc or SphereDesc; the
// scene-file reader adds the shape's BSDF and emitter. To add a shape: its entry (plugin and
// reader) in shape_plugins.cpp.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "core/properties.hpp"
#include "geometry/shape.hpp"

namespace pathlab {

struct ShapeContext {
    std::string base_dir = ".";  // relative file names are resolved against it
    bool allow_files = true;     // false: shapes that read files are an error (the fuzzer)
    // Where else relative file names are searched, in order (the scene file's folder and its
    // <path> folders); base_dir when empty.
    std::vector<std::string> search_dirs = {};

    // A relative file name: the first of search_dirs (or base_dir) where it exists, else its
    // place in the first, so that the error names a path.
    std::string resolve(const std::string& name) const;
};

using ShapeDesc = std::variant<MeshDesc, SphereDesc>;

struct ShapePlugin {
    const PluginInfo& (*info)();
    ShapeDesc (*read)(Properties&, const ShapeContext&);
};

const std::vector<ShapePlugin>& shape_plugins();
const ShapePlugin* find_shape_plugin(const std::string& type);

}  // namespace pathlab
