// Plain data describing a scene, produced by the built-in scenes and by scene-file loaders,
// consumed by Scene::build. Nothing here knows about Embree or sampling.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scene/camera.hpp"
#include "scene/light.hpp"
#include "scene/material.hpp"

namespace pathlab {

struct MeshDesc {
    std::string name;
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;  // per vertex, optional (empty: flat shading)
    std::vector<std::array<uint32_t, 3>> triangles;
    uint32_t material = 0;
    Rgb emission{0.0f};  // radiance of a one-sided area emitter on the winding-normal side
};

struct SphereDesc {
    Vec3f center;
    float radius = 1;
    uint32_t material = 0;
    bool flip_normals = false;  // normals point inwards
    Rgb emission{0.0f};         // radiance of a one-sided area emitter on the normal side
};

// Lights that are not attached to geometry (area emitters come from MeshDesc::emission).
using FreeLight = std::variant<PointLight, EnvironmentLight, DirectionalLight>;

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
    std::optional<int> spp, max_depth;
};

}  // namespace pathlab
