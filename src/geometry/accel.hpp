// Ray-scene intersection through Embree 3: triangle meshes, and spheres as user geometry
// intersected analytically in double precision (exact, not tessellated).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/ray.hpp"
#include "geometry/shape.hpp"

struct RTCDeviceTy;
struct RTCSceneTy;

namespace pathlab {

struct RawHit {
    float t;
    float u, v;  // barycentrics of vertices 1 and 2 (triangles)
    uint32_t geom_id, prim_id;
};

class Accel {
public:
    Accel();
    ~Accel();
    Accel(const Accel&) = delete;
    Accel& operator=(const Accel&) = delete;

    // Each returns the Embree geometry id.
    uint32_t add_mesh(const MeshDesc& mesh);
    uint32_t add_sphere(const SphereDesc& sphere);
    void commit();

    bool intersect(const Ray& ray, RawHit& hit) const;
    bool occluded(const Ray& ray) const;

    // The Embree scene itself, for benchmarks that measure Embree's raw throughput on it.
    RTCSceneTy* embree_scene() const { return scene_; }

private:
    RTCDeviceTy* device_ = nullptr;
    RTCSceneTy* scene_ = nullptr;
    std::vector<std::unique_ptr<SphereDesc>> spheres_;  // stable addresses for Embree callbacks
};

}  // namespace pathlab
