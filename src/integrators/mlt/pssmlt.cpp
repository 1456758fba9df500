// Primary-sample-space Metropolis light transport (Kelemen, Szirmay-Kalos, Antal and Csonka
// 2002) over pt-mis: a path is pt-mis's pixel sample made from a vector of uniform numbers X
// (the first two: the raster position over the whole image; then the lens, the wavelengths in
// spectral mode, and every number the path tracer draws), and Markov chains over X
// (samplers/primary_samples.hpp: large and small steps) visit paths in proportion to their
// scalar contribution I(X) (the luminance of |R|, |G|, |B|, so that I > 0 wherever the path
// carries light). In a scene with participating media the path is volpath's instead (pt-mis
// extended to media: its distances, hero channel and transmittance estimates read the same
// numbers).
//
// The chains, their bootstrap and their splatting are markov_chains.hpp's; each state has one
// stream of numbers and no label.
#include "integrators/mlt/pssmlt.hpp"

#include <algorithm>
#include <cmath>

#include "integrators/common/camera_ray.hpp"
#include "integrators/integrators.hpp"
#include "integrators/path/pt_mis.hpp"
#include "integrators/path/volpath.hpp"

namespace pathlab {

template <class T>
Pssmlt<T>::Pssmlt(const IntegratorOptions& o, ChainFaults faults)
    : options_(limited_to_length(o)),
      rules_(options_),
      chains_(options_, /*streams=*/1, /*labels=*/1, faults),
      volpath_(make_volpath(options_)) {}

template <class T>
ChainSample Pssmlt<T>::evaluate(const RenderContext& ctx, PrimarySamples& state) const {
    Sampler sampler(state);
    const Vec2f raster = raster_anywhere(ctx, sampler.next2d());
    const Ray ray = camera_ray(ctx.camera, raster.x, raster.y, sampler);
    WavelengthsOf<T> wl = T::camera_wavelengths(sampler);
    const auto L = ctx.scene.has_media()
                       ? static_cast<const PixelIntegrator<T>&>(*volpath_).radiance(ctx.scene, ray, sampler, wl)
                       : pt_mis_camera_radiance(ctx.scene, ray, sampler, rules_, wl, false, options_.only_length);
    return chain_sample(raster, film_colour(L, wl));
}

template <class T>
void Pssmlt<T>::prepare(const RenderContext& ctx, const PassProgress&) {
    chains_.prepare(ctx, [this](const RenderContext& c, PrimarySamples& state, int) { return evaluate(c, state); });
}

template <class T>
PassCounters Pssmlt<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    return chains_.render_passes(ctx, film, first, count, progress,
                                 [this](const RenderContext& c, PrimarySamples& state, int) { return evaluate(c, state); });
}

template class Pssmlt<RgbTransport>;
template class Pssmlt<SpectralTransport>;

const IntegratorInfo& pssmlt_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"pssmlt",
                         {},
                         "primary-sample-space Metropolis light transport (Kelemen 2002) over pt-mis (volpath in media): Markov chains of "
                         "large and small steps, expected-value splatting",
                         false,
                         true,
                         path_params(),
                         [](const IntegratorOptions& o) { return make_for_transport<Pssmlt>(o); }};
        i.samples_lights = true;
        i.skips_null_events = true;  // (pt-mis's and volpath's loops)
        i.media = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
