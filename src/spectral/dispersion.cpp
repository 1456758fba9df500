#include "spectral/dispersion.hpp"

#include <cmath>

namespace pathlab {

double Ior::operator()(double lambda) const {
    const double um = lambda * 1e-3, l2 = um * um;
    switch (model) {
        case Model::Constant: return b[0];
        case Model::Sellmeier: {
            double n2 = 1;
            for (int i = 0; i < 3; ++i) n2 += b[size_t(i)] * l2 / (l2 - c[size_t(i)]);
            return std::sqrt(n2);
        }
        case Model::Cauchy: return b[0] + b[1] / l2 + b[2] / (l2 * l2);
    }
    return b[0];
}

Spectrum4 Ior::sample(const SampledWavelengths& wl) const {
    Spectrum4 s;
    for (int i = 0; i < kSpectrumLanes; ++i) s[i] = float((*this)(wl[i]));
    return s;
}

double Ior::abbe_number() const {
    const double d = (*this)(kHydrogenF) - (*this)(kHydrogenC);
    return d != 0 ? ((*this)(kHeliumD) - 1) / d : INFINITY;
}

std::optional<Ior> named_glass(const std::string& name) {
    if (name == "bk7")
        return Ior::sellmeier({1.03961212, 0.231792344, 1.01046945}, {0.00600069867, 0.0200179144, 103.560653});
    if (name == "fused silica")
        return Ior::sellmeier({0.6961663, 0.4079426, 0.8974794},
                              {0.0684043 * 0.0684043, 0.1162414 * 0.1162414, 9.896161 * 9.896161});
    return std::nullopt;
}

}  // namespace pathlab
