#include "bsdfs/material_textures.hpp"

#include <optional>

namespace pathlab {
namespace {

// `v` made orthogonal to the unit vector n and normalised; nothing if that leaves no direction.
std::optional<Vec3f> orthogonal_unit(const Vec3f& v, const Vec3f& n) {
    const Vec3f s = v - n * dot(n, v);
    const float len2 = dot(s, s);
    if (!(len2 > 1e-12f * dot(v, v)) || !std::isfinite(len2)) return std::nullopt;
    return s / std::sqrt(len2);
}

// The frame (s, n x s, n) with s = dp/du made orthogonal to n, or Frame(n).
Frame frame_along(const Vec3f& n, const Vec3f& dpdu) {
    const std::optional<Vec3f> s = orthogonal_unit(dpdu, n);
    if (!s) return Frame(n);
    Frame f;
    f.n = n;
    f.s = *s;
    f.t = cross(n, *s);
    return f;
}

}  // namespace

Frame tangent_frame(const Vec3f& n, const Vec3f& dpdu) { return frame_along(n, dpdu); }

Frame flip_invalid_normal(const Frame& f, const Vec3f& n, const Vec3f& wi) {
    if (dot(wi, n) * dot(wi, f.n) > 0) return f;
    return frame_along(n * (2 * dot(f.n, n)) - f.n, f.s);
}

Frame perturbed_frame(const MaterialTextures& t, const Vec3f& n, const Vec3f& ng, const Vec3f& dpdu, const Vec3f& dpdv,
                      const SurfaceUv& uv) {
    const Frame base = frame_along(n, dpdu);
    if (!t.perturbation_texture) return base;
    Vec3f p(0.0f);
    if (t.perturbation == FramePerturbation::NormalMap) {
        const Rgb c = t.perturbation_texture->eval(uv);
        p = base.to_world(c * 2.0f - Rgb(1.0f));
    } else if (t.perturbation == FramePerturbation::BumpMap) {
        const Vec2f g = t.perturbation_texture->eval_1_grad(uv);
        const Vec3f du = dpdu + n * (t.bump_scale * g.x - dot(n, dpdu));
        const Vec3f dv = dpdv + n * (t.bump_scale * g.y - dot(n, dpdv));
        p = cross(du, dv);
    }
    const float len = length(p);
    if (!(len > 0) || !std::isfinite(len)) return base;
    Vec3f np = p / len;
    if (dot(np, ng) < 0) np = -np;
    return frame_along(np, base.s);
}

}  // namespace pathlab
