// sppm: stochastic progressive photon mapping (Hachisuka and Jensen 2009) in Knaus and
// Zwicker's probabilistic formulation (2011): every pass is an independent iteration with its
// own radius r_i, r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1), so the image, the average of the
// iterations' images, converges (bias and variance both vanish) for 0 < alpha < 1, and a render
// split into parts gives the same result as one (the radius depends only on the pass index).
//
// An iteration: N light paths (--photons, default one per pixel) traced with the light
// interface's emission sampling and the adjoint BSDFs, one photon stored wherever a path
// meets a non-Dirac surface after at least one bounce (y_2, y_3, ...: direct light is next-event
// estimation's); then per pixel one camera path, followed through Dirac lobes (mirrors, glass,
// plastic's coating) to its first other surface x (the visible point), which adds the emission
// found on the way, direct light (a light sample and a BSDF sample, by the balance heuristic:
// light sampling alone has infinite variance next to an area light) and the density estimate
//   L(x, wo) = sum over photons p within r_i of f(x, wo, wi_p) power_p / (N pi r_i^2).
// Depth: a photon at light vertex j merged at camera vertex t makes a path of t + j - 1 bounces,
// which must not exceed --max-depth, so sppm converges to the path tracers' image at any depth.
//
// The initial radius (--radius, default: two pixel footprints at the distance of the scene's
// centre, so that the blur starts at the scale of a pixel whatever the resolution) and alpha
// (--alpha, default 2/3) trade bias against noise early on; the result converges for any. The photons are searched with a hashed grid (photon_grid.hpp; measured
// against a k-d tree in README). Deterministic: photons are stored in chunk order, and every
// pixel sums its photons in the grid's fixed order.
//
// Participating media (docs/volumes.md "Photon methods in media"): the light paths scatter in
// media as bdpt's subpaths do (light_subpath), and a light vertex in a medium is a photon too. The
// camera path walks through the media (delta tracking, as volpath) to its first scattering point
// that is not a Dirac surface: on a surface as before, or in a medium, where direct light is
// volpath's MIS pair (a light sample with its shadow ray's transmittance, a phase sample) and the
// rest comes from the photons in media within the ball of radius r_i (the 3D kernel):
//   L = sum of phase(x, wo, wi_p) power_p / (sigma_s(x) N 4/3 pi r_i^3)
// (a photon's power includes sigma_s at its own point, as the camera path's throughput does at x:
// the path's, once). Surface photons are gathered at surface points only, medium photons at
// medium points only. Every path of an iteration shares one hero channel (RGB; spectrally the
// pass's hero wavelength), and a gathered photon's contribution is divided by the channels' mean
// of the product of both subpaths' distance densities (media/medium.hpp), as vcm's merges.
//
// Spectral mode (docs/spectral.md "Spectral photon mapping"): a merge multiplies a camera path's
// throughput by a photon's power lane by lane, so every path of a pass, camera and light, carries
// the pass's wavelengths (SpectralTransport::pass_wavelengths); each pixel's pass sample is
// converted by the film's estimator with its camera path's wavelengths.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <memory>
#include <vector>

#include "integrators/bidir/bdpt.hpp"
#include "integrators/common/media_lighting.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/integrator.hpp"
#include "integrators/photon/photon.hpp"
#include "integrators/photon/photon_grid.hpp"

namespace pathlab {

// Deliberate faults, for the tests that must be able to fail.
struct SppmFaults {
    bool no_pi_in_kernel = false;  // the density estimate divides by r^2 instead of pi r^2
    bool volume_kernel_as_disc = false;  // in a medium it divides by N pi r^2 (the surfaces' kernel)
    bool beam_without_transmittance = false;  // a beam's photons are not attenuated on their way to the camera
};

// How the camera rays are chosen: sppm jitters them over the pixel anew in every iteration (so
// the image integrates the pixel's footprint: antialiasing, and glossy and Dirac choices
// resampled); ppm (Hachisuka, Ogaki and Jensen 2008) sends them through the pixel centres, the
// eye pass of the paper, whose hit points then stay where they are (the Dirac choices along the
// way are drawn anew per iteration, in place of the paper's ray tree; the expectation is the
// same). ppm converges to the radiance through the pixel centres, without antialiasing. Both
// reduce the radius as Knaus and Zwicker do (a global radius per iteration rather than the
// paper's per-hit-point photon statistics), which keeps iterations independent.
enum class CameraRays { Jittered, PixelCentres };

template <class T>
class Sppm final : public Integrator {
public:
    explicit Sppm(const IntegratorOptions& options, SppmFaults faults = {}, CameraRays rays = CameraRays::Jittered);

    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                               const PassProgress& progress) override;

    // The radius of iteration i (1-based) for the initial radius r1.
    static double radius(double r1, double alpha, uint64_t i);
    float initial_radius(const RenderContext& ctx) const;

private:
    // The photons of one iteration into photons_ (and, in media, their subpaths' distance
    // densities into photon_r_), in chunk order; returns the rays traced.
    uint64_t trace_photons(const RenderContext& ctx, uint64_t pass, size_t paths, const WavelengthsOf<T>& wl, int hero);
    // The camera ray of a pixel: jittered (sppm) or through its centre (ppm).
    Ray pixel_ray(const RenderContext& ctx, size_t pixel, Sampler& sampler) const;
    // One pixel's sample of the iteration, as the film's colour.
    Vec3d camera_sample(const RenderContext& ctx, size_t pixel, uint64_t pass, float r, size_t paths, const WavelengthsOf<T>& pass_wl) const;
    // The same in a scene with media (the iteration's hero channel).
    Vec3d camera_sample_in_media(const RenderContext& ctx, size_t pixel, uint64_t pass, float r, size_t paths,
                                 const WavelengthsOf<T>& pass_wl, int hero) const;
    // The photons' estimate at a visible point v (on the surface sp, or in a medium: the 3D
    // kernel) reached as camera vertex t with the distance densities r_camera, without its throughput.
    ColourOf<T> gather(const Scene& scene, const ScatterVertex& v, const ShadingPoint& sp, const ColourOf<T>& r_camera, int t, float r,
                       size_t paths, const WavelengthsOf<T>& wl) const;
    // The beam radiance estimate along o + s d, s in [0, tmax), in `medium` (its phase function,
    // the transmittance from o along the ray), the camera path's vertex t being on it.
    ColourOf<T> beam(const Vec3f& o, const Vec3f& d, float tmax, int32_t medium, const TransmittanceTrack<ColourOf<T>>& Tr,
                     const PhaseFunction& phase, int t, float r, size_t paths, const WavelengthsOf<T>& wl) const;
    // Whether paths of this many bounces count (all, or one length only).
    bool counts(int length) const { return length_counts(options_, length); }

    IntegratorOptions options_;
    SppmFaults faults_;
    CameraRays rays_;
    int max_bounces_;
    Bdpt<T> light_paths_;  // its light subpaths are the photon paths
    std::vector<std::vector<Photon<T>>> chunk_photons_;
    std::vector<std::vector<ColourOf<T>>> chunk_r_;
    std::vector<Photon<T>> photons_;
    std::vector<ColourOf<T>> photon_r_;  // in media: each photon's light subpath's distance densities (PathVertex::r)
    size_t medium_photons_ = 0;          // how many photons lie in media, and their bounds
    Vec3f medium_lo_{0.0f}, medium_hi_{0.0f};
    PhotonGrid grid_;
    const Scene* checked_scene_ = nullptr;  // the photons' memory was checked for it (check_photon_memory)
    tbb::enumerable_thread_specific<std::vector<PathVertex<T>>> paths_;  // each thread's light subpath
    std::vector<Vec3d> image_;                                           // one iteration's image
};
extern template class Sppm<RgbTransport>;
extern template class Sppm<SpectralTransport>;

}  // namespace pathlab
