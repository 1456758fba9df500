// One render: a scene, an integrator with its options, the render settings and the outputs.
// Every command (render, reference, check, report), the benchmarks and the tests set their
// renders up through it, so the rules of precedence live here only:
//   algorithm  the request's, else the scene file's <integrator>, else pt-mis
//   spp        the request's, else (without a time budget) the scene file's sample_count,
//              else the request's default_spp (64 for renders)
//   max_depth  the request's, else the scene file's, else -1 (unlimited)
//   rr_depth   the request's, else the scene file's, else 3
//   null-depth the request's, else the scene file's (skip for Mitsuba's volpath), else count
// For smoke tests of whole commands (the docs test runs every command of README this way), the
// environment variables PATHLAB_SPP_CAP=N, PATHLAB_TIME_CAP=S and PATHLAB_RESOLUTION_CAP=P cap
// every render at N samples per pixel, S seconds and P pixels on its longer side (the aspect
// kept), whatever the command asked for.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "job/renderer.hpp"
#include "job/scene_choice.hpp"

namespace pathlab {

constexpr double kDefaultCheckpointEvery = 300;  // --checkpoint-every's default, in seconds
// Sample (pass) indices end at 2^62: a render's first_sample + spp must not reach past it.
constexpr uint64_t kMaxSampleIndex = uint64_t(1) << 62;

struct JobRequest {
    std::optional<std::string> algorithm;
    std::optional<uint64_t> spp;
    std::optional<int> max_depth;
    std::optional<int> rr_depth;  // bounces before Russian roulette (-1: none); default: the scene file's, else 3
    int width = 0, height = 0;  // 0: the scene's resolution
    double time_limit = 0;      // seconds; 0: none
    uint64_t seed = 1234;
    SamplerKind sampler = SamplerKind::Independent;
    bool spectral = false;  // --spectral (else the scene file's <default name="mode">, else RGB)
    uint64_t default_spp = 64;
    uint64_t first_sample = 0;     // --first-sample N: the index of the first pass (disjoint ranges merge into one render)
    double checkpoint_every = kDefaultCheckpointEvery;  // --checkpoint-every SECONDS (0: only at the end and when interrupted)
    bool mis_power = false;        // --mis power (bdpt, vcm, bpm, upbp, mmlt, pt-mis, pt-mis3, direct-mis, volpath)
    std::string strategies_dir;    // --strategies DIR (bdpt)
    int strategies_depth = 4;      // --strategies-depth N (bdpt)
    std::optional<int64_t> photons;       // --photons N (sppm, pm)
    std::optional<float> photon_radius;   // --radius R (sppm, pm)
    std::optional<double> photon_alpha;   // --alpha A (sppm, vcm, bpm)
    std::optional<bool> volume_beam;      // --volume-estimate beam|points (sppm, ppm, pm)
    bool vcm_merging = true;              // not --no-merging (vcm)
    bool vcm_connections = true;          // not --no-connections (vcm)
    std::optional<int> ic_rays;           // --ic-rays (ic)
    std::optional<float> ic_error;        // --ic-error (ic)
    std::optional<bool> ic_gradients;     // false: --ic-no-gradients (ic)
    bool ic_records = false;              // --ic-records given (ic; the command line writes the image)
    std::optional<int> pbgi_surfels;          // --pbgi-surfels (pbgi)
    std::optional<float> pbgi_cutoff;         // --pbgi-cutoff (pbgi)
    std::optional<int> pbgi_bounces;          // --pbgi-bounces (pbgi)
    std::optional<int> pbgi_resolution;       // --pbgi-resolution (pbgi)
    std::optional<int> pbgi_direct_samples;   // --pbgi-direct-samples (pbgi)
    std::optional<int> pbgi_spacing;          // --pbgi-spacing (pbgi)
    std::optional<int> guiding_spp;           // --guiding-spp (ppg)
    bool guiding_rr = false;                  // --guiding-rr (ppg)
    std::optional<std::string> guiding_fraction;  // --guiding-fraction (ppg)
    std::optional<std::string> guiding;           // --guiding sd-tree|vmm (ppg)
    std::optional<std::string> estimators;    // --estimators (upbp)
    std::optional<int64_t> photon_beams;      // --photon-beams (upbp)
    std::optional<float> beam_radius;         // --beam-radius (upbp)
    std::optional<LightSamplerKind> light_sampler;  // --light-sampler (next-event estimation; default power)
    std::optional<int> ris_candidates;              // --ris-candidates (ris)
    std::optional<float> light_split;               // --light-split (bvh)
    std::optional<int> mlt_chains;                  // --chains (pssmlt)
    std::optional<int> mlt_bootstrap;               // --bootstrap (pssmlt)
    std::optional<float> mlt_large_step;            // --large-step (pssmlt)
    std::optional<float> mlt_sigma;                 // --sigma (pssmlt)
    std::vector<std::string> aovs;                  // --aovs (render/aov_film.hpp's names), as EXR layers
    std::optional<bool> skip_null_events;           // --null-depth skip|count (default: the scene file's, else count)
};

// The integrator `name` (or an alias); a UsageError listing them all otherwise.
const IntegratorInfo& integrator_or_usage_error(const std::string& name);

// What an estimator's image converges to, so that a reference is only used for what it is a
// reference of: "direct illumination" (the direct-* estimators, or any at --max-depth 1),
// "global illumination" (", at most N bounces" with a depth limit), or the integrator's own
// name for a debug view (eyelight).
std::string integrator_family(const IntegratorInfo& info, int max_depth);

// Why `info` cannot render scene `d` as `request` asks (empty: it can): a medium, spectral mode,
// a sensor or reconstruction filter it does not handle, a light sampler it does not use. RenderJob
// refuses such a job with it; `-a all` leaves such estimators out.
std::string integrator_refusal(const IntegratorInfo& info, const SceneDescription& d, const JobRequest& request);

class RenderJob {
public:
    // Makes the integrator (the scene is built when first needed). Unknown algorithms and
    // invalid values are UsageErrors; a scene that cannot be built throws SceneError.
    RenderJob(SceneChoice scene, const JobRequest& request);
    RenderJob(int builtin_scene, const JobRequest& request) : RenderJob(builtin_scene_choice(builtin_scene), request) {}
    // With a scene already built from scene.description (shared between jobs, as the
    // benchmarks do to build each BVH once), with the request's light sampler.
    RenderJob(SceneChoice scene, const JobRequest& request, std::shared_ptr<const Scene> built)
        : RenderJob(std::move(scene), request) {
        if (built->light_sampler().kind() != options_.light_sampler ||
            (options_.light_sampler == LightSamplerKind::Ris && built->light_sampler().candidates() != options_.ris_candidates) ||
            built->light_sampler().split() != options_.light_split)
            throw std::invalid_argument("RenderJob: the shared scene was built with another light sampler");
        scene_ = std::move(built);
    }

    const SceneChoice& scene_choice() const { return choice_; }
    const Scene& scene();
    // The same scene, built if needed, to share with other jobs (the constructor above).
    std::shared_ptr<const Scene> shared_scene() {
        scene();
        return scene_;
    }
    const IntegratorInfo& integrator_info() const { return *info_; }
    // The integrator is made when first needed, so its options may still be changed before.
    Integrator& integrator();
    const IntegratorOptions& integrator_options() const { return options_; }
    // The image size: the settings' (after the request and the caps), else the scene's.
    int width() const { return settings.width > 0 ? settings.width : choice_.description.width; }
    int height() const { return settings.height > 0 ? settings.height : choice_.description.height; }
    // integrator_family() of this job's integrator and depth.
    std::string family() const { return integrator_family(*info_, options_.max_depth); }
    IntegratorOptions& integrator_options() { return options_; }
    // Progress, cancellation, callbacks and the size may be adjusted before run().
    RenderSettings settings;
    // Output files (patterns already expanded), written by write_outputs().
    std::vector<std::string> outputs;

    // With --aovs, also fills aov_film() (created for the render's size; a continued render's
    // earlier passes are not in it).
    RenderResult run();
    // Continues a render into `film` (see render_into); settings.first_sample says where.
    RenderStats run_into(Film& film);

    // Expands {scene}, {index} and {algorithm} in an output pattern (UsageError if malformed).
    std::string expand(const std::string& pattern) const;
    // Writes the mean image to every output (format by extension; `exposure` for .png); an .exr
    // also gets the standard-error image as its layer "stderr" and `attributes` in its header
    // (render_metadata in job/render_identity.hpp).
    void write_outputs(const RenderResult& result, float exposure = 0,
                       const std::vector<std::pair<std::string, std::string>>& attributes = {}) const;
    // --aovs: the names asked for, and the first-vertex sums of the last run (null when none
    // of them needs the first vertex, or before a run).
    const std::vector<std::string>& aovs() const { return aovs_; }
    const AovFilm* aov_film() const { return aov_film_.get(); }

private:
    SceneChoice choice_;
    std::shared_ptr<const Scene> scene_;
    const IntegratorInfo* info_ = nullptr;
    IntegratorOptions options_;
    std::unique_ptr<Integrator> integrator_;
    std::vector<std::string> aovs_;
    std::unique_ptr<AovFilm> aov_film_;
    void prepare_aov_film(int width, int height);
};

// The integrators that record the first-vertex AOVs (albedo, normal, depth, position): the pixel integrators.
std::string aov_integrator_names();

}  // namespace pathlab
