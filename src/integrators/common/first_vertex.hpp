// The first non-specular vertex of the camera sample being taken (--aovs; render/aov_film.hpp),
// found as the path goes, with no change to any integrator's sampling: while a pixel integrator
// takes a sample with AOVs on, a FirstVertexScope makes a recorder current on its thread;
// make_shading_point offers every surface vertex it makes, and volpath every scattering point
// in a medium. The first offer that is not purely specular (Dirac lobes only, or an
// index-matched boundary) is kept; the specular ones before it only add to the path's length.
// Light paths (the light tracer, bdpt, the photon methods) trace no camera path here: their
// integrators are not pixel integrators, and no recorder is current while they run.
#pragma once

#include "render/aov_film.hpp"

namespace pathlab {

class Scene;
struct ShadingPoint;

struct FirstVertexRecorder {
    FirstVertex vertex;
    Vec3f last{0.0f};     // the camera, then the last specular vertex
    float distance = 0;   // the path's length up to `last`
};

// The current thread's recorder, or null (the usual case: no AOVs, or not a camera sample).
inline thread_local FirstVertexRecorder* t_first_vertex = nullptr;

class FirstVertexScope {
public:
    FirstVertexScope(FirstVertexRecorder& r, const Vec3f& camera) : previous_(t_first_vertex) {
        r = FirstVertexRecorder{};
        r.last = camera;
        t_first_vertex = &r;
    }
    ~FirstVertexScope() { t_first_vertex = previous_; }
    FirstVertexScope(const FirstVertexScope&) = delete;
    FirstVertexScope& operator=(const FirstVertexScope&) = delete;

private:
    FirstVertexRecorder* previous_;
};

// A surface vertex of the camera path (make_shading_point calls it when a recorder is current).
void offer_surface_vertex(FirstVertexRecorder& r, const Scene& scene, const ShadingPoint& sp);
// A scattering point in medium `medium` of the scene.
void offer_medium_vertex(FirstVertexRecorder& r, const Scene& scene, int32_t medium, const Vec3f& p);

}  // namespace pathlab
