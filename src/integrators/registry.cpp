#include <algorithm>

#include <fmt/format.h>

#include "integrators/integrators.hpp"
#include "integrators/photon/spectral_photon_methods.hpp"

namespace pathlab {
namespace {

// An integrator whose spectral mode is another class (the photon methods: spectral_photon_methods.hpp):
// its RGB factory for RGB mode, `spectral` for spectral mode. Made here so that the RGB
// integrators' translation units (pm.cpp, sppm.cpp) stay as they were, object code included.
IntegratorInfo with_spectral_mode(IntegratorInfo info, std::function<std::unique_ptr<Integrator>(const IntegratorOptions&)> spectral) {
    info.make = [rgb = info.make, spectral = std::move(spectral)](const IntegratorOptions& o) { return o.spectral ? spectral(o) : rgb(o); };
    info.spectral = true;
    return info;
}

}  // namespace

const std::vector<IntegratorInfo>& integrators() {
    static const std::vector<IntegratorInfo> table = {
        eyelight_integrator(),       direct_light_integrator(), direct_uniform_integrator(), direct_cosine_integrator(),
        direct_brdf_integrator(),    direct_mis_integrator(),   pt_naive_integrator(),       pt_mis3_integrator(),
        pt_mis_integrator(),         light_tracer_integrator(), bdpt_integrator(),
        with_spectral_mode(pm_integrator(), make_spectral_pm),
        with_spectral_mode(ppm_integrator(), [](const IntegratorOptions& o) { return make_spectral_sppm(o, /*pixel_centres=*/true); }),
        with_spectral_mode(sppm_integrator(), [](const IntegratorOptions& o) { return make_spectral_sppm(o, /*pixel_centres=*/false); }),
        bpm_integrator(), vcm_integrator(), ic_integrator(), pbgi_integrator(),
        volpath_integrator(),
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

std::string spectral_integrator_names() {
    std::string out;
    for (const IntegratorInfo& e : integrators())
        if (e.spectral) out += (out.empty() ? "" : ", ") + e.name;
    return out;
}

}  // namespace pathlab
