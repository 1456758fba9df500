// dielectric: a smooth interface between two dielectrics (glass, water), with Fresnel
// reflection and refraction.
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   int_ior   float or string  interior index of refraction, or a name (bk7, water, ...)  default bk7 (1.5046)
//   ext_ior   float or string  exterior index of refraction                            default air (1.000277)
// The exterior is the side the normal points to. Cannot be wrapped in twosided: both of its
// sides matter.
//
// Reflection is chosen with probability F (Fresnel), refraction with 1 - F; both lobes are
// Dirac deltas (see bsdf_sample.hpp). Radiance keeps L / eta^2 invariant across the interface,
// so a refracted sample carries the weight (eta_wi / eta_wo)^2 (indices on the sides of wi
// and wo); a path that enters and leaves a body picks up factors that cancel.
#pragma once

#include <cmath>
#include <cstdlib>
#include <memory>
#include <vector>

#include "spectral/dispersion.hpp"

#include <cmath>
#include <optional>

#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/ior.hpp"

namespace pathlab {

struct DielectricMaterial {
    float int_ior = 1.5046f;  // Mitsuba's default (BK7 glass)
    float ext_ior = 1.000277f;
    // A wavelength-dependent interior index (Sellmeier or Cauchy), or null. RGB mode refracts
    // with int_ior, the index at kDispersionReferenceWavelength (n_d); spectral mode refracts
    // the hero wavelength with its own index and drops the other three (bsdfs/spectral_bsdf.hpp).
    std::shared_ptr<const Ior> dispersion = nullptr;

    Rgb eval(const Vec3f&, const Vec3f&) const { return Rgb(0.0f); }
    float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        const bool outside = wi.z > 0;
        const float eta_wi = outside ? ext_ior : int_ior, eta_other = outside ? int_ior : ext_ior;
        const float cos_i = std::abs(wi.z);
        float cos_t = 0;
        const float F = fresnel_dielectric(cos_i, eta_other / eta_wi, &cos_t);
        if (u.x < F) {
            const Vec3f wo(-wi.x, -wi.y, wi.z);
            return BsdfSample{wo, Rgb(F / cos_i), F, true, kLobeSpecular | kLobeReflection};
        }
        // Refraction: wo on the other side, tangential part scaled by eta_wi / eta_other.
        const float r = eta_wi / eta_other;
        const Vec3f wo(-wi.x * r, -wi.y * r, outside ? -cos_t : cos_t);
        const float scale = r * r;  // (eta_wi / eta_wo)^2
        return BsdfSample{wo, Rgb((1 - F) * scale / cos_t), 1 - F, true, kLobeSpecular | kLobeTransmission};
    }
};

// The wavelength at which a dispersive glass's index is its RGB-mode index: helium's d line,
// 587.56 nm (the glass catalogues' n_d).
inline constexpr double kDispersionReferenceWavelength = kHeliumD;

inline const ParamInfo kIntIorParam{"int_ior", ParamType::FloatOrString, "bk7",
                                    "interior index of refraction, a number or a name: " + kIorNames, "intIOR"};
inline const ParamInfo kExtIorParam{"ext_ior", ParamType::FloatOrString, "air", "exterior index of refraction (the normal's side)",
                                    "extIOR"};

inline const PluginInfo& dielectric_plugin() {
    static const PluginInfo info{
        "bsdf", "dielectric", "a smooth interface between two dielectrics (glass, water): Fresnel reflection and refraction",
        {{"int_ior", ParamType::FloatOrString, "bk7",
          "interior index of refraction, a number or a name: " + kIorNames +
              "; or a dispersive glass: bk7-sellmeier (Schott N-BK7), fused silica (Malitson 1965)",
          "intIOR"},
         kExtIorParam,
         {"sellmeier_b", ParamType::String, "",
          "dispersive interior index n^2 = 1 + sum B_i l^2 / (l^2 - C_i), l in um: \"B1, B2, B3\" (with sellmeier_c)"},
         {"sellmeier_c", ParamType::String, "", "the Sellmeier C_i in um^2: \"C1, C2, C3\""},
         {"cauchy", ParamType::String, "", "dispersive interior index n = A + B / l^2 + C / l^4, l in um: \"A, B\" or \"A, B, C\""}}};
    return info;
}
// Comma- or space-separated numbers of a string parameter: exactly `count` (or, with
// `optional_last`, one fewer).
inline std::vector<double> read_numbers(Properties& p, const std::string& name, size_t count, bool optional_last = false) {
    const std::string text = p.get_string(name);
    std::vector<double> out;
    const char* s = text.c_str();
    while (*s) {
        while (*s == ' ' || *s == ',' || *s == '\t') ++s;
        if (!*s) break;
        char* end = nullptr;
        const double v = std::strtod(s, &end);
        if (end == s || !std::isfinite(v)) p.fail(name, fmt::format("'{}' is not a list of numbers", text));
        out.push_back(v);
        s = end;
    }
    if (out.size() != count && !(optional_last && out.size() + 1 == count))
        p.fail(name, fmt::format("{} needs {}{} numbers, got {}", name, optional_last ? fmt::format("{} or ", count - 1) : "", count, out.size()));
    return out;
}
// A dispersive interior index (int_ior naming a dispersive glass, sellmeier_b and _c, or cauchy), or null.
inline std::shared_ptr<const Ior> read_dispersion(Properties& p) {
    std::optional<Ior> ior;
    int given = 0;
    if (p.has("int_ior") && p.is_string("int_ior")) {
        const std::string name = p.get_string("int_ior");
        if (name == "bk7-sellmeier") ior = named_glass("bk7"), ++given;
        else if (name == "fused silica") ior = named_glass("fused silica"), ++given;
        else if (name != "" && named_iors().count(name)) given += 1;  // a constant by name
    } else if (p.has("int_ior")) {
        ++given;
    }
    if (p.has("sellmeier_b") || p.has("sellmeier_c")) {
        if (!p.has("sellmeier_b") || !p.has("sellmeier_c")) p.fail("sellmeier_b", "give both sellmeier_b and sellmeier_c");
        const std::vector<double> b = read_numbers(p, "sellmeier_b", 3), c = read_numbers(p, "sellmeier_c", 3);
        ior = Ior::sellmeier({b[0], b[1], b[2]}, {c[0], c[1], c[2]});
        ++given;
    }
    if (p.has("cauchy")) {
        const std::vector<double> a = read_numbers(p, "cauchy", 3, true);
        ior = Ior::cauchy(a[0], a[1], a.size() > 2 ? a[2] : 0.0);
        ++given;
    }
    if (given > 1) p.fail("int_ior", "give one interior index: int_ior, sellmeier_b and sellmeier_c, or cauchy");
    if (!ior) return nullptr;
    const double n_d = (*ior)(kDispersionReferenceWavelength);
    for (double l : {360.0, 587.5618, 830.0}) {
        const double n = (*ior)(l);
        if (!(n >= 1 && n < 10)) p.fail("int_ior", fmt::format("the dispersive index is {} at {} nm; it must be between 1 and 10 over 360-830 nm", n, l));
    }
    (void)n_d;
    return std::make_shared<const Ior>(*ior);
}
inline DielectricMaterial read_dielectric(Properties& p) {
    const float ext_ior = read_ior(p, "ext_ior");
    if (auto dispersion = read_dispersion(p))
        return DielectricMaterial{float((*dispersion)(kDispersionReferenceWavelength)), ext_ior, std::move(dispersion)};
    return DielectricMaterial{read_ior(p, "int_ior"), ext_ior};
}

}  // namespace pathlab
