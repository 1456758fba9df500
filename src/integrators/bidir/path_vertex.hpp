// Vertices of bidirectional subpaths and the densities that multiple importance sampling needs.
//
// A vertex stores the density with which it was sampled from its predecessor on its own
// subpath (pdf_fwd) and the density with which the next vertex of the subpath would have
// sampled it, had the path been traced the other way (pdf_rev). Both are per unit area at the
// vertex (Veach's thesis, ch. 10), except for vertices at infinity (a camera ray that escaped to
// the environment, or the light vertex of an environment or directional light), whose density
// is per unit solid angle of their direction. A Dirac scattering (mirror, glass, the coating of
// plastic) makes both 0 and sets `delta`: no strategy may connect there.
//
// These are the pieces of Veach's ratio form of the MIS weight (pbrt's formulation): for a
// path of n + 1 vertices sampled by strategy (s, t), the weight is 1 / sum_i (p_i / p_s)^beta,
// and the ratios p_{i+1} / p_i of neighbouring strategies are pdf_rev / pdf_fwd of one vertex.
#pragma once

#include <vector>

#include "integrators/common/shading.hpp"
#include "integrators/common/transport.hpp"

namespace pathlab {

enum class VertexKind : unsigned char { Camera, Light, Surface };

// A vertex apart from the colour its subpath carries there (what the densities and the MIS
// weights read).
struct PathVertexBase {
    VertexKind kind = VertexKind::Surface;
    Vec3f p;                 // position (on the entry disk for a light at infinity)
    Vec3f n{0.0f};           // geometric normal for the G term (zero: a point, e.g. the pinhole)
    Vec3f emitter_n{0.0f};   // the emitter's own normal (its emitting side), where it is one
    Vec3f dir{0.0f};         // at infinity: the unit direction from the scene towards the light
    ShadingPoint sp;         // surface vertices: material, frame, arrival direction, mode
    float pdf_fwd = 0, pdf_rev = 0;
    bool delta = false;      // scattered by a Dirac lobe here
    bool infinite = false;   // a light at infinity
    bool delta_light = false;  // a point or directional light
    // Reached through a dispersive interface (spectral mode): its subpath carries the hero
    // wavelength alone from here on (the throughput's other lanes are 0).
    bool dispersed = false;
    int light = -1;          // the light of a light vertex, or of the emitter a surface lies on

    bool has_normal() const { return !is_black(n); }
    // Whether a strategy may connect a new edge here.
    bool connectible() const {
        switch (kind) {
            case VertexKind::Camera: return true;
            case VertexKind::Light: return !(delta_light && infinite);  // not a directional light
            case VertexKind::Surface: return !sp.material->is_delta();
        }
        return false;
    }
    // Where a connecting ray leaves this vertex for `to` (offset off its surface).
    Ray segment_to(const PathVertexBase& to) const;
};

// A vertex of a subpath of transport T.
template <class T>
struct PathVertex : PathVertexBase {
    ColourOf<T> beta{0.0f};  // throughput of the subpath up to and including this vertex
};

// The solid-angle density pdfW at `from` of the direction to `to`, as an area density at `to`
// (kept in solid angle if `to` is at infinity).
float to_area_density(float pdfW, const PathVertexBase& from, const PathVertexBase& to);

// The density with which `cur` samples `next`, having been reached from `prev` (null for the
// first vertex of a subpath); per unit area at `next`.
float pdf_next(const Scene& scene, const PerspectiveCamera& camera, const PathVertexBase* prev, const PathVertexBase& cur,
               const PathVertexBase& next);
// The density with which the light at vertex `v` (a light vertex, or a surface on an emitter)
// emits towards `next`, per unit area at `next`.
float pdf_light_emission(const Scene& scene, const PathVertexBase& v, const PathVertexBase& next);
// The density with which light sampling chooses and samples `v` as a light's origin (its
// position for finite lights, its direction for lights at infinity), looking from `from`.
float pdf_light_origin(const Scene& scene, const PathVertexBase& v, const PathVertexBase& from);

// What the MIS weights read of a vertex (so that a weight can be computed with some of a
// path's densities replaced, without copying its vertices).
struct MisVertex {
    float pdf_fwd, pdf_rev;
    bool delta, delta_light;
    bool surface;  // a surface vertex (where vertex merging may happen)
};
inline MisVertex mis_vertex(const PathVertexBase& v) { return {v.pdf_fwd, v.pdf_rev, v.delta, v.delta_light, v.kind == VertexKind::Surface}; }

// Vertex merging (vcm, bpm; Georgiev et al. 2012): the strategies a path can also be sampled by.
// Merging at vertex x (a non-Dirac surface vertex with at least one light vertex before it and
// the camera after it) samples x from both sides; its density is that of the connection whose
// camera endpoint is x, times the light side's area density of x, times eta = the number of
// light paths merged with (n_VM, against n_VC = 1 for connections) times the acceptance area
// pi r^2 (the VCM report's formulation). After a Dirac vertex on the light side the density of
// x is that vertex's delta, which every strategy sampling x from the light side shares: 1.
struct MergeMis {
    double eta = 0;
    bool merging = false;     // merging strategies take part
    bool connections = true;  // connection strategies with s >= 1 take part (s = 0 always does)
};

// The sum over the path's strategies other than (s, t) of (p_i / p_(s,t))^beta (beta = 2 for
// the power heuristic, else 1): Veach's ratio walk over light(0..s) and camera(0..t), callables
// giving each vertex's MisVertex, with the connecting vertices' densities already those of
// strategy (s, t). With `vm`, merging strategies too.
template <typename LightAt, typename CameraAt>
double mis_ratio_sum(const LightAt& light, int s, const CameraAt& camera, int t, bool power, const MergeMis* vm) {
    // A density of 0 marks a Dirac lobe: those strategies are left out, and the ratio passes
    // through the vertex unchanged.
    const auto remap0 = [](float f) { return f != 0 ? double(f) : 1.0; };
    const auto h = [power](double r) { return power ? r * r : r; };
    const bool connections = !vm || vm->connections, merging = vm && vm->merging;
    double sum = 0, ri = 1;
    // Strategies with fewer light vertices: the camera subpath's vertices, taken from the light side.
    for (int i = t - 1; i > 0; --i) {
        const MisVertex c = camera(i);
        // Merging at camera vertex i: ri is here the ratio of the connection ending there. A
        // light-side density of 0 after a Dirac vertex is that vertex's delta, common to every
        // strategy that samples i from the light side: 1, as in the ratios.
        if (merging && c.surface && !c.delta && s + (t - 1 - i) >= 1) {
            const bool after_dirac = i == t - 1 ? light(s - 1).delta : camera(i + 1).delta;
            sum += h(ri * (after_dirac ? 1.0 : double(c.pdf_rev)) * vm->eta);
        }
        ri *= remap0(c.pdf_rev) / remap0(c.pdf_fwd);
        if (connections && !c.delta && !camera(i - 1).delta) sum += h(ri);
    }
    // Strategies with more light vertices.
    ri = 1;
    for (int i = s - 1; i >= 0; --i) {
        const MisVertex l = light(i);
        ri *= remap0(l.pdf_rev) / remap0(l.pdf_fwd);
        const bool delta_before = i > 0 ? light(i - 1).delta : l.delta_light;
        if ((connections || i == 0) && !l.delta && !delta_before) sum += h(ri);
        // Merging at light vertex i, now the camera endpoint of the connection (i, s + t - i).
        if (merging && i >= 1 && l.surface && !l.delta) sum += h(ri * (light(i - 1).delta ? 1.0 : double(l.pdf_fwd)) * vm->eta);
    }
    return sum;
}

// The balance (power = false) or power heuristic weight of strategy (s, t) for the path made
// of light[0..s) and camera[0..t), from their stored densities: Veach's ratio walk. `light`
// and `camera` hold the subpaths with the connecting vertices' densities already updated for
// this strategy (see Bdpt::mis_weight); vertices are left unchanged.
template <class Vertex>
float mis_weight_ratio_walk(const Vertex* light, int s, const Vertex* camera, int t, bool power, const MergeMis* vm = nullptr) {
    if (s + t == 2) return 1.0f;  // a light seen directly: only s = 0 samples it (s = t = 1 is not used)
    const double sum = mis_ratio_sum([light](int i) { return mis_vertex(light[i]); }, s, [camera](int i) { return mis_vertex(camera[i]); },
                                     t, power, vm);
    return float(1 / (1 + sum));
}

}  // namespace pathlab
