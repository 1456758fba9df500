#include "bsdfs/spectral_bsdf.hpp"
#include "job/render_job.hpp"

#include <filesystem>

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstdlib>
#include <optional>

#include <fmt/format.h>

#include "image/image_io.hpp"
#include "job/extra_channels.hpp"
#include "job/usage_error.hpp"
#include "scene/medium_in_use.hpp"
#include "integrators/photon/vcm.hpp"

namespace pathlab {

const IntegratorInfo& integrator_or_usage_error(const std::string& name) {
    const IntegratorInfo* info = find_integrator(name);
    if (!info) throw UsageError(fmt::format("unknown algorithm '{}'. Valid algorithms: {}", name, integrator_names()));
    return *info;
}

std::string integrator_family(const IntegratorInfo& info, int max_depth) {
    if (info.name == "eyelight") return info.name;
    if (info.name.rfind("direct-", 0) == 0 || max_depth == 1) return "direct illumination";
    return max_depth > 1 ? fmt::format("global illumination, at most {} bounces", max_depth) : "global illumination";
}

namespace {

// A positive number from the environment variable `name`, if set.
std::optional<double> environment_cap(const char* name) {
    const char* text = std::getenv(name);
    if (!text || !*text) return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(text, &end);
    if (*end != 0 || !(v > 0)) throw UsageError(fmt::format("{}={}: expected a positive number", name, text));
    return v;
}

// PATHLAB_SPP_CAP, PATHLAB_TIME_CAP and PATHLAB_RESOLUTION_CAP (see the header).
void apply_environment_caps(RenderSettings& s, const SceneDescription& d) {
    if (const auto cap = environment_cap("PATHLAB_RESOLUTION_CAP")) {
        int w = s.width > 0 ? s.width : d.width, h = s.height > 0 ? s.height : d.height;
        const int longest = std::max(w, h), limit = std::max(1, int(*cap));
        if (longest > limit) {
            w = std::max(1, int(std::lround(double(w) * limit / longest)));
            h = std::max(1, int(std::lround(double(h) * limit / longest)));
        }
        s.width = w, s.height = h;
    }
    if (const auto cap = environment_cap("PATHLAB_SPP_CAP")) {
        const uint64_t spp = uint64_t(std::max(1.0, *cap));
        s.spp = s.spp > 0 ? std::min(s.spp, spp) : spp;
    }
    if (const auto seconds = environment_cap("PATHLAB_TIME_CAP")) s.time_limit = s.time_limit > 0 ? std::min(s.time_limit, *seconds) : *seconds;
}

}  // namespace

// The first material of the scene whose BSDF is not reciprocal ("" for none), as "<what> has
// <why>": a principledthin with specular transmission (principledthin.hpp), a normal or bump map
// with Mitsuba's flip_invalid_normals or use_shadowing_function (material_textures.hpp); also
// inside a blend or mask.
std::string non_reciprocal_material(const SceneDescription& d) {
    const std::function<std::string(const Material&)> why = [&](const Material& m) -> std::string {
        if (m.mitsuba_bump_rules())
            return fmt::format("a {} with Mitsuba's flip_invalid_normals or use_shadowing_function (its defaults: set both false for "
                               "the reciprocal map)",
                               m.textures->perturbation == FramePerturbation::NormalMap ? "normalmap" : "bumpmap");
        if (const auto* t = std::get_if<PrincipledThinMaterial>(&m.model); t && t->spec_trans > 0)
            return "specular transmission, which Mitsuba's principledthin defines without reciprocity";
        if (const auto* b = std::get_if<BlendMaterial>(&m.model)) {
            const std::string first = why(*b->first);
            return first.empty() ? why(*b->second) : first;
        }
        if (const auto* k = std::get_if<MaskMaterial>(&m.model)) return why(*k->inner);
        return "";
    };
    for (size_t i = 0; i < d.materials.size(); ++i)
        if (const std::string w = why(d.materials[i]); !w.empty()) {
            const char* kind = std::holds_alternative<PrincipledThinMaterial>(d.materials[i].model) ? "principledthin" : "material";
            return i < d.material_ids.size() && !d.material_ids[i].empty() ? fmt::format("{} '{}' has {}", kind, d.material_ids[i], w)
                                                                             : fmt::format("{} has {}", kind, w);
        }
    return "";
}

namespace {

// Whether the render asks for --null-depth skip: the request's, else the scene file's.
bool null_skip_requested(const JobRequest& r, const SceneDescription& d) {
    return r.skip_null_events ? *r.skip_null_events : d.skip_null_events.value_or(false);
}

}  // namespace

// The first material with a straight pass through it (kLobeNull: thindielectric, mask), named as
// the scene file does ("" if none).
std::string null_lobe_material(const SceneDescription& d) {
    for (size_t i = 0; i < d.materials.size(); ++i)
        if (d.materials[i].lobes() & kLobeNull) {
            const char* kind = std::holds_alternative<ThinDielectricMaterial>(d.materials[i].model) ? "thindielectric" : "material with a mask";
            return i < d.material_ids.size() && !d.material_ids[i].empty() ? fmt::format("{} '{}'", kind, d.material_ids[i]) : std::string(kind);
        }
    return "";
}

std::string integrator_refusal(const IntegratorInfo& info, const SceneDescription& d, const JobRequest& r) {
    if (aovs_need_first_vertex(r.aovs) && !info.make(IntegratorOptions{})->records_aovs())
        return fmt::format("--aovs {}: {} has no camera samples to take them from (it traces light paths); these come with: {} "
                           "(variance and sample-count come with every integrator)",
                           fmt::join(r.aovs, ","), info.name, aov_integrator_names());
    const bool mlt = info.name == "pssmlt" || info.name == "mmlt";
    if (r.sampler == SamplerKind::Sobol && mlt)
        return fmt::format("{} takes no --sampler sobol: its numbers are its Markov chains' states in primary sample space, not a pixel "
                           "sampler's",
                           info.name);
    if (info.name == "mmlt" && (r.max_depth ? *r.max_depth : d.max_depth.value_or(-1)) < 0)
        return "mmlt needs a finite --max-depth: its Markov chains run per path length, 0 to --max-depth bounces, and an unlimited "
               "depth has no last length (give the same --max-depth to the estimators it is compared with, e.g. --max-depth 10)";
    if (r.light_sampler && !info.samples_lights)
        return fmt::format("{} does not choose lights at its shading points (its light paths start on a light chosen "
                           "by power), so --light-sampler does not apply to it; the integrators it applies to: {}",
                           info.name, light_sampling_integrator_names());
    if ((r.spectral || d.spectral) && !info.spectral)
        return fmt::format("{} does not render in spectral mode yet (--spectral, or the scene file's <default name=\"mode\" "
                           "value=\"spectral\"/>); the integrators that do: {}",
                           info.name, spectral_integrator_names());
    if (!info.media)
        if (const std::string medium = medium_in_use(d); !medium.empty())
            return fmt::format("{0} does not render participating media, and this scene has the {1}: {0} would render "
                               "the scene as if the medium were not there. The integrators that render media: {2}",
                               info.name, medium, media_integrator_names());
    if (info.name == "upbp") {
        bool beams = true;
        try {
            const VcmEstimators e = parse_estimators(r.estimators ? *r.estimators : d.estimators.value_or("all"));
            beams = e.pb2d || e.bb1d;
        } catch (const std::invalid_argument&) {  // (said when the options are read)
        }
        if (const std::string medium = beams ? medium_in_use(d, true) : ""; !medium.empty())
            return fmt::format("upbp's beam estimators (pb2d, bb1d) need homogeneous media (the transmittance along a beam in closed "
                               "form), and this scene has the {}: leave them out (--estimators bpt,surf,pp3d) or render it with "
                               "volpath, lt, bdpt, pm, ppm, sppm, bpm, vcm, pssmlt or mmlt",
                               medium);
    }
    if (info.light_paths)
        if (const std::string m = non_reciprocal_material(d); !m.empty())
            return fmt::format("{} scatters light paths with the adjoint BSDF, and this scene's {}, which is not reciprocal "
                               "(f(wi, wo) != f(wo, wi)): {} would converge to another image. Render it with a camera-side "
                               "integrator (path, pt-mis3, pt-naive, volpath, direct, ic, pbgi)",
                               info.name, m, info.name);
    if (!info.skips_null_events && null_skip_requested(r, d) &&
        (r.max_depth ? *r.max_depth : d.max_depth.value_or(-1)) >= 0)
        if (const std::string m = null_lobe_material(d); !m.empty())
            return fmt::format("{0} counts a straight pass through a surface as a bounce, and this render asks for --null-depth "
                               "skip{1} with a finite depth in a scene with a {2}: {0} would converge to another image. "
                               "Give --null-depth count, or --max-depth -1 (then the two agree), or render it with {3}",
                               info.name, r.skip_null_events ? "" : " (the scene file's volpath counts depth that way)", m,
                               null_skipping_integrator_names());
    if (!info.any_camera && d.camera.kind != CameraKind::Perspective)
        return fmt::format("{} cannot render through a {} sensor: it connects light paths to a pinhole camera (or sizes "
                           "its radii by the pinhole's pixels); use a camera-side integrator (path, direct, pt-naive, "
                           "pm, eyelight) or a perspective sensor",
                           info.name, d.camera.kind == CameraKind::ThinLens ? "thinlens" : "orthographic");
    if (!info.any_filter && !(d.filter.is_box() && d.filter.radius == 0.5))
        return fmt::format("{} adds its samples to the film without a reconstruction filter; the scene's rfilter '{}'{} "
                           "works with the pixel integrators (path, direct, pt-naive, pm, ic, eyelight, ...); use "
                           "<rfilter type=\"box\"/> for {}",
                           info.name, d.filter.type,
                           d.filter.type == "gaussian" ? " (also Mitsuba's default, for a <film> that names no <rfilter>)" : "", info.name);
    return "";
}

// Options that belong to other estimators than `info` (the command line's names), and values out
// of their range: why the request cannot be rendered (empty: it can). The command line and
// Python's render() both come through here.
static std::string option_refusal(const IntegratorInfo& info, const JobRequest& r) {
    const auto one_of = [&](std::initializer_list<const char*> names) {
        for (const char* n : names)
            if (info.name == n) return true;
        return false;
    };
    const std::string& a = info.name;
    if (r.photons && !one_of({"sppm", "ppm", "pm"})) return fmt::format("--photons sets the light paths of sppm, ppm and pm; {} has no such count", a);
    if (r.photon_radius && !one_of({"sppm", "ppm", "pm", "vcm", "bpm", "upbp"}))
        return fmt::format("--radius sets the photon radius of sppm, ppm, pm, vcm, bpm and upbp; {} has none", a);
    if (r.photon_alpha && !one_of({"sppm", "ppm", "vcm", "bpm", "upbp"}))
        return fmt::format("--alpha is the radius reduction of sppm, ppm, vcm, bpm and upbp, not {}'s", a);
    if (r.estimators && a != "upbp") return fmt::format("--estimators chooses the estimators upbp combines; {} has no such choice", a);
    if (r.photon_beams && a != "upbp") return fmt::format("--photon-beams sets how many of upbp's light paths leave photon beams; {} has none", a);
    if (r.photon_beams && *r.photon_beams < 0) return "--photon-beams must be zero (the default count) or positive";
    if (r.beam_radius && a != "upbp") return fmt::format("--beam-radius sets the radius of upbp's beam estimators; {} has none", a);
    if (r.beam_radius && !(*r.beam_radius >= 0 && std::isfinite(*r.beam_radius)))
        return "--beam-radius must be zero (the photon radius) or a positive length in scene units";
    if (r.volume_beam && !one_of({"sppm", "ppm", "pm"}))
        return fmt::format("--volume-estimate chooses how sppm, ppm and pm gather photons in media; {} has no such choice", a);
    if (r.mis_power && !one_of({"bdpt", "vcm", "bpm", "upbp", "mmlt", "pt-mis", "pt-mis3", "direct-mis", "volpath"}))
        return fmt::format("--mis chooses the heuristic of bdpt, vcm, bpm, upbp, mmlt, pt-mis, pt-mis3, direct-mis and volpath; {} has its own", a);
    if (!r.vcm_merging && !r.vcm_connections) return "--no-merging and --no-connections together leave vcm no strategy";
    if ((!r.vcm_merging || !r.vcm_connections) && a != "vcm")
        return fmt::format("--no-merging and --no-connections switch off vcm's strategies, not {}'s", a);
    if ((r.ic_rays || r.ic_error || r.ic_gradients || r.ic_records) && a != "ic")
        return fmt::format("--ic-rays, --ic-error, --ic-no-gradients and --ic-records are ic's, not {}'s", a);
    if ((r.pbgi_surfels || r.pbgi_cutoff || r.pbgi_bounces || r.pbgi_resolution || r.pbgi_direct_samples || r.pbgi_spacing) && a != "pbgi")
        return fmt::format(
            "--pbgi-surfels, --pbgi-cutoff, --pbgi-bounces, --pbgi-resolution, --pbgi-direct-samples and --pbgi-spacing are pbgi's, not {}'s", a);
    if ((r.guiding_spp || r.guiding_rr || r.guiding_fraction || r.guiding) && a != "ppg")
        return fmt::format(
            "--guiding, --guiding-spp, --guiding-rr and --guiding-fraction set the model, the training, the roulette and the BSDF's share of "
            "ppg's guiding; {} learns nothing",
            a);
    if (r.guiding && !parse_guiding_model(*r.guiding)) return fmt::format("--guiding must be {}, got '{}'", kGuidingModelHelp, *r.guiding);
    if (r.guiding_fraction && !parse_guiding_fraction(*r.guiding_fraction))
        return fmt::format("--guiding-fraction must be {}, got '{}'", kGuidingFractionHelp, *r.guiding_fraction);
    if ((r.mlt_chains || r.mlt_bootstrap || r.mlt_large_step || r.mlt_sigma) && !one_of({"pssmlt", "mmlt"}))
        return fmt::format("--chains, --bootstrap, --large-step and --sigma set the Markov chains of pssmlt and mmlt, not {}'s", a);
    const auto out_of = [](const char* name, const auto& v, double lo, double hi) -> std::string {
        if (v && !(double(*v) >= lo && double(*v) <= hi)) return fmt::format("{} must be {:g} to {:g}, got {}", name, lo, hi, *v);
        return "";
    };
    for (const std::string& why : {out_of("--ic-rays", r.ic_rays, 4, 65536), out_of("--ic-error", r.ic_error, 0, 10),
                                   out_of("--pbgi-surfels", r.pbgi_surfels, 1, 1e7), out_of("--pbgi-cutoff", r.pbgi_cutoff, 0, 4 * kPi),
                                   out_of("--pbgi-bounces", r.pbgi_bounces, 1, 64), out_of("--pbgi-resolution", r.pbgi_resolution, 2, 256),
                                   out_of("--pbgi-direct-samples", r.pbgi_direct_samples, 1, 65536),
                                   out_of("--pbgi-spacing", r.pbgi_spacing, 1, 64), out_of("--chains", r.mlt_chains, 1, 1 << 20),
                                   out_of("--bootstrap", r.mlt_bootstrap, 1, 1 << 24), out_of("--large-step", r.mlt_large_step, 0, 1),
                                   out_of("--sigma", r.mlt_sigma, 1e-6, 1), out_of("--guiding-spp", r.guiding_spp, 0, 1 << 20)})
        if (!why.empty()) return why;
    return "";
}

RenderJob::RenderJob(SceneChoice scene, const JobRequest& r) : choice_(std::move(scene)) {
    const SceneDescription& d = choice_.description;
    if (!d.unknown_integrator.empty()) {
        if (!r.algorithm)
            throw UsageError(fmt::format("{}: error: unsupported integrator type '{}'; supported: {}, and the wrappers moment and aov; or "
                                         "choose one of pathlab's with -a NAME (e.g. -a pt-mis), which replaces it",
                                         d.unknown_integrator_at, d.unknown_integrator, integrator_names()));
        choice_.description.notes.push_back(fmt::format(
            "{}: note: the scene's integrator is not one of pathlab's; -a {} renders the scene instead", d.unknown_integrator_at, *r.algorithm));
    }
    info_ = &integrator_or_usage_error(r.algorithm ? *r.algorithm : d.algorithm.value_or("pt-mis"));
    options_.max_depth = r.max_depth ? *r.max_depth : d.max_depth.value_or(-1);
    options_.rr_depth = r.rr_depth ? *r.rr_depth : d.rr_depth.value_or(3);
    options_.mis_power = r.mis_power;
    options_.strategies_dir = r.strategies_dir;
    options_.strategies_depth = r.strategies_depth;
    if (r.strategies_depth < 0) throw UsageError("--strategies-depth must be zero or positive");
    options_.photons = r.photons ? *r.photons : d.photons.value_or(0);
    options_.photon_radius = r.photon_radius ? *r.photon_radius : d.photon_radius.value_or(0.0f);
    options_.photon_alpha = r.photon_alpha ? *r.photon_alpha : d.photon_alpha.value_or(2.0 / 3.0);
    options_.volume_beam = r.volume_beam ? *r.volume_beam : d.volume_beam.value_or(true);
    options_.vcm_merging = r.vcm_merging;
    options_.vcm_connections = r.vcm_connections;
    options_.ic_rays = r.ic_rays ? *r.ic_rays : d.ic_rays.value_or(options_.ic_rays);
    options_.ic_error = r.ic_error ? *r.ic_error : d.ic_error.value_or(options_.ic_error);
    options_.ic_gradients = r.ic_gradients ? *r.ic_gradients : d.ic_gradients.value_or(options_.ic_gradients);
    options_.ic_clamp_screen = d.ic_clamp_screen.value_or(true);
    options_.ic_clamp_neighbours = d.ic_clamp_neighbours.value_or(true);
    options_.pbgi_surfels = r.pbgi_surfels ? *r.pbgi_surfels : d.pbgi_surfels.value_or(options_.pbgi_surfels);
    options_.pbgi_cutoff = r.pbgi_cutoff ? *r.pbgi_cutoff : d.pbgi_cutoff.value_or(options_.pbgi_cutoff);
    options_.pbgi_bounces = r.pbgi_bounces ? *r.pbgi_bounces : d.pbgi_bounces.value_or(options_.pbgi_bounces);
    options_.pbgi_resolution = r.pbgi_resolution ? *r.pbgi_resolution : d.pbgi_resolution.value_or(options_.pbgi_resolution);
    options_.pbgi_direct_samples = r.pbgi_direct_samples ? *r.pbgi_direct_samples : d.pbgi_direct_samples.value_or(options_.pbgi_direct_samples);
    options_.pbgi_spacing = r.pbgi_spacing ? *r.pbgi_spacing : d.pbgi_spacing.value_or(options_.pbgi_spacing);
    options_.hide_emitters = d.hide_emitters.value_or(false);
    // (Only where it matters: a scene without thin glass or masks renders as it did.)
    options_.skip_null_events = null_skip_requested(r, d) && !null_lobe_material(d).empty();
    for (size_t i = 0; i < r.aovs.size(); ++i) {
        const std::vector<std::string>& names = aov_names();
        if (std::find(names.begin(), names.end(), r.aovs[i]) == names.end())
            throw UsageError(fmt::format("unknown AOV '{}'. Valid AOVs: {}", r.aovs[i], fmt::join(names, ", ")));
        if (std::find(r.aovs.begin(), r.aovs.begin() + long(i), r.aovs[i]) != r.aovs.begin() + long(i))
            throw UsageError(fmt::format("--aovs names {} twice", r.aovs[i]));
    }
    if (const std::string why = integrator_refusal(*info_, d, r); !why.empty()) throw UsageError(why);
    aovs_ = r.aovs;  // (an integrator without camera samples was refused by integrator_refusal)
    if (const std::string why = option_refusal(*info_, r); !why.empty()) throw UsageError(why);
    options_.mlt_chains = r.mlt_chains.value_or(options_.mlt_chains);
    options_.guiding_spp = r.guiding_spp ? *r.guiding_spp : d.guiding_spp.value_or(options_.guiding_spp);
    options_.guiding_rr = r.guiding_rr || d.guiding_rr.value_or(false);
    if (const auto fraction = r.guiding_fraction ? r.guiding_fraction : d.guiding_fraction)
        options_.guiding_fraction = *parse_guiding_fraction(*fraction);
    if (const auto model = r.guiding ? r.guiding : d.guiding) options_.guiding = *parse_guiding_model(*model);
    if (info_->name == "upbp") {
        options_.estimators = r.estimators ? *r.estimators : d.estimators.value_or("all");
        try {
            options_.estimators = estimator_names(parse_estimators(options_.estimators));
        } catch (const std::invalid_argument& e) {
            throw UsageError(e.what());
        }
        if (options_.estimators.empty()) throw UsageError("--estimators is empty: upbp needs at least one of bpt, surf, pp3d, pb2d, bb1d");
        options_.photon_beams = r.photon_beams ? *r.photon_beams : d.photon_beams.value_or(0);
        options_.beam_radius = r.beam_radius ? *r.beam_radius : d.beam_radius.value_or(0.0f);
    }
    options_.mlt_bootstrap = r.mlt_bootstrap.value_or(options_.mlt_bootstrap);
    options_.mlt_large_step = r.mlt_large_step.value_or(options_.mlt_large_step);
    options_.mlt_sigma = r.mlt_sigma.value_or(options_.mlt_sigma);
    options_.light_sampler = r.light_sampler.value_or(LightSamplerKind::Power);
    if (r.ris_candidates && options_.light_sampler != LightSamplerKind::Ris)
        throw UsageError("--ris-candidates is the number of light samples --light-sampler ris resamples; give --light-sampler ris");
    options_.ris_candidates = r.ris_candidates.value_or(kDefaultRisCandidates);
    if (options_.ris_candidates < 1 || options_.ris_candidates > kMaxRisCandidates)
        throw UsageError(fmt::format("--ris-candidates must be between 1 and {}, not {}", kMaxRisCandidates, options_.ris_candidates));
    if (r.light_split && options_.light_sampler != LightSamplerKind::Bvh)
        throw UsageError("--light-split is the light tree's adaptive splitting threshold; give --light-sampler bvh");
    options_.light_split = r.light_split.value_or(options_.light_sampler == LightSamplerKind::Bvh ? kDefaultLightSplit : 0.0f);
    if (!(options_.light_split >= 0) || !(options_.light_split <= kMaxLightSplit))
        throw UsageError(fmt::format("--light-split must be between 0 (no splitting) and {}, not {}", kMaxLightSplit, options_.light_split));
    options_.spectral = r.spectral || d.spectral;
    if (options_.photons < 0) throw UsageError("--photons must be zero (the default count) or positive");
    if (!(options_.photon_radius >= 0) || !std::isfinite(options_.photon_radius))
        throw UsageError("--radius must be zero (from the scene's size) or a positive distance");
    if (!(options_.photon_alpha > 0 && options_.photon_alpha <= 1)) throw UsageError("--alpha must be in (0, 1]");
    if (options_.max_depth < -1 || options_.max_depth == 0) throw UsageError("--max-depth must be positive, or -1 for unlimited");
    if (r.time_limit < 0 || !std::isfinite(r.time_limit)) throw UsageError("--time must be a positive number of seconds");
    if (r.spp && *r.spp == 0) throw UsageError("--spp must be a positive number of samples");

    settings.width = r.width;
    settings.height = r.height;
    settings.spp = r.spp ? *r.spp : (r.time_limit > 0 ? 0 : (d.spp ? uint64_t(*d.spp) : r.default_spp));
    settings.time_limit = r.time_limit;
    settings.seed = r.seed;
    settings.sampler = r.sampler;
    settings.spectral = options_.spectral;
    apply_environment_caps(settings, d);
    // Sample indices from 2^62 on are refused up front: first + spp must not wrap round (an image
    // of 0 samples after a minute's work), and no render reaches them (after the caps, which may
    // lower spp).
    settings.first_sample = r.first_sample;
    if (r.first_sample >= kMaxSampleIndex || settings.spp > kMaxSampleIndex - r.first_sample)
        throw UsageError(fmt::format("--first-sample {} with {} samples per pixel reaches past the last sample index, 2^62 = {}",
                                     r.first_sample, settings.spp, kMaxSampleIndex));
    // A render bounded by --time alone (no spp) could run past 2^62: it must start 2^40 samples
    // before it (more than any render reaches: 10^12 passes).
    constexpr uint64_t kTimedMargin = uint64_t(1) << 40;
    if (settings.spp == 0 && r.first_sample > kMaxSampleIndex - kTimedMargin)
        throw UsageError(fmt::format("--first-sample {} with --time and no --spp may reach past the last sample index, 2^62 = {}: "
                                     "give --spp, or a first sample at most 2^62 - 2^40 = {}",
                                     r.first_sample, kMaxSampleIndex, kMaxSampleIndex - kTimedMargin));
    if (!(r.checkpoint_every >= 0) || !std::isfinite(r.checkpoint_every))
        throw UsageError("--checkpoint-every must be zero (only at the end) or a positive number of seconds");
    settings.checkpoint_every = r.checkpoint_every;
}

namespace {

// Spectral mode renders only the material models it has spectral values for; a scene with
// another one is refused (rather than rendered with RGB values).
void check_spectral_materials(const SceneDescription& d) {
    for (size_t i = 0; i < d.materials.size(); ++i) {
        const std::string model = spectral_unsupported_model(d.materials[i]);
        if (model.empty()) continue;
        const std::string id = i < d.material_ids.size() && !d.material_ids[i].empty() ? fmt::format(" '{}'", d.material_ids[i]) : "";
        throw UsageError(fmt::format("spectral mode does not render the bsdf{}: {}; it renders {} (or render in RGB "
                                     "mode, without --spectral)", id, model, spectral_material_names()));
    }
}

}  // namespace

const Scene& RenderJob::scene() {
    if (!scene_) {
        if (options_.spectral) check_spectral_materials(choice_.description);
        choice_.description.light_sampler = options_.light_sampler;
        choice_.description.ris_candidates = options_.ris_candidates;
        choice_.description.light_split = options_.light_split;
        scene_ = Scene::build(choice_.description);
    }
    return *scene_;
}

Integrator& RenderJob::integrator() {
    if (!integrator_) integrator_ = info_->make(options_);
    return *integrator_;
}

std::string aov_integrator_names() {
    static const std::string names = [] {
        std::vector<std::string> v;
        for (const IntegratorInfo& info : integrators())
            if (info.make(IntegratorOptions{})->records_aovs()) v.push_back(info.name);
        return fmt::format("{}", fmt::join(v, ", "));
    }();
    return names;
}

void RenderJob::prepare_aov_film(int width, int height) {
    settings.aovs = nullptr;
    if (!aovs_need_first_vertex(aovs_)) return;
    aov_film_ = std::make_unique<AovFilm>(width, height);
    settings.aovs = aov_film_.get();
}

RenderResult RenderJob::run() {
    const Scene& s = scene();
    prepare_aov_film(settings.width > 0 ? settings.width : s.default_width(), settings.height > 0 ? settings.height : s.default_height());
    return render(s, integrator(), settings);
}

RenderStats RenderJob::run_into(Film& film) {
    prepare_aov_film(film.width(), film.height());
    return render_into(scene(), integrator(), settings, film);
}

std::string RenderJob::expand(const std::string& pattern) const {
    try {
        // {dir}: the scene file's folder (scenes laid out as DIR/scene.xml, Bitterli's way), or the
        // built-in scene's name (as {path}).
        const std::filesystem::path file =
            choice_.file.empty() ? std::filesystem::path() : std::filesystem::absolute(choice_.file).lexically_normal();
        const std::string dir = choice_.file.empty() ? choice_.name : file.parent_path().filename().string();
        // {path}: the scene file's path without its extension (from the current folder when the
        // file is under it), its folders joined by '-': tells a/k/scene.xml from b/k/scene.xml.
        std::string path = choice_.name;
        if (!choice_.file.empty()) {
            std::filesystem::path p = file.lexically_relative(std::filesystem::current_path());
            if (p.empty() || *p.begin() == "..") p = file.relative_path();
            path.clear();
            for (const auto& part : p.replace_extension()) path += (path.empty() ? "" : "-") + part.string();
        }
        return fmt::format(fmt::runtime(pattern), fmt::arg("scene", choice_.name), fmt::arg("index", choice_.index),
                           fmt::arg("algorithm", info_->name), fmt::arg("dir", dir), fmt::arg("path", path));
    } catch (const fmt::format_error& e) {
        throw UsageError(fmt::format("invalid output pattern '{}': {} (placeholders: {{scene}}, {{dir}}, {{path}}, {{index}}, {{algorithm}})",
                                     pattern, e.what()));
    }
}

void RenderJob::write_outputs(const RenderResult& result, float exposure,
                              const std::vector<std::pair<std::string, std::string>>& attributes) const {
    const Image image = result.film.mean();
    const SceneDescription& d = choice_.description;
    const bool has_exr = std::any_of(outputs.begin(), outputs.end(), [](const std::string& p) { return image_format_for(p) == ImageFormat::Exr; });
    if (!has_exr) {
        for (const std::string& path : outputs) write_image(image, path, exposure);
        return;
    }
    // An EXR carries the standard errors, the render's identity, and the moment and aov
    // integrators' channels.
    ExrExtras extras{{{"stderr", result.film.standard_error()}}, attributes, {}};
    if (d.moment) extras.channels = moment_channels(result.film);
    for (ExrChannel& c : render_aov_channels(aovs_, result.film, aov_film_.get())) extras.channels.push_back(std::move(c));
    if (!d.aovs.empty()) {
        std::vector<ExrChannel> a = aov_channels(*scene_, d.aovs, result.film.width(), result.film.height(), result.stats.spp, settings.seed);
        for (ExrChannel& c : a) extras.channels.push_back(std::move(c));
    }
    for (const std::string& path : outputs) {
        if (image_format_for(path) == ImageFormat::Exr) write_exr(image, extras, path);
        else write_image(image, path, exposure);
    }
}

}  // namespace pathlab
