// The local view of a surface hit that every estimator needs: material, shading frame and the
// incoming direction in local coordinates, plus the rays that leave the surface.
#pragma once

#include "core/frame.hpp"
#include "integrators/common/first_vertex.hpp"
#include "scene/scene.hpp"

namespace pathlab {

// The BSDF's shading context (p, uv, frame, ng, transport mode) and what the integrator adds.
struct ShadingPoint : BsdfContext {
    const Material* material = nullptr;
    Vec3f wi;  // local direction back along the arriving ray (where the path came from)

    // A ray leaving the surface in the local direction w.
    Ray spawn(const Vec3f& w_local) const { return spawn_ray(p, ng, frame.to_world(w_local)); }
};

// The surface coordinates and the shading frame at a hit on a material that uses them (out of
// the hot path): uv for its textures, and the frame along dp/du for tangent_frame materials.
// A normal map's flip_invalid_normals (material_textures.hpp) looks at where the path came from
// (ray_dir), in radiance mode (importance mode refuses such maps: RenderJob).
[[gnu::noinline]] inline void set_surface_coordinates(const Scene& scene, const Intersection& hit, bool back, const Vec3f& ray_dir,
                                                      ShadingPoint& sp) {
    const Scene::SurfaceCoordinates c = scene.surface_coordinates(hit);
    sp.uv = c.uv;
    sp.ns = back ? -hit.ns : hit.ns;
    sp.frame = sp.material->tangent_frame ? sp.material->shading_frame(hit.ns, hit.ng, back, c.dpdu, c.dpdv, c.uv) : Frame(sp.ns);
    if (sp.mode == TransportMode::Radiance && sp.material->flips_invalid_normals()) sp.frame = flip_invalid_normal(sp.frame, sp.ns, -ray_dir);
}

// Two-sided materials see the front of every surface: their normals are flipped to face the
// arriving ray. One-sided ones keep the shape's orientation (black from behind). The shading
// frame is Frame(ns), or for materials whose frame follows the surface's tangent dp/du
// (anisotropic, normal or bump mapped) the material's shading_frame(). A ShadingPoint holds
// only values and a pointer to the scene's material (a textured material is evaluated at
// sp.uv when it is used), so it may be copied freely (bdpt's and vcm's path vertices).
inline ShadingPoint make_shading_point(const Scene& scene, const Intersection& hit, const Vec3f& ray_dir,
                                       TransportMode mode = TransportMode::Radiance) {
    ShadingPoint sp;
    sp.material = &scene.material(hit.material);
    sp.p = hit.p;
    sp.uv = hit.uv;
    sp.mode = mode;
    sp.ng = hit.ng;
    Vec3f ns = hit.ns;
    const bool back = sp.material->two_sided && dot(ray_dir, hit.ng) > 0;
    if (back) {
        sp.ng = -sp.ng;
        ns = -ns;
        if (sp.material->back >= 0) sp.material = &scene.material(uint32_t(sp.material->back));
    }
    if (sp.material->surface_coordinates) [[unlikely]]
        set_surface_coordinates(scene, hit, back, ray_dir, sp);
    else
        sp.frame = Frame(ns);
    sp.wi = sp.frame.to_local(-ray_dir);
    if (FirstVertexRecorder* r = t_first_vertex) [[unlikely]]  // a camera sample with --aovs
        offer_surface_vertex(*r, scene, sp);
    return sp;
}

// The fraction of light passing straight through the surface at `hit` along `dir` (its material's
// kLobeNull lobe, Material::null_transmission; 0 for the rest): what a shadow ray carries through
// thin glass or a mask's hole under --null-depth skip.
inline float null_transmission(const Scene& scene, const Intersection& hit, const Vec3f& dir) {
    const Material* m = &scene.material(hit.material);
    if (!(m->lobes() & kLobeNull)) return 0.0f;
    if (m->two_sided && m->back >= 0 && dot(dir, hit.ng) > 0) m = &scene.material(uint32_t(m->back));
    const SurfaceUv uv = m->surface_coordinates ? scene.surface_coordinates(hit).uv : hit.uv;
    return m->null_transmission(uv, std::abs(dot(dir, hit.ns)) / length(dir));
}

// Emitted radiance of the surface at `hit` towards direction `w` (unit, away from the surface):
// surface emitters are one-sided, radiating on the side of the shape's geometric normal.
inline Rgb emitted_radiance(const Scene& scene, const Intersection& hit, const Vec3f& w) {
    if (hit.light < 0 || dot(hit.ng, w) <= 0) return Rgb(0.0f);
    return surface_radiance(scene.lights()[size_t(hit.light)], hit.uv);
}

}  // namespace pathlab
