#include "integrators/cache/ic.hpp"

#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>

#include "core/sampling.hpp"
#include "image/image_io.hpp"
#include "integrators/cache/first_hit.hpp"
#include "integrators/integrators.hpp"
#include "integrators/path/pt_mis.hpp"

namespace pathlab {
namespace {

// Random-number streams: the records' gathers, apart from every pixel's own.
uint64_t record_stream(size_t pixel) { return uint64_t(pixel) + (uint64_t(5) << 41); }

}  // namespace

template <class T>
IrradianceCaching<T>::IrradianceCaching(const IntegratorOptions& options)
    : options_(options), rules_(options), cache_(options.ic_error, 1.0f, options.ic_gradients) {
    const int rays = std::max(4, options.ic_rays);
    M_ = std::max(1, int(std::lround(std::sqrt(double(rays) / kPi))));
    N_ = std::max(1, int(std::lround(double(rays) / M_)));
}

template <class T>
float IrradianceCaching<T>::footprint(const Vec3f& p) const { return std::max(1e-6f, length(p - camera_position_) * pixel_angle_); }

template <class T>
void IrradianceCaching<T>::clamp_radius(IrradianceRecord& r, float scene_radius) const {
    const float a = std::max(cache_.error_threshold(), 1e-6f), f = footprint(r.p);
    // Without the screen-space clamps: the harmonic mean distance, at most the scene's radius
    // (a record whose rays all escaped would otherwise cover everything).
    const float lo = options_.ic_clamp_screen ? 1.5f * f / a : 0.0f, hi = options_.ic_clamp_screen ? 20.0f * f / a : scene_radius;
    float R = std::clamp(r.harmonic, lo, hi);
    // The translational gradient's limit: R <= E / |grad_t E| (in luminance).
    const Vec3f g = r.grad_t[0] * 0.2126f + r.grad_t[1] * 0.7152f + r.grad_t[2] * 0.0722f;
    const float E = luminance(r.E), gl = length(g);
    if (gl > 0 && E > 0) R = std::max(std::min(R, E / gl), lo);
    r.R = R;
}

template <class T>
IrradianceRecord IrradianceCaching<T>::make_record(const Scene& scene, const ShadingPoint& sp, Sampler& sampler) const {
    // Records hold RGB (in spectral mode too).
    RgbWavelengths rgb;
    IrradianceRecord r = gather_record(sp.p, sp.frame, M_, N_, sampler, [&](const Vec3f& d, float& distance) {
        Intersection hit;
        if (!scene.intersect(spawn_ray(sp.p, sp.ng, d), hit)) return Rgb(0.0f);  // the environment: direct light
        distance = length(hit.p - sp.p);
        return pt_mis_from_hit(scene, hit, d, 1, sampler, rules_, rgb);
    });
    clamp_radius(r, scene.bounds_radius());
    return r;
}

template <class T>
ColourOf<T> IrradianceCaching<T>::indirect_irradiance(const Scene& scene, const ShadingPoint& sp, Sampler& sampler,
                                                      WavelengthsOf<T>& wl) const {
    Rgb E;
    if (cache_.interpolate(sp.p, sp.frame.n, E)) return illuminant_colour(E, wl);
    // One cosine-distributed gather ray: E = pi L, unbiased.
    const Vec3f local = square_to_cosine_hemisphere(sampler.next2d());
    const Vec3f d = sp.frame.to_world(local);
    Intersection hit;
    if (!scene.intersect(spawn_ray(sp.p, sp.ng, d), hit)) return ColourOf<T>(0.0f);
    return pt_mis_from_hit(scene, hit, d, 1, sampler, rules_, wl) * kPi;
}

template <class T>
void IrradianceCaching<T>::prepare(const RenderContext& ctx, const PassProgress& progress) {
    // The cache depends on the scene, the image and the seed: a continued render keeps it.
    if (prepared_.matches(ctx) && cache_.size() > 0) return;
    const auto start = std::chrono::steady_clock::now();
    camera_position_ = ctx.camera.position();
    pixel_angle_ = ctx.camera.pixel_angle();
    // Grid cubes of about an average record's influence (10 pixel footprints at the scene's centre).
    const float cell = std::max(10 * pixel_angle_ * length(ctx.scene.scene_sphere().center - camera_position_), 1e-4f);
    cache_.reset(options_.ic_error, cell, options_.ic_gradients);
    gathered_ = 0;
    prepared_.set(ctx);
    if (!(options_.ic_error > 0) || !rules_.may_bounce(1)) return;  // every point gathers for itself, or no indirect light

    const int w = ctx.width, h = ctx.height;
    std::vector<int> strides;
    for (int s = 8; s >= 1; s /= 2) strides.push_back(s);
    std::vector<size_t> candidates;
    std::vector<std::optional<IrradianceRecord>> made;
    for (size_t level = 0; level < strides.size(); ++level) {
        const int s = strides[level];
        candidates.clear();
        for (int y = 0; y < h; y += s)
            for (int x = 0; x < w; x += s)
                if (level == 0 || x % (2 * s) != 0 || y % (2 * s) != 0) candidates.push_back(size_t(y) * size_t(w) + size_t(x));
        made.assign(candidates.size(), std::nullopt);
        // The first hits no record covers yet get a record, in parallel (the cache is only read).
        tbb::parallel_for(size_t(0), candidates.size(), [&](size_t i) {
            const size_t pixel = candidates[i];
            const Ray ray = ctx.camera.generate(float(pixel % size_t(w)) + 0.5f, float(pixel / size_t(w)) + 0.5f);
            Intersection hit;
            if (!ctx.scene.intersect(ray, hit)) return;
            const ShadingPoint sp = make_shading_point(ctx.scene, hit, ray.d);
            if (sp.material->is_black() || !cached_diffuse(sp) || cache_.covered(sp.p, sp.frame.n)) return;
            Sampler sampler(ctx.seed, record_stream(pixel), 0, ctx.sampler);
            made[i] = make_record(ctx.scene, sp, sampler);
            made[i]->pixel = uint32_t(pixel);
        });
        // Added in pixel order, unless one added before covers it.
        for (const auto& r : made) {
            if (!r) continue;
            ++gathered_;
            if (!cache_.covered(r->p, r->n)) cache_.add(*r);
        }
        if (progress) progress(double(level + 1) / double(strides.size()));
    }
    if (options_.ic_clamp_neighbours) cache_.clamp_to_neighbours();
    build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <class T>
ColourOf<T> IrradianceCaching<T>::radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const {
    return first_hit_radiance(scene, ray, sampler, rules_, wl,
                              [&](const ShadingPoint& sp, Sampler& s, WavelengthsOf<T>& w) { return indirect_irradiance(scene, sp, s, w); });
}

template <class T>
void IrradianceCaching<T>::finish(const RenderContext& ctx) {
    if (options_.ic_records_path.empty()) return;
    // Where the records are: the cache's own view of the indirect diffuse light (rho_d/pi E at
    // the pixel centres' first hits, one stop brighter; black where no record covers them), and
    // a red pixel where each record was placed.
    const int w = ctx.width, h = ctx.height;
    Image img(w, h);
    tbb::parallel_for(0, h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const Ray ray = ctx.camera.generate(float(x) + 0.5f, float(y) + 0.5f);
            Intersection hit;
            if (!ctx.scene.intersect(ray, hit)) continue;
            const ShadingPoint sp = make_shading_point(ctx.scene, hit, ray.d);
            const std::optional<PhongMaterial> phong = sp.material->is_black() ? std::nullopt : cached_diffuse(sp);
            Rgb E;
            if (phong && cache_.interpolate(sp.p, sp.frame.n, E)) img.at(x, y) = phong->diffuse * (2 * kInvPi) * E;
        }
    });
    for (const IrradianceRecord& r : cache_.records()) img.at(int(r.pixel % uint32_t(w)), int(r.pixel / uint32_t(w))) = Rgb(4.0f, 0.2f, 0.2f);
    write_image(img, options_.ic_records_path);
}

template <class T>
std::vector<IntegratorStatistic> IrradianceCaching<T>::statistics() const {
    return {{"records", double(cache_.size())}, {"records_gathered", double(gathered_)}, {"cache_seconds", build_seconds_}};
}

template class IrradianceCaching<RgbTransport>;
template class IrradianceCaching<SpectralTransport>;

namespace {

// pathlab's names, and Mitsuba 0.6's irrcache names where they mean the same thing.
std::vector<ParamInfo> ic_params() {
    std::vector<ParamInfo> p = path_params();
    p.push_back({"rays", ParamType::Integer, "256", "rays per record, stratified (--ic-rays wins)"});
    p.push_back({"resolution", ParamType::Integer, "",
                 "Mitsuba 0.6's elevational resolution R of the gather hemisphere: 3 R^2 rays (R x 3R in Mitsuba; instead of rays)"});
    p.push_back({"error", ParamType::Float, "0.2", "the error threshold a (0: no cache; --ic-error wins)"});
    p.push_back({"gradients", ParamType::Boolean, "true", "interpolate with the irradiance gradients (--ic-no-gradients wins)"});
    p.push_back({"clamp_neighbor", ParamType::Boolean, "true", "neighbour clamping of the radii", "clampNeighbor"});
    p.push_back({"clamp_screen", ParamType::Boolean, "true", "radii between 1.5 and 20 pixel footprints (else at most the scene's radius)",
                 "clampScreen"});
    return p;
}

}  // namespace

const IntegratorInfo& ic_integrator() {
    static const IntegratorInfo info = sampling_lights(IntegratorInfo{"ic", {"irrcache"}, "irradiance caching with gradients (Ward): cached indirect diffuse light at first hits, pt-mis elsewhere",
                                     false, true, ic_params(), [](const IntegratorOptions& o) { return make_for_transport<IrradianceCaching>(o); },
                                     false, true});
    return info;
}

}  // namespace pathlab
