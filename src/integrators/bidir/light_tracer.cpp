#include "integrators/bidir/light_tracer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "integrators/common/light_path_start.hpp"
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

    // Paths of no bounce: the emitter seen by the camera.
    if (hide_emitters_) {
    } else if (flags & kLightSurface) {
        if (const auto k = camera.connect(es->origin)) {
            const float cos_light = dot(es->normal, k->wi);
            if (cos_light > 0 && !scene.occluded(spawn_segment(es->origin, es->normal, camera.position(), Vec3f(0.0f))))
                splat(out, ctx, k->raster, Le * (cos_light * k->We / (choice.pmf * es->pdfA * k->pdfW)), wl, invalid);
        }
    } else if ((flags & kLightInfinite) && !(flags & kLightDeltaDirection)) {
        const Vec2f u = sampler.next2d();
        if (const auto ls = sample_light(*start->light, camera.position(), u)) {
            const auto raster = camera.raster_of(ls->wi);
            if (raster && ls->pdfW > 0 && !scene.occluded(Ray{camera.position(), ls->wi, kInf})) {
                const float cos_lens = dot(ls->wi, camera.forward());
                const Colour seen = light_colour(scene, choice.index, ls->Le, wl);
                splat(out, ctx, *raster, seen * (camera.We(ls->wi) * cos_lens / (choice.pmf * ls->pdfW)), wl, invalid);
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
        if (!scene.intersect(ray, hit)) return;
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d, TransportMode::Importance);
        const Material& m = *sp.material;
        if (m.is_black()) return;
        // Connect this vertex to the camera: a path of `bounces` bounces. After a dispersive
        // interface wl holds the hero alone, and the film's estimator of the splat counts it so.
        if (!m.is_delta()) {
            if (const auto k = camera.connect(sp.p)) {
                const Vec3f wo = sp.frame.to_local(k->wi);
                const Rgb f = m.eval(sp, sp.wi, wo);
                const float camera_pdf = faults_.drop_camera_geometry ? 1.0f : k->pdfW;
                if (!is_black(f) && !scene.occluded(spawn_segment(sp.p, sp.ng, camera.position(), Vec3f(0.0f))))
                    splat(out, ctx, k->raster, power * beta * bsdf_colour(sp, wo, f, wl) * (std::abs(wo.z) * k->We / camera_pdf), wl, invalid);
            }
        }
        if (!rules_.may_bounce(bounces)) return;
        const auto s = bsdf_sample(sp, sampler.next2d(), wl);
        if (!s) return;
        beta *= bsdf_sample_colour(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        if (wl.secondary_terminated()) beta = hero_lane(beta);
        if (!rules_.survive_roulette(bounces, beta, sampler)) return;
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
    static const IntegratorInfo info{"lt", {"ptracer"}, "light tracing: paths from the lights, every vertex connected to the camera",
                                     false, false, path_params(), [](const IntegratorOptions& o) { return make_for_transport<LightTracer>(o); },
                                     /*any_camera=*/false};
    return info;
}

}  // namespace pathlab
