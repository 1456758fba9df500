// lt (alias ptracer, Mitsuba 3's name): light tracing, the adjoint of path tracing. Paths
// start on the lights (emission sampling, light chosen by power) and scatter with the adjoint
// BSDF (importance transport, bsdfs/bsdf_context.hpp); every vertex whose BSDF is not purely
// specular is connected to the camera with a shadow ray and its contribution
//   beta f*(wi, w_camera) |cos at the vertex| We / pdfW_camera
// (pdfW_camera = d^2 / cos at the lens, cameras/camera.hpp) is splatted onto the pixel it
// projects to. Emitters seen directly are found by connecting the emission point itself to
// the camera (Le cos_light We / (pmf pdfA pdfW_camera)); for the environment, which has no
// point, a direction is sampled from the camera instead (as Mitsuba 3's ptracer does). Point
// and directional lights are not visible to the camera, as in the path tracers.
//
// One pass traces one light path per pixel (w x h paths), so the pixel estimate of a pass is
// simply the sum of its splats (We is normalised over the whole image). Depth: connecting the
// k-th surface hit after the light gives a path of k bounces, allowed when k <= max_depth, as
// the path tracers count. Russian roulette acts on the scattering throughput only (beta
// without the emitted power), by the path tracers' rule.
//
// In participating media the path also scatters in them (by the phase function) and connects
// those points to the camera; every connection carries its segment's transmittance, estimated
// as volpath estimates a shadow ray's (docs/volumes.md).
//
// By design, pixels whose first vertex seen from the camera is specular (a mirror, glass, the
// coating of plastic) miss that part: no light path can connect through a Dirac lobe to a
// pinhole. `pathlab check` reports such pixels as black by design.
#pragma once

#include "integrators/common/path_rules.hpp"
#include "integrators/integrator.hpp"
#include "render/pass_image.hpp"

namespace pathlab {

// Deliberate faults, for the tests that must be able to fail (never set by pathlab itself).
struct LightTracerFaults {
    bool drop_camera_geometry = false;  // leave out cos at the lens / d^2 (pdfW_camera)
    bool drop_emission_pdf = false;     // leave out 1 / (pdfA pdfW) of the emission sample
};

template <class T>
class LightTracer final : public Integrator {
public:
    explicit LightTracer(const IntegratorOptions& options, LightTracerFaults faults = {})
        : rules_(options), faults_(faults), hide_emitters_(options.hide_emitters) {}

    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                               const PassProgress& progress) override;

    // One light path: splats its contributions (pixel, value) into `out`; counts NaN/Inf ones.
    // In spectral mode the path draws its own wavelengths (from the stream of a camera sample's,
    // forked from its sampler) and each splat is the film's estimator of its value.
    void trace(const RenderContext& ctx, Sampler& sampler, SplatList& out, uint64_t& invalid) const;

    // Light paths per chunk of a pass: a function of the pass size only, so that chunking (and
    // with it the order in which splats are added) never depends on the thread count.
    static size_t chunk_size(size_t paths) { return std::max<size_t>(16, paths / 64); }

private:
    PathRules rules_;
    LightTracerFaults faults_;
    bool hide_emitters_ = false;
    PassImage pass_;
};
extern template class LightTracer<RgbTransport>;
extern template class LightTracer<SpectralTransport>;

}  // namespace pathlab
