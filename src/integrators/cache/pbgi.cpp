#include "integrators/cache/pbgi.hpp"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>

#include "integrators/cache/first_hit.hpp"
#include "integrators/integrators.hpp"

namespace pathlab {
namespace {

constexpr float kBounceCutoff = 0.1f;

}  // namespace

template <class T>
PointBasedGi<T>::PointBasedGi(const IntegratorOptions& options, SurfelTreeFaults faults)
    : options_(options), rules_(options), faults_(faults) {
    settings_.cutoff = options.pbgi_cutoff;
    settings_.resolution = options.pbgi_resolution;
}

template <class T>
int PointBasedGi<T>::bounces() const {
    // A first hit's gather reaches paths of 1 + bounces bounces.
    const int b = std::max(1, options_.pbgi_bounces);
    return options_.max_depth < 0 ? b : std::max(1, std::min(b, options_.max_depth - 1));
}

template <class T>
void PointBasedGi<T>::prepare(const RenderContext& ctx, const PassProgress& progress) {
    // The cloud depends on the scene and the seed, the corners on the image too.
    const bool same_cloud = prepared_scene_ == &ctx.scene && prepared_seed_ == ctx.seed && !tree_.surfels().empty();
    if (same_cloud && width_ == ctx.width && height_ == ctx.height) return;
    camera_.emplace(ctx.camera);
    width_ = ctx.width, height_ = ctx.height;
    corners_.clear();
    corner_counters_ = {};
    if (!rules_.may_bounce(1)) return;  // direct light only: no indirect light to gather
    const int levels = bounces() + 1;
    if (!same_cloud) {
        const auto start = std::chrono::steady_clock::now();
        prepared_scene_ = &ctx.scene, prepared_seed_ = ctx.seed;
        std::vector<Surfel> surfels = make_surfels(ctx.scene, size_t(std::max(1, options_.pbgi_surfels)));
        light_surfels(ctx.scene, surfels, options_.pbgi_direct_samples, ctx.seed, ctx.sampler);
        tree_.build(std::move(surfels), faults_);
        if (progress) progress(1.0 / levels);
        // Multiple bounces: every side gathers from the cloud as it was (Jacobi), then the
        // aggregates are remade. These gathers are coarser (the light of later bounces is
        // smoother): a cutoff of at least 0.1 sr and at most a 12 x 12 micro-buffer.
        const GatherSettings bounce_settings{std::max(settings_.cutoff, kBounceCutoff), std::min(settings_.resolution, 12)};
        for (int b = 1; b < bounces(); ++b) {
            std::vector<Surfel>& s = tree_.surfels();
            std::vector<Rgb> next(2 * s.size());
            tbb::parallel_for(size_t(0), s.size(), [&](size_t i) {
                for (int side = 0; side < 2; ++side) {
                    if (is_black(s[i].albedo[side])) continue;
                    const Rgb E = tree_.gather(s[i].p, side == 0 ? s[i].n : -s[i].n, bounce_settings);
                    next[2 * i + size_t(side)] = s[i].direct[side] + s[i].albedo[side] * kInvPi * E;
                }
            });
            for (size_t i = 0; i < s.size(); ++i) s[i].radiance[0] = next[2 * i], s[i].radiance[1] = next[2 * i + 1];
            tree_.update();
            if (progress) progress(double(b + 1) / levels);
        }
        surfel_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    // Gathers at the first hits through every spacing-th pixel corner.
    const auto start = std::chrono::steady_clock::now();
    spacing_ = std::max(1, options_.pbgi_spacing);
    grid_width_ = (ctx.width + spacing_ - 1) / spacing_ + 1, grid_height_ = (ctx.height + spacing_ - 1) / spacing_ + 1;
    const int w = grid_width_, h = grid_height_;
    corners_.assign(size_t(w) * size_t(h), Corner{});
    std::vector<GatherCounters> rows(static_cast<size_t>(h));
    tbb::parallel_for(0, h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const Ray ray = ctx.camera.generate(float(x * spacing_), float(y * spacing_));
            Intersection hit;
            if (!ctx.scene.intersect(ray, hit)) continue;
            const ShadingPoint sp = make_shading_point(ctx.scene, hit, ray.d);
            if (sp.material->is_black() || !cached_diffuse(sp)) continue;
            Corner& c = corners_[size_t(y) * size_t(w) + size_t(x)];
            c.p = sp.p, c.n = sp.frame.n, c.valid = true;
            c.E = tree_.gather(sp.p, sp.frame.n, settings_, &rows[size_t(y)]);
        }
    });
    for (const GatherCounters& r : rows) {
        corner_counters_.gathers += r.gathers, corner_counters_.nodes += r.nodes;
        corner_counters_.clusters += r.clusters, corner_counters_.surfels += r.surfels;
    }
    gather_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    own_gathers_ = 0;
    if (progress) progress(1.0);
}

template <class T>
Rgb PointBasedGi<T>::indirect_irradiance(const ShadingPoint& sp, const Vec3f& d) const {
    const Vec3f& x = sp.p;
    const Vec3f& n = sp.frame.n;
    if (!corners_.empty() && camera_) {
        if (const auto r = camera_->raster_of(d)) {
            const float gx = r->x / float(spacing_), gy = r->y / float(spacing_);
            const int i = std::min(int(gx), grid_width_ - 2), j = std::min(int(gy), grid_height_ - 2);
            const float tx = std::min(gx - float(i), 1.0f), ty = std::min(gy - float(j), 1.0f);
            const size_t w = size_t(grid_width_);
            const size_t at[4] = {size_t(j) * w + size_t(i), size_t(j) * w + size_t(i) + 1, (size_t(j) + 1) * w + size_t(i),
                                  (size_t(j) + 1) * w + size_t(i) + 1};
            const float weight[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
            Rgb sum(0.0f);
            float wsum = 0;
            for (int k = 0; k < 4; ++k) {
                const Corner& c = corners_[at[k]];
                // On the same surface: normals within 18 degrees, the corner within 3 degrees of
                // the tangent plane at x.
                if (!c.valid || dot(c.n, n) < 0.95f) continue;
                const Vec3f v = c.p - x;
                if (std::abs(dot(v, n)) > 0.05f * length(v) + 1e-6f * (1 + std::abs(x.x) + std::abs(x.y) + std::abs(x.z))) continue;
                sum += c.E * weight[k];
                wsum += weight[k];
            }
            if (wsum > 0) return sum / wsum;
        }
    }
    own_gathers_.fetch_add(1, std::memory_order_relaxed);
    return tree_.gather(x, n, settings_);
}

template <class T>
ColourOf<T> PointBasedGi<T>::radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const {
    if (tree_.surfels().empty()) {
        // Not prepared (or direct light only): no indirect diffuse light from the cloud.
        return first_hit_radiance(scene, ray, sampler, rules_, wl,
                                  [](const ShadingPoint&, Sampler&, WavelengthsOf<T>&) { return ColourOf<T>(0.0f); });
    }
    return first_hit_radiance(scene, ray, sampler, rules_, wl, [&](const ShadingPoint& sp, Sampler&, WavelengthsOf<T>& w) {
        return illuminant_colour(indirect_irradiance(sp, ray.d), w);
    });
}

template <class T>
std::vector<IntegratorStatistic> PointBasedGi<T>::statistics() const {
    const double g = double(std::max<uint64_t>(corner_counters_.gathers, 1));
    return {{"surfels", double(tree_.surfels().size())},
            {"nodes", double(tree_.node_count())},
            {"surfel_seconds", surfel_seconds_},
            {"gather_seconds", gather_seconds_},
            {"cache_seconds", surfel_seconds_ + gather_seconds_},
            {"nodes_per_gather", double(corner_counters_.nodes) / g},
            {"clusters_per_gather", double(corner_counters_.clusters) / g},
            {"surfels_per_gather", double(corner_counters_.surfels) / g},
            {"own_gathers", double(own_gathers_.load())}};
}

template class PointBasedGi<RgbTransport>;
template class PointBasedGi<SpectralTransport>;

namespace {

std::vector<ParamInfo> pbgi_params() {
    std::vector<ParamInfo> p = path_params();
    p.push_back({"surfels", ParamType::Integer, "8000", "about this many surfels over the scene's surfaces (--pbgi-surfels wins)"});
    p.push_back({"cutoff", ParamType::Float, "0.05",
                 "solid angle (sr) above which a cluster is opened rather than used whole; 0: every surfel (--pbgi-cutoff wins)"});
    p.push_back({"bounces", ParamType::Integer, "3", "surfel bounces: 1 direct light only, each more one more reflection (--pbgi-bounces wins)"});
    p.push_back({"buffer_resolution", ParamType::Integer, "16", "the micro-buffer's side in pixels (--pbgi-resolution wins)"});
    p.push_back({"direct_samples", ParamType::Integer, "16", "MIS pairs per surfel side for its direct light (--pbgi-direct-samples wins)"});
    p.push_back({"gather_spacing", ParamType::Integer, "2", "pixels between the gathers at the first hits (--pbgi-spacing wins)"});
    return p;
}

}  // namespace

const IntegratorInfo& pbgi_integrator() {
    static const IntegratorInfo info = sampling_lights(IntegratorInfo{"pbgi", {}, "point-based global illumination (Christensen): indirect diffuse light at first hits gathered from a surfel octree, pt-mis elsewhere",
                                     false, true, pbgi_params(), [](const IntegratorOptions& o) { return make_for_transport<PointBasedGi>(o); },
                                     /*any_camera=*/false, /*any_filter=*/true});
    return info;
}

}  // namespace pathlab
