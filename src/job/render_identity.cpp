#include "job/render_identity.hpp"

#include <xxhash.h>

#include <cctype>
#include <sstream>

#include <fmt/format.h>

#include "job/render_job.hpp"

namespace pathlab {

const std::vector<std::string> kIdentityFields = {"scene", "scene hash", "integrator", "options", "resolution", "seed", "sampler"};
const std::vector<std::string> kMergeFields = {"scene", "scene hash", "integrator", "options", "resolution", "sampler"};

std::string RenderIdentity::value(const std::string& key) const {
    for (const auto& [k, v] : fields)
        if (k == key) return v;
    return "";
}

std::string RenderIdentity::to_text() const {
    std::string s;
    for (const auto& [k, v] : fields) s += k + "=" + v + "\n";
    return s;
}

RenderIdentity RenderIdentity::from_text(const std::string& text) {
    RenderIdentity id;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        const size_t eq = line.find('=');
        if (eq == std::string::npos || eq == 0) continue;
        id.fields.emplace_back(line.substr(0, eq), line.substr(eq + 1));
    }
    return id;
}

std::string RenderIdentity::hash() const {
    const std::string t = to_text();
    return fmt::format("{:016x}", XXH3_64bits(t.data(), t.size()));
}

std::string RenderIdentity::differences(const RenderIdentity& ours, const std::vector<std::string>& keys, const std::string& theirs_name,
                                        const std::string& ours_name) const {
    std::string out;
    for (const std::string& k : keys) {
        const std::string a = value(k), b = ours.value(k);
        if (a != b) out += fmt::format("  {}: {} in {}, {} in {}\n", k, a.empty() ? "(none)" : a, theirs_name, b.empty() ? "(none)" : b, ours_name);
    }
    return out;
}

namespace {

std::string hex_float(double v) { return fmt::format("{:a}", v); }

}  // namespace

std::string options_text(const IntegratorOptions& o) {
    const IntegratorOptions defaults;
    return fmt::format("max_depth={} rr_depth={} only_length={} mis={} photons={} radius={} alpha={} merging={} connections={} "
                       "ic_rays={} ic_error={} ic_gradients={}",
                       o.max_depth, o.rr_depth, o.only_length, o.mis_power ? "power" : "balance", o.photons, hex_float(o.photon_radius),
                       hex_float(o.photon_alpha), int(o.vcm_merging), int(o.vcm_connections), o.ic_rays, hex_float(o.ic_error),
                       int(o.ic_gradients)) +
           (o.spectral ? " mode=spectral" : "") + (o.volume_beam ? "" : " volume=points") + (o.skip_null_events ? " null_depth=skip" : "") +
           (o.light_sampler == LightSamplerKind::Power ? "" : fmt::format(" lights={}", light_sampler_name(o.light_sampler))) +
           (o.light_sampler == LightSamplerKind::Ris ? fmt::format(" ris={}", o.ris_candidates) : "") +
           (o.light_split > 0 ? fmt::format(" split={}", hex_float(o.light_split)) : "") +
           (o.mlt_chains == defaults.mlt_chains && o.mlt_bootstrap == defaults.mlt_bootstrap && o.mlt_large_step == defaults.mlt_large_step &&
                    o.mlt_sigma == defaults.mlt_sigma
                ? ""
                : fmt::format(" chains={} bootstrap={} large_step={} sigma={}", o.mlt_chains, o.mlt_bootstrap, hex_float(o.mlt_large_step),
                              hex_float(o.mlt_sigma))) +
           (o.guiding_spp == defaults.guiding_spp ? "" : fmt::format(" guiding_spp={}", o.guiding_spp)) + (o.guiding_rr ? " guiding_rr=1" : "") +
           (o.guiding_fraction == defaults.guiding_fraction
                ? ""
                : o.guiding_fraction == kLearnedGuidingFraction ? " guiding_fraction=learned" : " guiding_fraction=" + hex_float(o.guiding_fraction)) +
           (o.guiding == defaults.guiding ? "" : fmt::format(" guiding={}", guiding_model_name(o.guiding))) +
           (o.estimators.empty() ? "" : " estimators=" + o.estimators) +
           (o.photon_beams == 0 ? "" : fmt::format(" photon_beams={}", o.photon_beams)) +
           (o.beam_radius == 0 ? "" : " beam_radius=" + hex_float(o.beam_radius));  // the text of the defaults as it always was
}

std::string metadata_key(const std::string& field) {
    std::string key = "pathlab:";
    bool upper = false;
    for (char c : field) {
        if (c == ' ') upper = true;
        else key += upper ? char(std::toupper(static_cast<unsigned char>(c))) : c, upper = false;
    }
    return key;
}

std::vector<std::pair<std::string, std::string>> render_metadata(const RenderIdentity& identity, const PassSet& passes,
                                                                 uint64_t invalid_samples, const std::vector<IntegratorStatistic>& statistics) {
    std::vector<std::pair<std::string, std::string>> m;
    for (const auto& [k, v] : identity.fields) m.emplace_back(metadata_key(k), v);
    m.emplace_back("pathlab:spp", fmt::format("{}", passes.count()));
    m.emplace_back("pathlab:firstSample", fmt::format("{}", passes.begin()));
    m.emplace_back("pathlab:passes", passes.to_string());
    m.emplace_back("pathlab:invalidSamples", fmt::format("{}", invalid_samples));
    m.emplace_back("pathlab:version", PATHLAB_VERSION);
    for (const IntegratorStatistic& x : statistics)
        if (x.in_metadata) m.emplace_back(metadata_key(x.name), fmt::format("{}", x.value));
    return m;
}

RenderIdentity render_identity(RenderJob& job, int width, int height) {
    const SceneChoice& c = job.scene_choice();
    RenderIdentity id;
    id.fields = {{"scene", c.name},
                 {"scene hash", scene_hash(c)},
                 {"integrator", job.integrator_info().name},
                 {"options", options_text(job.integrator_options())},
                 {"resolution", fmt::format("{}x{}", width, height)},
                 {"seed", fmt::format("{}", job.settings.seed)},
                 {"sampler", job.settings.sampler == SamplerKind::Sobol ? "sobol" : "independent"}};
    if (job.integrator_options().spectral) id.fields.push_back({"mode", "spectral"});  // pathlab:mode (absent: RGB)
    return id;
}

}  // namespace pathlab
