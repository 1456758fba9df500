// Wavelength-dependent indices of refraction of dielectrics (docs/spectral.md "Dispersion"),
// with lambda in micrometres inside the formulas (as the glass catalogues give them):
//   Sellmeier  n^2(lambda) = 1 + sum_{i=1..3} B_i lambda^2 / (lambda^2 - C_i)    C_i in um^2
//   Cauchy     n(lambda)   = A + B / lambda^2 + C / lambda^4                   B in um^2, C in um^4
//   constant   n
// Named glasses (named_glass()):
//   "bk7"           Schott N-BK7, Sellmeier coefficients of the Schott optical glass data sheet
//                   (B = 1.03961212, 0.231792344, 1.01046945; C = 0.00600069867, 0.0200179144,
//                   103.560653 um^2): n_d = 1.5168, Abbe number v_d = 64.17
//   "fused silica"  I. H. Malitson, "Interspecimen comparison of the refractive index of fused
//                   silica", J. Opt. Soc. Am. 55, 1205-1209 (1965): B = 0.6961663, 0.4079426,
//                   0.8974794; sqrt(C) = 0.0684043, 0.1162414, 9.896161 um: n_d = 1.4585, v_d = 67.8
#pragma once

#include <array>
#include <optional>
#include <string>

#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

// Fraunhofer lines of the Abbe number v_d = (n_d - 1) / (n_F - n_C), nm.
inline constexpr double kHeliumD = 587.5618, kHydrogenF = 486.1327, kHydrogenC = 656.2725;

struct Ior {
    enum class Model { Constant, Sellmeier, Cauchy };
    Model model = Model::Constant;
    std::array<double, 3> b{1, 0, 0};  // Constant: n; Sellmeier: B_1..3; Cauchy: A, B, C
    std::array<double, 3> c{0, 0, 0};  // Sellmeier: C_1..3 (um^2)

    static Ior constant(double n) { return {Model::Constant, {n, 0, 0}, {}}; }
    static Ior sellmeier(const std::array<double, 3>& B, const std::array<double, 3>& C) { return {Model::Sellmeier, B, C}; }
    static Ior cauchy(double A, double B, double C = 0) { return {Model::Cauchy, {A, B, C}, {}}; }

    bool is_dispersive() const { return model != Model::Constant; }
    // The index at `lambda` nm.
    double operator()(double lambda) const;
    Spectrum4 sample(const SampledWavelengths& wl) const;
    double abbe_number() const;
};

// "bk7" or "fused silica" (above); nullopt for another name.
std::optional<Ior> named_glass(const std::string& name);
inline const char* kNamedGlasses = "bk7, fused silica";

}  // namespace pathlab
