#include <algorithm>

#include <fmt/format.h>

#include "integrators/integrators.hpp"

namespace pathlab {

const std::vector<IntegratorInfo>& integrators() {
    static const std::vector<IntegratorInfo> table = {
        eyelight_integrator(),       direct_light_integrator(), direct_uniform_integrator(), direct_cosine_integrator(),
        direct_brdf_integrator(),    direct_mis_integrator(),   pt_naive_integrator(),       pt_mis3_integrator(),
        pt_mis_integrator(),         light_tracer_integrator(), bdpt_integrator(),
        pm_integrator(),             ppm_integrator(),          sppm_integrator(),           bpm_integrator(),
        vcm_integrator(),            upbp_integrator(),         ic_integrator(),           pbgi_integrator(),           volpath_integrator(),
        pssmlt_integrator(),         mmlt_integrator(),         ppg_integrator(),
    };
    return table;
}

PluginInfo IntegratorInfo::plugin() const {
    return PluginInfo{"integrator", name, summary, params};
}

const IntegratorInfo* find_integrator(const std::string& key) {
    for (const IntegratorInfo& e : integrators())
        if (e.name == key || std::find(e.aliases.begin(), e.aliases.end(), key) != e.aliases.end()) return &e;
    return nullptr;
}

std::string integrator_names() {
    std::string out;
    for (const IntegratorInfo& e : integrators()) {
        if (!out.empty()) out += ", ";
        out += e.name;
        if (!e.aliases.empty()) out += fmt::format(" ({})", fmt::join(e.aliases, "/"));
    }
    return out;
}

namespace {

// "a, b, ...": the integrators whose `capability` is true.
std::string names_of_integrators_with(bool IntegratorInfo::*capability) {
    std::string out;
    for (const IntegratorInfo& e : integrators())
        if (e.*capability) out += (out.empty() ? "" : ", ") + e.name;
    return out;
}

}  // namespace

std::string spectral_integrator_names() { return names_of_integrators_with(&IntegratorInfo::spectral); }

std::string media_integrator_names() { return names_of_integrators_with(&IntegratorInfo::media); }

std::string light_sampling_integrator_names() { return names_of_integrators_with(&IntegratorInfo::samples_lights); }

std::string null_skipping_integrator_names() { return names_of_integrators_with(&IntegratorInfo::skips_null_events); }

}  // namespace pathlab
