// A renderable scene: geometry in Embree, materials, lights with their selection distributions
// (next-event estimation's light sampler, light paths' power table), and the camera. Built once from a SceneDescription; immutable and
// shared by all render threads afterwards.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/accel.hpp"
#include "lights/light_distribution.hpp"
#include "lights/light_sampler.hpp"
#include "scene/scene_description.hpp"
#include "textures/mesh_attribute.hpp"

namespace pathlab {

struct SceneError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A ray's hit on a surface.
struct Intersection {
    Vec3f p;             // hit point, recomputed from the primitive (not o + t d) for accuracy
    Vec3f ng;            // unit geometric normal as the shape defines it (winding / outward)
    Vec3f ns;            // unit shading normal (ng unless the mesh has vertex normals)
    Vec2f uv{0.0f, 0.0f};  // a mesh's interpolated texture coordinates; (0, 0) where it has none
    float t = 0;
    uint32_t geom_id, prim_id;  // the shape and triangle hit, for surface_coordinates() (set by intersect())
    static constexpr uint32_t kInstanceHit = 0xffffffffu;  // geom_id of a hit on an instance's mesh
    uint32_t material = 0;
    int32_t light = -1;  // index into Scene::lights() of the area light here, or -1
};

class Scene {
public:
    // Validates the description (indices in range, finite vertices, non-empty meshes) and
    // throws SceneError naming the offending element.
    static std::unique_ptr<Scene> build(const SceneDescription& desc);

    bool intersect(const Ray& ray, Intersection& hit) const;
    bool occluded(const Ray& ray) const;
    // volpath's: the shapes `mask` lets through (accel.hpp: surfaces, index-matched medium
    // boundaries), and `media`, the media on the two sides of the shape hit (null when it
    // changes no medium). The functions above see surfaces only.
    bool intersect(const Ray& ray, Intersection& hit, uint32_t mask, const MediumInterface*& media) const;

    const std::string& name() const { return name_; }
    const Camera& camera() const { return camera_; }
    int default_width() const { return width_; }
    int default_height() const { return height_; }
    const SceneDescription& description() const { return desc_; }

    const Material& material(uint32_t index) const { return materials_[index]; }
    // Participating media: only volpath renders them; the other estimators see a scene without.
    const Medium& medium(int32_t index) const { return desc_.media[size_t(index)]; }
    int32_t camera_medium() const { return desc_.camera_medium; }
    // True when some shape changes the medium or the camera sits in one.
    bool has_media() const { return has_media_; }
    // True when no straight segment joins a point in medium a to a point in medium b: they
    // differ and one of them is sealed (every boundary it has is a scattering surface, none
    // index-matched), so the segment meets a surface that blocks it. A shortcut for
    // connections out of a dielectric-bounded medium, which would each cost a shadow ray.
    bool media_separated(int32_t a, int32_t b) const {
        return a != b && ((a >= 0 && sealed_[size_t(a)]) || (b >= 0 && sealed_[size_t(b)]));
    }
    // The medium at point p (-1: none), found by following the segment from the camera to p
    // through every boundary it crosses, as the camera's paths track media.
    int32_t medium_at(const Vec3f& p) const;
    // The medium light i's light paths start in: at its position (point lights), on the
    // emitting side of its surface, or at infinity (outside the scene's bounds); found once by
    // medium_at at a point of the light (an emitter lies in one medium on its emitting side).
    int32_t light_medium(int i) const { return light_media_.empty() ? -1 : light_media_[size_t(i)]; }

    // The surface's coordinates at a hit, for materials that use them (textures, normal and bump
    // maps, anisotropic roughness), computed on demand so that other hits pay nothing: uv (a
    // mesh's interpolated texture coordinates, or the analytic parameterisations of spheres
    // and disks, Mitsuba 3's) and the derivatives dp/du, dp/dv (on a mesh from its triangle's
    // texture coordinates; without them, two unit tangents from the geometric normal).
    struct SurfaceCoordinates {
        SurfaceUv uv;  // on a mesh with attributes (mesh_attribute textures) also the triangle and barycentrics
        Vec3f dpdu, dpdv;
    };
    SurfaceCoordinates surface_coordinates(const Intersection& hit) const;
    const std::vector<Light>& lights() const { return lights_; }
    // Spectral mode: the spectrum of light i's emission when its scene file gave one, else null
    // (its RGB colour is then upsampled as an illuminant).
    const EmissionSpectrum* light_spectrum(int i) const {
        return i >= 0 && size_t(i) < light_spectra_.size() ? light_spectra_[size_t(i)].get() : nullptr;
    }
    bool has_delta_lights() const;
    // True when a sampled direction can find emission (an area light or the environment).
    bool has_hittable_emitters() const;

    // Radiance along a ray that escapes the scene in direction w (the environment, if any).
    Rgb escaped_radiance(const Vec3f& w = {}) const {
        return environment_ >= 0 ? environment_radiance(lights_[size_t(environment_)], w) : Rgb(0.0f);
    }
    // The environment light (constant or envmap), or -1.
    int environment_light() const { return environment_; }

    // Next-event estimation's choice of a light for the point p with normal n (n = 0 in a
    // medium), by the description's light_sampler, and the probability of choosing light i there.
    LightChoice choose_light(const Vec3f& p, const Vec3f& n, float u) const { return light_sampler_.choose(p, n, u); }
    // `split`: at a vertex where next-event estimation splits (light_sampler.hpp; the camera path's first).
    float light_pmf(const Vec3f& p, const Vec3f& n, int index, bool split = true) const { return light_sampler_.pmf(p, n, index, split); }
    const LightSampler& light_sampler() const { return light_sampler_; }
    // Light paths' choice of the light they start on: in proportion to power (uniformly if all are 0).
    LightChoice choose_emitter(float u) const { return light_distribution_.choose(u); }
    float emitter_pmf(int index) const { return light_distribution_.pmf(index); }
    // The bounding sphere that lights at infinity emit light paths through.
    SceneSphere scene_sphere() const { return {center_, radius_}; }

    const Accel& accel() const { return accel_; }
    Vec3f bounds_center() const { return center_; }
    float bounds_radius() const { return radius_; }

    // Rays traced by the calling thread since it started (for throughput statistics).
    static uint64_t rays_traced_by_this_thread();

private:
    Scene() = default;
    void fill(const Ray& ray, const RawHit& raw, Intersection& hit) const;
    struct GeometryRecord {
        bool is_sphere = false;
        uint32_t index = 0;        // into desc_.meshes or desc_.spheres
        int32_t first_light = -1;  // area light of triangle k is first_light + k
        const MeshDesc* mesh = nullptr;       // triangles: the mesh, and its unit face normals
        const Vec3f* face_normals = nullptr;  // (computed once, not per hit)
        const MediumInterface* media = nullptr;  // a shape's media, if it changes the medium
        int32_t instance = -1;                // an instance: its index in desc_.instances
    };

    // A hit on an instance: the group's mesh placed by the instance's transform, computed as
    // transform_mesh would have placed its vertices (so a shapegroup renders like the same
    // meshes written out, bit for bit wherever Embree's object-space hit is exact).
    void instance_hit(const RawHit& raw, Intersection& hit) const;

    SceneDescription desc_;
    std::string name_;
    Camera camera_;
    int width_ = 512, height_ = 512;
    Accel accel_;
    std::vector<GeometryRecord> geometry_;  // by Embree geometry id
    std::vector<std::vector<Vec3f>> face_normals_;  // per mesh, per triangle
    std::vector<Material> materials_;
    std::vector<Light> lights_;
    std::vector<std::shared_ptr<const EmissionSpectrum>> light_spectra_;  // by light; empty when no emitter has one
    LightDistribution light_distribution_;
    LightSampler light_sampler_;
    int environment_ = -1;
    bool has_media_ = false;
    std::vector<char> sealed_;          // by medium: no index-matched boundary (media_separated)
    std::vector<int32_t> light_media_;  // by light, when the scene has media
    Vec3f center_{0.0f};
    float radius_ = 1;
};

}  // namespace pathlab
