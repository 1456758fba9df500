// The emitter plugins of scene files. Lights that stand on their own (point, spot, ies,
// constant, envmap, directional) read into a FreeLight; `area` gives the radiance of a shape's
// emitter. Readers that read files (envmap, ies) find them through the EmitterContext. To add
// a light: its header (model, plugin, reader), one alternative in light.hpp's variant (and in
// FreeLight if it stands alone), and one line in registry.cpp.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "core/properties.hpp"
#include "lights/light.hpp"

namespace pathlab {

// Lights that are not attached to geometry (area emitters come from a shape's emission).
using FreeLight = std::variant<PointLight, EnvironmentLight, DirectionalLight, EnvMapLight, SpotLight, IesLight, ProjectorLight>;

struct EmitterPlugin {
    const PluginInfo& (*info)();
    FreeLight (*read)(Properties&, const EmitterContext&);  // null for area, which belongs to a shape
};

const std::vector<EmitterPlugin>& emitter_plugins();
const EmitterPlugin* find_emitter_plugin(const std::string& type);

}  // namespace pathlab
