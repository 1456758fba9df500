#include "integrators/bidir/path_vertex.hpp"

#include <cmath>

namespace pathlab {

Ray PathVertexBase::segment_to(const PathVertexBase& to) const {
    const Vec3f offset_n = kind == VertexKind::Surface ? sp.ng : n;
    if (to.infinite) return is_black(offset_n) ? Ray{p, to.dir, kInf} : spawn_ray(p, offset_n, to.dir);
    return spawn_segment(p, offset_n, to.p, to.kind == VertexKind::Surface ? to.sp.ng : to.n);
}

float to_area_density(float pdfW, const PathVertexBase& from, const PathVertexBase& to) {
    if (to.infinite) return pdfW;
    const Vec3f d = to.p - from.p;
    const float dist2 = dot(d, d);
    if (!(dist2 > 0)) return 0.0f;
    float pdf = pdfW / dist2;
    if (to.has_normal()) pdf *= std::abs(dot(to.n, d)) / std::sqrt(dist2);
    return pdf;
}

namespace {

// The unit direction from `from` towards `to` (for a vertex at infinity, its direction).
Vec3f direction(const PathVertexBase& from, const PathVertexBase& to) { return to.infinite ? to.dir : normalize(to.p - from.p); }

}  // namespace

float pdf_next(const Scene& scene, const PerspectiveCamera& camera, const PathVertexBase* prev, const PathVertexBase& cur,
               const PathVertexBase& next) {
    if (cur.kind == VertexKind::Light) return pdf_light_emission(scene, cur, next);
    const Vec3f wn = direction(cur, next);
    float pdfW = 0;
    if (cur.kind == VertexKind::Camera) {
        pdfW = camera.pdf_direction(wn);
    } else if (cur.kind == VertexKind::Medium) {
        if (!prev) return 0.0f;
        pdfW = phase_pdf(medium_phase(scene.medium(cur.medium)), direction(cur, *prev), wn);
    } else {
        if (!prev) return 0.0f;
        const Vec3f wp = direction(cur, *prev);
        pdfW = cur.sp.material->pdf(cur.sp, cur.sp.frame.to_local(wp), cur.sp.frame.to_local(wn));
    }
    return to_area_density(pdfW, cur, next);
}

float pdf_light_emission(const Scene& scene, const PathVertexBase& v, const PathVertexBase& next) {
    if (v.light < 0) return 0.0f;
    const SceneSphere sphere = scene.scene_sphere();
    if (v.infinite) {
        // An origin on the entry disk, then straight on: area density at `next` by projection.
        float pdf = entry_disk_pdfA(sphere);
        if (next.has_normal()) pdf *= std::abs(dot(next.n, v.dir));
        return pdf;
    }
    const Vec3f d = next.p - v.p;
    const float dist2 = dot(d, d);
    if (!(dist2 > 0)) return 0.0f;
    const Vec3f w = d / std::sqrt(dist2);
    const EmissionPdf e = pdf_emission(scene.lights()[size_t(v.light)], v.p, v.emitter_n, w, sphere);
    float pdf = e.pdfW / dist2;
    if (next.has_normal()) pdf *= std::abs(dot(next.n, w));
    return pdf;
}

float pdf_light_origin(const Scene& scene, const PathVertexBase& v, const PathVertexBase& from) {
    if (v.light < 0) return 0.0f;
    const Light& light = scene.lights()[size_t(v.light)];
    if (v.infinite) {
        // Light sampling picks directions at infinity: only the environment has a density.
        return is_environment(light) ? scene.emitter_pmf(v.light) * environment_pdf_li(light, v.dir) : 0.0f;
    }
    const Vec3f w = normalize(from.p - v.p);
    return scene.emitter_pmf(v.light) * pdf_emission(light, v.p, v.emitter_n, w, scene.scene_sphere()).pdfA;
}

}  // namespace pathlab
