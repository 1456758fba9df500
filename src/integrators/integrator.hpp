// The integrator contract and the registry of integrators selectable by name.
//
// An integrator owns its render passes (as SmallVCM's RunIteration, pbrt-v4's
// Integrator::Render or Mitsuba 3's render do): render_passes() is given the passes with
// sample indices first, ..., first + count - 1 and must add, for each pass, one sample to
// every pixel of the film, however it computes it. The driver (job/renderer.hpp) decides how
// many passes go into one call, stops on a sample count, a time budget or Ctrl-C, and measures.
// A pass must be a pure function of (seed, pass index): the result may not depend on the thread
// count, the tile order or how the passes are split between calls.
//
// Two kinds exist today:
//  - PixelIntegrator: one camera ray per pixel sample and one radiance value back (every
//    estimator of the course); the adapter runs the tiles in parallel.
//  - integrators that splat onto arbitrary pixels (the light tracer) collect each pass in a
//    PassImage (render/pass_image.hpp).
// To add an integrator: one file under src/integrators/<family>/ and one line in registry.cpp.
//
// Across processes and checkpoints (docs/distributed.md) the passes of one render are split
// into parts rendered by different processes, or before and after a restart, each part into its
// own film, and the films are summed exactly (render/film.hpp). That gives the one-process image
// bit for bit if, and only if, the integrator keeps to this contract:
//  1. a pass is a pure function of (scene, seed, image size, options, pass index): anything
//     that changes from pass to pass (sppm's radius, vcm's) is computed from the pass index,
//     never carried from the previous pass;
//  2. prepare() is a pure function of (scene, seed, image size, options), since every process
//     runs it (pm's photon maps, ic's cache: built identically on every rank, not shared);
//  3. everything a pass contributes goes into the film given to render_passes (add, or
//     add_pass of a PassImage); state that accumulates across passes elsewhere (bdpt's
//     --strategies films) is neither summed across processes nor checkpointed, so the command
//     line refuses those options there;
//  4. finish() writes extra outputs only; with several processes it runs on rank 0 alone.
#pragma once

#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cameras/camera.hpp"
#include "core/properties.hpp"
#include "image/image_io.hpp"
#include "render/aov_film.hpp"
#include "render/film.hpp"
#include "render/pixel_filter.hpp"
#include "samplers/sampler.hpp"
#include "scene/scene.hpp"
#include "integrators/common/first_vertex.hpp"
#include "integrators/common/transport.hpp"
#include "integrators/guiding/guiding_model.hpp"

namespace pathlab {

inline constexpr float kLearnedGuidingFraction = -1.0f;  // --guiding-fraction learned
inline constexpr const char* kGuidingFractionHelp = "a number in (0, 1] or 'learned'";
// --guiding-fraction: a number in (0, 1], or "learned" (kLearnedGuidingFraction); nullopt for anything else.
inline std::optional<float> parse_guiding_fraction(const std::string& text) {
    if (text == "learned") return kLearnedGuidingFraction;
    char* end = nullptr;
    const float a = std::strtof(text.c_str(), &end);
    if (!text.empty() && end == text.c_str() + text.size() && a > 0 && a <= 1) return a;
    return std::nullopt;
}

struct IntegratorOptions {
    int max_depth = -1;  // longest path in bounces (1 = direct illumination only); -1 = unlimited
    int rr_depth = 3;    // bounces before Russian roulette may end a path
    // Only paths of exactly this many bounces count (-1: all); pt-mis and bdpt honour it, so
    // that strategies can be compared with path tracing one length at a time.
    int only_length = -1;
    bool mis_power = false;        // bdpt, vcm, bpm, the MIS path tracers, direct-mis: the power heuristic (beta = 2) instead of the balance heuristic
    std::string strategies_dir;    // bdpt: write one image per strategy (s, t) there ("" for none)
    int strategies_depth = 4;      // bdpt: ... for paths of up to this many bounces
    // Photon mapping (sppm): light paths per iteration (0: one per pixel), the first
    // iteration's radius (0: from the scene's size) and the radius reduction alpha.
    int64_t photons = 0;
    float photon_radius = 0;
    double photon_alpha = 2.0 / 3.0;
    // sppm, ppm, pm in media: the beam radiance estimate along camera rays (true), or the 3D kernel
    // at the camera path's first scattering point (false).
    bool volume_beam = true;
    // vcm: its two families of strategies (off: merging = bdpt, connections = bpm).
    bool vcm_merging = true;
    bool vcm_connections = true;
    std::string estimators;  // upbp: the estimators it combines ("": all; vcm.hpp parse_estimators)
    int64_t photon_beams = 0;  // upbp: light paths per iteration whose edges are photon beams (0: vcm.hpp's default)
    float beam_radius = 0;     // upbp: pb2d's and bb1d's first radius (0: a quarter of the photon radius)
    // ic: rays per record, the error threshold a, gradients on, and where to draw the records.
    int ic_rays = 256;
    float ic_error = 0.2f;
    bool ic_gradients = true;
    bool ic_clamp_screen = true;      // radii within 1.5 to 20 pixel footprints (Tabellion and Lamorlette)
    bool ic_clamp_neighbours = true;  // neighbour clamping (Krivanek et al.)
    std::string ic_records_path;
    // pssmlt: Markov chains (a fixed number, so the image does not depend on the threads), the
    // independent paths of each pass's bootstrap, the probability of a large step and the
    // small steps' standard deviation in primary sample space.
    int mlt_chains = 64;
    int mlt_bootstrap = 4096;
    float mlt_large_step = 0.3f;
    float mlt_sigma = 0.01f;
    // pbgi: surfels (about), the cutoff solid angle (0: brute force), surfel bounces, the
    // micro-buffer's side, the MIS pairs of each surfel side's direct light, and the pixels
    // between the gathers at the camera's first hits.
    int pbgi_spacing = 2;
    int pbgi_surfels = 8000;
    float pbgi_cutoff = 0.05f;
    int pbgi_bounces = 3;
    int pbgi_resolution = 16;
    int pbgi_direct_samples = 16;
    // ppg: samples per pixel of the SD-tree's training (iterations of 1, 2, 4, ...; 0: no guiding).
    int guiding_spp = 31;
    bool guiding_rr = false;  // ppg: adjoint-driven Russian roulette and splitting (ADRRS)
    // ppg: the probability of sampling the BSDF rather than the SD-tree where a leaf guides, in
    // (0, 1]; kLearnedGuidingFraction: learned per leaf (Müller 2019).
    float guiding_fraction = 0.5f;
    GuidingModel guiding = GuidingModel::kSdTree;  // ppg: what a spatial leaf learns (--guiding sd-tree|vmm)
    // Paths of no bounce (emitters and the environment seen directly) are left out (Mitsuba's hide_emitters).
    bool hide_emitters = false;
    // --null-depth skip: a straight pass through a surface (a kLobeNull sample: thindielectric's
    // transmission, a mask's hole) is no bounce under --max-depth, as in Mitsuba's volpath; by
    // default (count) it is one, as in Mitsuba's path. Only a finite depth makes them differ.
    bool skip_null_events = false;
    // Spectral mode (docs/spectral.md): paths carry 4 sampled wavelengths instead of RGB, the
    // integrator's SpectralTransport instantiation (common/transport.hpp; make_for_transport).
    bool spectral = false;
    // How next-event estimation chooses a light (--light-sampler); the scene is built with it.
    LightSamplerKind light_sampler = LightSamplerKind::Power;
    int ris_candidates = kDefaultRisCandidates;  // --ris-candidates: the light samples ris resamples
    float light_split = 0;  // --light-split: bvh's adaptive splitting threshold (0: none)
};

// The processes that render one image together (MPI ranks), as prepare() may share its work
// among them: all_gather(bytes) gives every rank's bytes in rank order, on every rank (all ranks
// call it at the same points). One process alone: rank 0 of 1.
struct PrepareRanks {
    int rank = 0, size = 1;
    std::function<std::vector<std::string>(const std::string&)> all_gather;
};

// What every pass of one render sees; fixed for the whole render.
struct RenderContext {
    const Scene& scene;
    const PerspectiveCamera& camera;  // prepared for width x height
    int width = 0, height = 0;
    uint64_t seed = 0;
    SamplerKind sampler = SamplerKind::Independent;
    int tile_size = 32;  // largest tile edge for pixel integrators (smaller when there are few tiles)
    // The reconstruction filter (render/pixel_filter.hpp); null or box: each sample in its own pixel.
    const PixelFilter* filter = nullptr;
    // --aovs: the first non-specular vertex of every camera sample, summed per pixel (pixel
    // integrators only: records_aovs()); null: none.
    AovFilm* aovs = nullptr;
    // The ranks rendering this image (null: this process alone).
    const PrepareRanks* ranks = nullptr;

    size_t pixel_count() const { return size_t(width) * size_t(height); }
};

// What prepare() was last run for (a cache or a tree built up front is kept for a render continued
// with the same scene, seed and image size: prepare() is a pure function of them).
struct PreparedFor {
    const Scene* scene = nullptr;
    uint64_t seed = 0;
    int width = 0, height = 0;

    bool matches(const RenderContext& ctx) const { return scene == &ctx.scene && seed == ctx.seed && width == ctx.width && height == ctx.height; }
    void set(const RenderContext& ctx) { *this = {&ctx.scene, ctx.seed, ctx.width, ctx.height}; }
};

// What a call of render_passes counted.
struct PassCounters {
    uint64_t rays = 0;             // rays traced (camera, shadow, continuation, light paths)
    uint64_t invalid_samples = 0;  // NaN/Inf contributions, discarded (never averaged in)
};

// Called from worker threads with the fraction of the current call's work that is done.
using PassProgress = std::function<void(double)>;

// A figure an integrator reports after a render (ic: its record count, the cache's build time).
struct IntegratorStatistic {
    std::string name;
    double value;
    bool in_metadata = false;  // also written into the image's metadata (pathlab:NAME): a pure function of the render's settings
};

class Integrator {
public:
    virtual ~Integrator() = default;
    // Called once before the first pass of a render (a cache or photon map built up front),
    // with the fraction of that work done.
    virtual void prepare(const RenderContext&, const PassProgress&) {}
    virtual PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                                       const PassProgress& progress) = 0;
    // Called once after the last pass (also of an interrupted render): extra outputs.
    virtual void finish(const RenderContext&) {}
    // Its own figures, for the summary line and --stats.
    virtual std::vector<IntegratorStatistic> statistics() const { return {}; }
    // Whether it fills RenderContext::aovs from its camera samples (the pixel integrators).
    virtual bool records_aovs() const { return false; }
    // Images of its own to show beside the image as it converges (--display-server; bdpt's
    // per-strategy images with --strategies), as channels of the film's size. Called between
    // passes.
    virtual std::vector<ExrChannel> display_channels() const { return {}; }
};

// Today's per-pixel estimators: one Monte Carlo estimate of the radiance arriving along a
// camera ray, in the colour of transport T (common/transport.hpp: RGB, or the sample's 4
// wavelengths, which a dispersive interface may reduce to the hero). Sample s of pixel p uses
// Sampler(seed, p, s) (its first 2D sample jitters the ray within the pixel; spectral mode's
// wavelengths come from a stream of their own), and each pixel accumulates its samples in index
// order, each converted by film_colour.
template <class T>
class PixelIntegrator : public Integrator {
public:
    virtual ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const = 0;
    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                               const PassProgress& progress) final;
    bool records_aovs() const final { return true; }

private:
    PassCounters render_filtered_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress);
    // One camera sample's colour for the film (and with --aovs, its first vertex for pixel `pixel`).
    Vec3d sample_colour(const RenderContext& ctx, const Ray& ray, Sampler& sampler, size_t pixel) const {
        WavelengthsOf<T> wl = T::camera_wavelengths(sampler);
        if (!ctx.aovs) return film_colour(radiance(ctx.scene, ray, sampler, wl), wl);
        FirstVertexRecorder recorder;
        Vec3d L;
        {
            FirstVertexScope scope(recorder, ray.o);
            L = film_colour(radiance(ctx.scene, ray, sampler, wl), wl);
        }
        ctx.aovs->add(pixel, recorder.vertex);
        return L;
    }
    std::vector<Vec3d> lattice_, filtered_;  // a filtered pass (pixel_filter.hpp)
};
extern template class PixelIntegrator<RgbTransport>;
extern template class PixelIntegrator<SpectralTransport>;

// The lattice shift of a filtered pass: every pixel's sample of that pass is at pixel + shift.
Vec2f filter_shift(const RenderContext& ctx, uint64_t pass);

struct IntegratorInfo {
    std::string name;                  // e.g. "direct-light"
    std::vector<std::string> aliases;  // the course's assignment numbers ("1"), Mitsuba's names ("ptracer")
    std::string summary;               // one line
    // True when the integrator cannot see delta (point, spot, ies, directional) lights at all, so its image
    // is black in scenes lit only by them (BRDF-sampled estimators).
    bool blind_to_delta_lights = false;
    // False when pixels whose first camera-side vertex is specular stay black (the light
    // tracer cannot connect through a Dirac lobe to the camera).
    bool sees_specular_from_camera = true;
    // Its parameters in scene files (<integrator type=...>), Mitsuba's names and depth convention.
    std::vector<ParamInfo> params;
    std::function<std::unique_ptr<Integrator>(const IntegratorOptions&)> make;
    // What of a scene file's sensor and film it supports (RenderJob refuses the rest, saying why):
    // thin lens and orthographic cameras (false: it connects light paths to the pinhole, or
    // sizes its radii by the pinhole's pixel angle), and reconstruction filters other than box
    // (false: it adds its samples to the film without them).
    bool any_camera = true;
    bool any_filter = true;
    // Renders in spectral mode (--spectral); the others refuse it.
    bool spectral = true;
    // Renders participating media (a scene whose shapes or camera refer to a <medium>); the
    // others refuse such a scene (RenderJob), rather than render it as if the media were not there.
    bool media = false;
    // Chooses a light at each shading point for next-event estimation, so --light-sampler applies
    // (light paths start on a light chosen by power, whatever it says).
    bool samples_lights = false;
    // Traces light paths that scatter with the adjoint BSDF f(wo, wi) (light tracing, bdpt, the
    // photon methods, vcm): a BSDF that is not reciprocal (principledthin's specular transmission,
    // as Mitsuba defines it) would make them converge to another image, so RenderJob refuses it.
    bool light_paths = false;
    // Honours --null-depth skip (IntegratorOptions::skip_null_events); the others refuse it where it
    // would change their image (a finite depth and a material with a null lobe).
    bool skips_null_events = false;

    PluginInfo plugin() const;
};

// `info` with samples_lights set (for the integrators declared as one aggregate).
inline IntegratorInfo sampling_lights(IntegratorInfo info) {
    info.samples_lights = true;
    return info;
}

// IntegratorInfo::make of an integrator written once (a class template over the transport, whose
// constructor takes the options first): its instantiation for the transport the options ask for.
template <template <class> class I, class... Args>
std::unique_ptr<Integrator> make_for_transport(const IntegratorOptions& options, const Args&... args) {
    if (options.spectral) return std::make_unique<I<SpectralTransport>>(options, args...);
    return std::make_unique<I<RgbTransport>>(options, args...);
}

const std::vector<IntegratorInfo>& integrators();
const IntegratorInfo* find_integrator(const std::string& name_or_alias);
// "a, b (alias 1), ..." for error messages and help.
std::string integrator_names();
// "pt-mis, pt-naive, ...": the integrators that render in spectral mode.
std::string spectral_integrator_names();
// ... and those that render participating media.
std::string media_integrator_names();
// ... and those that choose lights for next-event estimation (--light-sampler).
std::string light_sampling_integrator_names();
// ... and those that honour --null-depth skip.
std::string null_skipping_integrator_names();

}  // namespace pathlab
