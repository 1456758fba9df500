// bdpt in spectral mode (docs/spectral.md, "Spectral bdpt and the light tracer"). Each pixel
// sample draws its wavelengths as the pixel integrators do (from the camera sampler's
// wavelength stream, which RGB mode never reads) and traces BOTH subpaths at them, so that a
// connection multiplies throughputs lane by lane at the same wavelengths. The subpaths,
// strategies, random streams and MIS weights are RGB mode's (bdpt.cpp): the weights depend on
// the geometry and densities only, which spectral mode leaves as they are; only the values
// (emission, BSDFs) are evaluated at the wavelengths. A copy of bdpt.cpp's loops rather than a
// template of them, as for pt-mis, so that RGB mode's translation unit compiles as before.
//
// Dispersion: a subpath that scatters at a dispersive interface continues with the hero
// wavelength alone (spectral_sample). A strategy whose path contains such a vertex, on
// either side, is the hero's estimate: hero_only(L), the factor 4 of terminate_secondary()
// applied once for the whole path, even when both subpaths met dispersion (they share the hero).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "integrators/bidir/bdpt.hpp"
#include "integrators/bidir/hero_only.hpp"
#include "integrators/bidir/strategy_images.hpp"
#include "integrators/common/light_path_start.hpp"
#include "integrators/common/spectral_shading.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab {
namespace {

// bdpt.cpp's bsdf_towards at the wavelengths: the BSDF of surface vertex v (in its subpath's
// transport mode) for light leaving towards the world direction w, and its density pdfW.
Spectrum4 bsdf_towards(const PathVertex& v, const Vec3f& w, float& pdfW, const SampledWavelengths& wl) {
    const Vec3f wo = v.sp.frame.to_local(w);
    return spectral_eval(v.sp, wo, v.sp.material->eval_and_pdf(v.sp, v.sp.wi, wo, pdfW), wl);
}

// |cos| at v of the world direction w (bdpt.cpp's cos_at).
float cos_at(const PathVertex& v, const Vec3f& w) {
    return v.kind == VertexKind::Surface ? std::abs(dot(v.sp.frame.n, w)) : (v.has_normal() ? std::abs(dot(v.n, w)) : 1.0f);
}

}  // namespace

void Bdpt::random_walk_spectral(const RenderContext& ctx, Ray ray, Sampler& sampler, Spectrum4 beta, float pdfW, int max_vertices,
                                TransportMode mode, SampledWavelengths wl, SpectralSubpath& path) const {
    const Scene& scene = ctx.scene;
    Spectrum4 scatter(1.0f);  // the throughput of the scattering alone, for Russian roulette
    for (int bounces = 0;; ++bounces) {
        if (int(path.size()) >= max_vertices) return;
        const size_t prev = path.size() - 1;
        Intersection hit;
        if (!scene.intersect(ray, hit)) {
            if (mode == TransportMode::Radiance && scene.environment_light() >= 0) {
                PathVertex v;
                v.kind = VertexKind::Light;
                v.infinite = true;
                v.dir = normalize(ray.d);
                v.light = scene.environment_light();
                v.pdf_fwd = pdfW;  // per unit solid angle
                path.push_back(v, beta);
            }
            return;
        }
        PathVertex v;
        v.kind = VertexKind::Surface;
        v.sp = make_shading_point(scene, hit, normalize(ray.d), mode);
        v.p = hit.p;
        v.n = v.sp.ng;
        v.emitter_n = hit.ng;
        v.light = hit.light;
        v.pdf_fwd = to_area_density(pdfW, path.vertices[prev], v);
        path.push_back(v, beta);
        PathVertex& cur = path.vertices.back();
        if (cur.sp.material->is_black() || int(path.size()) >= max_vertices) return;

        cur.sp.reverse_pdf = true;
        const auto s = spectral_sample(cur.sp, sampler.next2d(), wl);
        cur.sp.reverse_pdf = false;
        if (!s) return;
        const Spectrum4 weight = spectral_sample_value(cur.sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        beta *= weight;
        scatter *= weight;
        if (wl.secondary_terminated() && path.dispersed_from > int(path.size())) {
            // Dispersion here: the next vertex and all after it carry the hero alone.
            path.dispersed_from = int(path.size());
        }
        if (path.dispersed(int(path.size()))) {
            beta = Spectrum4(beta[0], 0.0f, 0.0f, 0.0f);
            scatter = Spectrum4(scatter[0], 0.0f, 0.0f, 0.0f);
        }
        pdfW = s->pdfW;
        float pdf_rev = s->pdf_rev;
        if (s->delta) {
            cur.delta = true;
            pdfW = pdf_rev = 0;
        }
        if (!(faults_.specular_pdf_rev_missing && path.vertices[prev].delta))
            path.vertices[prev].pdf_rev = to_area_density(pdf_rev, cur, path.vertices[prev]);
        if (options_.rr_depth >= 0 && bounces + 1 >= options_.rr_depth) {
            const float q = std::clamp(scatter.max_value(), 0.05f, 1.0f);
            if (sampler.next1d() >= q) return;
            beta /= q;
            scatter /= q;
        }
        ray = cur.sp.spawn(s->wo);
    }
}

void Bdpt::camera_subpath_spectral(const RenderContext& ctx, size_t pixel, Sampler& sampler, const SampledWavelengths& wl,
                                   SpectralSubpath& path, const Vec2f* shift) const {
    path.clear();
    PathVertex c;
    c.kind = VertexKind::Camera;
    c.p = ctx.camera.position();
    c.pdf_fwd = 1;
    path.push_back(c, Spectrum4(1.0f));
    const Vec2f jitter = shift ? (sampler.next2d(), *shift) : sampler.next2d();
    const float x = float(pixel % size_t(ctx.width)), y = float(pixel / size_t(ctx.width));
    const Ray ray = ctx.camera.generate(x + jitter.x, y + jitter.y);
    random_walk_spectral(ctx, ray, sampler, Spectrum4(1.0f), ctx.camera.pdf_direction(ray.d), max_camera_vertices(), TransportMode::Radiance,
                         wl, path);
}

void Bdpt::light_subpath_spectral(const RenderContext& ctx, Sampler& sampler, const SampledWavelengths& wl, SpectralSubpath& path) const {
    path.clear();
    const Scene& scene = ctx.scene;
    const auto start = start_light_path(scene, sampler);
    if (!start) return;
    const LightChoice& choice = start->choice;
    const Light& light = *start->light;
    const EmissionSample* es = &start->emission;
    const uint32_t flags = start->flags;
    PathVertex l;
    l.kind = VertexKind::Light;
    l.p = es->origin;
    l.infinite = (flags & kLightInfinite) != 0;
    l.delta_light = is_delta_light(light);
    l.dir = -es->direction;
    l.n = (flags & kLightSurface) ? es->normal : Vec3f(0.0f);
    l.emitter_n = es->normal;
    l.light = choice.index;
    l.pdf_fwd = choice.pmf * es->pdfA;
    const Spectrum4 Le = emission_spectrum(scene, choice.index, es->Le, wl);
    path.push_back(l, Le);
    const Spectrum4 beta = Le * (es->cos / (choice.pmf * es->pdfA * es->pdfW));
    const Ray ray = (flags & kLightSurface) ? spawn_ray(es->origin, es->normal, es->direction) : Ray{es->origin, es->direction, kInf};
    random_walk_spectral(ctx, ray, sampler, beta, es->pdfW, max_light_vertices(), TransportMode::Importance, wl, path);
    if (l.infinite) {
        std::vector<PathVertex>& v = path.vertices;
        if (v.size() > 1) v[1].pdf_fwd = es->pdfA * (v[1].has_normal() ? std::abs(dot(v[1].n, es->direction)) : 1.0f);
        v[0].pdf_fwd = pdf_light_origin(scene, v[0], v[0]);
    }
}

SpectralStrategyResult Bdpt::connect_spectral(const RenderContext& ctx, SpectralSubpath& light, int s, SpectralSubpath& camera, int t,
                                              Sampler& sampler, const SampledWavelengths& wl, const MergeMis* vm) const {
    const Scene& scene = ctx.scene;
    SpectralStrategyResult r;
    PathVertex sampled;
    EdgeDensities known;
    const PathVertex& pt = camera.vertices[size_t(t - 1)];
    const Spectrum4& pt_beta = camera.beta[size_t(t - 1)];
    if (t > 1 && s != 0 && pt.kind == VertexKind::Light) return r;
    if (s == 0) {
        if (pt.kind == VertexKind::Light) {
            r.L = pt_beta * escaped_spectrum(scene, pt.dir, wl);
        } else if (pt.light >= 0) {
            const Vec3f w = normalize(camera.vertices[size_t(t - 2)].p - pt.p);
            if (dot(pt.emitter_n, w) > 0)
                r.L = pt_beta * emission_spectrum(scene, pt.light, surface_radiance(scene.lights()[size_t(pt.light)]), wl);
        }
    } else if (t == 1) {
        const PathVertex& qs = light.vertices[size_t(s - 1)];
        if (!qs.connectible() || qs.kind != VertexKind::Surface) return r;
        const auto k = ctx.camera.connect(qs.p);
        if (!k) return r;
        sampled.kind = VertexKind::Camera;
        sampled.p = ctx.camera.position();
        sampled.beta = Rgb(k->We / k->pdfW);
        r.L = light.beta[size_t(s - 1)] * bsdf_towards(qs, k->wi, known.qs_to_pt, wl) * (k->We / k->pdfW * cos_at(qs, k->wi));
        if (r.L.is_black() || scene.occluded(qs.segment_to(sampled))) return SpectralStrategyResult{};
        r.splat = true;
        r.raster = k->raster;
    } else if (s == 1) {
        if (!pt.connectible()) return r;
        const LightChoice choice = scene.choose_light(sampler.next1d());
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
        sampled.pdf_fwd = pdf_light_origin(scene, sampled, pt);
        const Spectrum4 Le = emission_spectrum(scene, choice.index, ls->Le, wl);
        r.L = pt_beta * bsdf_towards(pt, ls->wi, known.pt_to_qs, wl) * Le * (cos_at(pt, ls->wi) / (choice.pmf * ls->pdfW));
        if (r.L.is_black() || scene.occluded(pt.segment_to(sampled))) return SpectralStrategyResult{};
    } else {
        const PathVertex& qs = light.vertices[size_t(s - 1)];
        if (!qs.connectible() || !pt.connectible() || qs.kind != VertexKind::Surface) return r;
        const Vec3f d = qs.p - pt.p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return r;
        const Vec3f w = d / std::sqrt(dist2);  // from pt towards qs
        const float G = cos_at(pt, w) * cos_at(qs, w) / dist2;
        r.L = light.beta[size_t(s - 1)] * bsdf_towards(qs, -w, known.qs_to_pt, wl) * bsdf_towards(pt, w, known.pt_to_qs, wl) * pt_beta * G;
        if (r.L.is_black() || scene.occluded(pt.segment_to(qs))) return SpectralStrategyResult{};
    }
    if (r.L.is_black()) return r;
    // A path through a dispersive vertex on either side is the hero's estimate, once.
    if ((s >= 2 && light.dispersed(s - 1)) || (t >= 2 && camera.dispersed(t - 1))) r.L = hero_only(r.L);
    r.weight = mis_weight(ctx, light.vertices, s, camera.vertices, t, sampled, known, vm);
    return r;
}

PassCounters Bdpt::render_spectral_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
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
            auto& [camera, light] = spectral_subpaths_.local();
            for (int c = range.begin(); c != range.end(); ++c) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t chunk_invalid = 0;
                SplatList& splats = pass_.chunk(c);
                for (size_t pixel = size_t(c) * per_chunk; pixel < std::min(pixels, size_t(c + 1) * per_chunk); ++pixel) {
                    Sampler camera_sampler(ctx.seed, pixel, pass, ctx.sampler);
                    Sampler light_sampler(ctx.seed, sample_stream(pixel, 1), pass, ctx.sampler);
                    // The camera sample's wavelengths (as PixelIntegrator's), for both subpaths.
                    const SampledWavelengths wl = sample_camera_wavelengths(camera_sampler);
                    camera_subpath_spectral(ctx, pixel, camera_sampler, wl, camera, filtered ? &shift : nullptr);
                    light_subpath_spectral(ctx, light_sampler, wl, light);
                    // The pixel's own contributions (t >= 2), summed at the wavelengths and
                    // converted once; each light-tracing splat (t = 1) converted on its own.
                    Spectrum4 own(0.0f);
                    for (int t = 1; t <= int(camera.size()); ++t) {
                        Sampler sampler(ctx.seed, sample_stream(pixel, 1 + uint64_t(t)), pass, ctx.sampler);
                        const int s_max = std::max(1, int(light.size()));
                        for (int s = 0; s <= s_max; ++s) {
                            const int depth = s + t - 2;
                            if ((s == 1 && t == 1) || depth < 0 || depth > max_bounces_) continue;
                            if (options_.only_length >= 0 && depth != options_.only_length) continue;
                            if (options_.hide_emitters && depth == 0) continue;
                            const SpectralStrategyResult r = connect_spectral(ctx, light, s, camera, t, sampler, wl);
                            if (r.L.is_black()) continue;
                            const Spectrum4 value = r.L * r.weight;
                            if (!value.is_finite()) {
                                ++chunk_invalid;
                                continue;
                            }
                            const uint32_t target = r.splat ? uint32_t(ctx.camera.pixel_of(r.raster)) : uint32_t(pixel);
                            if (r.splat) {
                                const Rgb rgb(spectral_sample_to_linear_srgb(value, wl));
                                if (filtered) splats.add_at(r.raster, rgb);
                                else splats.add(target, rgb);
                            } else {
                                own += value;
                            }
                            if (depth <= strategies_depth)
                                strategies_->chunk(c).push_back({target, uint16_t(StrategyImages::index(s, t)),
                                                                 Rgb(spectral_sample_to_linear_srgb(value, wl)),
                                                                 Rgb(spectral_sample_to_linear_srgb(r.L, wl))});
                        }
                    }
                    if (!own.is_black()) pass_.pixel(pixel) += spectral_sample_to_linear_srgb(own, wl);
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

}  // namespace pathlab
