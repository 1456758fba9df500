#include "integrators/bidir/bdpt.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "integrators/bidir/strategy_images.hpp"
#include "integrators/common/light_path_start.hpp"
#include "integrators/common/media_walk.hpp"
#include "integrators/integrators.hpp"

namespace pathlab {
namespace {

// The BSDF of surface vertex v for light leaving towards the world direction w (the mode of v's
// subpath: radiance on the camera side, importance on the light side), at the wavelengths wl, or
// the phase function of a medium vertex. Also the solid-angle density with which v samples w
// (which the MIS weight needs).
template <class Wl>
ColourAt<Wl> bsdf_towards(const Scene& scene, const PathVertexBase& v, const Vec3f& w, float& pdfW, const Wl& wl) {
    if (v.kind == VertexKind::Medium) {
        const PhaseFunction& phase = medium_phase(scene.medium(v.medium));
        pdfW = phase_pdf(phase, v.dir, w);
        return ColourAt<Wl>(phase_eval(phase, v.dir, w));
    }
    const Vec3f wo = v.sp.frame.to_local(w);
    return bsdf_colour(v.sp, wo, v.sp.material->eval_and_pdf(v.sp, v.sp.wi, wo, pdfW), wl);
}

// |cos| at v of the world direction w, with the shading normal (1 for points).
float cos_at(const PathVertexBase& v, const Vec3f& w) {
    return v.kind == VertexKind::Surface ? std::abs(dot(v.sp.frame.n, w)) : (v.has_normal() ? std::abs(dot(v.n, w)) : 1.0f);
}

// Connections inside one medium whose transmittance is below this in every channel are made
// with probability T / kConnectionRouletteT (Bdpt::connect).
constexpr float kConnectionRouletteT = 1.0f / 64;

// The probability of making the connection from o along the unit direction d, length dist,
// inside medium m: 1 unless its clearest channel's transmittance (exact in homogeneous media,
// the midpoint rule over the majorant cells in grids) is below kConnectionRouletteT.
float connection_survival(const Medium& m, const Vec3f& o, const Vec3f& d, float dist) {
    const float T = clearest_transmittance(m, o, d, dist);
    return T < kConnectionRouletteT ? std::max(T / kConnectionRouletteT, 1e-30f) : 1.0f;
}

// The random numbers of one sample come from separate streams (Bdpt::sample_stream): the
// camera subpath (the stream a pixel integrator would use), the light subpath, and the
// connections of each camera vertex t (next-event estimation draws there). So a subpath's
// vertices, and the light points s = 1 samples, are the same whichever strategies are
// evaluated: a render restricted to one path length (or to a lower depth) is made of the same
// paths as the full one.

}  // namespace

template <class T>
Bdpt<T>::Bdpt(const IntegratorOptions& options, BdptFaults faults)
    : options_(limited_to_length(options)), faults_(faults),
      max_bounces_(bounce_limit(options_.max_depth)) {
    if (!options.strategies_dir.empty())
        strategies_ = std::make_unique<StrategyImages>(std::min(options.strategies_depth, max_bounces_), options.strategies_dir);
}

template <class T>
Bdpt<T>::~Bdpt() = default;

template <class T>
void Bdpt<T>::random_walk(const RenderContext& ctx, Ray ray, Sampler& sampler, Colour beta, float pdfW, int max_vertices,
                          TransportMode mode, Wavelengths wl, Subpath& path, int32_t medium, int hero,
                          std::vector<SubpathBeam<T>>* beams) const {
    const Scene& scene = ctx.scene;
    const bool media = scene.has_media();
    // Media's random numbers and the subpath's spectral MIS state (media_walk.hpp).
    MediumState<T> st{sampler, wl};
    st.hero = hero;
    Colour scatter(1.0f);  // the throughput of the scattering alone, for Russian roulette
    for (int bounces = 0;; ++bounces) {
        if (int(path.size()) >= max_vertices) return;
        const size_t prev = path.size() - 1;
        Vertex v;
        v.beta = beta;
        v.dispersed = wl.secondary_terminated();
        Intersection hit;
        bool found;
        Vec3f dir = ray.d;
        if (!media) {
            found = scene.intersect(ray, hit);
        } else {
            // Through media and index-matched boundaries to a scattering point or a surface.
            Colour seg(1.0f);
            MediumWalk w;
            if (!beams) {
                w = walk_media(scene, ray, medium, st, seg, &v.T_in);
            } else {
                const int from = int(prev);
                const bool dispersed = v.dispersed;
                w = walk_media(scene, ray, medium, st, seg, &v.T_in,
                               [&](const Vec3f& o, const Vec3f& d, float length, int32_t m, const Colour& seg_o, const Colour& r_o, float mis_T) {
                                   beams->push_back({o, d, length, pdfW, mis_T, m, from, dispersed, beta * seg_o, r_o});
                               });
            }
            if (w.kind == MediumWalk::kLost) return;
            if (faults_.drop_distance_pdf) v.T_in = 1;
            beta *= seg;
            scatter *= seg;
            v.beta = beta;
            v.r = st.r;
            v.medium = w.medium;
            dir = w.dir;
            found = w.kind != MediumWalk::kEscaped;
            if (w.kind == MediumWalk::kMedium) {
                v.kind = VertexKind::Medium;
                v.p = w.p;
                v.dir = -normalize(w.dir);
                v.sigma_mis = faults_.drop_distance_pdf ? 1.0f : mis_extinction(scene.medium(w.medium), w.p);
                v.pdf_fwd = to_area_density(pdfW, path[prev], v) * v.distance_factor(v.T_in);
                path.push_back(v);
            } else if (found) {
                hit = w.isect;
                v.media = w.media;
            }
        }
        if (!found) {
            // A camera ray that escapes reaches the environment: a light vertex at infinity.
            if (mode == TransportMode::Radiance && scene.environment_light() >= 0) {
                v.kind = VertexKind::Light;
                v.infinite = true;
                v.dir = normalize(dir);
                v.light = scene.environment_light();
                v.pdf_fwd = pdfW * v.T_in;  // per unit solid angle
                path.push_back(v);
            }
            return;
        }
        if (v.kind != VertexKind::Medium) {
            v.kind = VertexKind::Surface;
            v.sp = make_shading_point(scene, hit, normalize(dir), mode);
            v.p = hit.p;
            v.n = v.sp.ng;
            v.emitter_n = hit.ng;
            v.light = hit.light;
            v.pdf_fwd = to_area_density(pdfW, path[prev], v) * v.T_in;
            path.push_back(v);
        }
        Vertex& cur = path.back();
        if (int(path.size()) >= max_vertices) return;

        Vec3f wo;  // the next direction: in world space in a medium, local to the surface's frame on one
        float pdf_rev;
        if (cur.kind == VertexKind::Medium) {
            // The phase function samples the next direction; p / pdf = 1, and it is symmetric.
            const PhaseFunction& phase = medium_phase(scene.medium(cur.medium));
            const PhaseSample ps = phase_sample(phase, cur.dir, sampler.next2d());
            if (!(ps.pdfW > 0)) return;
            const Colour weight(ps.p / ps.pdfW);
            beta *= weight;
            scatter *= weight;
            wo = ps.wo;
            cur.sin_theta = length(cross(cur.dir, wo));
            pdfW = ps.pdfW;
            pdf_rev = phase_pdf(phase, ps.wo, cur.dir);
        } else {
            if (cur.sp.material->is_black()) return;
            cur.sp.reverse_pdf = true;
            const auto s = bsdf_sample(cur.sp, sampler.next2d(), wl);
            cur.sp.reverse_pdf = false;
            if (!s) return;
            const Colour weight = bsdf_sample_colour(cur.sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
            beta *= weight;
            scatter *= weight;
            if (wl.secondary_terminated()) {
                // Dispersion here or before: the next vertex and all after it carry the hero alone.
                beta = hero_lane(beta);
                scatter = hero_lane(scatter);
            }
            // A Dirac lobe keeps its coefficient (the probability of choosing it, the same both
            // ways) as its density: the delta itself is common to every strategy that can sample
            // the path, and the neighbours' area densities keep their cosines and distances (as the
            // VCM report's specular vertices do; reading the density as 0, and 0 as 1 in the
            // ratios, as pbrt-v3 does, leaves out a factor d^2 / cos per Dirac vertex and gave
            // the camera strategies of a caustic seen through glass too much weight).
            pdfW = s->pdfW;
            pdf_rev = s->pdf_rev;
            if (s->delta) cur.delta = true;
            wo = s->wo;
        }
        // The reverse density of the previous vertex: cur's sampling of it, back along the same edge.
        if (!(faults_.specular_pdf_rev_missing && path[prev].delta))
            path[prev].pdf_rev = to_area_density(pdf_rev, cur, path[prev]) * path[prev].distance_factor(cur.T_in);
        // Russian roulette after rr_depth bounces, as in the path tracers (in media on the
        // throughput over the path's density, its actual weight).
        if (options_.rr_depth >= 0 && bounces + 1 >= options_.rr_depth) {
            const float q = std::clamp(media ? max_component(scatter / st.density()) : max_component(scatter), 0.05f, 1.0f);
            if (sampler.next1d() >= q) return;
            beta /= q;
            scatter /= q;
        }
        if (cur.kind == VertexKind::Medium) {
            medium = cur.medium;
            ray = Ray{cur.p, wo, kInf};
        } else {
            if (media) medium = cur.medium_towards(cur.sp.frame.to_world(wo));
            ray = cur.sp.spawn(wo);
        }
    }
}

template <class T>
int Bdpt<T>::sample_hero(const RenderContext& ctx, size_t pixel, uint64_t pass, const Wavelengths& wl) {
    if (!ctx.scene.has_media()) return -1;
    Sampler hero_sampler(ctx.seed, sample_stream(pixel, kHeroStream), pass, ctx.sampler);
    return hero_channel(wl, [&] { return hero_sampler.next1d(); });
}

template <class T>
void Bdpt<T>::camera_subpath(const RenderContext& ctx, size_t pixel, Sampler& sampler, const Wavelengths& wl, Subpath& path,
                             const Vec2f* shift, const MergeMis* vm, int hero, std::vector<SubpathBeam<T>>* beams) const {
    const Vec2f jitter = shift ? (sampler.next2d(), *shift) : sampler.next2d();
    const float x = float(pixel % size_t(ctx.width)), y = float(pixel / size_t(ctx.width));
    camera_subpath_at(ctx, {x + jitter.x, y + jitter.y}, sampler, wl, path, max_camera_vertices(), vm, hero, beams);
}

template <class T>
void Bdpt<T>::camera_subpath_at(const RenderContext& ctx, Vec2f raster, Sampler& sampler, const Wavelengths& wl, Subpath& path,
                                int max_vertices, const MergeMis* vm, int hero, std::vector<SubpathBeam<T>>* beams) const {
    path.clear();
    if (beams) beams->clear();
    Vertex c;
    c.kind = VertexKind::Camera;
    c.p = ctx.camera.position();
    c.beta = Colour(1.0f);
    c.pdf_fwd = 1;
    c.medium = ctx.scene.camera_medium();
    path.push_back(c);
    const Ray ray = ctx.camera.generate(raster.x, raster.y);
    // We cos / (pdfA pdfW) = 1 for the pinhole: the camera path starts with throughput 1.
    random_walk(ctx, ray, sampler, Colour(1.0f), ctx.camera.pdf_direction(ray.d), max_vertices, TransportMode::Radiance, wl, path,
                c.medium, hero, beams);
    set_running_mis(path.data(), int(path.size()), /*light_side=*/false, MisRules(options_.mis_power, vm));
}

template <class T>
void Bdpt<T>::light_subpath(const RenderContext& ctx, Sampler& sampler, const Wavelengths& wl, Subpath& path, const MergeMis* vm,
                            int hero, int max_vertices, std::vector<SubpathBeam<T>>* beams) const {
    path.clear();
    if (beams) beams->clear();
    const Scene& scene = ctx.scene;
    const auto start = start_light_path(scene, sampler);
    if (!start) return;
    const LightChoice& choice = start->choice;
    const EmissionSample* es = &start->emission;
    const uint32_t flags = start->flags;
    Vertex l;
    l.kind = VertexKind::Light;
    l.p = es->origin;
    l.infinite = (flags & kLightInfinite) != 0;
    l.delta_light = is_delta_light(*start->light);
    l.dir = -es->direction;
    l.n = (flags & kLightSurface) ? es->normal : Vec3f(0.0f);
    l.emitter_n = es->normal;
    l.light = choice.index;
    l.medium = start->medium;
    l.beta = light_colour(scene, choice.index, es->Le, wl);
    l.pdf_fwd = choice.pmf * es->pdfA;
    path.push_back(l);
    const Colour beta = l.beta * (es->cos / (choice.pmf * es->pdfA * es->pdfW));
    const Ray ray = (flags & kLightSurface) ? spawn_ray(es->origin, es->normal, es->direction) : Ray{es->origin, es->direction, kInf};
    random_walk(ctx, ray, sampler, beta, es->pdfW, max_vertices < 0 ? max_light_vertices() : max_vertices, TransportMode::Importance, wl,
                path, l.medium, hero, beams);
    if (l.infinite && beams)
        for (SubpathBeam<T>& b : *beams)
            if (b.from == 0) b.pdfW = es->pdfA, b.from_infinity = true;
    if (l.infinite) {
        // From infinity the first hit's density is that of the entry disk, projected; the light
        // vertex's own density is that of its direction under light sampling.
        if (path.size() > 1)
            path[1].pdf_fwd = es->pdfA * (path[1].has_normal() ? std::abs(dot(path[1].n, es->direction)) : 1.0f) *
                              path[1].distance_factor(path[1].T_in);
        path[0].pdf_fwd = pdf_light_origin(scene, path[0], path[0]);
    }
    set_running_mis(path.data(), int(path.size()), /*light_side=*/true, MisRules(options_.mis_power, vm));
}

template <class T>
ConnectionDensities Bdpt<T>::connection_densities(const RenderContext& ctx, const Vertex* ys, int s, const Vertex* zs, int t,
                                                  const EdgeDensities& known) const {
    const Scene& scene = ctx.scene;
    const Vertex* qs = s > 0 ? &ys[s - 1] : nullptr;
    const Vertex* pt = &zs[t - 1];
    const Vertex* qs_minus = s > 1 ? &ys[s - 2] : nullptr;
    const Vertex* pt_minus = t > 1 ? &zs[t - 2] : nullptr;
    ConnectionDensities d;
    // Each density times the distance-sampling factor of the edge it arrives along (1 without
    // media): the new edge's MIS transmittance known.T, or that of the subpath's own edge.
    const auto factor = [this](const Vertex& v, float edge_T) { return faults_.drop_distance_pdf ? 1.0f : v.distance_factor(edge_T); };
    if (s == 0) d.camera_end = pdf_light_origin(scene, *pt, *pt_minus);
    else if (known.qs_to_pt >= 0) d.camera_end = to_area_density(known.qs_to_pt, *qs, *pt) * factor(*pt, known.T);
    else d.camera_end = pdf_next(scene, ctx.camera, qs_minus, *qs, *pt) * factor(*pt, known.T);
    if (pt_minus)
        d.camera_prev = (s > 0 ? pdf_next(scene, ctx.camera, qs, *pt, *pt_minus) : pdf_light_emission(scene, *pt, *pt_minus)) *
                        factor(*pt_minus, pt->T_in);
    if (qs)
        d.light_end = (known.pt_to_qs >= 0 ? to_area_density(known.pt_to_qs, *pt, *qs) : pdf_next(scene, ctx.camera, pt_minus, *pt, *qs)) *
                      factor(*qs, known.T);
    if (qs_minus) d.light_prev = pdf_next(scene, ctx.camera, pt, *qs, *qs_minus) * factor(*qs_minus, qs->T_in);
    if (qs && (qs->kind == VertexKind::Medium || pt->kind == VertexKind::Medium)) {
        const Vec3f w = qs->infinite ? -qs->dir : normalize(pt->p - qs->p);  // (a light at infinity: its direction)
        if (qs->kind == VertexKind::Medium) d.light_end_sin = length(cross(qs->dir, w));
        if (pt->kind == VertexKind::Medium) d.camera_end_sin = length(cross(pt->dir, w));
    }
    return d;
}

template <class T>
float Bdpt<T>::seen_directly_weight(const RenderContext& ctx, SubpathView light, int s, SubpathView camera, const Vertex& sampled,
                                    const EdgeDensities& known, const MergeMis* vm) const {
    const Vertex& end = s == 0 ? camera[1] : light[0];
    if ((vm && !vm->connections) || !both_strategies_see(ctx.scene, end)) return 1.0f;
    // The other strategy's density of the shared vertex across the edge, as for any connection;
    // T, the edge's MIS transmittance, is the same function of the segment on both sides.
    if (s == 0) {
        const float p1 = connection_densities(ctx, light.data(), 0, camera.data(), 2, known).camera_end;
        return seen_directly_weight(0, end.pdf_fwd, p1, end.T_in, options_.mis_power);
    }
    const float p0 = connection_densities(ctx, light.data(), 1, &sampled, 1, known).light_end;
    return seen_directly_weight(1, p0, end.pdf_fwd, known.T, options_.mis_power);
}

template <class T>
float Bdpt<T>::mis_weight(const RenderContext& ctx, SubpathView light, int s, SubpathView camera, int t, const Vertex& sampled,
                          const EdgeDensities& known, const MergeMis* vm) const {
    if (s + t == 2) return seen_directly_weight(ctx, light, s, camera, sampled, known, vm);
    if (faults_.any()) return mis_weight_oracle(ctx, light, s, camera, t, sampled, known, vm);
    // The strategy's own vertices: the sampled endpoint (y_0 for s = 1 and t > 1, z_0 for t = 1),
    // and the densities across the new edge; the rest from the running quantities (path_vertex.hpp).
    const Vertex* const ys = s == 1 && t > 1 ? &sampled : light.data();
    const Vertex* const zs = t == 1 ? &sampled : camera.data();
    const ConnectionDensities d = connection_densities(ctx, ys, s, zs, t, known);
    const MisRules rules(options_.mis_power, vm);
    double sum = 0;
    if (s >= 1) sum += light_side_sum(ys, s - 1, d.light_end, d.light_prev, rules, d.light_end_sin);
    if (t >= 2)
        sum += camera_side_sum(zs, t - 1, zs[t - 1].pdf_fwd, d.camera_end, d.camera_end, s >= 1, d.camera_prev, rules, d.camera_end_sin);
    return float(1 / (1 + sum));
}

template <class T>
float Bdpt<T>::mis_weight_oracle(const RenderContext& ctx, SubpathView light_view, int s, SubpathView camera_view, int t,
                                 const Vertex& sampled, const EdgeDensities& known, const MergeMis* vm) const {
    if (s + t == 2) return seen_directly_weight(ctx, light_view, s, camera_view, sampled, known, vm);
    // The connection's densities written onto copies of the vertices for the walk.
    Subpath light(light_view.begin(), light_view.end()), camera(camera_view.begin(), camera_view.end());
    Vertex end = sampled;
    Vertex* const ys = s == 1 && t > 1 ? &end : light.data();
    Vertex* const zs = t == 1 ? &end : camera.data();
    const ConnectionDensities d = connection_densities(ctx, ys, s, zs, t, known);
    Vertex* qs = s > 0 ? &ys[s - 1] : nullptr;
    Vertex* pt = &zs[t - 1];
    Vertex* qs_minus = s > 1 ? &ys[s - 2] : nullptr;
    Vertex* pt_minus = t > 1 ? &zs[t - 2] : nullptr;
    // The connected vertices are not Dirac here (the connection evaluated their BSDFs).
    pt->delta = false;
    if (qs) qs->delta = false;
    pt->pdf_rev = d.camera_end;
    pt->sin_theta = d.camera_end_sin;
    if (qs) qs->sin_theta = d.light_end_sin;
    if (pt_minus) pt_minus->pdf_rev = d.camera_prev;
    if (qs) qs->pdf_rev = d.light_end;
    if (qs_minus) qs_minus->pdf_rev = d.light_prev;

    float w = 0;
    if (faults_.drop_nee_strategy && s != 1) {
        // The faulty weight: the same walk without the s = 1 term.
        const auto remap0 = [](float f) { return f != 0 ? double(f) : 1.0; };
        double sum = 0, ri = 1;
        for (int i = t - 1; i > 0; --i) {
            ri *= remap0(zs[i].pdf_rev) / remap0(zs[i].pdf_fwd);
            if (!zs[i].delta && !zs[i - 1].delta && s + (t - i) != 1) sum += ri;
        }
        ri = 1;
        for (int i = s - 1; i >= 0; --i) {
            ri *= remap0(ys[i].pdf_rev) / remap0(ys[i].pdf_fwd);
            const bool delta_before = i > 0 ? ys[i - 1].delta : ys[0].delta_light;
            if (!ys[i].delta && !delta_before && i != 1) sum += ri;
        }
        w = float(1 / (1 + sum));
    } else {
        w = mis_weight_ratio_walk(ys, s, zs, t, options_.mis_power, vm);
    }
    return w;
}

template <class T>
StrategyResult<T> Bdpt<T>::connect(const RenderContext& ctx, SubpathView light, int s, SubpathView camera, int t, Sampler& sampler,
                                   const Wavelengths& wl, const MergeMis* vm) const {
    const Scene& scene = ctx.scene;
    const bool media = scene.has_media();
    StrategyResult<T> r;
    Vertex sampled;
    EdgeDensities known;  // the BSDF densities across the new edge, from the evaluations below
    // The connecting edge's transmittance: 0 where a surface blocks it; through media an
    // estimate (ratio tracking, from a stream of strategy (s, t)'s own), and its MIS transmittance.
    MediumState<T> st{sampler, wl};
    st.stream_id = kMediumStream + uint64_t(s);
    // Checked before a connection's BSDFs: a segment out of a sealed medium is blocked without a ray.
    const auto separated = [&](const PathVertexBase& from, const PathVertexBase& to, const Vec3f& w) {
        return media && scene.media_separated(from.medium_towards(w), to.medium_towards(-w));
    };
    const auto transmittance = [&](const PathVertexBase& from, const PathVertexBase& to, const Vec3f& w) {
        if (!media) return scene.occluded(from.segment_to(to)) ? Colour(0.0f) : Colour(1.0f);
        const Colour Tr = shadow_transmittance(scene, from.segment_to(to), from.medium_towards(w), st, &known.T);
        if (faults_.drop_distance_pdf) known.T = 1;
        return faults_.drop_connection_transmittance && !is_black(Tr) ? Colour(1.0f) : Tr;
    };
    const Vertex& pt = camera[size_t(t - 1)];
    // A camera subpath that escaped ends at infinity: only s = 0 can use that vertex.
    if (t > 1 && s != 0 && pt.kind == VertexKind::Light) return r;
    if (s == 0) {
        if (pt.kind == VertexKind::Light) {
            r.L = pt.beta * escaped_radiance(scene, pt.dir, wl);
        } else if (pt.light >= 0) {
            const Vec3f w = normalize(camera[size_t(t - 2)].p - pt.p);
            if (dot(pt.emitter_n, w) > 0) r.L = pt.beta * light_colour(scene, pt.light, surface_radiance(scene.lights()[size_t(pt.light)], pt.sp.uv), wl);
        }
    } else if (t == 1) {
        if (s > int(light.size())) return r;  // (s = 1 with no light subpath: an emission sample that failed)
        const Vertex& qs = light[size_t(s - 1)];
        // The emitter's own point (s = 1) where a light seen directly has two strategies.
        const bool emitter = qs.kind == VertexKind::Light;
        if (!qs.connectible() || (emitter && !both_strategies_see(scene, qs))) return r;
        const auto k = ctx.camera.connect(qs.p);
        if (!k) return r;
        sampled.kind = VertexKind::Camera;
        sampled.p = ctx.camera.position();
        sampled.medium = scene.camera_medium();
        sampled.beta = Colour(k->We / k->pdfW);
        if (separated(qs, sampled, k->wi)) return r;
        if (emitter) {
            // Le towards the camera (area emitters are Lambertian: y_0's beta is Le), over the
            // density of y_0 (pdf_fwd: the emitter's pmf times its position's area density).
            const float cos_light = dot(qs.emitter_n, k->wi);
            if (!(cos_light > 0)) return r;
            r.L = qs.beta * (cos_light / qs.pdf_fwd) * sampled.beta;
        } else {
            r.L = qs.beta * bsdf_towards(scene, qs, k->wi, known.qs_to_pt, wl) * sampled.beta * cos_at(qs, k->wi);
        }
        if (is_black(r.L)) return StrategyResult<T>{};
        const Colour Tr = transmittance(qs, sampled, k->wi);
        if (is_black(Tr)) return StrategyResult<T>{};
        if (emitter && !(known.T < 1)) return StrategyResult<T>{};  // through no medium: weight 0 (seen_directly_weight)
        if (media) r.L *= Tr;
        r.splat = true;
        r.raster = k->raster;
    } else if (s == 1) {
        if (!pt.connectible()) return r;
        const LightChoice choice = scene.choose_emitter(sampler.next1d());
        const Vec2f u = sampler.next2d();
        if (choice.index < 0) return r;
        const Light& l = scene.lights()[size_t(choice.index)];
        const auto ls = sample_light(l, pt.p, u);
        if (!ls || is_black(ls->Le) || !(ls->pdfW > 0)) return r;
        const uint32_t flags = light_flags(l);
        sampled.kind = VertexKind::Light;
        sampled.infinite = (flags & kLightInfinite) != 0;
        sampled.delta_light = is_delta_light(l);
        sampled.dir = ls->wi;
        sampled.p = std::isinf(ls->distance) ? pt.p + ls->wi : ls->point;
        sampled.n = (flags & kLightSurface) ? ls->normal : Vec3f(0.0f);
        sampled.emitter_n = ls->normal;
        sampled.light = choice.index;
        sampled.medium = scene.light_medium(choice.index);
        sampled.beta = light_colour(scene, choice.index, ls->Le, wl) / (choice.pmf * ls->pdfW);
        sampled.pdf_fwd = pdf_light_origin(scene, sampled, pt);
        if (separated(pt, sampled, ls->wi)) return r;
        r.L = pt.beta * bsdf_towards(scene, pt, ls->wi, known.pt_to_qs, wl) * sampled.beta * cos_at(pt, ls->wi);
        if (is_black(r.L)) return StrategyResult<T>{};
        const Colour Tr = transmittance(pt, sampled, ls->wi);
        if (is_black(Tr)) return StrategyResult<T>{};
        if (media) r.L *= Tr;
    } else {
        const Vertex& qs = light[size_t(s - 1)];
        if (!qs.connectible() || !pt.connectible() || qs.kind == VertexKind::Light) return r;
        const Vec3f d = qs.p - pt.p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return r;
        const float dist = std::sqrt(dist2);
        const Vec3f w = d / dist;  // from pt towards qs
        if (separated(pt, qs, w)) return r;
        float survival = 1;
        if (media) {
            // Roulette on connections that the medium all but extinguishes (transmittance below
            // kConnectionRouletteT in every channel): made with probability T / that, and
            // divided by it (unbiased; a made one weighs about as one of transmittance
            // kConnectionRouletteT). In a dense medium most of a long subpath's O(n m) connections
            // are of this kind; the rest cost their BSDFs and a shadow ray as before.
            const int32_t medium = pt.medium_towards(w);
            if (medium >= 0 && medium == qs.medium_towards(-w) && !faults_.no_connection_roulette) {
                survival = connection_survival(scene.medium(medium), pt.p, w, dist);
                if (survival < 1 && !(st.rng().next1d() < survival)) return r;
            }
        }
        const float G = cos_at(pt, w) * cos_at(qs, w) / dist2;
        r.L = qs.beta * bsdf_towards(scene, qs, -w, known.qs_to_pt, wl) * bsdf_towards(scene, pt, w, known.pt_to_qs, wl) * pt.beta * (faults_.connection_roulette_undivided ? G : G / survival);
        if (is_black(r.L)) return StrategyResult<T>{};
        const Colour Tr = transmittance(pt, qs, w);
        if (is_black(Tr)) return StrategyResult<T>{};
        if (media) r.L *= Tr;
    }
    if (is_black(r.L)) return r;
    // A path through a dispersive vertex on either side is the hero's estimate, once.
    const bool dispersed = (s >= 2 && light[size_t(s - 1)].dispersed) || (t >= 2 && camera[size_t(t - 1)].dispersed);
    if (dispersed) r.L = hero_only(r.L);
    // In media: the spectral MIS over the hero channel that both subpaths shared (media/medium.hpp).
    if (media) r.L /= path_density_of((s >= 2 ? light[size_t(s - 1)].r : Colour(1.0f)) * (t >= 2 ? pt.r : Colour(1.0f)), dispersed);
    r.weight = mis_weight(ctx, light, s, camera, t, sampled, known, vm);
    return r;
}

template <class T>
PassCounters Bdpt<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    const size_t pixels = ctx.pixel_count(), per_chunk = chunk_size(pixels);
    const int chunks = int((pixels + per_chunk - 1) / per_chunk);
    const int strategies_depth = strategies_ ? strategies_->max_length() : -1;
    std::atomic<uint64_t> rays{0}, invalid{0};
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        pass_.begin(pixels, chunks);
        const bool filtered = ctx.filter && !ctx.filter->is_box();
        const Vec2f shift = filtered ? filter_shift(ctx, pass) : Vec2f(0.0f, 0.0f);
        if (strategies_) strategies_->begin_pass(ctx.width, ctx.height, chunks);
        std::atomic<int> chunks_done{0};
        tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& range) {
            // Each thread's subpath vectors keep their capacity from pass to pass.
            auto& [camera, light] = subpaths_.local();
            for (int c = range.begin(); c != range.end(); ++c) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t chunk_invalid = 0;
                SplatList& splats = pass_.chunk(c);
                for (size_t pixel = size_t(c) * per_chunk; pixel < std::min(pixels, size_t(c + 1) * per_chunk); ++pixel) {
                    Sampler camera_sampler(ctx.seed, pixel, pass, ctx.sampler);
                    Sampler light_sampler(ctx.seed, sample_stream(pixel, 1), pass, ctx.sampler);
                    // The camera sample's wavelengths (as PixelIntegrator's), for both subpaths.
                    const Wavelengths wl = T::camera_wavelengths(camera_sampler);
                    const int hero = sample_hero(ctx, pixel, pass, wl);
                    camera_subpath(ctx, pixel, camera_sampler, wl, camera, filtered ? &shift : nullptr, nullptr, hero);
                    light_subpath(ctx, light_sampler, wl, light, nullptr, hero);
                    // The pixel's own contributions (t >= 2) are summed and converted once; each
                    // light-tracing splat (t = 1) on its own.
                    typename T::SampleSum own(0.0f);
                    for_each_connection(
                        ctx, pixel, pass, light, camera, wl, nullptr,
                        [&](int s, int t, const StrategyResult<T>& r) {
                            const Colour value = r.L * r.weight;
                            if (!is_finite(value)) return void(++chunk_invalid);
                            const uint32_t target = r.splat ? uint32_t(ctx.camera.pixel_of(r.raster)) : uint32_t(pixel);
                            if (r.splat && filtered) splats.add_at(r.raster, Rgb(film_colour(value, wl)));
                            else if (r.splat) splats.add(target, Rgb(film_colour(value, wl)));
                            else accumulate(own, value);
                            if (s + t - 2 <= strategies_depth)
                                strategies_->chunk(c).push_back({target, uint16_t(StrategyImages::index(s, t)), Rgb(film_colour(value, wl)),
                                                                 Rgb(film_colour(r.L, wl))});
                        },
                        [](int) {});
                    pass_.pixel(pixel) += film_colour(own, wl);
                }
                rays += Scene::rays_traced_by_this_thread() - rays_before;
                invalid += chunk_invalid;
                if (progress) progress((double(k) + double(++chunks_done) / chunks) / count);
            }
        });
        pass_.finish(film, ctx.filter, shift);
        if (strategies_) strategies_->finish_pass();
    }
    return {rays.load(), invalid.load()};
}

template <class T>
std::vector<ExrChannel> Bdpt<T>::display_channels() const {
    return strategies_ ? strategies_->weighted_channels() : std::vector<ExrChannel>{};
}

template <class T>
void Bdpt<T>::finish(const RenderContext&) {
    if (strategies_) strategies_->write();
}

template class Bdpt<RgbTransport>;
template class Bdpt<SpectralTransport>;

const IntegratorInfo& bdpt_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"bdpt", {"bpt"}, "bidirectional path tracing: every connection strategy (s, t), combined by MIS",
                         false, true, path_params(), [](const IntegratorOptions& o) { return make_for_transport<Bdpt>(o); },
                         /*any_camera=*/false};
        i.media = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
