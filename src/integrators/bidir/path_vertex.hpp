// Vertices of bidirectional subpaths and the densities that multiple importance sampling needs.
//
// A vertex stores the density with which it was sampled from its predecessor on its own
// subpath (pdf_fwd) and the density with which the next vertex of the subpath would have
// sampled it, had the path been traced the other way (pdf_rev). Both are per unit area at the
// vertex (Veach's thesis, ch. 10), except for vertices at infinity (a camera ray that escaped to
// the environment, or the light vertex of an environment or directional light), whose density
// is per unit solid angle of their direction. A Dirac scattering (mirror, glass, the coating of
// plastic) sets `delta`: no strategy may connect there. Its lobe counts with its coefficient,
// the probability of choosing it (the same in both directions), as its solid-angle density: the
// delta itself is common to every strategy that can sample the path, so it cancels in their
// ratios, and the neighbours' area densities keep their cosines and distances (the VCM report's
// treatment of specular vertices; pbrt-v3's reading of the density as 0, and of 0 as 1 in the
// ratios, drops a factor d^2 / cos per Dirac vertex). A density of 0 is a strategy that cannot
// sample the vertex at all (read as 1 in the ratios, where the delta flags leave it out anyway).
//
// In participating media (bdpt, lt; docs/volumes.md) a subpath also scatters at points in a
// medium (VertexKind::Medium, the phase function its BSDF, no normal), and the densities include
// distance sampling's: a vertex reached along an edge has density
//   pdfW / d^2 x (|cos| at a surface) x T(edge) x (sigma(x) at a medium vertex),
// per unit area at a surface and per unit volume in a medium, with T and sigma the deterministic
// MIS transmittance and extinction of media/medium.hpp; every vertex keeps T of the edge it was
// reached by (T_in) and its sigma (sigma_mis), which both directions of that edge share.
//
// These are the pieces of Veach's ratio form of the MIS weight (pbrt's formulation): for a
// path of n + 1 vertices sampled by strategy (s, t), the weight is 1 / sum_i (p_i / p_s)^beta,
// and the ratios p_{i+1} / p_i of neighbouring strategies are pdf_rev / pdf_fwd of one vertex.
#pragma once

#include <cmath>
#include <vector>

#include "integrators/common/shading.hpp"
#include "integrators/common/transport.hpp"

namespace pathlab {

enum class VertexKind : unsigned char { Camera, Light, Surface, Medium };

// A vertex apart from the colour its subpath carries there (what the densities and the MIS
// weights read).
struct PathVertexBase {
    VertexKind kind = VertexKind::Surface;
    Vec3f p;                 // position (on the entry disk for a light at infinity)
    Vec3f n{0.0f};           // geometric normal for the G term (zero: a point, e.g. the pinhole)
    Vec3f emitter_n{0.0f};   // the emitter's own normal (its emitting side), where it is one
    Vec3f dir{0.0f};         // at infinity: the unit direction from the scene towards the light;
                             // in a medium: the unit direction back towards where the subpath came from
    ShadingPoint sp;         // surface vertices: material, frame, arrival direction, mode
    float pdf_fwd = 0, pdf_rev = 0;
    bool delta = false;      // scattered by a Dirac lobe here
    bool infinite = false;   // a light at infinity
    bool delta_light = false;  // a point or directional light
    // Reached through a dispersive interface (spectral mode): its subpath carries the hero
    // wavelength alone from here on (the throughput's other lanes are 0).
    bool dispersed = false;
    int light = -1;          // the light of a light vertex, or of the emitter a surface lies on
    // Media: the medium the vertex lies in (a surface: the one the subpath arrived in; -1: none),
    // a surface's media on its two sides (null: it changes none), and the MIS densities' factors.
    int32_t medium = -1;
    const MediumInterface* media = nullptr;
    float sigma_mis = 1;     // a medium vertex's extinction (1 elsewhere)
    float sin_theta = 0;     // a medium vertex with an edge on: |sin| of the angle between its two edges (upbp's bb1d)
    float T_in = 1;          // the MIS transmittance of the edge from the previous vertex
    // The running MIS quantity (set_running_mis): the part of a strategy's MIS sum that comes
    // from this subpath's vertices two or more before this one, as a connection or merge ending
    // here needs it (the VCM report's dVCM / dVC / dVM, folded into one number).
    double mis_running = 0;

    bool has_normal() const { return !is_black(n); }
    // Whether a strategy may connect a new edge here.
    [[gnu::always_inline]] bool connectible() const {
        switch (kind) {
            case VertexKind::Camera: return true;
            case VertexKind::Light: return !(delta_light && infinite);  // not a directional light
            case VertexKind::Surface: return !sp.material->is_delta();
            case VertexKind::Medium: return true;
        }
        return false;
    }
    // Where a connecting ray leaves this vertex for `to` (offset off its surface).
    Ray segment_to(const PathVertexBase& to) const;
    // The medium a ray leaving this vertex in direction w starts in (a surface may separate two).
    int32_t medium_towards(const Vec3f& w) const {
        return kind == VertexKind::Surface && media && media->changes_medium() ? media->medium_towards(w, emitter_n) : medium;
    }
    // The distance-sampling factor of a density arriving here along an edge of MIS transmittance T.
    float distance_factor(float T) const { return T * sigma_mis; }
};

// A vertex of a subpath of transport T.
template <class T>
struct PathVertex : PathVertexBase {
    ColourOf<T> beta{0.0f};  // throughput of the subpath up to and including this vertex
    // The channels' densities of the subpath's distance sampling over a common normaliser
    // (media/medium.hpp's spectral MIS): a path's contribution is divided by their mean.
    ColourOf<T> r{1.0f};
};

// The solid-angle density pdfW at `from` of the direction to `to`, as an area density at `to`
// (kept in solid angle if `to` is at infinity).
float to_area_density(float pdfW, const PathVertexBase& from, const PathVertexBase& to);

// The density with which `cur` samples `next`, having been reached from `prev` (null for the
// first vertex of a subpath); per unit area at `next` (per unit volume in a medium), without the
// edge's distance_factor, which the caller multiplies.
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
    VertexKind kind;  // merging happens at surface and medium vertices
    float sigma_mis = 1;  // a medium vertex's extinction in the densities (the beam estimators leave it out)
    float sin_theta = 0;  // ... the angle between its two edges (bb1d)
};
inline MisVertex mis_vertex(const PathVertexBase& v) {
    return {v.pdf_fwd, v.pdf_rev, v.delta, v.delta_light, v.kind, v.sigma_mis, v.sin_theta};
}

// Vertex merging (vcm, bpm; Georgiev et al. 2012): the strategies a path can also be sampled by.
// Merging at vertex x (a non-Dirac surface vertex with at least one light vertex before it and
// the camera after it) samples x from both sides; its density is that of the connection whose
// camera endpoint is x, times the light side's area density of x, times eta = the number of
// light paths merged with (n_VM, against n_VC = 1 for connections) times the acceptance area
// pi r^2 (the VCM report's formulation). After a Dirac vertex on the light side the density of
// x is that lobe's coefficient times the edge's cos / d^2, as in every ratio (the delta cancels).
// In a medium (the point-point estimator of UPBP, Krivanek et al. 2014) x is a medium vertex,
// its densities are per unit volume and the acceptance region is the ball, eta_volume = the
// number of light paths times 4/3 pi r^3.
//
// upbp adds a second strategy at a medium vertex x: the point-beam estimator (P-B2D, Křivánek et
// al. 2014; Jarosz et al.'s beam radiance estimate), a photon point found within r of the camera
// subpath's edge through x. That edge's camera side samples x's direction but not its distance
// (the query beam is the whole edge, up to where the walk sampled its end: covering x with
// probability T, which stays in the density), so its density is the connection's times the
// light side's density of x, times eta_beam2d = N pi r^2 over x's extinction sigma.
// And the beam-beam estimator (B-B1D, Jarosz et al. 2011): a light subpath's edge through x (a
// photon beam) passing within r of the camera subpath's edge through x, neither side sampling
// x's distance along its edge, the kernel 1 / (2r) across both and the estimate divided by the
// sine of the angle between them: eta_beam1d sin(theta) / sigma^2 with eta_beam1d = N 2r.
// Several strategies at one vertex add h(psi eta_k) each; as h(ab) = h(a) h(b), that is one
// term h(psi eta_eff) with h(eta_eff) = sum_k h(eta_k) (merge_eta).
struct MergeMis {
    double eta = 0, eta_volume = 0;
    double eta_beam2d = 0;    // point-beam (upbp's pb2d): 0 when it takes no part
    double eta_beam1d = 0;    // beam-beam (upbp's bb1d): 0 when it takes no part
    bool merging = false;     // merging strategies take part
    bool connections = true;  // connection strategies with s >= 1 take part (s = 0 always does)
};

// Whether merging may happen at a vertex of this kind (if it is not Dirac), and with which eta:
// every merging strategy there, for the balance (power = false) or power heuristic.
inline bool merges_at(VertexKind k) { return k == VertexKind::Surface || k == VertexKind::Medium; }
inline double merge_eta(const MergeMis& vm, VertexKind k, float sigma_mis, float sin_theta, bool power) {
    if (k != VertexKind::Medium) return vm.eta;
    if (vm.eta_beam2d == 0 && vm.eta_beam1d == 0) return vm.eta_volume;
    const double sigma = sigma_mis, b2 = vm.eta_beam2d / sigma, b1 = vm.eta_beam1d * double(sin_theta) / (sigma * sigma);
    return power ? std::sqrt(vm.eta_volume * vm.eta_volume + b2 * b2 + b1 * b1) : vm.eta_volume + b2 + b1;
}

// The sum over the path's strategies other than (s, t) of (p_i / p_(s,t))^beta (beta = 2 for
// the power heuristic, else 1): Veach's ratio walk over light(0..s) and camera(0..t), callables
// giving each vertex's MisVertex, with the connecting vertices' densities already those of
// strategy (s, t). With `vm`, merging strategies too.
template <typename LightAt, typename CameraAt>
double mis_ratio_sum(const LightAt& light, int s, const CameraAt& camera, int t, bool power, const MergeMis* vm) {
    // Strategies ending at a Dirac vertex are left out (the delta flags); a density of 0 counts as 1.
    const auto remap0 = [](float f) { return f != 0 ? double(f) : 1.0; };
    const auto h = [power](double r) { return power ? r * r : r; };
    const bool connections = !vm || vm->connections, merging = vm && vm->merging;
    double sum = 0, ri = 1;
    // Strategies with fewer light vertices: the camera subpath's vertices, taken from the light side.
    for (int i = t - 1; i > 0; --i) {
        const MisVertex c = camera(i);
        // Merging at camera vertex i: ri is here the ratio of the connection ending there.
        if (merging && merges_at(c.kind) && !c.delta && s + (t - 1 - i) >= 1) sum += h(ri * double(c.pdf_rev) * merge_eta(*vm, c.kind, c.sigma_mis, c.sin_theta, power));
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
        if (merging && i >= 1 && merges_at(l.kind) && !l.delta) sum += h(ri * double(l.pdf_fwd) * merge_eta(*vm, l.kind, l.sigma_mis, l.sin_theta, power));
    }
    return sum;
}

// The balance (power = false) or power heuristic weight of strategy (s, t) for the path made
// of light[0..s) and camera[0..t), from their stored densities: Veach's ratio walk. `light`
// and `camera` hold the subpaths with the connecting vertices' densities already updated for
// this strategy (see Bdpt::mis_weight); vertices are left unchanged.
template <class Vertex>
float mis_weight_ratio_walk(const Vertex* light, int s, const Vertex* camera, int t, bool power, const MergeMis* vm = nullptr) {
    // (A light seen directly, s + t = 2: the caller decides whether s = t = 1 is a strategy; a
    // path with s = 0 alone has weight 1 without the walk.)
    const double sum = mis_ratio_sum([light](int i) { return mis_vertex(light[i]); }, s, [camera](int i) { return mis_vertex(camera[i]); },
                                     t, power, vm);
    return float(1 / (1 + sum));
}

// ---- MIS weights from running quantities (Georgiev et al., "Implementing Vertex Connection
// and Merging", 2012) --------------------------------------------------------------------------
// The ratio walk above costs O(path length) per connection and per merged photon. The same sums
// are carried along each subpath instead: mis_running of vertex m holds what the walk adds for
// the strategies whose endpoint lies at vertex m - 1 or before, with the densities that a
// connection or merge at m leaves unchanged (every pdf_fwd, and pdf_rev of vertices m - 2 and
// before), as a factor of the ratios at m and m - 1 that the connection decides. A connection
// then completes the sum from its endpoint's neighbourhood in O(1):
//   light side, endpoint y_e:  h(Q'_e) (c_e + mc_e h(phi_e eta) + h(Q'_{e-1}) X_e)
//   camera side, endpoint z_e: mc_e h(psi_e eta) + h(R'_e) (c_e + mc_{e-1} h(rev'_{e-1} eta) + h(R'_{e-1}) Y_e)
// with Q, R = pdf_rev / pdf_fwd (0 read as 1), c / mc whether a connection / a
// merge exists there, phi_i the light side's own density of y_i, psi_i
// the light side's density of z_i, X / Y the running quantities. The walk stays as the oracle
// (tests/test_bdpt_mis.cpp compares both).

// The parameters of the heuristic a subpath's running quantities are made for.
struct MisRules {
    bool power = false;
    bool merging = false, connections = true;
    MergeMis vm;
    MisRules(bool power_heuristic, const MergeMis* merge) : power(power_heuristic) {
        if (merge) merging = merge->merging, connections = merge->connections, vm = *merge;
    }
    double h(double r) const { return power ? r * r : r; }
    // Whether a merge at vertex v is a strategy, and its eta.
    bool merge_at(const PathVertexBase& v) const { return merging && merges_at(v.kind) && !v.delta; }
    double eta_at(const PathVertexBase& v) const { return merge_eta(vm, v.kind, v.sigma_mis, v.sin_theta, power); }
    // ... with the angle between its edges that a strategy gives it (negative: its own).
    double eta_at(const PathVertexBase& v, float sin_theta) const {
        return merge_eta(vm, v.kind, v.sigma_mis, sin_theta < 0 ? v.sin_theta : sin_theta, power);
    }
    static double remap0(double f) { return f != 0 ? f : 1.0; }
};

// Fills mis_running of every vertex of a complete subpath (light or camera side), from its
// stored densities; a vertex reads pdf_rev only of vertices two or more before it.
template <class Vertex>
void set_running_mis(Vertex* v, int n, bool light_side, const MisRules& m) {
    double prefix = 0;  // the walk's sum up to vertex i, all of whose densities are final
    for (int k = 0; k < n; ++k) {
        v[k].mis_running = 0;
        const int i = k - 1;  // the vertex the new quantity ends at
        if (i < 0) continue;
        if (light_side) {
            // X_k = c_i + mc_i h(phi_i eta) + P_{i-1};  P_i = h(Q_i) X_k
            const bool delta_before = i > 0 ? v[i - 1].delta : v[0].delta_light;
            double x = prefix;
            if ((m.connections || i == 0) && !v[i].delta && !delta_before) x += 1;
            if (i >= 1 && m.merge_at(v[i])) x += m.h(double(v[i].pdf_fwd) * m.eta_at(v[i]));
            v[k].mis_running = x;
            prefix = m.h(MisRules::remap0(v[i].pdf_rev) / MisRules::remap0(v[i].pdf_fwd)) * x;
        } else {
            // Y_k = c_i + S_{i-1};  S_i = mc_i h(psi_i eta) + h(R_i) Y_k (the pinhole z_0 is no endpoint)
            if (i == 0) continue;
            double y = prefix;
            if (m.connections && !v[i].delta && !v[i - 1].delta) y += 1;
            v[k].mis_running = y;
            prefix = m.h(MisRules::remap0(v[i].pdf_rev) / MisRules::remap0(v[i].pdf_fwd)) * y;
            if (m.merge_at(v[i])) prefix += m.h(double(v[i].pdf_rev) * m.eta_at(v[i]));
        }
    }
}

// The light side's part of the MIS sum of a connection ending at y_e (e = s - 1, not Dirac
// there), with the densities rev_e of y_e and rev_prev of y_{e-1} that the connection gives
// (and the sine of the angle at y_e between its edge and the connection's, for bb1d).
template <class Vertex>
double light_side_sum(const Vertex* y, int e, double rev_e, double rev_prev, const MisRules& m, float sin_e = -1) {
    const double q = m.h(MisRules::remap0(rev_e) / MisRules::remap0(y[e].pdf_fwd));
    if (e == 0) return y[0].delta_light ? 0.0 : q;
    double inner = m.h(MisRules::remap0(rev_prev) / MisRules::remap0(y[e - 1].pdf_fwd)) * y[e].mis_running;
    if (m.connections && !y[e - 1].delta) inner += 1;
    if (m.merging && merges_at(y[e].kind)) inner += m.h(double(y[e].pdf_fwd) * m.eta_at(y[e], sin_e));  // (y_e is connected: not Dirac here)
    return q * inner;
}

// The camera side's part of the MIS sum of a strategy ending at z_e (e = t - 1 >= 1, not Dirac
// there): z_e's light-side density rev_e (merging at z_e counts with psi_e, its density from the
// light side; merge_here: the strategy has a light vertex), and
// z_{e-1}'s, rev_prev. `fwd_e` is z_e's own density (a merge's camera endpoint has its own);
// sin_e the sine of the angle at z_e between its edge and the strategy's light side (bb1d).
template <class Vertex>
double camera_side_sum(const Vertex* z, int e, double fwd_e, double rev_e, double psi_e, bool merge_here, double rev_prev,
                       const MisRules& m, float sin_e = -1) {
    double inner = 0;
    if (e >= 2) {
        inner = m.h(MisRules::remap0(rev_prev) / MisRules::remap0(z[e - 1].pdf_fwd)) * z[e].mis_running;
        if (m.merge_at(z[e - 1])) inner += m.h(rev_prev * m.eta_at(z[e - 1]));
    }
    if (m.connections && !z[e - 1].delta) inner += 1;
    double sum = m.h(MisRules::remap0(rev_e) / MisRules::remap0(fwd_e)) * inner;
    if (merge_here && m.merging && merges_at(z[e].kind)) sum += m.h(psi_e * m.eta_at(z[e], sin_e));
    return sum;
}

}  // namespace pathlab
