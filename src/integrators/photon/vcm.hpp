// vcm and bpm: vertex connection and merging (Georgiev, Křivánek, Davidovič and Slusallek 2012,
// and their technical report "Implementing Vertex Connection and Merging"), and bidirectional
// photon mapping (Vorba 2011), which is vcm without connections.
//
// An iteration i: one light subpath per pixel (N = the pixel count), traced and kept, and a
// photon at every vertex y_1, y_2, ... on a non-Dirac surface; then per pixel a camera subpath
// z_0, z_1, ..., which
//   - connects to its own pixel's light subpath by every strategy (s, t) of bdpt (the same
//     code, random numbers and densities: bdpt.hpp);
//   - merges at every non-Dirac surface vertex z_{t-1} with the photons of all N light paths
//     within the iteration's radius r_i: a photon y_{s-1} there makes the path y_0 .. y_{s-1},
//     z_{t-2} .. z_0, with the estimate f(z, wo, wi_y) beta_y beta_z / (N pi r_i^2).
// All these strategies are combined by multiple importance sampling (balance heuristic, or
// power with --mis power) with bdpt's weights extended by the merging strategies: merging at a
// vertex x has the density of the connection ending at x, times the light side's area density
// of x, times eta = N pi r_i^2 (path_vertex.hpp, MergeMis). Every weight, a merged photon's too,
// costs O(1): the subpaths carry running quantities, and a photon is a compact MergeVertex that
// holds its subpath's (no merge reads the subpath it came from). The photons are sorted into the
// grid's cell order as they are made (PhotonGrid::build_placed).
//
// The radius shrinks as in sppm (Knaus and Zwicker: r_i^2 = r_1^2 prod (k + alpha) / (k + 1),
// progressive_radius.hpp; --radius, --alpha), so iterations are independent given their index
// and the image converges. --no-merging leaves bdpt (bit for bit: the same samples and
// weights), --no-connections bpm (the integrator `bpm`): merging at every camera vertex, plus
// the emission the camera subpath hits (s = 0), by MIS between them.
// Depth: merging y_{s-1} at z_{t-1} makes s + t - 3 bounces, limited by --max-depth as in bdpt.
// Deterministic: light subpaths are traced in fixed chunks and stored in order, the grid's
// order is fixed, and the camera pass splats (t = 1) through bdpt's per-chunk lists.
//
// Participating media (docs/volumes.md "vcm and bpm in media"): the subpaths scatter in media as
// bdpt's do, a light vertex in a medium is a photon too, and a camera vertex in a medium merges
// with the photons in media within the ball of radius r_i around it (the point-point 3D estimator
// of UPBP, Krivanek et al. 2014): the estimate phase(z, wo, wi_y) beta_y beta_z / (sigma_s(z) N
// 4/3 pi r_i^3) (both throughputs include the scattering coefficient of their vertex, the path
// once), weighed with eta_volume = N 4/3 pi r_i^3 and the densities per unit volume
// (path_vertex.hpp). Surface photons merge at surface vertices only, medium photons at medium
// vertices only (of any medium within the ball, as a surface merge takes photons of any surface
// within its disc). All subpaths of an iteration share one hero channel (in RGB; spectrally the
// hero wavelength is lane 0 of the iteration's wavelengths anyway): a merge joins any light path
// with any camera path, and its contribution is divided by the channels' mean of their distance
// densities' product (media/medium.hpp), as a connection's is.
//
// Spectral mode (docs/spectral.md "Spectral vcm and bpm"): a merge multiplies a camera throughput
// by a photon's power, and a connection two subpaths' throughputs, lane by lane, so every camera
// and light path of an iteration carries the pass's wavelengths (pass_wavelengths, as the photon
// methods). A connection through a dispersive vertex is hero_only() (bdpt.hpp); a merge whose
// photon or camera vertex was reached through one counts lane 0 times 4, once for the whole path
// (MergeSum against the camera's wavelengths, then hero_only() when the camera side is the
// dispersed one).
//
// upbp (Křivánek, Georgiev, Hachisuka, Vévoda, Šik, Nowrouzezahrai and Jarosz 2014, "Unifying
// points, beams, and paths in volumetric light transport simulation") is this class with a
// choice of estimators (--estimators, SmallUPBP's names): bpt (the connections), surf (merging on
// surfaces), pp3d (merging at points in media: the ball above) and pb2d, the point-beam estimator:
// every piece of every camera subpath edge inside a medium (a query beam, from its vertex to
// where the walk sampled the edge's end: a "short" beam) gathers the medium photons within r of
// it (Jarosz, Zwicker and Jensen 2008's beam radiance estimate with a fixed radius; BallTree):
// photon y at distance s along the beam adds
//   phase(y, -d, wi_y) beta_y beta_beam T(s) / (P(s) N pi r^2),
// P(s) the probability that the walk reached s (T(s) for the channel that sampled it, whose
// channels' mean the spectral MIS divides by, as for a connection). Its MIS density leaves out the
// camera side's distance density of y but not P(s): eta_beam2d / sigma (path_vertex.hpp). And
// bb1d, the beam-beam estimator (Jarosz et al. 2011): the light subpaths' pieces of edges in media
// (photon beams, of the first --photon-beams light paths; BeamTree) against every query beam, a
// pair whose lines pass within r adding beta_c T_c / P_c beta_l T_l / P_l sigma_s phase /
// (K 2r sin theta), with the MIS density eta_beam1d sin theta / sigma^2. s = 0 (the camera subpath
// hitting a light) always takes part, so every subset renders the whole image. pb2d and bb1d need
// homogeneous media (the closed-form T(s)); a scene with a grid medium is refused for them.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <vector>

#include "integrators/bidir/bdpt.hpp"
#include "integrators/integrator.hpp"
#include "integrators/photon/ball_tree.hpp"
#include "integrators/photon/beam_tree.hpp"
#include "integrators/photon/photon.hpp"
#include "integrators/photon/photon_grid.hpp"
#include "render/pass_image.hpp"

namespace pathlab {

// A light vertex as merging needs it (the VCM report's light vertex, without the BSDF: a merge
// evaluates the camera vertex's): the photon, and the MIS quantities of its light subpath that a
// merge completes in O(1) (path_vertex.hpp), so that no merge reads the subpath it came from.
template <class T>
struct MergeVertex : Photon<T> {
    float pdf_fwd = 0;       // its light subpath's area density of it
    float prev_pdf_fwd = 0;  // ... of the vertex before it
    float prev_g = 0;        // |cos| / distance^2 at the vertex before it (1 at infinity): a solid-angle density from here, as area there
    float mis_running = 0;   // its light-side running quantity
    bool prev_delta = false; // the vertex before it scattered by a Dirac lobe
};

// The estimators of the vcm family, by SmallUPBP's names: bdpt's connections (bpt), merging on
// surfaces (surf), at points in media (pp3d), photon points along camera beams (pb2d) and photon
// beams against camera beams (bb1d).
struct VcmEstimators {
    bool bpt = true, surf = true, pp3d = true, pb2d = false, bb1d = false;
    bool merging() const { return surf || pp3d || pb2d || bb1d; }
};
// A comma-separated list of estimator names ("" or "all": every one); std::invalid_argument
// names the valid ones.
VcmEstimators parse_estimators(const std::string& list);
// The list's names, in the canonical order (for messages and the render's identity).
std::string estimator_names(const VcmEstimators& e);

// Deliberate faults, for the tests that must be able to fail.
struct VcmFaults {
    bool beam_without_transmittance = false;  // pb2d leaves the beam's T(s) out of a photon's contribution (keeps 1 / P(s))
    bool beam_kernel_as_ball = false;         // pb2d divides by N 4/3 pi r^3 instead of N pi r^2 (not in the MIS)
    bool beam_beam_without_sine = false;      // bb1d leaves 1 / sin(theta) out of its estimate (not of the MIS)
    bool no_pi_in_kernel = false;  // the merge divides by N r^2 instead of N pi r^2 (also in the MIS)
    bool merge_weight_without_light_pdf = false;  // a merge's own density lacks the light side's density of its vertex
    bool volume_kernel_as_disc = false;  // a merge in a medium divides by N pi r^2 (the surfaces' kernel; also in the MIS)
};

template <class T>
class Vcm final : public Integrator {
public:
    using Colour = ColourOf<T>;
    using Wavelengths = WavelengthsOf<T>;
    using Vertex = PathVertex<T>;

    explicit Vcm(const IntegratorOptions& options, VcmFaults faults = {});

    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                               const PassProgress& progress) override;

    // The light subpaths and photons of iteration `pass` at its wavelengths (kept until the next),
    // with the running MIS quantities of the strategies in `vm` and the hero channel of media;
    // returns the rays traced. The photons are made by place_photons.
    uint64_t trace_light_paths(const RenderContext& ctx, uint64_t pass, const Wavelengths& wl, const MergeMis& vm, int hero = -1);
    // The merging estimate at camera vertex z_{t-1} (t >= 2, on a surface or in a medium) with the
    // current photons, radius r, MIS-weighted against every strategy in `vm` (times the camera throughput).
    Colour merge(const Scene& scene, const std::vector<Vertex>& camera, int t, float r, const MergeMis& vm, const Wavelengths& wl) const;
    // The merge vertex of light vertex y_j of the subpath y (with its running MIS quantities).
    static MergeVertex<T> merge_vertex(const Vertex* y, int j);
    // The MIS weight of merging `photon` at camera vertex z_{t-1}, whose BSDF samples the photon's
    // direction with solid-angle density pdf_to_light and the camera's from it with pdf_to_camera:
    // O(1), from the running quantities of both subpaths (made with the same `vm`).
    // camera_prev_g: to_area_density(1, z_{t-1}, z_{t-2}) if known (negative: computed here).
    // own_eta: the merge's own eta (negative: the point estimator's at z_{t-1}, eta or eta_volume).
    float merge_weight(const MergeVertex<T>& photon, float pdf_to_light, float pdf_to_camera, const std::vector<Vertex>& camera,
                       int t, const MergeMis& vm, float camera_prev_g = -1, double own_eta = -1) const;
    // The point-beam estimate (pb2d) along one query beam of the camera subpath, MIS-weighted
    // against every strategy in `vm` (times the beam's throughput). `scratch` holds the camera
    // subpath up to the beam's vertex and the merge vertex on the beam.
    Colour beam_merge(const Scene& scene, const std::vector<Vertex>& camera, const SubpathBeam<T>& beam, float r, const MergeMis& vm,
                      const Wavelengths& wl, std::vector<Vertex>& scratch) const;
    // The MIS weight of pb2d merging photon y_{s-1} on the camera beam from z_{a} at distance
    // `along`, by the running quantities and by the ratio walk (the tests' oracle).
    float beam_merge_weight(const Scene& scene, const Vertex* y, int s, const std::vector<Vertex>& camera, const SubpathBeam<T>& beam,
                            float along, const MergeMis& vm, bool oracle) const;
    // The beam-beam estimate (bb1d) of the iteration's photon beams along one query beam,
    // MIS-weighted (times both beams' throughputs).
    Colour beam_beam(const Scene& scene, const std::vector<Vertex>& camera, const SubpathBeam<T>& beam, float r, const MergeMis& vm,
                     const Wavelengths& wl, std::vector<Vertex>& scratch) const;
    // The MIS weight of bb1d joining the light subpath y's beam `light_beam` (from y_{from}) at
    // distance along_light with the camera beam at distance along_camera, by the running
    // quantities and by the ratio walk (the tests' oracle).
    float beam_beam_weight(const Scene& scene, const Vertex* y, const SubpathBeam<T>& light_beam, float along_light,
                           const std::vector<Vertex>& camera, const SubpathBeam<T>& camera_beam, float along_camera, const MergeMis& vm,
                           bool oracle) const;
    const VcmEstimators& estimators() const { return estimators_; }
    // The MIS weight of merging photon y_{s-1} (light subpath y[0..s)) at camera vertex z_{t-1},
    // by the running quantities as the render does, and by Veach's ratio walk (the tests' oracle).
    float merge_weight(const Scene& scene, const Vertex* y, int s, const std::vector<Vertex>& camera, int t, const MergeMis& vm) const;
    float merge_weight_oracle(const Scene& scene, const Vertex* y, int s, const std::vector<Vertex>& camera, int t,
                              const MergeMis& vm, double own_eta = -1) const;
    // The merge densities N pi r^2 (surfaces) and N 4/3 pi r^3 (media) of N light paths and
    // radius r, pb2d's N pi r_beam^2 and bb1d's K 2 r_beam (negative r_beam: r), for the
    // estimators chosen.
    MergeMis merge_mis(size_t light_paths, double r, double r_beam = -1) const;
    // bb1d: how many of an iteration's light paths (the first ones) leave photon beams: a beam
    // meets many camera beams, and SmallUPBP too lets fewer paths than the pixels make them.
    size_t photon_beam_paths(size_t light_paths) const;
    static constexpr size_t kDefaultPhotonBeamPaths = 256;
    static constexpr float kBeamRadiusDivisor = 4;  // the beams' radius against the points' by default

    const Bdpt<T>& bdpt() const { return bdpt_; }
    size_t photon_count() const { return photons_.size(); }
    size_t light_vertex_count() const;
    // Bytes held for the light vertices and photons of one iteration (the grid included).
    size_t memory_bytes() const;

private:
    // pb2d's tree of the iteration's medium photons, balls of radius r.
    void build_volume_tree(float r);
    // A photon beam of the iteration: a piece of light path `path`'s edge in a medium, and the
    // running MIS quantity of a light vertex on it (that of the vertex after beam.from).
    struct LightBeam {
        SubpathBeam<T> beam;
        uint32_t path = 0;
        float mis_running = 0;
    };
    // The merge vertex (a photon) that light beam b has at distance `along`, and the light
    // vertex it stands for (for the MIS).
    MergeVertex<T> photon_on_beam(const Scene& scene, const Vertex* y, const SubpathBeam<T>& b, float along, float mis_running,
                                  Vertex& x) const;
    const Vertex* light_path(uint32_t j) const;
    // The merge vertices of the traced light subpaths (of `paths` pixels), each made in its slot of
    // the grid's cell order (with its distance densities in media), and the grid for radius r.
    void place_photons(size_t paths, bool media, float r);
    // The merge vertex that stands for a photon on a camera beam (pb2d) at distance `along`.
    void place_on_beam(const Scene& scene, const SubpathBeam<T>& beam, float along, const Vertex& from, Vertex& x) const;

    IntegratorOptions options_;
    VcmEstimators estimators_;
    VcmFaults faults_;
    Bdpt<T> bdpt_;  // the subpaths, the connections and their weights
    // One iteration's light subpaths (for the connections of their own pixels), per chunk of
    // light paths, and where each path starts; its merge vertices, in one array.
    std::vector<std::vector<Vertex>> chunk_vertices_;
    std::vector<size_t> chunk_photons_;   // chunk c's merge vertices are these in path order
    std::vector<Vec3f> photon_positions_;  // the merge vertices' positions in path order (the grid's input)
    std::vector<uint32_t> path_begin_;    // light path j: its chunk's vertices from here
    std::vector<uint16_t> path_length_;   // ... this many
    std::vector<MergeVertex<T>> photons_;  // in the grid's cell order
    std::vector<Colour> photon_r_;         // in media: each photon's subpath's distance densities (PathVertex::r), in the same order
    PhotonGrid grid_;
    BallTree volume_tree_;                  // pb2d: the medium photons (indices into photons_ in volume_index_)
    std::vector<uint32_t> volume_index_;
    std::vector<Vec3f> volume_position_;
    std::vector<std::vector<LightBeam>> chunk_beams_;  // bb1d: per chunk of light paths, in path order
    std::vector<LightBeam> light_beams_;               // ... all of them, in path order
    BeamTree beam_tree_;
    size_t light_per_chunk_ = 1;
    PassImage pass_;
    tbb::enumerable_thread_specific<std::pair<std::vector<Vertex>, std::vector<Vertex>>> subpaths_;  // camera, light
    struct BeamScratch {
        std::vector<SubpathBeam<T>> beams;
        std::vector<Vertex> camera;
    };
    tbb::enumerable_thread_specific<BeamScratch> beam_scratch_;
};
extern template class Vcm<RgbTransport>;
extern template class Vcm<SpectralTransport>;

}  // namespace pathlab
