// volpath: volumetric path tracing. pt-mis's loop (its MIS pair of a light sample and a
// BSDF sample at every surface, the BSDF sample continuing the path) with participating media:
//  - every ray walks through media and index-matched boundaries (walk_media(), common/media_walk.hpp): in a medium it may
//    scatter, sampled by delta tracking (free-flight sampling, media/medium.hpp), and a
//    boundary only changes the medium; it ends at a scattering point, a surface or the sky;
//  - at a scattering point the phase function plays the BSDF's part: a light sample and a
//    phase sample, combined by the balance heuristic (--mis power: the power heuristic, as
//    Mitsuba 3's volpath), the phase sample continuing the path;
//  - a light sample's shadow ray crosses boundaries and media too, and its contribution is
//    multiplied by their transmittance (closed form, or ratio tracking in grids), estimated
//    with the random numbers of a second stream;
//  - under --null-depth skip (Mitsuba's volpath, and a scene file's <integrator type="volpath">) a
//    straight pass through thin glass or a mask's hole is no bounce, light samples' shadow rays
//    pass such surfaces times their null transmission, and emission found past them is weighed
//    against light sampling at the vertex before them (MisOrigin);
//  - a hero channel drives distance sampling, with spectral MIS over the channels (beta /
//    path_density(r), media/medium.hpp): in RGB one of the three chosen per path, in spectral
//    mode the hero wavelength (media/spectral_medium.hpp); Russian roulette on that ratio.
// Media's random numbers (the hero channel, distances, ratio tracking) come from a fork of the
// sample's stream (Sampler::fork), so a path that meets no medium draws exactly pt-mis's
// numbers in pt-mis's order and does pt-mis's arithmetic: in a scene without media volpath's
// image is pt-mis's, bit for bit (tests/test_volumes.cpp), in RGB and in spectral mode.
#include "integrators/path/volpath.hpp"

#include <optional>

#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/media_lighting.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/path/pt_mis.hpp"

namespace pathlab {
namespace {

template <class T>
class Volpath final : public PixelIntegrator<T> {
public:
    using Colour = ColourOf<T>;

    Volpath(const IntegratorOptions& o, VolpathSettings s) : rules_(o), settings_(s) {}

    Colour radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, WavelengthsOf<T>& wl) const override {
        // pt-mis's own loop: the same image, pt-mis's speed (not under --null-depth skip, whose shadow rays pass thin glass)
        if (!scene.has_media() && settings_.pt_mis_without_media && !rules_.skips_null()) {
            Intersection hit;
            if (!scene.intersect(camera_ray, hit)) return rules_.hides_emitters() ? Colour(0.0f) : escaped_radiance(scene, camera_ray.d, wl);
            const Colour emitted = rules_.hides_emitters() ? Colour(0.0f) : emitted_radiance(scene, hit, -camera_ray.d, wl);
            return pt_mis_from_hit(scene, hit, camera_ray.d, 0, sampler, rules_, wl, false, -1, emitted);
        }
        const bool mis = settings_.mis;
        MediumState<T> st{sampler, wl, settings_.majorant_factor};
        st.pass_null = rules_.skips_null();
        MisOrigin origin;  // where the path last scattered (the camera: a delta)
        Colour seg(1.0f);
        MediumWalk w = walk_media(scene, camera_ray, scene.camera_medium(), st, seg);
        Colour beta = seg;
        // What the camera sees directly (pt-mis: L starts as the emission at the first hit).
        Colour L(0.0f);
        // (hide_emitters: not the emitters and the sky seen directly, also through media.)
        if (w.kind == MediumWalk::kEscaped) return rules_.hides_emitters() ? Colour(0.0f) : beta * escaped_radiance(scene, w.dir, wl) / st.density();
        if (w.kind == MediumWalk::kSurface && !rules_.hides_emitters()) L = beta * emitted_radiance(scene, w.isect, -w.dir, wl) / st.density();
        // `bounces`: those made before the vertex w reached. At the depth limit a path under
        // --null-depth skip may still pass straight through surfaces (kLobeNull), and nothing else.
        for (int bounces = 0, step = 0; w.kind != MediumWalk::kLost && step < kMaxBounces; ++step) {
            const bool may_scatter = rules_.may_bounce(bounces);
            if (!may_scatter && !(rules_.skips_null() && w.kind == MediumWalk::kSurface)) break;
            ScatterVertex v;
            v.medium = w.medium;
            ShadingPoint sp;
            if (w.kind == MediumWalk::kSurface) {
                sp = make_shading_point(scene, w.isect, w.dir);
                if (!may_scatter && !(sp.material->lobes() & kLobeNull)) break;
                if (sp.material->is_black()) break;
                v.sp = &sp;
                v.hit = &w;
                v.p = sp.p;
            } else {
                if (FirstVertexRecorder* r = t_first_vertex) [[unlikely]]  // a camera sample with --aovs
                    offer_medium_vertex(*r, scene, w.medium, w.p);
                v.p = w.p;
                v.wi = -w.dir / length(w.dir);
                v.phase = &medium_phase(scene.medium(w.medium));
            }
            // The MIS pair: a light sample, and a BSDF or phase sample whose walk may find emission.
            if (may_scatter) {
                const Colour direct = estimate_light(scene, v, sampler, st, mis, wl, rules_.power_mis(), {}, nullptr, /*split=*/bounces == 0);
                L += beta * direct / st.density();
            }

            const ScatterSample<T> n = sample_scatter(scene, v, sampler, st, mis, wl, rules_.power_mis(), st.pass_null ? &origin : nullptr, {},
                                                      /*split=*/bounces == 0);
            if (!n.sampled) break;  // pt-mis: no BSDF sample, nothing found, and the path ends
            const bool bounce = rules_.is_bounce(n.lobe);
            if (bounce) origin = MisOrigin{v.p, v.sp ? v.sp->frame.n : Vec3f(0.0f), n.pdf, n.delta, bounces == 0};
            if (!may_scatter && bounce) break;  // a scattering past the depth limit
            if (!(rules_.hides_emitters() && bounces == 0 && !bounce)) L += beta * n.next_seg * n.found / st.density();
            const MediumWalk& next = n.next;
            const Colour& next_seg = n.next_seg;
            const Colour& weight_next = n.weight;
            if (!rules_.skips_null() && !rules_.may_bounce(bounces + 1)) break;
            if (next.kind == MediumWalk::kEscaped || next.kind == MediumWalk::kLost) break;
            beta = beta * next_seg * weight_next;
            if (bounce && !rules_.survive_roulette(bounces + 1, beta, st.density(), sampler)) break;
            bounces += bounce ? 1 : 0;
            w = next;
        }
        return L;
    }

private:
    PathRules rules_;
    VolpathSettings settings_;
};

}  // namespace

std::unique_ptr<Integrator> make_volpath(const IntegratorOptions& options, VolpathSettings settings) {
    return make_for_transport<Volpath>(options, settings);
}

const IntegratorInfo& volpath_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"volpath", {"volpathmis"}, "volumetric path tracing: participating media, delta tracking, MIS",
                         false, true, path_params(), [](const IntegratorOptions& o) { return make_volpath(o); }};
        i.media = true;
        i.samples_lights = true;
        i.skips_null_events = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
