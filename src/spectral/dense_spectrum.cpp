#include "spectral/dense_spectrum.hpp"

namespace pathlab {

DenseSpectrum::DenseSpectrum(const std::function<double(double)>& f) {
    for (int l = kFirst; l <= kLast; ++l) v_[size_t(l - kFirst)] = float(f(l));
    v_.back() = v_[size_t(kLast - kFirst)];
}

DenseSpectrum::DenseSpectrum(const SampledSpectrum& s) : DenseSpectrum([&](double l) { return spectrum_value(s, l); }) {}

}  // namespace pathlab
