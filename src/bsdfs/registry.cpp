#include "bsdfs/registry.hpp"

#include <fmt/format.h>

#include "bsdfs/bumpmap.hpp"
#include "bsdfs/normalmap.hpp"

namespace pathlab {
namespace {

// A model read from its parameters, as a one-sided material (Mitsuba's convention: black from
// behind unless wrapped in twosided).
template <typename Model, Model (*read)(Properties&)>
Material one_sided(Properties& p) {
    return Material{read(p), false};
}

}  // namespace

const PluginInfo& twosided_plugin() {
    static const PluginInfo info{"bsdf", "twosided",
                                 "shades the back of a surface like its front (one nested BSDF), or with a second nested BSDF (front, back); not dielectrics",
                                 {}};
    return info;
}

const PluginInfo& blendbsdf_plugin() {
    static const PluginInfo info{"bsdf", "blendbsdf",
                                 "(1 - weight) first + weight second: wraps exactly two nested BSDFs (<bsdf> or <ref>, not dielectrics)",
                                 {{"weight", ParamType::Float, "0.5", "the second BSDF's share, 0 to 1", "", BlendMaterial::kSlotWeight}}};
    return info;
}

const PluginInfo& mask_plugin() {
    static const PluginInfo info{"bsdf", "mask",
                                 "opacity * the nested BSDF; the rest passes straight through (cut-outs such as leaves): wraps one BSDF",
                                 {{"opacity", ParamType::Float, "0.5", "0 (invisible) to 1 (opaque)", "", MaskMaterial::kSlotOpacity}}};
    return info;
}

const std::vector<BsdfPlugin>& bsdf_plugins() {
    static const std::vector<BsdfPlugin> table = {
        {diffuse_plugin, one_sided<PhongMaterial, read_diffuse>},
        {phong_plugin, one_sided<PhongMaterial, read_phong>},
        {conductor_plugin, one_sided<ConductorMaterial, read_conductor>},
        {roughconductor_plugin, one_sided<RoughConductorMaterial, read_roughconductor>},
        {dielectric_plugin, one_sided<DielectricMaterial, read_dielectric>},
        {roughdielectric_plugin, one_sided<RoughDielectricMaterial, read_roughdielectric>},
        {plastic_plugin, one_sided<PlasticMaterial, read_plastic>},
        {roughplastic_plugin, one_sided<RoughPlasticMaterial, read_roughplastic>},
        {principled_plugin, one_sided<PrincipledMaterial, read_principled>},
        {principledthin_plugin, [](Properties& p) { return Material{read_principledthin(p), true}; }},  // (the same from both sides)
        {thindielectric_plugin, [](Properties& p) { return Material{read_thindielectric(p), true}; }},
        {twosided_plugin, nullptr},
        {blendbsdf_plugin, nullptr},
        {mask_plugin, nullptr},
        {normalmap_plugin, nullptr},
        {bumpmap_plugin, nullptr},
    };
    return table;
}

const BsdfPlugin* find_bsdf_plugin(const std::string& type) {
    for (const BsdfPlugin& b : bsdf_plugins())
        if (b.info().type == type) return &b;
    return nullptr;
}

std::string bsdf_type_names() {
    std::vector<std::string> names;
    for (const BsdfPlugin& b : bsdf_plugins()) names.push_back(b.info().type);
    return fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace pathlab
