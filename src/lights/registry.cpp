#include "lights/registry.hpp"

#include "lights/area.hpp"

namespace pathlab {
namespace {

template <typename L, L (*read)(Properties&)>
FreeLight free_light(Properties& p, const EmitterContext&) {
    return read(p);
}
template <typename L, L (*read)(Properties&, const EmitterContext&)>
FreeLight free_light_with_files(Properties& p, const EmitterContext& ctx) {
    return read(p, ctx);
}

}  // namespace

const std::vector<EmitterPlugin>& emitter_plugins() {
    static const std::vector<EmitterPlugin> table = {
        {point_plugin, free_light<PointLight, read_point_light>},
        {spot_plugin, free_light_with_files<SpotLight, read_spot_light>},
        {ies_plugin, free_light_with_files<IesLight, read_ies_light>},
        {projector_plugin, free_light_with_files<ProjectorLight, read_projector_light>},
        {constant_plugin, free_light<EnvironmentLight, read_constant_light>},
        {envmap_plugin, free_light_with_files<EnvMapLight, read_envmap_light>},
        {directional_plugin, free_light<DirectionalLight, read_directional_light>},
        {area_plugin, nullptr},
    };
    return table;
}

const EmitterPlugin* find_emitter_plugin(const std::string& type) {
    for (const EmitterPlugin& e : emitter_plugins())
        if (e.info().type == type) return &e;
    return nullptr;
}

}  // namespace pathlab
