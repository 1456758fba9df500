// pm: photon mapping as Jensen teaches it (Realistic Image Synthesis Using Photon Mapping, 2001),
// two passes:
//   1. photon pass (once, when the render starts): --photons light paths (default 8 per pixel)
//      from the lights' emission sampling with the adjoint BSDFs; every non-Dirac surface hit is
//      a photon of the global map, and those reached only through Dirac lobes (L S+ D paths)
//      also of the caustic map. Each photon carries its path's throughput / the path count.
//   2. rendering, per pixel sample: the camera path is followed through Dirac lobes to its first
//      other surface x, which adds the emission found on the way, direct light (a light sample
//      and a BSDF sample, by the balance heuristic), caustics from the caustic map's radiance estimate at x, and the
//      rest by one-bounce final gathering: one BSDF-sampled ray from x, followed through Dirac
//      lobes, and the global map's radiance estimate where it lands.
// Radiance estimate: the k nearest photons (k = 50 for the global map, 20 for the caustic map)
// and the disc of the k-th's distance r: L = sum over the k - 1 nearer ones of f(wo, wi_p)
// power_p / (pi r^2) (with the k-th in the sum, as Jensen writes it, a uniform density comes
// out k / (k - 1) too bright: measured, 2% in scene 2); with --radius R a fixed radius instead. Both maps are nanoflann k-d trees (the k-nearest search is theirs).
//
// pm is biased (the density estimate blurs the light over r) and consistent only as the photon
// count grows: its bias at a photon count is measured (tests, README), not hidden. --max-depth
// limits each photon's light path and the camera path to the gather point; the estimates count a
// photon only if the whole path it makes stays within the depth (the k-th distance is still that
// of all photons).
//
// Participating media (docs/volumes.md "Photon methods in media"), as Jensen and Christensen
// (1998) add them: light paths scatter in media as bdpt's subpaths do (light_subpath), and every
// light vertex in a medium is a photon of a third map, the volume map; the camera path walks
// through media as sppm's does, with one of two volumetric estimates (--volume-estimate):
//   points  the camera path scatters in media by distance sampling (as volpath). At a first
//           scattering point x in a medium: direct light by volpath's MIS pair, and the rest from
//           the volume map's photons after at least one bounce (j >= 2): the 50 nearest and the
//           ball of the 50th's distance r, L = sum of phase(x, wo, wi_p) power_p / (sigma_s(x)
//           4/3 pi r^3) (a photon's power includes sigma_s at its own point, as the camera
//           path's throughput does at x: the path's, once);
//   beam    (the default) the camera rays do not scatter in media: along every piece of a
//           camera ray through a medium the beam radiance estimate of Jarosz, Zwicker and
//           Jensen (2008) sums the volume map's photons (all, j >= 1: no light sample there)
//           whose balls the ray passes through, each ball of the radius of its photon's 16 nearest
//           neighbours: L = sum of Tr(s_p) phase(wo, wi_p) power_p / (pi r_p^2).
// At a surface x the caustic map and the direct light are as before, and the gathering ray walks
// through the media the same way: with beams it gathers along its pieces; with points it may
// scatter at z in a medium, where the volume map's estimate takes every photon (j >= 1). The
// photons' subpaths and the camera path each draw their own hero channel, and each divides by
// its own channels' mean density (the product of two independent estimates is the path's).
//
// Spectral mode (docs/spectral.md "Spectral photon mapping"): photons and camera paths must carry
// the same wavelengths, and maps built once at fixed wavelengths would fix every pass's colour
// sampling too, an error more passes never remove. So each pass draws its wavelengths
// (SpectralTransport::pass_wavelengths), traces pm's full photon count at them (the same light
// paths, each pass from its own sample index) and builds both maps anew before its camera
// samples; RGB mode builds them once, before the first pass (its colour is every pass's). The
// estimator per pass is RGB pm's, with the same bias at a photon count; the price is the photon
// pass in every pass.
#pragma once

#include <vector>

#include "integrators/bidir/bdpt.hpp"
#include "integrators/common/media_lighting.hpp"
#include "integrators/integrator.hpp"
#include "integrators/photon/ball_tree.hpp"
#include "integrators/photon/photon.hpp"
#include "integrators/photon/photon_grid.hpp"
#include "media/free_flight.hpp"

namespace pathlab {

struct PmFaults {
    bool no_pi_in_kernel = false;  // the radiance estimate divides by r^2 instead of pi r^2
    bool volume_kernel_as_disc = false;  // in a medium the points' estimate divides by pi r^2 (the surfaces' kernel)
    bool beam_without_transmittance = false;  // a beam's photons are not attenuated on their way to the camera
};

template <class T>
class PhotonMapper final : public Integrator {
public:
    explicit PhotonMapper(const IntegratorOptions& options, PmFaults faults = {});

    void prepare(const RenderContext& ctx, const PassProgress& progress = {}) override;
    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) override;
    std::vector<IntegratorStatistic> statistics() const override;

    // One camera sample's radiance at the wavelengths of the current maps.
    ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const;

    size_t global_photons() const { return global_.size(); }
    size_t caustic_photons() const { return caustic_.size(); }
    size_t volume_photons() const { return volume_.size(); }

private:
    // The maps from the light paths of sample index `pass` at the wavelengths wl; returns the rays traced.
    uint64_t build_maps(const RenderContext& ctx, uint64_t pass, const WavelengthsOf<T>& wl, const PassProgress& progress);
    // The radiance estimate of `map` at the surface point sp (camera vertex t) for its wi.
    ColourOf<T> estimate(const std::vector<Photon<T>>& photons, const PhotonKdTree& map, size_t k, const ShadingPoint& sp, int t,
                         const WavelengthsOf<T>& wl) const;
    // radiance() in a scene with media.
    ColourOf<T> radiance_in_media(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const;
    // The volume map's estimate at the point v in a medium (camera vertex t) from the photons at
    // light vertices first_vertex and on (the points' estimate).
    ColourOf<T> volume_estimate(const Scene& scene, const ScatterVertex& v, int t, int first_vertex, const WavelengthsOf<T>& wl) const;
    // The beam radiance estimate along o + s d, s in [0, tmax), in `medium` (its phase function,
    // the transmittance from o along the ray), the camera path's vertex t being on it.
    ColourOf<T> beam_estimate(const Vec3f& o, const Vec3f& d, float tmax, int32_t medium, const TransmittanceTrack<ColourOf<T>>& Tr,
                              const PhaseFunction& phase, int t, const WavelengthsOf<T>& wl) const;

    IntegratorOptions options_;
    PmFaults faults_;
    int max_bounces_;
    Bdpt<T> light_paths_;
    std::vector<std::vector<Photon<T>>> chunk_global_, chunk_caustic_, chunk_volume_;
    std::vector<Photon<T>> global_, caustic_, volume_;
    PhotonKdTree global_map_, caustic_map_, volume_map_;
    BallTree volume_balls_;  // beams: each volume photon's ball
    const Scene* prepared_scene_ = nullptr;  // RGB mode: the maps were made for this scene and seed
    uint64_t prepared_seed_ = 0;
    std::vector<Vec3d> lattice_, filtered_;  // a filtered pass (pixel_filter.hpp)
};
extern template class PhotonMapper<RgbTransport>;
extern template class PhotonMapper<SpectralTransport>;

}  // namespace pathlab
