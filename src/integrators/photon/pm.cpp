#include "integrators/photon/pm.hpp"

#include <atomic>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/photon/visible_point.hpp"
#include "render/pixel_filter.hpp"

namespace pathlab {
namespace {

constexpr size_t kGlobalK = 50, kCausticK = 20;
constexpr int kMaxDiracChain = 16;  // Dirac lobes followed in a row before giving up

}  // namespace

template <class T>
PhotonMapper<T>::PhotonMapper(const IntegratorOptions& options, PmFaults faults)
    : options_(limited_to_length(options)), faults_(faults),
      max_bounces_(options_.max_depth < 0 ? kMaxBounces : std::min(options_.max_depth, kMaxBounces)), light_paths_(options_) {}

template <class T>
void PhotonMapper<T>::prepare(const RenderContext& ctx, const PassProgress& progress) {
    if constexpr (!T::spectral) {
        // The maps depend on the scene and the seed only: a continued render keeps them.
        if (prepared_scene_ == &ctx.scene && prepared_seed_ == ctx.seed) return;
        build_maps(ctx, 0, {}, progress);
        prepared_scene_ = &ctx.scene, prepared_seed_ = ctx.seed;
    }
    if (progress) progress(1.0);
}

template <class T>
uint64_t PhotonMapper<T>::build_maps(const RenderContext& ctx, uint64_t pass, const WavelengthsOf<T>& wl, const PassProgress& progress) {
    const size_t paths = options_.photons > 0 ? size_t(options_.photons) : 8 * ctx.pixel_count();
    const size_t per_chunk = std::max<size_t>(256, paths / 256), chunks = (paths + per_chunk - 1) / per_chunk;
    chunk_global_.resize(chunks), chunk_caustic_.resize(chunks);
    std::atomic<size_t> chunks_done{0};
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const uint64_t rays_before = Scene::rays_traced_by_this_thread();
        std::vector<Photon<T>>& global = chunk_global_[c];
        std::vector<Photon<T>>& caustic = chunk_caustic_[c];
        global.clear(), caustic.clear();
        std::vector<PathVertex<T>> path;
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            // The photon pass's streams: apart from every pixel's.
            Sampler sampler(ctx.seed, uint64_t(j) + (uint64_t(3) << 41), pass, ctx.sampler);
            light_paths_.light_subpath(ctx, sampler, wl, path);
            bool through_dirac_only = true;  // y_1 .. y_{v-1} all Dirac
            for (size_t v = 1; v < path.size(); ++v) {
                const PathVertex<T>& y = path[v];
                if (y.kind != VertexKind::Surface) break;
                if (y.connectible()) {
                    const Photon<T> ph{y.p, y.sp.frame.to_world(y.sp.wi), y.beta / float(paths), uint16_t(v), y.dispersed};
                    global.push_back(ph);
                    if (v >= 2 && through_dirac_only) caustic.push_back(ph);
                }
                through_dirac_only &= y.delta;
            }
        }
        rays += Scene::rays_traced_by_this_thread() - rays_before;
        // The k-d trees' building after the tracing: about a tenth of the work.
        if (progress) progress(0.9 * double(++chunks_done) / double(chunks));
    });
    global_.clear(), caustic_.clear();
    for (size_t c = 0; c < chunks; ++c) {
        global_.insert(global_.end(), chunk_global_[c].begin(), chunk_global_[c].end());
        caustic_.insert(caustic_.end(), chunk_caustic_[c].begin(), chunk_caustic_[c].end());
    }
    global_map_.build(global_, 0);
    caustic_map_.build(caustic_, 0);
    return rays.load();
}

template <class T>
PassCounters PhotonMapper<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    // PixelIntegrator's sampling (the jitter, replaced by the pass's lattice shift under a
    // filter; the lens sample), pass by pass, since a pass may need its own maps first.
    const int w = ctx.width;
    const size_t pixels = ctx.pixel_count();
    const bool filtered = ctx.filter && !ctx.filter->is_box();
    const bool lens = ctx.camera.needs_lens_sample();
    if (filtered) lattice_.assign(pixels, Vec3d(0.0));
    std::atomic<uint64_t> rays{0}, invalid{0};
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        const WavelengthsOf<T> wl = T::pass_wavelengths(ctx.seed, ctx.sampler, pass);
        if constexpr (T::spectral) rays += build_maps(ctx, pass, wl, {});
        const Vec2f shift = filtered ? filter_shift(ctx, pass) : Vec2f(0.0f, 0.0f);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 64), [&](const tbb::blocked_range<size_t>& range) {
            const uint64_t before = Scene::rays_traced_by_this_thread();
            uint64_t bad = 0;
            for (size_t p = range.begin(); p != range.end(); ++p) {
                const int x = int(p % size_t(w)), y = int(p / size_t(w));
                Sampler sampler(ctx.seed, p, pass, ctx.sampler);
                const Vec2f jitter = sampler.next2d();
                const float sx = float(x) + (filtered ? shift.x : jitter.x), sy = float(y) + (filtered ? shift.y : jitter.y);
                const Ray ray = lens ? ctx.camera.generate(sx, sy, sampler.next2d()) : ctx.camera.generate(sx, sy);
                WavelengthsOf<T> camera_wl = wl;
                const Vec3d L = film_colour(radiance(ctx.scene, ray, sampler, camera_wl), camera_wl);
                // As PixelIntegrator: an invalid sample is not added (a filtered pass adds 0 there).
                if (!is_finite(L)) ++bad;
                if (filtered) lattice_[p] = is_finite(L) ? L : Vec3d(0.0);
                else if (is_finite(L)) film.add(p, L);
            }
            rays += Scene::rays_traced_by_this_thread() - before;
            invalid += bad;
        });
        if (filtered) {
            ctx.filter->filter_pass(lattice_, shift, filtered_);
            film.add_pass(filtered_);
        }
        if (progress) progress(double(k + 1) / count);
    }
    return {rays.load(), invalid.load()};
}

template <class T>
std::vector<IntegratorStatistic> PhotonMapper<T>::statistics() const {
    if constexpr (T::spectral)
        return {{"global photons (last pass)", double(global_.size())}, {"caustic photons (last pass)", double(caustic_.size())}};
    return {};
}

template <class T>
ColourOf<T> PhotonMapper<T>::estimate(const std::vector<Photon<T>>& photons, const PhotonKdTree& map, size_t k, const ShadingPoint& sp,
                                      int t, const WavelengthsOf<T>& wl) const {
    uint32_t indices[kGlobalK];
    float dist2[kGlobalK];
    float r2 = 0;
    MergeSum<T> sum;
    const auto add = [&](uint32_t i) {
        const Photon<T>& ph = photons[i];
        if (t + int(ph.vertex) - 1 > max_bounces_) return;  // the whole path must stay within the depth
        const Vec3f wo = sp.frame.to_local(ph.wi);
        sum.add(bsdf_colour(sp, wo, sp.material->eval(sp, sp.wi, wo), wl) * ph.power, ph.dispersed);
    };
    if (options_.photon_radius > 0) {
        r2 = options_.photon_radius * options_.photon_radius;
        map.for_each_within(sp.p, options_.photon_radius, add);
    } else {
        // The k nearest; the k-th sets the disc and is left out of the sum, which makes the
        // estimate of a uniform density unbiased ((k - 1) / (pi r_k^2); with all k it is k / (k - 1)
        // too bright).
        const size_t n = map.nearest(sp.p, std::min(k, kGlobalK), indices, dist2);
        if (n < 2) return ColourOf<T>(0.0f);
        r2 = dist2[n - 1];
        for (size_t i = 0; i + 1 < n; ++i) add(indices[i]);
    }
    if (!(r2 > 0)) return ColourOf<T>(0.0f);
    return sum.total(wl) / ((faults_.no_pi_in_kernel ? 1.0f : kPi) * r2);
}

template <class T>
ColourOf<T> PhotonMapper<T>::radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, WavelengthsOf<T>& wl) const {
    using Colour = ColourOf<T>;
    const auto counts = [&](int length) {
        return (options_.only_length < 0 || options_.only_length == length) && !(options_.hide_emitters && length == 0);
    };
    Colour L(0.0f);
    const auto x = trace_to_visible_point<T>(scene, camera_ray, sampler, max_bounces_, kMaxDiracChain, counts, L, wl);
    if (!x) return L;
    const ShadingPoint& sp = x->sp;
    const Colour& beta = x->beta;
    const int t = x->t;
    // x: direct light (a light sample and the gathering ray's BSDF sample, combined by the
    // balance heuristic as in direct-mis: light sampling alone has infinite variance next to
    // an area light), caustics, and one bounce of final gathering into the global map.
    if (counts(t)) L += beta * estimate_light_sample(scene, sp, sampler, /*mis=*/true, wl);
    if (options_.only_length < 0) L += beta * estimate(caustic_, caustic_map_, kCausticK, sp, t, wl);
    const auto g = bsdf_sample(sp, sampler.next2d(), wl);
    if (!g) return L;
    const Colour gf = bsdf_sample_colour(sp, *g, wl);
    EmitterHit found;
    const Colour emission = estimate_bsdf_sample_mis(scene, sp, *g, gf, found, wl);
    if (counts(t)) L += beta * emission;
    if (!found.hit || t + 1 > max_bounces_ || options_.only_length >= 0) return L;
    Colour gbeta = beta * gf * (std::abs(g->wo.z) / g->pdfW);
    Intersection ghit = found.isect;
    Vec3f gdir = sp.frame.to_world(g->wo);
    for (int u = t + 1; u - 1 <= max_bounces_ && u <= t + kMaxDiracChain; ++u) {
        const ShadingPoint gp = make_shading_point(scene, ghit, gdir);
        if (gp.material->is_black()) return L;
        if (!gp.material->is_delta()) return L + gbeta * estimate(global_, global_map_, kGlobalK, gp, u, wl);
        const auto s = bsdf_sample(gp, sampler.next2d(), wl);
        if (!s) return L;
        gbeta *= bsdf_sample_colour(gp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        gdir = gp.frame.to_world(s->wo);
        if (!scene.intersect(gp.spawn(s->wo), ghit)) return L;  // the environment is direct light (counted at x)
    }
    return L;
}

template class PhotonMapper<RgbTransport>;
template class PhotonMapper<SpectralTransport>;

const IntegratorInfo& pm_integrator() {
    static const IntegratorInfo info{"pm", {"photonmapper"}, "photon mapping (Jensen): global and caustic maps, k-nearest estimates, final gathering", false,
                                     true,
                                     [] {
                                         std::vector<ParamInfo> p = path_params();
                                         p.push_back({"photon_count", ParamType::Integer, "0",
                                                      "light paths of the photon maps (0: 8 per pixel; --photons wins)", "photonCount"});
                                         return p;
                                     }(),
                                     [](const IntegratorOptions& o) { return make_for_transport<PhotonMapper>(o); }};
    return info;
}

}  // namespace pathlab
