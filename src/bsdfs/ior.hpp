// Indices of refraction by name, and how BSDF plugins read them from their parameters:
// dielectrics (a real index) and conductors (a complex one, per RGB channel).
#pragma once

#include <map>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "core/properties.hpp"
#include "core/vec.hpp"
#include "spectral/metals.hpp"

namespace pathlab {

// Refractive indices of dielectrics by name (a few of Mitsuba's, at 589 nm).
inline const std::map<std::string, float>& named_iors() {
    static const std::map<std::string, float> table = {
        {"vacuum", 1.0f},       {"air", 1.000277f},       {"water", 1.3330f}, {"fused quartz", 1.458f},
        {"pyrex", 1.470f},      {"acrylic glass", 1.49f}, {"bk7", 1.5046f},   {"diamond", 2.419f},
        {"polypropylene", 1.49f},
    };
    return table;
}

// Complex refractive index (eta, k) of a conductor, as RGB.
struct ComplexIor {
    Rgb eta, k;
    // Spectral mode's eta(lambda) and k(lambda) of a metal given by name (spectral/metals.hpp:
    // Au, Ag, Cu, Al, Cr, a-C), null otherwise; RGB mode uses eta and k.
    const MeasuredConductor* measured = nullptr;
};

// A few metals by their chemical symbols. The values are RGB averages of measured spectral
// data (Palik, "Handbook of Optical Constants of Solids", as shipped with pbrt and Mitsuba
// 0.6), as tabulated by Benedikt Bitterli's Tungsten renderer (src/core/bsdfs/ComplexIorData.hpp).
// "none" is Mitsuba's perfect reflector: eta = 0, k = 1 gives F = 1 at every angle.
inline std::optional<ComplexIor> named_conductor(const std::string& name) {
    if (name == "none") return ComplexIor{Rgb(0.0f), Rgb(1.0f)};
    if (name == "Au") return ComplexIor{{0.1431190f, 0.3749570f, 1.4424786f}, {3.9831604f, 2.3857207f, 1.6032153f}};
    if (name == "Ag") return ComplexIor{{0.1552646f, 0.1167233f, 0.1383807f}, {4.8283433f, 3.1222459f, 2.1469504f}};
    if (name == "Cu") return ComplexIor{{0.2004377f, 0.9240334f, 1.1022120f}, {3.9129485f, 2.4528477f, 2.1421880f}};
    if (name == "Al") return ComplexIor{{1.6574600f, 0.8803690f, 0.5212287f}, {9.2238692f, 6.2695232f, 4.8370012f}};
    if (name == "Cr") return ComplexIor{{4.3696829f, 2.9167025f, 1.6547005f}, {5.2064338f, 4.2313645f, 3.7549468f}};
    // Metals known by their measurements only (a-C): the measured spectra's colours, as Mitsuba 3
    // makes a named conductor's RGB (mitsuba3 include/mitsuba/render/ior.h: the spectrum through
    // the CIE observer, no illuminant, unbounded).
    if (const MeasuredConductor* m = measured_conductor(name)) {
        const auto rgb = [](const SampledSpectrum& s) {
            const Vec3d c = spectrum_to_linear_srgb(s, SpectrumUse::Unbounded);
            return Rgb(float(c.x), float(c.y), float(c.z));
        };
        return ComplexIor{rgb(m->eta), rgb(m->k)};
    }
    return std::nullopt;
}
inline const char* kNamedConductors = "none, Au, Ag, Cu, Al, Cr, a-C";


// A dielectric's index from parameter `name`: a number in [1, 10) or a name of named_iors().
inline float read_ior(Properties& p, const std::string& name) {
    if (p.is_string(name)) {
        const std::string v = p.get_string(name);
        const auto it = named_iors().find(v);
        if (it == named_iors().end()) {
            std::vector<std::string> names;
            for (const auto& [k, x] : named_iors()) names.push_back(k);
            p.fail(name, fmt::format("unknown material '{}' for {}; known: {}", v, name, fmt::join(names, ", ")));
        }
        return it->second;
    }
    const float x = p.get_float(name);
    if (!(x >= 1.0f && x < 10.0f)) p.fail(name, fmt::format("{} must be between 1 and 10, got {}", name, x));
    return x;
}

// A conductor's complex index: `material` by name, or `eta` and `k`.
inline ComplexIor read_conductor_ior(Properties& p) {
    const bool explicit_ior = p.has("eta") || p.has("k");
    if (p.has("material") && explicit_ior) p.fail("material", "give either material or eta and k, not both");
    if (explicit_ior) return ComplexIor{p.get_rgb("eta"), p.get_rgb("k")};
    const std::string name = p.get_string("material");
    auto ior = named_conductor(name);
    if (!ior) p.fail("material", fmt::format("unknown conductor material '{}'; known: {}", name, kNamedConductors));
    ior->measured = measured_conductor(name);
    return *ior;
}

inline const ParamInfo kConductorMaterialParam{"material", ParamType::String, "none",
                                               "a metal by name: none (a perfect mirror, eta = 0, k = 1), Au, Ag, Cu, Al, Cr, a-C (amorphous carbon)"};
inline const ParamInfo kConductorEtaParam{"eta", ParamType::Rgb, "0", "complex index of refraction, real part (instead of material)"};
inline const ParamInfo kConductorKParam{"k", ParamType::Rgb, "1", "complex index of refraction, imaginary part"};
inline const std::string kIorNames =
    "vacuum, air, water, fused quartz, pyrex, acrylic glass, polypropylene, bk7, diamond";

}  // namespace pathlab
