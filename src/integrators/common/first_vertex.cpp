#include "integrators/common/first_vertex.hpp"

#include "integrators/common/shading.hpp"

namespace pathlab {

void offer_surface_vertex(FirstVertexRecorder& r, const Scene& scene, const ShadingPoint& sp) {
    if (r.vertex.found) return;
    const float depth = r.distance + length(sp.p - r.last);
    const Material& m = *sp.material;
    if (m.is_delta()) {  // a mirror, glass, an index-matched boundary: seen through
        r.distance = depth, r.last = sp.p;
        return;
    }
    FirstVertex& v = r.vertex;
    v.found = true;
    if (m.textures) {
        Material at_uv = m;
        at_uv.model = m.model_at(sp.uv);
        v.albedo = diffuse_albedo(at_uv);
    } else {
        v.albedo = diffuse_albedo(m);
    }
    v.normal = sp.frame.n;
    v.position = sp.p;
    v.depth = depth;
}

void offer_medium_vertex(FirstVertexRecorder& r, const Scene& scene, int32_t medium, const Vec3f& p) {
    if (r.vertex.found) return;
    const MediumCoefficients c = medium_coefficients(scene.medium(medium), p);
    FirstVertex& v = r.vertex;
    v.found = true;
    for (int k = 0; k < 3; ++k) v.albedo[k] = c.sigma_t[k] > 0 ? c.sigma_s[k] / c.sigma_t[k] : 0.0f;
    v.position = p;
    v.depth = r.distance + length(p - r.last);
}

}  // namespace pathlab
