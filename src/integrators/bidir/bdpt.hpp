// bdpt (alias bpt): bidirectional path tracing (Veach's thesis, ch. 10). Each pixel sample
// traces a camera subpath z_0 (the pinhole), z_1, ... and a light subpath y_0 (on a light),
// y_1, ..., and joins them by every strategy (s, t): the first s light vertices and the first t
// camera vertices, connected by one edge between y_{s-1} and z_{t-1} (t >= 1; the pinhole cannot
// be hit, so t = 0 does not exist):
//   s = 0   the camera subpath hits an emitter (or escapes to the environment) by itself;
//   s = 1   next-event estimation: a light point (or direction) sampled from z_{t-1};
//   t = 1   light tracing: y_{s-1} connected to the camera, splatted onto its pixel;
//   else    an inner connection with a shadow ray.
// s = t = 1 (a light connected to the camera) is not used: emitters seen directly come from
// s = 0, t = 2 alone. The strategies that produce one path are combined by multiple importance
// sampling, the balance heuristic by default or the power heuristic (`--mis power`). The weights
// are Veach's ratio form over the densities stored on the vertices (path_vertex.hpp), evaluated
// in O(1) per connection from running quantities carried along each subpath (Georgiev et al.,
// "Implementing Vertex Connection and Merging"); the ratio walk itself is kept as the tests'
// oracle (mis_weight_oracle). Dirac lobes (mirrors, glass, the coating of
// plastic), delta lights (point, spot, ies, directional), the environment (constant or a map)
// and one-sided emitters each enter the densities as path_vertex.hpp says.
//
// Depth: a path of s + t vertices has s + t - 2 bounces, counted as the path tracers count
// them, so `--max-depth` means the same and bdpt converges to pt-mis's image at every depth.
// Russian roulette acts on each subpath's scattering throughput after --rr-depth bounces, by
// the path tracers' rule; it divides the throughput by the survival probability and leaves the
// MIS densities alone (any weights that sum to one keep the estimator unbiased).
//
// One pass is one sample per pixel; pixels are processed in fixed chunks, each pixel's own
// contributions (t >= 2) go to it directly and light-tracing splats (t = 1) to the chunk's
// list, merged in chunk order: bit-identical for any thread count.
//
// `--strategies DIR` also writes, for paths of up to --strategies-depth bounces, one image per
// strategy, weighted and unweighted (strategy_images.hpp).
//
// Spectral mode (the SpectralTransport instantiation, docs/spectral.md): each pixel sample draws
// its wavelengths as the pixel integrators do and traces BOTH subpaths at them, so that a
// connection multiplies throughputs lane by lane at the same wavelengths; the weights depend on
// the geometry and densities only. A subpath that scatters at a dispersive interface continues
// with the hero wavelength alone (its vertices from there on are `dispersed`); a strategy whose
// path contains such a vertex, on either side, is the hero's estimate: hero_only(L), the factor 4
// of terminate_secondary() applied once for the whole path, even when both subpaths met
// dispersion (they share the hero). A pixel's own contributions are summed at the wavelengths
// and converted once; each light-tracing splat on its own.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <memory>
#include <span>
#include <vector>

#include "integrators/bidir/path_vertex.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/integrator.hpp"
#include "render/pass_image.hpp"

namespace pathlab {

class StrategyImages;

// Deliberate faults, for the tests that must be able to fail (never set by pathlab itself).
// A piece of a subpath's edge inside a medium (upbp's query beams on the camera side, photon
// beams on the light side): it leaves vertex `from` with solid-angle density pdfW (from a light at
// infinity: the area density of its entry disk, from_infinity) and runs from o along the unit d
// for `length` (to where the walk sampled the edge's end, or to a boundary), in `medium`, with the
// subpath's throughput, its channels' densities (PathVertex::r) and the MIS transmittance from
// vertex `from`, all at o.
template <class T>
struct SubpathBeam {
    Vec3f o, d;
    float length = 0, pdfW = 0, mis_T = 1;
    int32_t medium = -1;
    int from = 0;
    bool dispersed = false;
    ColourOf<T> beta{0.0f}, r{1.0f};
    bool from_infinity = false;
};

struct BdptFaults {
    bool drop_nee_strategy = false;      // MIS weights leave the s = 1 strategies out of their sums
    bool specular_pdf_rev_missing = false;  // a Dirac vertex's reverse density left unset (0)
    bool drop_connection_transmittance = false;  // media: a connection's transmittance left out
    bool drop_distance_pdf = false;              // media: densities without distance sampling's factor
    bool connection_roulette_undivided = false;  // media: a connection that survives roulette not divided by its probability
    // Not a fault: every weight by the ratio walk (the oracle), for the test that compares whole
    // renders with the running quantities' weights.
    bool ratio_walk = false;
    // Not a fault: every connection in a dense homogeneous medium made (no roulette), for the
    // test that the roulette changes the noise and not the image.
    bool no_connection_roulette = false;
    bool any() const { return drop_nee_strategy || specular_pdf_rev_missing || ratio_walk; }  // (the media faults act where they are)
};

// What one strategy gives for one sample: the unweighted contribution (a path through
// dispersion already as hero_only()), its MIS weight, and for t = 1 the raster position it lands on.
template <class T>
struct StrategyResult {
    ColourOf<T> L{0.0f};
    float weight = 0;
    bool splat = false;
    Vec2f raster;
};

// Solid-angle BSDF densities across a connection's new edge that the caller already has
// (negative: not known, computed from the vertices).
struct EdgeDensities {
    float pt_to_qs = -1;  // z_{t-1}'s BSDF sampling the direction to y_{s-1}
    float qs_to_pt = -1;  // y_{s-1}'s BSDF sampling the direction to z_{t-1}
    float T = 1;          // the new edge's MIS transmittance (media)
};

// The area densities that a connection gives the vertices at its new edge, from the other side:
// its camera endpoint z_{t-1} and the one before it, its light endpoint y_{s-1} and the one before.
struct ConnectionDensities {
    float camera_end = 0, camera_prev = 0, light_end = 0, light_prev = 0;
    // At an endpoint in a medium: the sine of the angle between its edge and the new one (upbp's bb1d).
    float camera_end_sin = 0, light_end_sin = 0;
};

template <class T>
class Bdpt final : public Integrator {
public:
    using Colour = ColourOf<T>;
    using Wavelengths = WavelengthsOf<T>;
    using Vertex = PathVertex<T>;
    using Subpath = std::vector<Vertex>;
    using SubpathView = std::span<const Vertex>;  // a subpath that strategies read (vcm's stored light paths too)

    explicit Bdpt(const IntegratorOptions& options, BdptFaults faults = {});
    ~Bdpt() override;

    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                               const PassProgress& progress) override;
    void finish(const RenderContext& ctx) override;

    // The subpaths of one sample at its wavelengths wl (for the tests and the per-pixel loop),
    // with their running MIS quantities for the strategies `vm` adds (vcm; none: bdpt's).
    // `shift`: with a reconstruction filter, the pass's lattice shift replaces the pixel's jitter.
    // `hero`: in media, the channel that drives distance sampling, shared by the subpaths of a
    // sample (sample_hero; -1: drawn from the subpath's own stream).
    // `beams`: the pieces of its edges inside media, if asked for (upbp).
    void camera_subpath(const RenderContext& ctx, size_t pixel, Sampler& sampler, const Wavelengths& wl, Subpath& path,
                        const Vec2f* shift = nullptr, const MergeMis* vm = nullptr, int hero = -1,
                        std::vector<SubpathBeam<T>>* beams = nullptr) const;
    // `max_vertices` (mmlt): at most this many vertices (-1: as many as --max-depth allows).
    void light_subpath(const RenderContext& ctx, Sampler& sampler, const Wavelengths& wl, Subpath& path,
                       const MergeMis* vm = nullptr, int hero = -1, int max_vertices = -1,
                       std::vector<SubpathBeam<T>>* beams = nullptr) const;
    // The camera subpath through the raster position `raster` (mmlt's), of at most max_vertices vertices.
    void camera_subpath_at(const RenderContext& ctx, Vec2f raster, Sampler& sampler, const Wavelengths& wl, Subpath& path,
                           int max_vertices, const MergeMis* vm = nullptr, int hero = -1,
                           std::vector<SubpathBeam<T>>* beams = nullptr) const;
    // The hero channel of a pixel sample in a scene with media (from a stream of its own; RGB
    // draws one of the three, spectral mode's hero is its first wavelength), else -1.
    static int sample_hero(const RenderContext& ctx, size_t pixel, uint64_t pass, const Wavelengths& wl);
    // Strategy (s, t) on the subpaths; `vm`: the merging strategies that also take part in its
    // MIS weight (vcm).
    StrategyResult<T> connect(const RenderContext& ctx, SubpathView light, int s, SubpathView camera, int t, Sampler& sampler,
                              const Wavelengths& wl, const MergeMis* vm = nullptr) const;
    // Whether a light seen directly has two strategies: the camera's ray finding it (s = 0) and
    // the emitter's own point connected to the camera (s = t = 1, as light tracing does). Only in
    // scenes with media: in a vacuum s = 0 alone is exact up to the pixel's sample position;
    // through a medium its free-flight sampling reaches the light with probability T, a coin
    // flip per sample, where the connection carries T as a factor.
    static bool connects_emitters_to_camera(const Scene& scene) { return scene.has_media(); }
    // Whether the path of no bounce (s + t = 2) whose camera vertex z_1 (s = 0) or light vertex
    // y_0 (s = 1) is `end` has both strategies (else its one strategy has weight 1).
    static bool both_strategies_see(const Scene& scene, const Vertex& end) {
        return connects_emitters_to_camera(scene) && !end.infinite && !end.delta_light && end.light >= 0 && end.has_normal();
    }
    // The weight of strategy s (0 or 1) of such a path: p0 the camera's density of the emitter
    // point (per unit area, times the segment's MIS transmittance T), p1 the light's (its pmf
    // times the area density). Not the balance heuristic of p0 and p1: s = 0's estimate is
    // exact but for free-flight sampling's coin flip, whose variance is the factor 1 - T of the
    // estimate's, so p0 counts as p0 / (1 - T) (variance-aware MIS, Grittmann et al. 2019, weighs
    // each technique by its density over its variance): s = 0 alone through a vacuum (T = 1, the
    // image of a scene without media), the balance (or power) heuristic in dense media (T -> 0).
    // Any weights that sum to 1 over the path's strategies keep the estimate unbiased.
    static float seen_directly_weight(int s, double p0, double p1, double transmittance, bool power) {
        const double a0 = p0, a1 = std::max(0.0, 1 - transmittance) * p1;
        const double h0 = power ? a0 * a0 : a0, h1 = power ? a1 * a1 : a1;
        if (!(h0 + h1 > 0)) return s == 0 ? 1.0f : 0.0f;
        return float((s == 0 ? h0 : h1) / (h0 + h1));
    }
    // That weight for strategy (s, t) with s + t = 2, from the subpaths (as mis_weight's
    // arguments; without connections, vm->connections off, s = 0 is the only strategy).
    float seen_directly_weight(const RenderContext& ctx, SubpathView light, int s, SubpathView camera, const Vertex& sampled,
                               const EdgeDensities& known, const MergeMis* vm) const;
    // The MIS weight of strategy (s, t); `sampled` replaces y_0 (s = 1, t > 1) or z_0 (t = 1). From the
    // subpaths' running quantities (made with the same `vm`) in O(1).
    float mis_weight(const RenderContext& ctx, SubpathView light, int s, SubpathView camera, int t, const Vertex& sampled,
                     const EdgeDensities& known = {}, const MergeMis* vm = nullptr) const;
    // The same weight by Veach's ratio walk over both subpaths: the oracle of the tests (and the
    // weight of the deliberate faults).
    float mis_weight_oracle(const RenderContext& ctx, SubpathView light, int s, SubpathView camera, int t, const Vertex& sampled,
                            const EdgeDensities& known = {}, const MergeMis* vm = nullptr) const;
    // The densities strategy (s, t) gives the vertices at its new edge.
    ConnectionDensities connection_densities(const RenderContext& ctx, const Vertex* ys, int s, const Vertex* zs, int t,
                                             const EdgeDensities& known) const;

    // Every connection strategy of one pixel sample, in bdpt's order and from its random
    // streams: strategy(s, t, result) for each one with a contribution, and after_vertex(t) once
    // those ending at camera vertex t are done. `vm`: merging strategies in the weights (vcm);
    // with vm->connections off only s = 0 is evaluated.
    template <typename Strategy, typename AfterVertex>
    void for_each_connection(const RenderContext& ctx, size_t pixel, uint64_t pass, SubpathView light, SubpathView camera, const Wavelengths& wl,
                             const MergeMis* vm, Strategy&& strategy, AfterVertex&& after_vertex) const {
        for (int t = 1; t <= int(camera.size()); ++t) {
            Sampler sampler(ctx.seed, sample_stream(pixel, 1 + uint64_t(t)), pass, ctx.sampler);
            // s = 1 samples its own light point: it exists even when the light subpath does not
            // (an emission sample that failed).
            const int s_max = !vm || vm->connections ? std::max(1, int(light.size())) : 0;
            for (int s = 0; s <= s_max; ++s) {
                const int depth = s + t - 2;
                if ((s == 1 && t == 1 && !connects_emitters_to_camera(ctx.scene)) || depth < 0 || depth > max_bounces_) continue;
                if (options_.only_length >= 0 && depth != options_.only_length) continue;
                if (options_.hide_emitters && depth == 0) continue;
                const StrategyResult<T> r = connect(ctx, light, s, camera, t, sampler, wl, vm);
                if (!is_black(r.L)) strategy(s, t, r);
            }
            after_vertex(t);
        }
    }

    // The random-number stream of a sample: 0 the camera subpath (the pixel's own), 1 the light
    // subpath, 1 + t the connections at camera vertex t, kHeroStream the hero channel in media.
    static uint64_t sample_stream(size_t pixel, uint64_t stream) { return uint64_t(pixel) + (stream << 40); }
    static constexpr uint64_t kHeroStream = 0xfffff;  // the hero channel's (beyond every 1 + t)
    // Pixels per chunk of a pass: a function of the image size only.
    static size_t chunk_size(size_t pixels) { return std::max<size_t>(16, pixels / 64); }
    bool power_heuristic() const { return options_.mis_power; }
    int max_bounces() const { return max_bounces_; }

    // The per-strategy films (null without --strategies).
    const StrategyImages* strategy_images() const { return strategies_.get(); }
    // The weighted per-strategy images so far (with --strategies), for the viewer.
    std::vector<ExrChannel> display_channels() const override;

    int max_camera_vertices() const { return max_bounces_ + 2; }
    int max_light_vertices() const { return max_bounces_ + 1; }

private:
    // Extends `path` from its last vertex along `ray` (starting in `medium`); `hero` as for the subpaths.
    void random_walk(const RenderContext& ctx, Ray ray, Sampler& sampler, Colour beta, float pdfW, int max_vertices, TransportMode mode,
                     Wavelengths wl, Subpath& path, int32_t medium, int hero, std::vector<SubpathBeam<T>>* beams = nullptr) const;

    IntegratorOptions options_;
    BdptFaults faults_;
    int max_bounces_;
    PassImage pass_;
    tbb::enumerable_thread_specific<std::pair<Subpath, Subpath>> subpaths_;  // camera, light
    std::unique_ptr<StrategyImages> strategies_;
};
extern template class Bdpt<RgbTransport>;
extern template class Bdpt<SpectralTransport>;

}  // namespace pathlab
