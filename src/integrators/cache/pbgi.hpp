// pbgi: point-based global illumination (Christensen 2008, "Point-based approximate color
// bleeding", Pixar technical memo 08-01) for the indirect diffuse light at the camera rays'
// first hits; the rest as ic does it (first_hit.hpp: direct light by pt-mis's MIS pair, the
// Phong lobe's indirect light and every other material by pt-mis).
//
// Before the first pass (prepare), deterministically:
//  1. the surfel cloud (surfels.hpp): about --pbgi-surfels disks over every surface, each side's
//     diffusely reflected direct light estimated by --pbgi-direct-samples MIS pairs;
//  2. the octree with each cluster's spherical-harmonic aggregate (surfel_tree.hpp);
//  3. --pbgi-bounces > 1: the cloud's radiance iterated (Christensen's multiple bounces): every
//     surfel side gathers from the cloud, L = L_direct + rho_d / pi E, the aggregates are remade;
//     bounce b adds the light of b surfel-to-surfel reflections (Jacobi: all from the previous);
//  4. gathers (micro-buffer, cutoff --pbgi-cutoff) at the first hits through every
//     --pbgi-spacing-th pixel corner, a grid like a REYES grid's vertices (shading rate).
// During the render a first hit's indirect irradiance is the bilinear interpolation of the four
// grid gathers around the sample's position in the image, over the corners that lie on
// the same surface (normals within 18 degrees, the corner within 3 degrees of the tangent plane),
// and a gather of its own where none does (silhouettes). The gathers have no noise: the surfels'
// direct-light noise is fixed by the seed, and pbgi converges to its own biased image.
// Spectral mode: the cloud and its gathers hold RGB; a first hit sees the gathered irradiance as
// an emitter's RGB is seen (illuminant_colour), as ic does (ic.hpp).
#pragma once

#include <atomic>
#include <optional>

#include "cameras/camera.hpp"
#include "integrators/cache/surfel_tree.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/common/shading.hpp"
#include "integrators/integrator.hpp"

namespace pathlab {

template <class T>
class PointBasedGi final : public PixelIntegrator<T> {
public:
    explicit PointBasedGi(const IntegratorOptions& options, SurfelTreeFaults faults = {});

    void prepare(const RenderContext& ctx, const PassProgress& progress) override;
    ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const override;
    std::vector<IntegratorStatistic> statistics() const override;

    // The indirect irradiance at the first hit sp of the camera ray with direction d.
    Rgb indirect_irradiance(const ShadingPoint& sp, const Vec3f& d) const;
    const SurfelTree& tree() const { return tree_; }
    const GatherSettings& gather_settings() const { return settings_; }
    // Bounces the cloud carries (--pbgi-bounces, cut so that no path is longer than --max-depth).
    int bounces() const;

private:
    struct Corner {
        Vec3f p{0.0f}, n{0.0f};
        Rgb E{0.0f};
        bool valid = false;
    };

    IntegratorOptions options_;
    PathRules rules_;
    SurfelTreeFaults faults_;
    GatherSettings settings_;
    SurfelTree tree_;
    std::vector<Corner> corners_;  // grid_width_ x grid_height_, row-major
    std::optional<PerspectiveCamera> camera_;
    int width_ = 0, height_ = 0;
    int spacing_ = 1, grid_width_ = 0, grid_height_ = 0;
    double surfel_seconds_ = 0, gather_seconds_ = 0;
    mutable std::atomic<uint64_t> own_gathers_{0};
    GatherCounters corner_counters_;
    const Scene* prepared_scene_ = nullptr;
    uint64_t prepared_seed_ = 0;
};
extern template class PointBasedGi<RgbTransport>;
extern template class PointBasedGi<SpectralTransport>;

}  // namespace pathlab
