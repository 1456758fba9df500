// The BSDF plugins of scene files: each model's header declares its parameters and reads them
// (e.g. roughconductor_plugin() and read_roughconductor() in roughconductor.hpp); this table
// lists them by type name. To add a BSDF: its header (model, plugin, reader), one alternative
// in material.hpp's variant, and one line in registry.cpp.
#pragma once

#include <string>
#include <vector>

#include "bsdfs/material.hpp"
#include "core/properties.hpp"

namespace pathlab {

struct BsdfPlugin {
    const PluginInfo& (*info)();
    // Builds the material from its parameters; null for twosided, a wrapper of another BSDF
    // that the scene-file reader applies.
    Material (*read)(Properties&);
};

const std::vector<BsdfPlugin>& bsdf_plugins();
const BsdfPlugin* find_bsdf_plugin(const std::string& type);
std::string bsdf_type_names();  // "diffuse, phong, ..." for error messages
const PluginInfo& twosided_plugin();
// The wrappers that the scene-file reader builds from their nested BSDFs (read is null).
const PluginInfo& blendbsdf_plugin();
const PluginInfo& mask_plugin();

}  // namespace pathlab
