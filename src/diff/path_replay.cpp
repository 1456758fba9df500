#include "diff/path_replay.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <deque>
#include <memory>
#include <mutex>
#include <tuple>
#include <optional>

#include "diff/bsdf_derivatives.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/media_lighting.hpp"
#include "integrators/common/path_rules.hpp"

namespace pathlab {

namespace {

enum class Mode { Primal, Reverse, Forward };

// What the reverse and forward passes carry besides the path itself.
struct Carry {
    // Reverse: the adjoint radiance, the radiance still to come, the gradient.
    Rgb delta{0.0f};
    Rgb Lr{0.0f};
    double* grad = nullptr;
    // Forward: the tangent in theta and the derivative of L along it.
    const float* tangent = nullptr;
    Rgb dL{0.0f};
};

IntegratorOptions path_options(const DiffSettings& s) {
    IntegratorOptions o;
    o.max_depth = s.max_depth;
    o.rr_depth = s.rr_depth;
    return o;
}

// RoughCoatingDerivative of a roughplastic, kept for the last few (distribution, alpha, eta):
// building it costs two table builds (0.1-0.5 s), and the gradients of one scene, pass after
// pass, ask for the same.
std::shared_ptr<const RoughCoatingDerivative> coating_derivative(const RoughPlasticMaterial& r) {
    using Key = std::tuple<int, float, float>;
    static std::mutex mutex;
    static std::deque<std::pair<Key, std::shared_ptr<const RoughCoatingDerivative>>> recent;
    const Key key{int(r.distribution.type), r.distribution.alpha_u, r.coat.eta};
    {
        const std::lock_guard lock(mutex);
        for (const auto& [k, d] : recent)
            if (k == key) return d;
    }
    auto d = std::make_shared<const RoughCoatingDerivative>(r);
    const std::lock_guard lock(mutex);
    recent.emplace_front(key, d);
    if (recent.size() > 16) recent.pop_back();
    return d;
}

class PathReplay {
public:
    PathReplay(const Scene& scene, const ParameterSet& set, const DiffSettings& s)
        : scene_(scene), set_(set), rules_(path_options(s)), hide_(s.hide_emitters), faults_(s.faults) {
        // A roughplastic's alpha also moves its coating's tables: their derivative, once per material.
        coatings_.resize(set.materials.size());
        for (size_t i = 0; i < set.materials.size(); ++i)
            if (const auto* r = std::get_if<RoughPlasticMaterial>(&scene.material(uint32_t(i)).model); r && set.materials[i].alpha >= 0)
                coatings_[i] = coating_derivative(*r);
        media_slots_.resize(size_t(set.media_slots));
        for (const MediumBinding& b : set.media)
            if (b.slot >= 0) media_slots_[size_t(b.slot)] = b;
    }

    template <Mode M>
    Rgb trace(const Ray& camera_ray, Sampler& sampler, Carry& c) const {
        if (scene_.has_media()) return trace_media<M>(camera_ray, sampler, c);
        Intersection hit;
        if (!scene_.intersect(camera_ray, hit)) {
            if (hide_) return Rgb(0.0f);
            const Rgb Le = scene_.escaped_radiance(camera_ray.d);
            emitter_term<M>(scene_.environment_light(), Rgb(1.0f), 1.0f, c);
            return Le;
        }
        Rgb L = hide_ ? Rgb(0.0f) : emitted_radiance(scene_, hit, -camera_ray.d);
        if (!is_black(L)) {
            emitter_term<M>(hit.light, Rgb(1.0f), 1.0f, c);
            if constexpr (M == Mode::Reverse) c.Lr -= L;
        }
        Rgb beta(1.0f), dbeta(0.0f);
        Vec3f dir = camera_ray.d;
        for (int bounces = 0; rules_.may_bounce(bounces); ++bounces) {
            const ShadingPoint sp = make_shading_point(scene_, hit, dir);
            if (sp.material->is_black()) break;
            const std::optional<VertexBsdf> vb = vertex_bsdf(sp);
            const VertexBsdf* v = vb ? &*vb : nullptr;

            // Next-event estimation, as estimate_light_sample(mis = true).
            // (With adaptive splitting, at the first vertex, one light sample for each light choose_split returns.)
            LightChoice chosen[kMaxSplitLights];
            const bool split = bounces == 0;
            const int n_chosen = scene_.light_sampler().choose_split(sp.p, sp.frame.n, sampler.next1d(), chosen, split);
            const Vec2f u = sampler.next2d();
            for (int i = 0; i < n_chosen; ++i) {
                const LightChoice choice = chosen[i];
                const Light& light = scene_.lights()[size_t(choice.index)];
                const auto ls = sample_light(light, sp.p, u);
                if (ls && !is_black(ls->Le) && !(dot(ls->wi, sp.ng) <= 0 && !sp.material->transmits())) {
                    const Vec3f wo = sp.frame.to_local(ls->wi);
                    float pdf_bsdf;
                    const Rgb f = sp.material->eval_and_pdf(sp, sp.wi, wo, pdf_bsdf);
                    if (!is_black(f)) {
                        const Ray shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi)
                                                                    : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
                        if (!scene_.occluded(shadow)) {
                            const float pdf_light = choice.pmf * ls->pdfW;
                            const float weight = !ls->delta ? balance_heuristic(pdf_light, pdf_bsdf) : 1.0f;
                            const float k = std::abs(wo.z) * weight / pdf_light;
                            const Rgb direct = f * ls->Le * k;
                            L += beta * direct;
                            vertex_term<M>(v, sp.wi, wo, false, f, ls->Le, k, choice.index, emission_scale(light, ls->distance), beta, dbeta, c);
                        }
                    }
                }
            }
            // The BSDF sample: its MIS-weighted emission, then the continuation.
            const auto s = sp.material->sample(sp, sp.wi, sampler.next2d());
            EmitterHit found;
            if (s) {
                found = trace_to_emitter(scene_, sp.spawn(s->wo), sp.p, sp.frame.n, split);
                if (!is_black(found.Le)) {
                    const float weight = s->delta ? 1.0f : balance_heuristic(s->pdfW, found.pdf_light);
                    const float k = std::abs(s->wo.z) * weight / s->pdfW;
                    L += beta * (s->f * found.Le * k);
                    const int light = found.hit ? found.isect.light : scene_.environment_light();
                    vertex_term<M>(v, sp.wi, s->wo, s->delta, s->f, found.Le, k, light, 1.0f, beta, dbeta, c);
                }
            }
            if (!rules_.may_bounce(bounces + 1) || !s || !found.hit) break;
            const float k = std::abs(s->wo.z) / s->pdfW;
            if constexpr (M == Mode::Forward) dbeta = dbeta * (s->f * k) + beta * (bsdf_tangent(v, sp.wi, *s, c) * k);
            beta *= s->f * k;
            if (rules_.roulette_applies(bounces + 1)) {
                const float q = std::clamp(max_component(beta), 0.05f, 1.0f);
                if (sampler.next1d() >= q) break;
                beta /= q;
                if constexpr (M == Mode::Forward) dbeta /= q;
            }
            // Reverse: the continuation's weight f scales everything still to come, Lr.
            if constexpr (M == Mode::Reverse) {
                if (v && !faults_.drop_continuation) {
                    Rgb W(0.0f);
                    for (int ch = 0; ch < 3; ++ch) {
                        const float f = (&s->f.x)[ch];
                        if (f > 0) (&W.x)[ch] = (&c.delta.x)[ch] * (&c.Lr.x)[ch] / f;
                    }
                    add_bsdf_adjoint(*v, sp.wi, s->wo, s->delta, W, c);
                }
            }
            hit = found.isect;
            dir = sp.frame.to_world(s->wo);
        }
        return L;
    }

private:
    // The differentiable side of a vertex's BSDF: the model at the hit (a textured material's
    // at its uv, so that a derivative that depends on another parameter sees its value there),
    // the binding, and for a reflectance given by texels the texels the lookup read with their
    // weights: df/d(texel j, channel c) = weight_j df/drho_c. The texel slots are bound to the
    // scratch offsets set.size + c (diffuse) and set.size + 3 + c (specular) for bsdf_jacobian,
    // and jacobian() scatters those to the texels.
    struct VertexBsdf {
        const Material* material = nullptr;
        std::optional<Material> at_uv;  // a textured material's model at the hit
        MaterialBinding binding;
        std::array<TexelFootprint, 2> footprint{};  // diffuse, specular
        std::array<int, 2> texel_offset{-1, -1};
        std::shared_ptr<const RoughCoatingDerivative> coating;
        const Material& m() const { return at_uv ? *at_uv : *material; }
    };

    // (None where the material has no bound parameter.)
    std::optional<VertexBsdf> vertex_bsdf(const ShadingPoint& sp) const {
        const size_t index = size_t(sp.material - &scene_.material(0));
        if (index >= set_.materials.size() || !set_.materials[index].any()) return std::nullopt;
        const MaterialBinding& mb = set_.materials[index];
        VertexBsdf v;
        v.material = sp.material;
        if (sp.material->varies) v.at_uv.emplace(Material{sp.material->model_at(sp.uv)});
        v.binding = effective(*sp.material, mb);
        v.coating = coatings_[index];
        for (int which = 0; which < 2; ++which) {
            const TexelBinding& tb = which == 0 ? mb.diffuse_texels : mb.specular_texels;
            if (!tb.bound()) continue;
            TexelFootprint fp = sp.material->textures->bindings[size_t(tb.binding)].texture->footprint(sp.uv);
            if (faults_.texel_weights_wrong_corner) std::reverse(fp.weight.begin(), fp.weight.begin() + fp.count);
            v.footprint[size_t(which)] = fp;
            v.texel_offset[size_t(which)] = tb.offset;
            (which == 0 ? v.binding.diffuse : v.binding.specular) = set_.size + 3 * which;
        }
        return v;
    }

    // bsdf_jacobian of the vertex's BSDF, with the texel slots scattered to their texels.
    template <typename Add>
    void jacobian(const VertexBsdf& v, const Vec3f& wi, const Vec3f& wo, bool delta, Add&& add) const {
        bsdf_jacobian(v.m(), v.binding, v.coating.get(), wi, wo, delta, [&](int off, const Rgb& df) {
            if (off < set_.size) return add(off, df);
            const int k = off - set_.size, which = k / 3, ch = k % 3;
            const TexelFootprint& fp = v.footprint[size_t(which)];
            for (int j = 0; j < fp.count; ++j) add(v.texel_offset[size_t(which)] + 3 * int(fp.index[size_t(j)]) + ch, df * fp.weight[size_t(j)]);
        });
    }

    // dLe/dtheta per unit of a light's parameter, seen from `distance`: a point light's intensity
    // reaches as intensity / d^2, the other emitters' radiance as itself.
    static float emission_scale(const Light& light, float distance) {
        return std::holds_alternative<PointLight>(light) ? 1 / (distance * distance) : 1.0f;
    }

    // A term beta f Le k added at a vertex (f the BSDF towards the emitter, Le its radiance,
    // `scale` = dLe/dtheta of the emitter's parameter).
    template <Mode M>
    void vertex_term(const VertexBsdf* v, const Vec3f& wi, const Vec3f& wo, bool delta, const Rgb& f, const Rgb& Le, float k, int light,
                     float scale, const Rgb& beta, const Rgb& dbeta, Carry& c) const {
        if constexpr (M == Mode::Reverse) {
            if (v) add_bsdf_adjoint(*v, wi, wo, delta, c.delta * beta * Le * k, c);
            emitter_term<M>(light, beta * f * k, scale, c);
            c.Lr -= beta * (f * Le * k);
        } else if constexpr (M == Mode::Forward) {
            Rgb dLe(0.0f);
            const int off = light >= 0 && size_t(light) < set_.lights.size() ? set_.lights[size_t(light)] : -1;
            if (off >= 0) dLe = Rgb(c.tangent[off], c.tangent[off + 1], c.tangent[off + 2]) * scale;
            Rgb df(0.0f);
            if (v) df = jacobian_dot(*v, wi, wo, delta, c.tangent);
            c.dL += dbeta * (f * Le * k) + beta * ((df * Le + f * dLe) * k);
        }
    }

    // Emission reached with weight W (everything multiplying Le, the adjoint apart): its
    // parameter's share.
    template <Mode M>
    void emitter_term(int light, const Rgb& W, float scale, Carry& c) const {
        const int off = light >= 0 && size_t(light) < set_.lights.size() ? set_.lights[size_t(light)] : -1;
        if (off < 0) return;
        if constexpr (M == Mode::Reverse) {
            const Rgb g = c.delta * W * scale;
            c.grad[off] += g.x, c.grad[off + 1] += g.y, c.grad[off + 2] += g.z;
        } else if constexpr (M == Mode::Forward) {
            c.dL += W * Rgb(c.tangent[off], c.tangent[off + 1], c.tangent[off + 2]) * scale;
        }
    }

    void add_bsdf_adjoint(const VertexBsdf& v, const Vec3f& wi, const Vec3f& wo, bool delta, const Rgb& W, Carry& c) const {
        jacobian(v, wi, wo, delta, [&](int off, const Rgb& df) { c.grad[off] += double(dot(W, df)); });
    }
    Rgb jacobian_dot(const VertexBsdf& v, const Vec3f& wi, const Vec3f& wo, bool delta, const float* t) const {
        Rgb d(0.0f);
        jacobian(v, wi, wo, delta, [&](int off, const Rgb& df) { d += df * t[off]; });
        return d;
    }
    Rgb bsdf_tangent(const VertexBsdf* v, const Vec3f& wi, const BsdfSample& s, const Carry& c) const {
        return v ? jacobian_dot(*v, wi, s.wo, s.delta, c.tangent) : Rgb(0.0f);
    }
    // The binding with the fault switch applied (Phong's glossy lobe dropped).
    MaterialBinding effective(const Material& m, MaterialBinding mb) const {
        if (faults_.drop_glossy_lobe && std::holds_alternative<PhongMaterial>(m.model)) mb.specular = mb.exponent = -1;
        return mb;
    }

    // d log(throughput)/d theta for the chosen homogeneous media, per slot and channel: their
    // sigma_t and albedo enter a path only as factors of its throughput, channel by channel
    // (exp(-sigma_t l) along a piece of length l, sigma_s = albedo sigma_t where it scatters), and
    // sampling is detached (the free-flight densities, the hero channel's, stay as they were).
    // (A medium's phase function enters as a factor p(wi, wo) where the path scatters in it:
    // d log p/d g of Henyey-Greenstein's.)
    struct MediaLog {
        std::array<Rgb, kMaxDiffMedia> dt{}, da{};  // d log / d sigma_t, d log / d albedo
        std::array<float, kMaxDiffMedia> dg{};      // d log / d g
        MediaLog operator+(const MediaLog& o) const {
            MediaLog r;
            for (size_t i = 0; i < kMaxDiffMedia; ++i) r.dt[i] = dt[i] + o.dt[i], r.da[i] = da[i] + o.da[i], r.dg[i] = dg[i] + o.dg[i];
            return r;
        }
    };
    int slot_of(int32_t medium) const {
        return medium >= 0 && size_t(medium) < set_.media.size() ? set_.media[size_t(medium)].slot : -1;
    }
    // A piece of length l through a medium: exp(-sigma_t l), d log/d sigma_t = -l.
    void pass(MediaLog& log, int32_t medium, float length) const {
        const int slot = slot_of(medium);
        if (slot >= 0 && std::isfinite(length)) log.dt[size_t(slot)] -= Rgb(length);
    }
    // Scattering in a medium: sigma_s = albedo sigma_t, d log/d sigma_t = 1 / sigma_t, d log/d albedo = 1 / albedo
    // (a channel of sigma_t or albedo 0 carries no throughput: nothing to add).
    void scatter(MediaLog& log, int32_t medium) const {
        const int slot = slot_of(medium);
        const auto* h = slot >= 0 ? std::get_if<HomogeneousMedium>(&scene_.medium(medium)) : nullptr;
        if (!h) return;
        for (int k = 0; k < 3; ++k) {
            if (!(h->sigma_t[k] > 0) || !(h->sigma_s[k] > 0)) continue;
            log.dt[size_t(slot)][k] += 1 / h->sigma_t[k];
            log.da[size_t(slot)][k] += h->sigma_t[k] / h->sigma_s[k];
        }
    }
    // The phase function's value p(wi, wo) where the path scatters in a medium (wi back along the
    // path, wo onwards): Henyey-Greenstein's p = (1 - g^2) / (4 pi D^(3/2)), D = 1 + g^2 - 2 g mu,
    // mu = -wi.wo, so d log p/d g = -2 g / (1 - g^2) - 3 (g - mu) / D.
    void phase(MediaLog& log, int32_t medium, const Vec3f& wi, const Vec3f& wo) const {
        const int slot = slot_of(medium);
        if (slot < 0 || media_slots_[size_t(slot)].g < 0) return;
        const float g = std::get<HgPhase>(medium_phase(scene_.medium(medium))).g, mu = -dot(wi, wo);
        const float D = 1 + g * g - 2 * g * mu;
        if (D > 0) log.dg[size_t(slot)] += -2 * g / (1 - g * g) - 3 * (g - mu) / D;
    }
    // A term C (radiance added to the sample) whose throughput has d log/d theta `log`.
    template <Mode M>
    void media_term(const Rgb& C, const MediaLog& log, Carry& c) const {
        for (int slot = 0; slot < set_.media_slots; ++slot) {
            const MediumBinding& b = media_slots_[size_t(slot)];
            const Rgb gt = C * log.dt[size_t(slot)], ga = C * log.da[size_t(slot)];
            const float dg = log.dg[size_t(slot)];
            for (int k = 0; k < 3; ++k) {
                if constexpr (M == Mode::Reverse) {
                    if (b.sigma_t >= 0) c.grad[b.sigma_t + k] += double(c.delta[k] * gt[k]);
                    if (b.albedo >= 0) c.grad[b.albedo + k] += double(c.delta[k] * ga[k]);
                    if (b.g >= 0) c.grad[b.g] += double(c.delta[k] * C[k] * dg);
                } else if constexpr (M == Mode::Forward) {
                    if (b.sigma_t >= 0) c.dL[k] += gt[k] * c.tangent[b.sigma_t + k];
                    if (b.albedo >= 0) c.dL[k] += ga[k] * c.tangent[b.albedo + k];
                    if (b.g >= 0) c.dL[k] += C[k] * dg * c.tangent[b.g];
                }
            }
        }
    }
    // A term f Le k added at a vertex with throughput beta (the free-flight weights, the shadow
    // ray's transmittance and 1 / density folded in) and media log `log`.
    template <Mode M>
    void scatter_term(const VertexBsdf* v, const Vec3f& wi, const Vec3f& wo, bool delta, const Rgb& f, const Rgb& Le, float k, int light,
                      float scale, const Rgb& beta, const Rgb& dbeta, const MediaLog& log, Carry& c) const {
        if constexpr (M != Mode::Primal) {
            vertex_term<M>(v, wi, wo, delta, f, Le, k, light, scale, beta, dbeta, c);
            if (set_.media_slots > 0) media_term<M>(beta * (f * Le * k), log, c);
        }
    }

    // volpath's estimator (path/volpath.cpp, without --null-depth skip), whose media, shadow
    // rays and MIS pairs it follows through the same functions (walk_media, estimate_light,
    // sample_scatter): the same image. Besides the surfaces' BSDF and emitter terms, each term
    // gets its media's: C (d log beta/d theta), with beta's log carried along the path.
    template <Mode M>
    Rgb trace_media(const Ray& camera_ray, Sampler& sampler, Carry& c) const {
        RgbWavelengths wl;
        MediumState<RgbTransport> st{sampler, wl, 1.0f};
        MediaLog walk;  // of the walk being taken
        const auto on_piece = [&](const Vec3f&, const Vec3f&, float length, int32_t medium, const Rgb&, const Rgb&, float) {
            pass(walk, medium, length);
        };
        Rgb seg(1.0f);
        MediumWalk w = walk_media(scene_, camera_ray, scene_.camera_medium(), st, seg, nullptr, on_piece);
        if (w.kind == MediumWalk::kMedium) scatter(walk, w.medium);
        MediaLog log = walk;  // of beta
        Rgb beta = seg, dbeta(0.0f);
        Rgb L(0.0f);
        // What the camera sees directly.
        if (w.kind == MediumWalk::kEscaped || (w.kind == MediumWalk::kSurface && !hide_)) {
            if (hide_) return Rgb(0.0f);
            const bool sky = w.kind == MediumWalk::kEscaped;
            const Rgb Le = sky ? escaped_radiance(scene_, w.dir, wl) : emitted_radiance(scene_, w.isect, -w.dir, wl);
            L = beta * Le / st.density();
            if (!is_black(L)) {
                emitter_term<M>(sky ? scene_.environment_light() : w.isect.light, beta / st.density(), 1.0f, c);
                if (set_.media_slots > 0) media_term<M>(L, log, c);
                if constexpr (M == Mode::Reverse) c.Lr -= L;
            }
            if (sky) return L;
        }
        for (int bounces = 0, step = 0; w.kind != MediumWalk::kLost && step < kMaxBounces; ++step) {
            if (!rules_.may_bounce(bounces)) break;
            ScatterVertex v;
            v.medium = w.medium;
            ShadingPoint sp;
            std::optional<VertexBsdf> vb;
            if (w.kind == MediumWalk::kSurface) {
                sp = make_shading_point(scene_, w.isect, w.dir);
                if (sp.material->is_black()) break;
                v.sp = &sp;
                v.hit = &w;
                v.p = sp.p;
                vb = vertex_bsdf(sp);
            } else {
                v.p = w.p;
                v.wi = -w.dir / length(w.dir);
                v.phase = &medium_phase(scene_.medium(w.medium));
            }
            const VertexBsdf* vbsdf = vb ? &*vb : nullptr;
            const Vec3f wi_local = v.sp ? sp.wi : Vec3f(0.0f);

            // Next-event estimation: each light sample's term, with its shadow ray's media.
            {
                const float density = st.density();
                LightHook<M> hook{*this, v, sp, vbsdf, beta, dbeta, density, log, c};
                const Rgb direct = estimate_light(scene_, v, sampler, st, true, wl, rules_.power_mis(), NoGuide{},
                                                  static_cast<LightSampleSeen<RgbWavelengths>*>(nullptr), bounces == 0, hook);
                L += beta * direct / density;
            }
            // The BSDF or phase sample: the emission its walk finds, then the continuation.
            walk = MediaLog{};
            const ScatterSample<RgbTransport> n =
                sample_scatter(scene_, v, sampler, st, true, wl, rules_.power_mis(), nullptr, NoGuide{}, bounces == 0, on_piece);
            if (!n.sampled) break;
            if (n.next.kind == MediumWalk::kMedium) scatter(walk, n.next.medium);
            if (!v.sp) phase(walk, v.medium, v.wi, n.ray.d);  // the phase sample's p / pdf (the pdf detached)
            const float density = st.density();
            const Rgb found = beta * n.next_seg * n.found / density;
            L += found;
            if (!is_black(found)) {
                const Rgb W = beta * n.next_seg / density;
                scatter_term<M>(vbsdf, wi_local, n.wo_local, n.delta, n.f, n.Le, n.k, n.light, 1.0f, W, dbeta * n.next_seg / density,
                                log + walk, c);
            }
            if (!rules_.may_bounce(bounces + 1)) break;
            if (n.next.kind == MediumWalk::kEscaped || n.next.kind == MediumWalk::kLost) break;
            const Rgb before = beta;
            beta = beta * n.next_seg * n.weight;
            if constexpr (M == Mode::Forward) {
                dbeta = dbeta * n.next_seg * n.weight;
                if (vbsdf) dbeta += before * n.next_seg * (jacobian_dot(*vbsdf, wi_local, n.wo_local, n.delta, c.tangent) * (std::abs(n.wo_local.z) / n.pdf));
            }
            log = log + walk;
            // Russian roulette on beta / density, as volpath.
            const Rgb kept = beta;
            if (!rules_.survive_roulette(bounces + 1, beta, st.density(), sampler)) break;
            if constexpr (M == Mode::Forward)
                for (int k = 0; k < 3; ++k) dbeta[k] = kept[k] != 0 ? dbeta[k] * (beta[k] / kept[k]) : 0.0f;
            // Reverse: the continuation's weight f scales everything still to come, Lr.
            if constexpr (M == Mode::Reverse) {
                if (vbsdf && !faults_.drop_continuation) {
                    Rgb W(0.0f);
                    for (int k = 0; k < 3; ++k)
                        if (n.f[k] > 0) W[k] = c.delta[k] * c.Lr[k] / n.f[k];
                    add_bsdf_adjoint(*vbsdf, wi_local, n.wo_local, n.delta, W, c);
                }
            }
            ++bounces;
            w = n.next;
        }
        return L;
    }

    // estimate_light's hook (media_lighting.hpp): each light sample's term at a vertex.
    template <Mode M>
    struct LightHook {
        static constexpr bool kActive = M != Mode::Primal;
        const PathReplay& r;
        const ScatterVertex& v;
        const ShadingPoint& sp;
        const VertexBsdf* vbsdf;
        const Rgb& beta;
        const Rgb& dbeta;
        float density;
        const MediaLog& log;
        Carry& c;
        MediaLog shadow{};
        void begin() { shadow = MediaLog{}; }
        void piece(int32_t medium, float length) { r.pass(shadow, medium, length); }
        void sample(const NeeSample& nee, const Rgb& f, const Rgb& Le, float k, const Rgb& Tr, const Rgb&) {
            const float scale = r.emission_scale(r.scene_.lights()[size_t(nee.choice.index)], nee.ls.distance);
            const Vec3f wo = v.sp ? sp.frame.to_local(nee.ls.wi) : Vec3f(0.0f);
            MediaLog l = log + shadow;
            if (!v.sp) r.phase(l, v.medium, v.wi, nee.ls.wi);  // the phase function towards the light
            r.scatter_term<M>(vbsdf, v.sp ? sp.wi : Vec3f(0.0f), wo, false, f, Le, k, nee.choice.index, scale, beta * Tr / density,
                              dbeta * Tr / density, l, c);
        }
    };

    const Scene& scene_;
    const ParameterSet& set_;
    PathRules rules_;
    bool hide_;
    DiffFaults faults_;
    std::vector<std::shared_ptr<const RoughCoatingDerivative>> coatings_;  // by material index
    std::vector<MediumBinding> media_slots_;  // the chosen media's offsets, by slot
};

// The camera ray of sample `sample` of pixel (x, y), drawn as PixelIntegrator draws it.
Ray camera_ray(const PerspectiveCamera& cam, int x, int y, Sampler& sampler) {
    const Vec2f jitter = sampler.next2d();
    return cam.needs_lens_sample() ? cam.generate(float(x) + jitter.x, float(y) + jitter.y, sampler.next2d())
                                   : cam.generate(float(x) + jitter.x, float(y) + jitter.y);
}

// Bands of rows, a fixed partition (not the thread count's), run in parallel.
constexpr int kRowsPerBand = 2;
template <typename F>
void for_each_band(int height, F&& f) {
    const int bands = (height + kRowsPerBand - 1) / kRowsPerBand;
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& r) {
        for (int b = r.begin(); b != r.end(); ++b) f(b, b * kRowsPerBand, std::min(height, (b + 1) * kRowsPerBand));
    });
}

const ParameterSet& empty_set() {
    static const ParameterSet set;
    return set;
}

}  // namespace

Image render_primal(const Scene& scene, const DiffSettings& s) {
    const PerspectiveCamera cam(scene.camera(), s.width, s.height);
    const PathReplay replay(scene, empty_set(), s);
    Image img(s.width, s.height);
    for_each_band(s.height, [&](int, int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < s.width; ++x) {
                const size_t pixel = size_t(y) * size_t(s.width) + size_t(x);
                Vec3d sum(0.0);
                for (int k = 0; k < s.spp; ++k) {
                    Sampler sampler(s.seed, pixel, s.first_pass + uint64_t(k), s.sampler);
                    const Ray ray = camera_ray(cam, x, y, sampler);
                    Carry c;
                    const Rgb L = replay.trace<Mode::Primal>(ray, sampler, c);
                    if (is_finite(L)) sum += Vec3d(L);
                }
                img[pixel] = Rgb(sum / double(std::max(1, s.spp)));
            }
    });
    return img;
}

std::vector<double> gradient(const Scene& scene, const ParameterSet& set, const DiffSettings& s, const Image& adjoint) {
    const PerspectiveCamera cam(scene.camera(), s.width, s.height);
    const PathReplay replay(scene, set, s);
    const int bands = (s.height + kRowsPerBand - 1) / kRowsPerBand;
    const uint64_t replay_shift = s.faults.replay_other_numbers ? 1 : 0;
    const auto add_band = [&](int band, std::vector<double>& g) {
        const int y1 = std::min(s.height, (band + 1) * kRowsPerBand);
        for (int y = band * kRowsPerBand; y < y1; ++y)
            for (int x = 0; x < s.width; ++x) {
                const size_t pixel = size_t(y) * size_t(s.width) + size_t(x);
                const Rgb delta = adjoint[pixel] / float(std::max(1, s.spp));
                if (is_black(delta)) continue;
                for (int k = 0; k < s.spp; ++k) {
                    const uint64_t index = s.first_pass + uint64_t(k);
                    Sampler primal_sampler(s.seed, pixel, index, s.sampler);
                    const Ray ray = camera_ray(cam, x, y, primal_sampler);
                    Carry primal;
                    const Rgb L = replay.trace<Mode::Primal>(ray, primal_sampler, primal);
                    if (!is_finite(L)) continue;
                    Sampler sampler(s.seed, pixel, index + replay_shift, s.sampler);
                    const Ray replay_ray = camera_ray(cam, x, y, sampler);
                    Carry c;
                    c.delta = delta;
                    c.Lr = L;
                    c.grad = g.data();
                    replay.trace<Mode::Reverse>(replay_ray, sampler, c);
                }
            }
    };
    // Gradient sums per band of rows, added pairwise in a fixed tree over the bands (the same
    // for any thread count: tbb's deterministic reduce splits the range down to single bands).
    // Only the sums in flight are held (about the threads times the tree's depth), so memory
    // stays small with parameters of a texture's size.
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<int>(0, bands, 1), std::vector<double>(size_t(set.size), 0.0),
        [&](const tbb::blocked_range<int>& r, std::vector<double> g) {
            for (int b = r.begin(); b != r.end(); ++b) add_band(b, g);
            return g;
        },
        [](std::vector<double> a, const std::vector<double>& b) {
            for (size_t i = 0; i < a.size(); ++i) a[i] += b[i];
            return a;
        },
        tbb::simple_partitioner());
}

Image forward_gradient(const Scene& scene, const ParameterSet& set, const DiffSettings& s, const std::vector<float>& tangent) {
    const PerspectiveCamera cam(scene.camera(), s.width, s.height);
    const PathReplay replay(scene, set, s);
    Image img(s.width, s.height);
    for_each_band(s.height, [&](int, int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < s.width; ++x) {
                const size_t pixel = size_t(y) * size_t(s.width) + size_t(x);
                Vec3d sum(0.0);
                for (int k = 0; k < s.spp; ++k) {
                    Sampler sampler(s.seed, pixel, s.first_pass + uint64_t(k), s.sampler);
                    const Ray ray = camera_ray(cam, x, y, sampler);
                    Carry c;
                    c.tangent = tangent.data();
                    const Rgb L = replay.trace<Mode::Forward>(ray, sampler, c);
                    if (is_finite(L) && is_finite(c.dL)) sum += Vec3d(c.dL);
                }
                img[pixel] = Rgb(sum / double(std::max(1, s.spp)));
            }
    });
    return img;
}

std::vector<float> parameter_tangent(const ParameterSet& set, size_t i) {
    std::vector<float> t(size_t(set.size), 0.0f);
    for (int k = 0; k < set.params.at(i).size; ++k) t[size_t(set.offsets[i] + k)] = 1;
    return t;
}

}  // namespace pathlab
