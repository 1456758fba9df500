#include "scene/medium_in_use.hpp"

#include <fmt/format.h>

namespace pathlab {

std::string medium_in_use(const SceneDescription& d, bool only_grids) {
    const auto attenuates = [&](int32_t m) {
        return m >= 0 && size_t(m) < d.media.size() && has_extinction(d.media[size_t(m)]) &&
               (!only_grids || std::holds_alternative<HeterogeneousMedium>(d.media[size_t(m)]));
    };
    const auto label = [&](int32_t m) {
        return size_t(m) < d.medium_labels.size() && !d.medium_labels[size_t(m)].empty() ? d.medium_labels[size_t(m)]
                                                                                        : fmt::format("medium {}", m);
    };
    const auto on_shape = [&](const MediumInterface& mi, const std::string& shape) -> std::string {
        if (attenuates(mi.interior)) return fmt::format("{} (inside {})", label(mi.interior), shape);
        if (attenuates(mi.exterior)) return fmt::format("{} (outside {})", label(mi.exterior), shape);
        return "";
    };
    if (attenuates(d.camera_medium)) return fmt::format("{} (the camera is in it)", label(d.camera_medium));
    std::string found;
    for (size_t i = 0; i < d.meshes.size() && found.empty(); ++i)
        found = on_shape(d.meshes[i].media, d.meshes[i].name.empty() ? fmt::format("mesh {}", i) : "mesh '" + d.meshes[i].name + "'");
    for (size_t i = 0; i < d.spheres.size() && found.empty(); ++i) found = on_shape(d.spheres[i].media, fmt::format("sphere {}", i));
    for (const ShapeGroupDesc& g : d.groups)
        for (const MeshDesc& m : g.meshes)
            if (found.empty()) found = on_shape(m.media, fmt::format("mesh '{}' of shapegroup '{}'", m.name, g.name));
    return found;
}

}  // namespace pathlab
