// The reference of every scene-file plugin and its parameters, printed from the declarations
// next to each plugin (`pathlab plugins`; the tables of docs/scene-files.md are this text, and a
// test keeps them equal).
#pragma once

#include <string>
#include <vector>

#include "core/properties.hpp"

namespace pathlab {

// Every plugin, grouped by kind in the order of a scene file.
std::vector<PluginInfo> all_plugins();
std::string plugin_reference_markdown();

}  // namespace pathlab
