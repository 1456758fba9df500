// Plain data describing a scene, produced by the built-in scenes and by scene-file loaders,
// consumed by Scene::build. Nothing here knows about Embree or sampling.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "bsdfs/material.hpp"
#include "cameras/camera.hpp"
#include "geometry/shape.hpp"
#include "lights/registry.hpp"

namespace pathlab {

struct SceneDescription {
    std::string name;
    Camera camera;
    int width = 512, height = 512;
    std::vector<Material> materials;
    std::vector<MeshDesc> meshes;
    std::vector<SphereDesc> spheres;
    std::vector<FreeLight> lights;
    // Render settings a scene file may suggest; command-line options override them.
    std::optional<std::string> algorithm;
    std::optional<int> spp, max_depth, rr_depth;  // depths in pathlab's bounces
    std::optional<int64_t> photons;               // sppm, pm: light paths (per iteration for sppm)
    std::optional<float> photon_radius;           // sppm: the first iteration's radius
    std::optional<double> photon_alpha;           // sppm: the radius reduction
    std::optional<int> pbgi_surfels, pbgi_bounces, pbgi_resolution, pbgi_direct_samples, pbgi_spacing;  // pbgi
    std::optional<float> pbgi_cutoff;                                                     // pbgi
    std::optional<int> ic_rays;                                                            // ic
    std::optional<float> ic_error;
    std::optional<bool> ic_gradients, ic_clamp_screen, ic_clamp_neighbours;
};

}  // namespace pathlab
