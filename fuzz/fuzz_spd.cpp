// libFuzzer target for the spectrum file parser (parse_spectrum_file: "wavelength value" lines,
// as Mitsuba's and pbrt's .spd files): any input must parse or return its problem; a parsed
// spectrum must be finite at increasing wavelengths. From memory. Built and run by scripts/fuzz.sh
// spd.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/spectrum.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    pathlab::SampledSpectrum s;
    const std::string why = pathlab::parse_spectrum_file(std::string(reinterpret_cast<const char*>(data), size), s);
    if (why.empty()) {
        if (s.values.size() != s.wavelengths.size() || s.values.size() < 2) __builtin_trap();
        for (size_t i = 0; i < s.values.size(); ++i)
            if (!std::isfinite(s.values[i]) || !std::isfinite(s.wavelengths[i]) || (i > 0 && !(s.wavelengths[i] > s.wavelengths[i - 1])))
                __builtin_trap();
    }
    return 0;
}
