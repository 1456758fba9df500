// <medium type="homogeneous|heterogeneous"> with its nested <phase> and <volume>s, declared at
// the top level with an id or nested in a <shape> (name="interior"/"exterior") or a <sensor>;
// <ref name="interior" id="..."/> refers to a declared one. And the null BSDF, a shape's
// index-matched boundary.
#include <fmt/format.h>

#include "media/medium.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

PhaseFunction read_phase(XmlSource& xml, const pugi::xml_node& n) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "a <phase> has no nested plugins");
    if (type == isotropic_phase_plugin().type) {
        Properties p = xml.properties(n, isotropic_phase_plugin());
        reading([&] { return p.check_all_used(), 0; });
        return IsotropicPhase{};
    }
    if (type == hg_phase_plugin().type) {
        Properties p = xml.properties(n, hg_phase_plugin());
        return reading([&] {
            const HgPhase hg = read_hg_phase(p);
            p.check_all_used();
            return hg;
        });
    }
    xml.fail(n, fmt::format("unsupported phase function type '{}'; supported: isotropic, hg", type));
}

Volume read_volume(XmlSource& xml, const pugi::xml_node& n, const SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "a <volume> has no nested plugins");
    if (type == constvolume_plugin().type) {
        Properties p = xml.properties(n, constvolume_plugin());
        return reading([&] {
            const Volume v = read_constvolume(p);
            p.check_all_used();
            return v;
        });
    }
    if (type == gridvolume_plugin().type) {
        Properties p = xml.properties(n, gridvolume_plugin());
        return reading([&] {
            const Volume v = read_gridvolume(p, b.shapes.base_dir, b.shapes.allow_files, b.shapes.files_read);
            p.check_all_used();
            return v;
        });
    }
    xml.fail(n, fmt::format("unsupported volume type '{}'; supported: gridvolume, constvolume", type));
}

}  // namespace

const PluginInfo& null_bsdf_plugin() {
    static const PluginInfo info{"bsdf", "null",
                                 "no surface at all: an index-matched boundary between media (the integrators that render media see it)", {}};
    return info;
}

int32_t read_medium(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    std::optional<PhaseFunction> phase;
    std::optional<Volume> sigma_t_volume, albedo_volume;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name();
        if (tag == "phase") {
            if (phase) xml.fail(c, "a medium can have only one phase function");
            phase = read_phase(xml, c);
        } else if (tag == "volume" && type == heterogeneous_plugin().type) {
            const std::string name = xml.attr(c, "name");
            std::optional<Volume>* slot = name == "sigma_t" ? &sigma_t_volume : name == "albedo" ? &albedo_volume : nullptr;
            if (!slot) xml.fail(c, fmt::format("a heterogeneous medium's <volume> is named sigma_t or albedo, not '{}'", name));
            if (*slot) xml.fail(c, fmt::format("the medium already has a volume named '{}'", name));
            *slot = read_volume(xml, c, b);
        } else {
            xml.fail(c, fmt::format("unsupported element <{}> in <medium type=\"{}\">; supported: <phase>{}", tag, type,
                                    type == heterogeneous_plugin().type ? ", <volume>" : ""));
        }
    }
    Medium medium;
    if (type == homogeneous_plugin().type) {
        Properties p = xml.properties(n, homogeneous_plugin());
        HomogeneousMedium m = reading([&] {
            const HomogeneousMedium h = read_homogeneous_medium(p);
            p.check_all_used();
            return h;
        });
        if (phase) m.phase = *phase;
        medium = m;
    } else if (type == heterogeneous_plugin().type) {
        Properties p = xml.properties(n, heterogeneous_plugin());
        HeterogeneousMedium m;
        reading([&] {
            for (const char* name : {"sigma_t", "albedo"})
                if (p.has(name) && (std::string(name) == "sigma_t" ? sigma_t_volume : albedo_volume))
                    p.fail(name, fmt::format("{} is given twice: as a value and as a <volume>", name));
            m.sigma_t = sigma_t_volume ? *sigma_t_volume : Volume::constant_value(p.get_rgb("sigma_t"));
            m.albedo = albedo_volume ? *albedo_volume : Volume::constant_value(p.get_rgb("albedo"));
            m.scale = p.get_float("scale");
            if (!(m.scale >= 0) || !std::isfinite(m.scale)) p.fail("scale", "scale must be finite and not negative");
            if (m.albedo.max_value() > 1) p.fail("albedo", "albedo must lie in [0, 1]");
            p.check_all_used();
            return 0;
        });
        if (phase) m.phase = *phase;
        m.prepare();
        medium = std::move(m);
    } else {
        xml.fail(n, fmt::format("unsupported medium type '{}'; supported: homogeneous, heterogeneous", type));
    }
    b.desc.media.push_back(std::move(medium));
    const auto id = xml.optional_attr(n, "id");
    const SourceLocation at = xml.where(n);
    b.desc.medium_labels.resize(b.desc.media.size());
    b.desc.medium_ids.resize(b.desc.media.size());
    if (id) b.desc.medium_ids.back() = *id;
    b.desc.medium_labels.back() = id ? fmt::format("{} medium '{}'", type, *id) : fmt::format("{} medium of {}:{}", type, at.file, at.line);
    return int32_t(b.desc.media.size() - 1);
}

void read_named_medium(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    const auto id = xml.optional_attr(n, "id");
    if (id && b.named.count(*id)) b.name(xml, n, *id, "medium", int32_t(-1));  // names the earlier declaration
    const int32_t index = read_medium(xml, n, b);
    if (id) b.name(xml, n, *id, "medium", index);
}

int32_t medium_reference(XmlSource& xml, const pugi::xml_node& ref, const SceneBuilder& b) {
    return std::any_cast<int32_t>(b.resolve(xml, ref, "medium").value);
}

}  // namespace pathlab
