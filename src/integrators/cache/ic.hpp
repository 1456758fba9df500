// ic: irradiance caching (Ward, Rubinstein and Clear 1988) with irradiance gradients (Ward and
// Heckbert 1992), for the indirect diffuse light at the camera rays' first hits.
//
// At a camera ray's first hit x on a Phong surface with rho_d > 0 it adds the emission, the direct
// light by pt-mis's MIS pair, rho_d / pi E_indirect(x) from the cache, and the Phong lobe's
// indirect light by the same BSDF sample (first_hit.hpp); elsewhere it is pt-mis.
//
// The cache is built before the first pass (prepare), deterministically: the pixel centres are
// visited coarse to fine (every 8th pixel, then every 4th, 2nd, each), and at each level the
// first hits that no record covers get a record (gathered in parallel, M x N = --ic-rays
// stratified rays whose radiance pt-mis estimates, irradiance_record.hpp), added in pixel order
// unless a record added before them in that order covers them. Radii: the harmonic mean distance,
// clamped so that the influence radius a R lies between 1.5 and 20 pixel footprints at the
// record (Tabellion and Lamorlette's screen-space limits), cut to E / |grad_t E| (Křivánek et al.:
// the gradient's limit) and to the neighbours' R_j + |p_i - p_j| (neighbour clamping). During the
// render the cache is only read: a first hit that no record covers (jittered samples near edges)
// gets one gather ray, pi L, unbiased and noisier. --ic-error 0 makes that every point's gather:
// ic is then pt-mis with one diffuse gather ray.
//
// Spectral mode (docs/spectral.md "Spectral ic and pbgi"): exact at the wavelengths are the first
// hit's emission and direct light, the Phong lobe's indirect light, pt-mis wherever the cache does
// not serve, and the gather ray where no record covers a point. Approximated: the cached indirect
// irradiance, which the cache holds in RGB (records gathered in RGB), is seen as an emitter's RGB
// is (illuminant_colour), so its film colour is the cached RGB (to the table's error) but its
// spectral shape is a guess.
#pragma once

#include "integrators/cache/irradiance_cache.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/common/shading.hpp"
#include "integrators/integrator.hpp"

namespace pathlab {

template <class T>
class IrradianceCaching final : public PixelIntegrator<T> {
public:
    explicit IrradianceCaching(const IntegratorOptions& options);

    void prepare(const RenderContext& ctx, const PassProgress& progress) override;
    ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const override;
    void finish(const RenderContext& ctx) override;
    std::vector<IntegratorStatistic> statistics() const override;

    // A record gathered at sp (clamped as the cache's are; the clamps need prepare()'s camera).
    IrradianceRecord make_record(const Scene& scene, const ShadingPoint& sp, Sampler& sampler) const;
    // The indirect irradiance at the first hit sp: interpolated from the cache, else one gather ray.
    ColourOf<T> indirect_irradiance(const Scene& scene, const ShadingPoint& sp, Sampler& sampler, WavelengthsOf<T>& wl) const;
    const IrradianceCache& cache() const { return cache_; }
    // The hemisphere's strata: M in theta, N in phi (M N close to --ic-rays, N about pi M).
    int strata_theta() const { return M_; }
    int strata_phi() const { return N_; }

private:
    float footprint(const Vec3f& p) const;  // a pixel's width at p
    void clamp_radius(IrradianceRecord& r, float scene_radius) const;

    IntegratorOptions options_;
    PathRules rules_;
    IrradianceCache cache_;
    int M_, N_;
    Vec3f camera_position_{0.0f};
    float pixel_angle_ = 0;
    double build_seconds_ = 0;
    uint64_t gathered_ = 0;  // records gathered (some were covered by earlier ones and dropped)
    PreparedFor prepared_;
};
extern template class IrradianceCaching<RgbTransport>;
extern template class IrradianceCaching<SpectralTransport>;

}  // namespace pathlab
