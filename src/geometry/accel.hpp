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

// Which shapes a ray sees (Embree's ray and geometry masks): surfaces, and the index-matched
// boundaries of media, which only the volumetric path tracer looks for.
enum RayMask : uint32_t {
    kMaskSurfaces = 1,
    kMaskMediumBoundaries = 2,
    kMaskAll = kMaskSurfaces | kMaskMediumBoundaries,
};

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

    // Each returns the Embree geometry id. An index-matched medium boundary gets the mask
    // kMaskMediumBoundaries, every other shape kMaskSurfaces.
    uint32_t add_mesh(const MeshDesc& mesh);
    uint32_t add_sphere(const SphereDesc& sphere);
    // A group of meshes for instances (its own Embree scene, committed here); returns its index.
    uint32_t add_group(const std::vector<MeshDesc>& meshes);
    // An instance of group `group`; returns its Embree geometry id (which hits report as inst_id).
    uint32_t add_instance(uint32_t group, const Transform& to_world);
    void commit();

    bool intersect(const Ray& ray, RawHit& hit, uint32_t mask = kMaskSurfaces) const;
    bool occluded(const Ray& ray, uint32_t mask = kMaskSurfaces) const;

    // The Embree scene itself, for benchmarks that measure Embree's raw throughput on it.
    RTCSceneTy* embree_scene() const { return scene_; }

private:
    RTCDeviceTy* device_ = nullptr;
    RTCSceneTy* scene_ = nullptr;
    std::vector<std::unique_ptr<SphereDesc>> spheres_;  // stable addresses for Embree callbacks
    std::vector<RTCSceneTy*> groups_;
};

}  // namespace pathlab
