#include "integrators/bidir/light_tracer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "integrators/common/light_path_start.hpp"
#include "integrators/common/media_walk.hpp"
#include "integrators/integrators.hpp"

namespace pathlab {
namespace {

// One contribution at the path's colour, converted by the film's estimator.
template <class Colour, class Wl>
void splat(SplatList& out, const RenderContext& ctx, const Vec2f& raster, const Colour& value, const Wl& wl, uint64_t& invalid) {
    if (!is_finite(value)) {
        ++invalid;
        return;
    }
    if (is_black(value)) return;
    const Rgb rgb(film_colour(value, wl));
    if (ctx.filter && !ctx.filter->is_box()) out.add_at(raster, rgb);
    else out.add(uint32_t(ctx.camera.pixel_of(raster)), rgb);
}

}  // namespace

template <class T>
void LightTracer<T>::trace(const RenderContext& ctx, Sampler& sampler, SplatList& out, uint64_t& invalid) const {
    using Colour = ColourOf<T>;
    const Scene& scene = ctx.scene;
    const PerspectiveCamera& camera = ctx.camera;
    WavelengthsOf<T> wl = T::camera_wavelengths(sampler);
    const auto start = start_light_path(scene, sampler);
    if (!start) return;
    const LightChoice& choice = start->choice;
    const EmissionSample* es = &start->emission;
    const uint32_t flags = start->flags;
    const Colour Le = light_colour(scene, choice.index, es->Le, wl);
    // Media (docs/volumes.md): the path walks through them (media_walk.hpp), scatters in them by
    // the phase function, and every connection to the camera carries the transmittance of its
    // segment; contributions are divided by the path's density over the hero channel.
    const bool media = scene.has_media();
    MediumState<T> st{sampler, wl};
    int32_t medium = start->medium;
    // Whether the segment to the camera is free, and its transmittance through media.
    const auto to_camera = [&](const Ray& segment, int32_t from_medium) {
        if (scene.media_separated(from_medium, scene.camera_medium())) return Colour(0.0f);  // blocked: no ray needed
        return shadow_transmittance(scene, segment, from_medium, st);
    };

    // Paths of no bounce: the emitter seen by the camera.
    if (hide_emitters_) {
    } else if (flags & kLightSurface) {
        if (const auto k = camera.connect(es->origin)) {
            const float cos_light = dot(es->normal, k->wi);
            if (cos_light > 0) {
                const Colour Tr = to_camera(spawn_segment(es->origin, es->normal, camera.position(), Vec3f(0.0f)), medium);
                if (!is_black(Tr)) {
                    const Colour seen = Le * (cos_light * k->We / (choice.pmf * es->pdfA * k->pdfW));
                    splat(out, ctx, k->raster, media ? seen * Tr : seen, wl, invalid);
                }
            }
        }
    } else if ((flags & kLightInfinite) && !(flags & kLightDeltaDirection)) {
        const Vec2f u = sampler.next2d();
        if (const auto ls = sample_light(*start->light, camera.position(), u)) {
            const auto raster = camera.raster_of(ls->wi);
            if (raster && ls->pdfW > 0) {
                const Colour Tr = to_camera(Ray{camera.position(), ls->wi, kInf}, scene.camera_medium());
                if (!is_black(Tr)) {
                    const float cos_lens = dot(ls->wi, camera.forward());
                    const Colour seen = light_colour(scene, choice.index, ls->Le, wl) * (camera.We(ls->wi) * cos_lens / (choice.pmf * ls->pdfW));
                    splat(out, ctx, *raster, media ? seen * Tr : seen, wl, invalid);
                }
            }
        }
    }

    // The emitted power this path carries, and its scattering throughput (for roulette).
    const float emission_pdf = faults_.drop_emission_pdf ? 1.0f : es->pdfA * es->pdfW;
    const Colour power = Le * (es->cos / (choice.pmf * emission_pdf));
    Colour beta(1.0f);
    Ray ray = (flags & kLightSurface) ? spawn_ray(es->origin, es->normal, es->direction) : Ray{es->origin, es->direction, kInf};
    for (int bounces = 1;; ++bounces) {
        Intersection hit;
        const MediumInterface* boundary = nullptr;  // the surface's media (null: it changes none)
        Vec3f dir = ray.d;
        if (!media) {
            if (!scene.intersect(ray, hit)) return;
        } else {
            Colour seg(1.0f);
            const MediumWalk w = walk_media(scene, ray, medium, st, seg);
            if (w.kind == MediumWalk::kLost || w.kind == MediumWalk::kEscaped) return;
            beta *= seg;
            medium = w.medium;
            if (w.kind == MediumWalk::kMedium) {
                // Scattering in the medium: connect to the camera through the phase function.
                const PhaseFunction& phase = medium_phase(scene.medium(medium));
                const Vec3f wi = -normalize(w.dir);
                if (const auto k = camera.connect(w.p)) {
                    const float f = phase_eval(phase, wi, k->wi);
                    const float camera_pdf = faults_.drop_camera_geometry ? 1.0f : k->pdfW;
                    if (f > 0) {
                        const Colour Tr = to_camera(spawn_segment(w.p, Vec3f(0.0f), camera.position(), Vec3f(0.0f)), medium);
                        if (!is_black(Tr))
                            splat(out, ctx, k->raster, power * beta * Tr * (f * k->We / camera_pdf / st.density()), wl, invalid);
                    }
                }
                if (!rules_.may_bounce(bounces)) return;
                const PhaseSample ps = phase_sample(phase, wi, sampler.next2d());
                if (!(ps.pdfW > 0)) return;
                beta *= Colour(ps.p / ps.pdfW);
                if (!rules_.survive_roulette(bounces, beta, st.density(), sampler)) return;
                ray = Ray{w.p, ps.wo, kInf};
                continue;
            }
            hit = w.isect;
            boundary = w.media;
            dir = w.dir;
        }
        const ShadingPoint sp = make_shading_point(scene, hit, media ? normalize(dir) : ray.d, TransportMode::Importance);
        const Material& m = *sp.material;
        if (m.is_black()) return;
        // Connect this vertex to the camera: a path of `bounces` bounces. After a dispersive
        // interface wl holds the hero alone, and the film's estimator of the splat counts it so.
        if (!m.is_delta()) {
            if (const auto k = camera.connect(sp.p)) {
                const Vec3f wo = sp.frame.to_local(k->wi);
                const Rgb f = m.eval(sp, sp.wi, wo);
                const float camera_pdf = faults_.drop_camera_geometry ? 1.0f : k->pdfW;
                if (!is_black(f)) {
                    const Colour Tr = to_camera(spawn_segment(sp.p, sp.ng, camera.position(), Vec3f(0.0f)),
                                                media ? medium_after(boundary, hit.ng, k->wi, medium) : medium);
                    if (!is_black(Tr)) {
                        const Colour value = power * beta * bsdf_colour(sp, wo, f, wl) * (std::abs(wo.z) * k->We / camera_pdf);
                        splat(out, ctx, k->raster, media ? value * Tr / st.density() : value, wl, invalid);
                    }
                }
            }
        }
        if (!rules_.may_bounce(bounces)) return;
        const auto s = bsdf_sample(sp, sampler.next2d(), wl);
        if (!s) return;
        beta *= bsdf_sample_colour(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        if (wl.secondary_terminated()) beta = hero_lane(beta);
        if (!rules_.survive_roulette(bounces, beta, media ? st.density() : 1.0f, sampler)) return;
        if (media) medium = medium_after(boundary, hit.ng, sp.frame.to_world(s->wo), medium);
        ray = sp.spawn(s->wo);
    }
}

template <class T>
PassCounters LightTracer<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                                           const PassProgress& progress) {
    const size_t paths = ctx.pixel_count(), per_chunk = chunk_size(paths);
    const int chunks = int((paths + per_chunk - 1) / per_chunk);
    std::atomic<uint64_t> rays{0}, invalid{0};
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        pass_.begin(paths, chunks);
        std::atomic<int> chunks_done{0};
        tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& range) {
            for (int c = range.begin(); c != range.end(); ++c) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t chunk_invalid = 0;
                SplatList& out = pass_.chunk(c);
                const size_t end = std::min(paths, size_t(c + 1) * per_chunk);
                for (size_t j = size_t(c) * per_chunk; j < end; ++j) {
                    Sampler sampler(ctx.seed, j, pass, ctx.sampler);
                    trace(ctx, sampler, out, chunk_invalid);
                }
                rays += Scene::rays_traced_by_this_thread() - rays_before;
                invalid += chunk_invalid;
                if (progress) progress((double(k) + double(++chunks_done) / chunks) / count);
            }
        });
        pass_.finish(film, ctx.filter, Vec2f(0.0f, 0.0f));
    }
    return {rays.load(), invalid.load()};
}

template class LightTracer<RgbTransport>;
template class LightTracer<SpectralTransport>;

const IntegratorInfo& light_tracer_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"lt", {"ptracer"}, "light tracing: paths from the lights, every vertex connected to the camera",
                         false, false, path_params(), [](const IntegratorOptions& o) { return make_for_transport<LightTracer>(o); },
                         /*any_camera=*/false};
        i.media = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
