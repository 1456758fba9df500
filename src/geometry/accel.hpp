// Ray-scene intersection through Embree 3: triangle meshes, and spheres as user geometry
// intersected analytically in double precision (exact, not tessellated).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/ray.hpp"
#include "core/transform.hpp"
#include "geometry/shape.hpp"

struct RTCDeviceTy;
struct RTCSceneTy;

namespace pathlab {

struct RawHit {
    float t;
    float u, v;  // barycentrics of vertices 1 and 2 (triangles)
    uint32_t geom_id, prim_id;
    uint32_t inst_id = kNoInstance;  // the instance hit (geom_id is then the mesh's id in its group)
    static constexpr uint32_t kNoInstance = 0xffffffffu;
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
    // A group of meshes for instances (its own Embree scene, committed here); returns its index.
    uint32_t add_group(const std::vector<MeshDesc>& meshes);
    // An instance of group `group`; returns its Embree geometry id (which hits report as inst_id).
    uint32_t add_instance(uint32_t group, const Transform& to_world);
    void commit();

    bool intersect(const Ray& ray, RawHit& hit) const;
    bool occluded(const Ray& ray) const;

    // The Embree scene itself, for benchmarks that measure Embree's raw throughput on it.
    RTCSceneTy* embree_scene() const { return scene_; }

private:
    RTCDeviceTy* device_ = nullptr;
    RTCSceneTy* scene_ = nullptr;
    std::vector<std::unique_ptr<SphereDesc>> spheres_;  // stable addresses for Embree callbacks
    std::vector<RTCSceneTy*> groups_;
};

}  // namespace pathlab
