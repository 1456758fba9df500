// The local view of a surface hit that every estimator needs: material, shading frame and the
// incoming direction in local coordinates, plus the rays that leave the surface.
#pragma once

#include "core/frame.hpp"
#include "scene/scene.hpp"

namespace pathlab {

// The BSDF's shading context (p, uv, frame, ng, transport mode) and what the integrator adds.
struct ShadingPoint : BsdfContext {
    const Material* material = nullptr;
    Vec3f wi;  // local direction back along the arriving ray (where the path came from)

    // A ray leaving the surface in the local direction w.
    Ray spawn(const Vec3f& w_local) const { return spawn_ray(p, ng, frame.to_world(w_local)); }
};

// Two-sided materials see the front of every surface: their normals are flipped to face the
// arriving ray. One-sided ones keep the shape's orientation (black from behind).
inline ShadingPoint make_shading_point(const Scene& scene, const Intersection& hit, const Vec3f& ray_dir,
                                       TransportMode mode = TransportMode::Radiance) {
    ShadingPoint sp;
    sp.material = &scene.material(hit.material);
    sp.p = hit.p;
    sp.uv = hit.uv;
    sp.mode = mode;
    sp.ng = hit.ng;
    Vec3f ns = hit.ns;
    if (sp.material->two_sided && dot(ray_dir, hit.ng) > 0) {
        sp.ng = -sp.ng;
        ns = -ns;
        if (sp.material->back >= 0) sp.material = &scene.material(uint32_t(sp.material->back));
    }
    sp.frame = Frame(ns);
    sp.wi = sp.frame.to_local(-ray_dir);
    return sp;
}

// Emitted radiance of the surface at `hit` towards direction `w` (unit, away from the surface):
// surface emitters are one-sided, radiating on the side of the shape's geometric normal.
inline Rgb emitted_radiance(const Scene& scene, const Intersection& hit, const Vec3f& w) {
    if (hit.light < 0 || dot(hit.ng, w) <= 0) return Rgb(0.0f);
    return surface_radiance(scene.lights()[size_t(hit.light)]);
}

}  // namespace pathlab
