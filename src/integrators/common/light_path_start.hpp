// The first vertex of a light path (light tracing, bdpt's light subpaths and with them the
// photons): a light chosen by power, then a point and a direction from its emission sampling.
#pragma once

#include <optional>

#include "scene/scene.hpp"

namespace pathlab {

struct LightPathStart {
    LightChoice choice;
    const Light* light;
    EmissionSample emission;
    uint32_t flags;  // light_flags(*light)
    int32_t medium;  // the medium the path starts in (Scene::light_medium; -1: none)
};

// Nothing where no light is chosen or its emission sample carries nothing, or where light from
// infinity would cross a medium that reaches infinity (it is all absorbed on its way, as
// volpath's escaped rays find).
inline std::optional<LightPathStart> start_light_path(const Scene& scene, Sampler& sampler) {
    const LightChoice choice = scene.choose_emitter(sampler.next1d());
    const Vec2f u_pos = sampler.next2d(), u_dir = sampler.next2d();
    if (choice.index < 0) return std::nullopt;
    const Light& light = scene.lights()[size_t(choice.index)];
    const auto es = sample_emission(light, u_pos, u_dir, scene.scene_sphere());
    if (!es || is_black(es->Le) || !(es->pdfA > 0) || !(es->pdfW > 0)) return std::nullopt;
    const uint32_t flags = light_flags(light);
    const int32_t medium = scene.light_medium(choice.index);
    if ((flags & kLightInfinite) && medium >= 0 && has_extinction(scene.medium(medium))) return std::nullopt;
    return LightPathStart{choice, &light, *es, flags, medium};
}

}  // namespace pathlab
