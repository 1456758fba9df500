#include "diff/parameters.hpp"

#include <algorithm>
#include <memory>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

namespace pathlab {
namespace {

std::vector<float> rgb(const Rgb& c) { return {c.x, c.y, c.z}; }
Rgb rgb(const std::vector<float>& v) { return Rgb(v.at(0), v.at(1), v.at(2)); }

// sigma_s / sigma_t per channel (0 where sigma_t is).
Rgb medium_albedo(const HomogeneousMedium& m) {
    Rgb a(0.0f);
    for (int c = 0; c < 3; ++c) a[c] = m.sigma_t[c] > 0 ? m.sigma_s[c] / m.sigma_t[c] : 0.0f;
    return a;
}

// The microfacet distribution of an anisotropic parameter's model (roughconductor or roughdielectric).
template <class Model>
auto& distribution_of(Model& m) {
    if (auto* r = std::get_if<RoughConductorMaterial>(&m)) return r->distribution;
    return std::get<RoughDielectricMaterial>(m).distribution;
}

const std::string& id_at(const std::vector<std::string>& ids, size_t i) {
    static const std::string none;
    return i < ids.size() ? ids[i] : none;
}

// The parameter that a texture bound to `slot` of model m gives, if it is one of ours.
std::optional<ParamField> textured_field(const MaterialModel& m, int slot) {
    if (std::holds_alternative<PhongMaterial>(m))
        return slot == PhongMaterial::kSlotDiffuse    ? ParamField::PhongDiffuse
               : slot == PhongMaterial::kSlotSpecular ? ParamField::PhongSpecular
                                                      : ParamField::PhongExponent;
    if (std::holds_alternative<ConductorMaterial>(m)) return ParamField::ConductorSpecular;
    const auto roughness = [&](ParamField isotropic) {
        return slot == MicrofacetDistribution::kSlotAlphaU ? ParamField::AlphaU : slot == MicrofacetDistribution::kSlotAlphaV ? ParamField::AlphaV : isotropic;
    };
    if (std::holds_alternative<RoughConductorMaterial>(m))
        return slot == RoughConductorMaterial::kSlotSpecularReflectance ? ParamField::RoughConductorSpecular : roughness(ParamField::RoughConductorAlpha);
    if (std::holds_alternative<PlasticMaterial>(m))
        return slot == CoatedDiffuse::kSlotDiffuse ? ParamField::PlasticDiffuse : ParamField::PlasticSpecular;
    if (std::holds_alternative<RoughPlasticMaterial>(m))
        return slot == CoatedDiffuse::kSlotDiffuse ? ParamField::RoughPlasticDiffuse : ParamField::RoughPlasticSpecular;
    if (std::holds_alternative<RoughDielectricMaterial>(m)) return roughness(ParamField::RoughDielectricAlpha);  // its only textured parameter
    return std::nullopt;
}

// The rgb reflectances (the fields whose texels are differentiable).
bool is_roughness(ParamField f) {
    return f == ParamField::RoughConductorAlpha || f == ParamField::RoughDielectricAlpha || f == ParamField::RoughPlasticAlpha ||
           f == ParamField::AlphaU || f == ParamField::AlphaV;
}
bool is_reflectance(ParamField f) {
    return f != ParamField::PhongExponent && !is_roughness(f) && f != ParamField::RoughDielectricEta && f < ParamField::Texels;
}

const BitmapTexture* bitmap_of(const TextureBinding& b) {
    return b.scalar || !b.texture ? nullptr : std::get_if<BitmapTexture>(&b.texture->model());
}

const TextureBinding& binding_of(const SceneDescription& d, const SceneParameter& p) {
    return d.materials.at(p.index).textures->bindings.at(size_t(p.binding));
}

// The textures that are also used where no derivative flows (a scalar parameter, a normal or
// bump map, a material nested in blendbsdf or mask): their texels are not parameters, since
// moving them would change the image in ways the gradient does not see.
void collect_undifferentiated(const Material& m, bool nested, std::vector<const Texture*>& out) {
    if (m.textures) {
        if (m.textures->perturbation_texture) out.push_back(m.textures->perturbation_texture.get());
        for (const TextureBinding& tb : m.textures->bindings) {
            const std::optional<ParamField> f = textured_field(m.model, tb.slot);
            if (nested || tb.scalar || !f || !is_reflectance(*f)) out.push_back(tb.texture.get());
        }
    }
    if (const auto* b = std::get_if<BlendMaterial>(&m.model)) collect_undifferentiated(*b->first, true, out), collect_undifferentiated(*b->second, true, out);
    if (const auto* k = std::get_if<MaskMaterial>(&m.model)) collect_undifferentiated(*k->inner, true, out);
}

// Which of a material binding's texel slots field f fills (a diffuse or a specular one).
bool is_diffuse_field(ParamField f) {
    return f == ParamField::PhongDiffuse || f == ParamField::PlasticDiffuse || f == ParamField::RoughPlasticDiffuse;
}

}  // namespace

std::string SceneParameter::range() const {
    switch (field) {
        case ParamField::PhongExponent: return "[0, 10000]";
        case ParamField::RoughConductorAlpha:
        case ParamField::RoughDielectricAlpha:
        case ParamField::RoughPlasticAlpha:
        case ParamField::AlphaU:
        case ParamField::AlphaV: return "[0.001, 10]";
        case ParamField::RoughDielectricEta: return "[0.2, 5]";
        case ParamField::MeshRadiance:
        case ParamField::SphereRadiance:
        case ParamField::PointIntensity:
        case ParamField::ConstantRadiance: return ">= 1e-6";
        case ParamField::MediumSigmaT: return ">= 1e-6";
        case ParamField::MediumPhaseG: return "[-0.99, 0.99]";
        default: return "[0, 1]";
    }
}

std::vector<SceneParameter> scene_parameters(const SceneDescription& d) {
    std::vector<SceneParameter> out;
    std::vector<const Texture*> listed;  // textures shared by several materials are listed once
    for (const Material& m : d.materials) collect_undifferentiated(m, false, listed);  // and these never
    for (size_t i = 0; i < d.materials.size(); ++i) {
        const std::string& id = id_at(d.material_ids, i);
        const Material& m = d.materials[i];
        if (id.empty() || m.is_black()) continue;
        const uint32_t k = uint32_t(i);
        const auto add = [&](const std::string& what, ParamField f, int size) {
            // A textured parameter: a bitmap's texels (reflectances only), or nothing.
            const std::vector<TextureBinding>* bindings = m.textures ? &m.textures->bindings : nullptr;
            for (size_t b = 0; bindings && b < bindings->size(); ++b) {
                const TextureBinding& tb = (*bindings)[b];
                if (textured_field(m.model, tb.slot) != f) continue;
                const BitmapTexture* bitmap = bitmap_of(tb);
                if (!bitmap || !is_reflectance(f) || std::find(listed.begin(), listed.end(), tb.texture.get()) != listed.end()) return;
                listed.push_back(tb.texture.get());
                SceneParameter p{id + "." + what.substr(0, what.rfind(".value")) + ".data", ParamField::Texels, k,
                                 bitmap->width() * bitmap->height() * 3};
                p.texels_of = f, p.binding = int(b), p.width = bitmap->width(), p.height = bitmap->height();
                out.push_back(p);
                return;
            }
            out.push_back({id + "." + what, f, k, size});
        };
        // alpha, or alpha_u and alpha_v (Mitsuba's names; a scene file's alpha_u = alpha_v is one alpha).
        const auto add_roughness = [&](const MicrofacetDistribution& dist, ParamField isotropic) {
            if (!dist.is_anisotropic()) return add("alpha", isotropic, 1);
            add("alpha_u", ParamField::AlphaU, 1);
            add("alpha_v", ParamField::AlphaV, 1);
        };
        if (const auto* p = std::get_if<PhongMaterial>(&m.model)) {
            if (is_black(p->specular)) {
                add("reflectance.value", ParamField::PhongDiffuse, 3);
            } else {
                add("diffuse_reflectance.value", ParamField::PhongDiffuse, 3);
                add("specular_reflectance.value", ParamField::PhongSpecular, 3);
                add("exponent", ParamField::PhongExponent, 1);
            }
        } else if (std::holds_alternative<ConductorMaterial>(m.model)) {
            add("specular_reflectance.value", ParamField::ConductorSpecular, 3);
        } else if (const auto* r = std::get_if<RoughConductorMaterial>(&m.model)) {
            add_roughness(r->distribution, ParamField::RoughConductorAlpha);
            add("specular_reflectance.value", ParamField::RoughConductorSpecular, 3);
        } else if (std::holds_alternative<PlasticMaterial>(m.model)) {
            add("diffuse_reflectance.value", ParamField::PlasticDiffuse, 3);
            add("specular_reflectance.value", ParamField::PlasticSpecular, 3);
        } else if (std::holds_alternative<RoughPlasticMaterial>(m.model)) {
            add("diffuse_reflectance.value", ParamField::RoughPlasticDiffuse, 3);
            add("specular_reflectance.value", ParamField::RoughPlasticSpecular, 3);
            add("alpha", ParamField::RoughPlasticAlpha, 1);  // (always isotropic)
        } else if (const auto* r = std::get_if<RoughDielectricMaterial>(&m.model)) {
            add_roughness(r->distribution, ParamField::RoughDielectricAlpha);
            if (!r->dispersion) add("eta", ParamField::RoughDielectricEta, 1);
        }
    }
    for (size_t i = 0; i < d.meshes.size(); ++i)  // (a textured emitter's radiance is its texture: not a value)
        if (!d.meshes[i].id.empty() && !is_black(d.meshes[i].emission) &&
            !(i < d.mesh_emission_textures.size() && d.mesh_emission_textures[i]))
            out.push_back({d.meshes[i].id + ".emitter.radiance.value", ParamField::MeshRadiance, uint32_t(i), 3});
    for (size_t i = 0; i < d.spheres.size(); ++i)
        if (!d.spheres[i].id.empty() && !is_black(d.spheres[i].emission))
            out.push_back({d.spheres[i].id + ".emitter.radiance.value", ParamField::SphereRadiance, uint32_t(i), 3});
    for (size_t i = 0; i < d.lights.size(); ++i) {
        const std::string& id = id_at(d.light_ids, i);
        if (id.empty()) continue;
        if (std::holds_alternative<PointLight>(d.lights[i]))
            out.push_back({id + ".intensity.value", ParamField::PointIntensity, uint32_t(i), 3});
        if (std::holds_alternative<EnvironmentLight>(d.lights[i]))
            out.push_back({id + ".radiance.value", ParamField::ConstantRadiance, uint32_t(i), 3});
    }
    for (size_t i = 0; i < d.media.size(); ++i) {  // (a grid's voxels are not parameters)
        const std::string& id = id_at(d.medium_ids, i);
        if (id.empty()) continue;
        if (std::holds_alternative<HomogeneousMedium>(d.media[i])) {
            out.push_back({id + ".sigma_t.value", ParamField::MediumSigmaT, uint32_t(i), 3});
            out.push_back({id + ".albedo.value", ParamField::MediumAlbedo, uint32_t(i), 3});
        }
        if (std::holds_alternative<HgPhase>(medium_phase(d.media[i]))) out.push_back({id + ".phase_function.g", ParamField::MediumPhaseG, uint32_t(i), 1});
    }
    return out;
}

const SceneParameter& find_parameter(const std::vector<SceneParameter>& all, const std::string& name) {
    for (const SceneParameter& p : all)
        if (p.name == name) return p;
    std::vector<std::string> names;
    for (const SceneParameter& p : all) names.push_back(p.name);
    throw std::invalid_argument(fmt::format("unknown parameter '{}'; the scene's parameters: {}", name,
                                            names.empty() ? "(none: give materials and emitters ids)" : fmt::format("{}", fmt::join(names, ", "))));
}

std::vector<float> parameter_value(const SceneDescription& d, const SceneParameter& p) {
    if (!p.is_material()) {
        switch (p.field) {
            case ParamField::MeshRadiance: return rgb(d.meshes.at(p.index).emission);
            case ParamField::SphereRadiance: return rgb(d.spheres.at(p.index).emission);
            case ParamField::PointIntensity: return rgb(std::get<PointLight>(d.lights.at(p.index)).intensity);
            case ParamField::MediumSigmaT: return rgb(std::get<HomogeneousMedium>(d.media.at(p.index)).sigma_t);
            case ParamField::MediumAlbedo: return rgb(medium_albedo(std::get<HomogeneousMedium>(d.media.at(p.index))));
            case ParamField::MediumPhaseG: return {std::get<HgPhase>(medium_phase(d.media.at(p.index))).g};
            default: return rgb(std::get<EnvironmentLight>(d.lights.at(p.index)).radiance);
        }
    }
    if (p.is_texels()) {
        const std::vector<Rgb>& texels = bitmap_of(binding_of(d, p))->texels();
        std::vector<float> v;
        v.reserve(texels.size() * 3);
        for (const Rgb& t : texels) v.insert(v.end(), {t.x, t.y, t.z});
        return v;
    }
    const MaterialModel& m = d.materials.at(p.index).model;
    switch (p.field) {
        case ParamField::PhongDiffuse: return rgb(std::get<PhongMaterial>(m).diffuse);
        case ParamField::PhongSpecular: return rgb(std::get<PhongMaterial>(m).specular);
        case ParamField::PhongExponent: return {std::get<PhongMaterial>(m).exponent};
        case ParamField::ConductorSpecular: return rgb(std::get<ConductorMaterial>(m).specular_reflectance);
        case ParamField::RoughConductorSpecular: return rgb(std::get<RoughConductorMaterial>(m).specular_reflectance);
        case ParamField::RoughConductorAlpha: return {std::get<RoughConductorMaterial>(m).distribution.alpha_u};
        case ParamField::RoughDielectricAlpha: return {std::get<RoughDielectricMaterial>(m).distribution.alpha_u};
        case ParamField::RoughPlasticAlpha: return {std::get<RoughPlasticMaterial>(m).distribution.alpha_u};
        case ParamField::AlphaU: return {distribution_of(m).alpha_u};
        case ParamField::AlphaV: return {distribution_of(m).alpha_v};
        case ParamField::RoughDielectricEta: {
            const RoughDielectricMaterial& r = std::get<RoughDielectricMaterial>(m);
            return {r.int_ior / r.ext_ior};
        }
        case ParamField::RoughPlasticSpecular: return rgb(std::get<RoughPlasticMaterial>(m).coat.specular_reflectance);
        case ParamField::PlasticDiffuse: return rgb(std::get<PlasticMaterial>(m).coat.diffuse_reflectance);
        case ParamField::PlasticSpecular: return rgb(std::get<PlasticMaterial>(m).coat.specular_reflectance);
        default: return rgb(std::get<RoughPlasticMaterial>(m).coat.diffuse_reflectance);
    }
}

namespace {

// A coat with new reflectances (what the constructor precomputes from them included).
CoatedDiffuse recoat(const CoatedDiffuse& c, const Rgb& diffuse, const Rgb& specular) {
    // eta = int_ior / ext_ior: the constructor only uses the ratio.
    return CoatedDiffuse(diffuse, specular, c.eta, 1.0f, c.nonlinear);
}

}  // namespace

namespace {

// A new texture with the texels v (the old one's size, filter, wrap mode and uv transform),
// given to every binding of every material that had the old one. The model's constant, which
// a textured parameter holds as the texture's largest value (its lobe flags follow it; see
// scenefile/read_bsdf.cpp), follows too.
void set_texels(SceneDescription& d, const SceneParameter& p, const std::vector<float>& v) {
    const std::shared_ptr<const Texture> old = binding_of(d, p).texture;
    const BitmapTexture& b = std::get<BitmapTexture>(old->model());
    std::vector<Rgb> texels(v.size() / 3);
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = Rgb(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    const auto fresh = std::make_shared<const Texture>(
        BitmapTexture(b.width(), b.height(), std::move(texels), b.filter(), b.wrap_mode(), b.to_uv(), b.colour(), b.name()));
    for (Material& m : d.materials) {
        if (!m.textures) continue;
        MaterialTextures t = *m.textures;
        bool changed = false;
        for (TextureBinding& tb : t.bindings)
            if (tb.texture == old) {
                tb.texture = fresh;
                const Rgb hi = tb.scalar ? Rgb(scalar_value(fresh->max_value())) : fresh->max_value();  // as the reader sets it
                std::visit(
                    [&](auto& x) {
                        if constexpr (requires { x.set_texel(tb.slot, hi); }) x.set_texel(tb.slot, hi);
                    },
                    m.model);
                changed = true;
            }
        if (!changed) continue;
        std::visit(
            [](auto& x) {
                if constexpr (requires { x.texels_changed(); }) x.texels_changed();
            },
            m.model);
        m.set_textures(std::move(t));
    }
}

}  // namespace

void set_parameter_value(SceneDescription& d, const SceneParameter& p, const std::vector<float>& v) {
    if (int(v.size()) != p.size) throw std::invalid_argument(fmt::format("{} takes {} values, got {}", p.name, p.size, v.size()));
    switch (p.field) {
        case ParamField::MeshRadiance: d.meshes.at(p.index).emission = rgb(v); return;
        case ParamField::SphereRadiance: d.spheres.at(p.index).emission = rgb(v); return;
        case ParamField::PointIntensity: std::get<PointLight>(d.lights.at(p.index)).intensity = rgb(v); return;
        case ParamField::ConstantRadiance: std::get<EnvironmentLight>(d.lights.at(p.index)).radiance = rgb(v); return;
        case ParamField::Texels: set_texels(d, p, v); return;
        case ParamField::MediumPhaseG:
            std::visit([&](auto& m) { std::get<HgPhase>(m.phase).g = v[0]; }, d.media.at(p.index));
            return;
        case ParamField::MediumSigmaT:
        case ParamField::MediumAlbedo: {
            HomogeneousMedium& m = std::get<HomogeneousMedium>(d.media.at(p.index));
            const Rgb albedo = p.field == ParamField::MediumAlbedo ? rgb(v) : medium_albedo(m);
            if (p.field == ParamField::MediumSigmaT) m.sigma_t = rgb(v);
            m.sigma_s = albedo * m.sigma_t;
            return;
        }
        default: break;
    }
    MaterialModel& m = d.materials.at(p.index).model;
    switch (p.field) {
        case ParamField::PhongDiffuse: std::get<PhongMaterial>(m).diffuse = rgb(v); return;
        case ParamField::PhongSpecular: std::get<PhongMaterial>(m).specular = rgb(v); return;
        case ParamField::PhongExponent: std::get<PhongMaterial>(m).exponent = v[0]; return;
        case ParamField::ConductorSpecular: std::get<ConductorMaterial>(m).specular_reflectance = rgb(v); return;
        case ParamField::RoughConductorSpecular: std::get<RoughConductorMaterial>(m).specular_reflectance = rgb(v); return;
        case ParamField::RoughConductorAlpha:
        case ParamField::RoughDielectricAlpha: {
            MicrofacetDistribution& dist = p.field == ParamField::RoughConductorAlpha ? std::get<RoughConductorMaterial>(m).distribution
                                                                                    : std::get<RoughDielectricMaterial>(m).distribution;
            dist = MicrofacetDistribution(dist.type, v[0], v[0]);
            return;
        }
        case ParamField::RoughPlasticAlpha: {
            // The coating's tables and Fdr depend on the roughness: built again.
            RoughPlasticMaterial& r = std::get<RoughPlasticMaterial>(m);
            r = RoughPlasticMaterial(MicrofacetDistribution(r.distribution.type, v[0], v[0]), r.coat);
            return;
        }
        case ParamField::AlphaU:
        case ParamField::AlphaV: {
            MicrofacetDistribution& dist = distribution_of(m);
            dist = p.field == ParamField::AlphaU ? MicrofacetDistribution(dist.type, v[0], dist.alpha_v)
                                                 : MicrofacetDistribution(dist.type, dist.alpha_u, v[0]);
            return;
        }
        case ParamField::RoughDielectricEta: {
            RoughDielectricMaterial& r = std::get<RoughDielectricMaterial>(m);
            r.int_ior = v[0] * r.ext_ior;
            return;
        }
        case ParamField::PlasticDiffuse: {
            CoatedDiffuse& c = std::get<PlasticMaterial>(m).coat;
            c = recoat(c, rgb(v), c.specular_reflectance);
            return;
        }
        case ParamField::PlasticSpecular: {
            CoatedDiffuse& c = std::get<PlasticMaterial>(m).coat;
            c = recoat(c, c.diffuse_reflectance, rgb(v));
            return;
        }
        default: {
            // The reflectances only: the rough coating's tables and Fdr (of eta and the roughness) stay.
            CoatedDiffuse& c = std::get<RoughPlasticMaterial>(m).coat;
            (p.field == ParamField::RoughPlasticSpecular ? c.specular_reflectance : c.diffuse_reflectance) = rgb(v);
            c.update();
            return;
        }
    }
}

void clamp_parameter_value(const SceneParameter& p, std::vector<float>& v) {
    float lo = 0, hi = 1;
    switch (p.field) {
        case ParamField::PhongExponent: hi = 1e4f; break;
        case ParamField::RoughConductorAlpha:
        case ParamField::RoughDielectricAlpha:
        case ParamField::RoughPlasticAlpha:
        case ParamField::AlphaU:
        case ParamField::AlphaV: lo = 1e-3f, hi = 10; break;
        case ParamField::RoughDielectricEta: lo = 0.2f, hi = 5; break;
        case ParamField::MeshRadiance:
        case ParamField::SphereRadiance:
        case ParamField::PointIntensity:
        case ParamField::ConstantRadiance: lo = 1e-6f, hi = 1e30f; break;
        case ParamField::MediumSigmaT: lo = 1e-6f, hi = 1e30f; break;  // (> 0: a channel of sigma_t 0 would lose its albedo)
        case ParamField::MediumPhaseG: lo = -0.99f, hi = 0.99f; break;
        default: break;
    }
    for (float& x : v) x = std::isnan(x) ? lo : std::clamp(x, lo, hi);
}

ParameterSet ParameterSet::choose(const SceneDescription& d, const std::vector<std::string>& names) {
    const std::vector<SceneParameter> all = scene_parameters(d);
    ParameterSet s;
    s.materials.assign(d.materials.size(), MaterialBinding{});
    s.media.assign(d.media.size(), MediumBinding{});
    std::vector<int> free_light(d.lights.size(), -1), mesh(d.meshes.size(), -1), sphere(d.spheres.size(), -1);
    for (const std::string& name : names) {
        const SceneParameter& p = find_parameter(all, name);
        for (const SceneParameter& q : s.params)
            if (q.name == name) throw std::invalid_argument(fmt::format("parameter '{}' is given twice", name));
        s.params.push_back(p);
        s.offsets.push_back(s.size);
        const int off = s.size;
        s.size += p.size;
        MaterialBinding* mb = p.is_material() ? &s.materials[p.index] : nullptr;
        if (p.is_texels()) {
            // Every material that reads this texture for a reflectance.
            const Texture* tex = binding_of(d, p).texture.get();
            for (size_t i = 0; i < d.materials.size(); ++i) {
                const Material& m = d.materials[i];
                for (size_t b = 0; m.textures && b < m.textures->bindings.size(); ++b) {
                    const TextureBinding& tb = m.textures->bindings[b];
                    const std::optional<ParamField> f = textured_field(m.model, tb.slot);
                    if (tb.texture.get() != tex || !f || !is_reflectance(*f)) continue;
                    (is_diffuse_field(*f) ? s.materials[i].diffuse_texels : s.materials[i].specular_texels) = {off, int(b)};
                }
            }
            continue;
        }
        switch (p.field) {
            case ParamField::PhongDiffuse:
            case ParamField::PlasticDiffuse:
            case ParamField::RoughPlasticDiffuse: mb->diffuse = off; break;
            case ParamField::PhongSpecular:
            case ParamField::ConductorSpecular:
            case ParamField::RoughConductorSpecular:
            case ParamField::PlasticSpecular:
            case ParamField::RoughPlasticSpecular: mb->specular = off; break;
            case ParamField::PhongExponent: mb->exponent = off; break;
            case ParamField::RoughConductorAlpha:
            case ParamField::RoughDielectricAlpha:
            case ParamField::RoughPlasticAlpha: mb->alpha = off; break;
            case ParamField::AlphaU: mb->alpha_u = off; break;
            case ParamField::AlphaV: mb->alpha_v = off; break;
            case ParamField::RoughDielectricEta: mb->eta = off; break;
            case ParamField::MeshRadiance: mesh[p.index] = off; break;
            case ParamField::SphereRadiance: sphere[p.index] = off; break;
            case ParamField::MediumSigmaT:
            case ParamField::MediumAlbedo:
            case ParamField::MediumPhaseG: {
                MediumBinding& m = s.media[p.index];
                if (m.slot < 0) {
                    if (s.media_slots == kMaxDiffMedia)
                        throw std::invalid_argument(fmt::format("parameters of at most {} media can be chosen at once", kMaxDiffMedia));
                    m.slot = s.media_slots++;
                }
                (p.field == ParamField::MediumSigmaT ? m.sigma_t : p.field == ParamField::MediumAlbedo ? m.albedo : m.g) = off;
                break;
            }
            default: free_light[p.index] = off; break;
        }
    }
    // Scene::build's order of lights.
    s.lights = free_light;
    for (size_t i = 0; i < d.meshes.size(); ++i)
        if (!is_black(d.meshes[i].emission)) s.lights.insert(s.lights.end(), d.meshes[i].triangles.size(), mesh[i]);
    for (size_t i = 0; i < d.spheres.size(); ++i)
        if (!is_black(d.spheres[i].emission)) s.lights.push_back(sphere[i]);
    return s;
}

std::vector<float> ParameterSet::values(const SceneDescription& d) const {
    std::vector<float> theta;
    for (const SceneParameter& p : params) {
        const std::vector<float> v = parameter_value(d, p);
        theta.insert(theta.end(), v.begin(), v.end());
    }
    return theta;
}

void ParameterSet::set_values(SceneDescription& d, const std::vector<float>& theta) const {
    for (size_t i = 0; i < params.size(); ++i)
        set_parameter_value(d, params[i], std::vector<float>(theta.begin() + offsets[i], theta.begin() + offsets[i] + params[i].size));
}

void ParameterSet::clamp(std::vector<float>& theta) const {
    for (size_t i = 0; i < params.size(); ++i) {
        std::vector<float> v(theta.begin() + offsets[i], theta.begin() + offsets[i] + params[i].size);
        clamp_parameter_value(params[i], v);
        std::copy(v.begin(), v.end(), theta.begin() + offsets[i]);
    }
}

}  // namespace pathlab
