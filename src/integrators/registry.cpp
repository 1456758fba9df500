#include <algorithm>

#include <fmt/format.h>

#include "integrators/integrators.hpp"

namespace pathlab {

const std::vector<IntegratorInfo>& integrators() {
    static const std::vector<IntegratorInfo> table = {
        {"eyelight", {}, "debug view: |cos| between camera ray and surface normal", false, true, make_eyelight},
        {"direct-light", {"1"}, "direct illumination by light sampling (one light chosen by power)", false, true, make_direct_light},
        {"direct-uniform", {"2a"}, "direct illumination by uniform hemisphere sampling", true, true, make_direct_uniform},
        {"direct-cosine", {"2b"}, "direct illumination by cosine-weighted hemisphere sampling", true, true, make_direct_cosine},
        {"direct-brdf", {"2c"}, "direct illumination by BRDF importance sampling", true, true, make_direct_brdf},
        {"direct-mis", {"3"}, "light + BRDF sampling combined by MIS (balance heuristic)", false, true, make_direct_mis},
        {"pt-naive", {"4a"}, "path tracing by BRDF sampling, Russian roulette", true, true, make_pt_naive},
        {"pt-mis3", {"4b"}, "path tracing, MIS direct lighting at every bounce + a third continuation ray", false, true, make_pt_mis3},
        {"pt-mis", {"4c"}, "path tracing, MIS direct lighting whose BRDF ray continues the path", false, true, make_pt_mis},
        {"lt", {"ptracer"}, "light tracing: paths from the lights, every vertex connected to the camera", false, false, make_light_tracer},
    };
    return table;
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

}  // namespace pathlab
