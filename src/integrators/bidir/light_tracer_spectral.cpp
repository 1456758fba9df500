// The light tracer in spectral mode (docs/spectral.md, "Spectral bdpt and the light tracer"):
// LightTracer::trace's path (the same random numbers in the same order, roulette on the largest
// lane), carrying a spectral throughput. A copy of the loop in its own file, as pt-mis's, so that
// RGB mode's translation unit compiles as before.
#include "integrators/bidir/hero_only.hpp"
#include "integrators/bidir/light_tracer.hpp"
#include "integrators/common/light_path_start.hpp"
#include "integrators/common/spectral_shading.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab {
namespace {

// One contribution at the path's wavelengths, converted by the film's estimator.
void splat_spectral(SplatList& out, const RenderContext& ctx, const Vec2f& raster, const Spectrum4& value, const SampledWavelengths& wl,
                    uint64_t& invalid) {
    if (!value.is_finite()) {
        ++invalid;
        return;
    }
    if (value.is_black()) return;
    const Rgb rgb(spectral_sample_to_linear_srgb(value, wl));
    if (ctx.filter && !ctx.filter->is_box()) out.add_at(raster, rgb);
    else out.add(uint32_t(ctx.camera.pixel_of(raster)), rgb);
}

}  // namespace

void LightTracer::trace_spectral(const RenderContext& ctx, Sampler& sampler, SplatList& out, uint64_t& invalid) const {
    const Scene& scene = ctx.scene;
    const PerspectiveCamera& camera = ctx.camera;
    // The path's own wavelengths, from a stream RGB mode never reads (the camera samples' one,
    // forked from this path's sampler): a pure function of (seed, path, pass).
    SampledWavelengths wl = sample_camera_wavelengths(sampler);
    const auto start = start_light_path(scene, sampler);
    if (!start) return;
    const LightChoice& choice = start->choice;
    const Light& light = *start->light;
    const EmissionSample* es = &start->emission;
    const uint32_t flags = start->flags;
    const Spectrum4 Le = emission_spectrum(scene, choice.index, es->Le, wl);

    // Paths of no bounce: the emitter seen by the camera.
    if (hide_emitters_) {
    } else if (flags & kLightSurface) {
        if (const auto k = camera.connect(es->origin)) {
            const float cos_light = dot(es->normal, k->wi);
            if (cos_light > 0 && !scene.occluded(spawn_segment(es->origin, es->normal, camera.position(), Vec3f(0.0f))))
                splat_spectral(out, ctx, k->raster, Le * (cos_light * k->We / (choice.pmf * es->pdfA * k->pdfW)), wl, invalid);
        }
    } else if ((flags & kLightInfinite) && !(flags & kLightDeltaDirection)) {
        const Vec2f u = sampler.next2d();
        if (const auto ls = sample_light(light, camera.position(), u)) {
            const auto raster = camera.raster_of(ls->wi);
            if (raster && ls->pdfW > 0 && !scene.occluded(Ray{camera.position(), ls->wi, kInf})) {
                const float cos_lens = dot(ls->wi, camera.forward());
                const Spectrum4 seen = emission_spectrum(scene, choice.index, ls->Le, wl);
                splat_spectral(out, ctx, *raster, seen * (camera.We(ls->wi) * cos_lens / (choice.pmf * ls->pdfW)), wl, invalid);
            }
        }
    }

    // The emitted power this path carries, and its scattering throughput (for roulette).
    const float emission_pdf = faults_.drop_emission_pdf ? 1.0f : es->pdfA * es->pdfW;
    const Spectrum4 power = Le * (es->cos / (choice.pmf * emission_pdf));
    Spectrum4 beta(1.0f);
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
                const Rgb f_rgb = m.eval(sp, sp.wi, wo);
                const float camera_pdf = faults_.drop_camera_geometry ? 1.0f : k->pdfW;
                if (!is_black(f_rgb) && !scene.occluded(spawn_segment(sp.p, sp.ng, camera.position(), Vec3f(0.0f)))) {
                    const Spectrum4 f = spectral_eval(sp, wo, f_rgb, wl);
                    splat_spectral(out, ctx, k->raster, power * beta * f * (std::abs(wo.z) * k->We / camera_pdf), wl, invalid);
                }
            }
        }
        if (!rules_.may_bounce(bounces)) return;
        const auto s = spectral_sample(sp, sampler.next2d(), wl);
        if (!s) return;
        beta *= spectral_sample_value(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        // The other lanes' light went elsewhere: their values no longer mean anything (and
        // must not keep the path alive in the roulette).
        if (wl.secondary_terminated()) beta = Spectrum4(beta[0], 0.0f, 0.0f, 0.0f);
        if (!rules_.survive_roulette(bounces, beta, sampler)) return;
        ray = sp.spawn(s->wo);
    }
}

}  // namespace pathlab
