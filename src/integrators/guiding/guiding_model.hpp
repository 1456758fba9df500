// ppg's directional model (--guiding): what a spatial leaf learns of the arriving radiance.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace pathlab {

enum class GuidingModel : uint8_t {
    kSdTree,  // a quadtree over cylindrical directions (Müller et al. 2017; sd_tree.hpp)
    kVmm,     // a mixture of von Mises-Fisher lobes fitted by on-line EM (Vorba et al. 2014; vmf_mixture.hpp)
};

inline constexpr const char* kGuidingModelHelp = "sd-tree or vmm";
inline const char* guiding_model_name(GuidingModel m) { return m == GuidingModel::kVmm ? "vmm" : "sd-tree"; }
// --guiding: "sd-tree" or "vmm"; nullopt for anything else.
inline std::optional<GuidingModel> parse_guiding_model(const std::string& text) {
    if (text == "sd-tree") return GuidingModel::kSdTree;
    if (text == "vmm") return GuidingModel::kVmm;
    return std::nullopt;
}

}  // namespace pathlab
