#include "integrators/photon/sppm.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>

#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/photon/progressive_radius.hpp"
#include "integrators/photon/visible_point.hpp"

namespace pathlab {
namespace {

// Streams of one pass's random numbers: camera paths use the pixel's own stream, light paths
// (indexed from 0) theirs.
uint64_t light_path_stream(size_t path) { return uint64_t(path) + (uint64_t(1) << 41); }

size_t paths_per_chunk(size_t paths) { return std::max<size_t>(64, paths / 256); }

}  // namespace

template <class T>
Sppm<T>::Sppm(const IntegratorOptions& options, SppmFaults faults, CameraRays rays)
    : options_(limited_to_length(options)), faults_(faults), rays_(rays),
      max_bounces_(options_.max_depth < 0 ? kMaxBounces : std::min(options_.max_depth, kMaxBounces)), light_paths_(options_) {}

template <class T>
double Sppm<T>::radius(double r1, double alpha, uint64_t i) { return progressive_radius(r1, alpha, i); }

template <class T>
float Sppm<T>::initial_radius(const RenderContext& ctx) const { return initial_photon_radius(ctx, options_); }

template <class T>
uint64_t Sppm<T>::trace_photons(const RenderContext& ctx, uint64_t pass, size_t paths, const WavelengthsOf<T>& wl) {
    const size_t per_chunk = paths_per_chunk(paths), chunks = (paths + per_chunk - 1) / per_chunk;
    chunk_photons_.resize(chunks);
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const uint64_t rays_before = Scene::rays_traced_by_this_thread();
        std::vector<PathVertex<T>>& path = paths_.local();  // keeps its capacity from pass to pass
        std::vector<Photon<T>>& out = chunk_photons_[c];
        out.clear();
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            Sampler sampler(ctx.seed, light_path_stream(j), pass, ctx.sampler);
            light_paths_.light_subpath(ctx, sampler, wl, path);
            // y_2, y_3, ...: y_1 is direct light, next-event estimation's.
            for (size_t v = 2; v < path.size(); ++v) {
                const PathVertex<T>& y = path[v];
                if (y.kind != VertexKind::Surface || !y.connectible() || int(v) > max_bounces_) continue;
                out.push_back({y.p, y.sp.frame.to_world(y.sp.wi), y.beta, uint16_t(std::min<size_t>(v, 65535)), y.dispersed});
            }
        }
        rays += Scene::rays_traced_by_this_thread() - rays_before;
    });
    photons_.clear();
    for (const auto& c : chunk_photons_) photons_.insert(photons_.end(), c.begin(), c.end());
    return rays.load();
}

template <class T>
Vec3d Sppm<T>::camera_sample(const RenderContext& ctx, size_t pixel, uint64_t pass, float r, size_t paths,
                             const WavelengthsOf<T>& pass_wl) const {
    using Colour = ColourOf<T>;
    const Scene& scene = ctx.scene;
    Sampler sampler(ctx.seed, pixel, pass, ctx.sampler);
    const Vec2f jitter = rays_ == CameraRays::Jittered ? sampler.next2d() : Vec2f(0.5f, 0.5f);
    const float px = float(pixel % size_t(ctx.width)), py = float(pixel / size_t(ctx.width));
    Ray ray = ctx.camera.generate(px + jitter.x, py + jitter.y);
    WavelengthsOf<T> wl = pass_wl;  // this camera path's: a dispersive interface would reduce it
    Colour L(0.0f);
    const auto counts = [&](int length) {
        return (options_.only_length < 0 || options_.only_length == length) && !(options_.hide_emitters && length == 0);
    };
    const auto x = trace_to_visible_point<T>(scene, ray, sampler, max_bounces_, max_bounces_ + 1, counts, L, wl);
    if (!x) return film_colour(L, wl);
    const ShadingPoint& sp = x->sp;
    const Colour& beta = x->beta;
    const int t = x->t;
    // The visible point: direct light by a light sample and a BSDF sample combined by the
    // balance heuristic (as in direct-mis: light sampling alone has infinite variance next
    // to an area light), the rest from the photons.
    if (counts(t)) {
        L += beta * estimate_light_sample(scene, sp, sampler, /*mis=*/true, wl);
        if (const auto s = bsdf_sample(sp, sampler.next2d(), wl)) {
            EmitterHit found;
            L += beta * estimate_bsdf_sample_mis(scene, sp, *s, bsdf_sample_colour(sp, *s, wl), found, wl);
        }
    }
    const float norm = float(paths) * (faults_.no_pi_in_kernel ? 1.0f : kPi) * r * r;
    MergeSum<T> sum;
    grid_.for_each_within(sp.p, r, [&](uint32_t i) {
        const Photon<T>& ph = photons_[i];
        const int bounces = t + int(ph.vertex) - 1;
        if (bounces > max_bounces_ || !counts(bounces)) return;
        const Vec3f wo = sp.frame.to_local(ph.wi);
        sum.add(bsdf_colour(sp, wo, sp.material->eval(sp, sp.wi, wo), wl) * ph.power, ph.dispersed);
    });
    return film_colour(L + beta * sum.total(wl) / norm, wl);
}

template <class T>
PassCounters Sppm<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    const size_t pixels = ctx.pixel_count();
    const size_t paths = options_.photons > 0 ? size_t(options_.photons) : pixels;
    const double r1 = initial_radius(ctx), alpha = options_.photon_alpha;
    image_.resize(pixels);
    std::vector<Vec3d>& image = image_;
    std::atomic<uint64_t> rays{0}, invalid{0};
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        const WavelengthsOf<T> wl = T::pass_wavelengths(ctx.seed, ctx.sampler, pass);
        const float r = float(radius(r1, alpha, pass + 1));
        rays += trace_photons(ctx, pass, paths, wl);
        grid_.build(photons_, r);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 64), [&](const tbb::blocked_range<size_t>& range) {
            const uint64_t before = Scene::rays_traced_by_this_thread();
            uint64_t bad = 0;
            for (size_t p = range.begin(); p != range.end(); ++p) {
                const Vec3d L = camera_sample(ctx, p, pass, r, paths, wl);
                if (is_finite(L)) image[p] = L;
                else image[p] = Vec3d(0.0), ++bad;
            }
            rays += Scene::rays_traced_by_this_thread() - before;
            invalid += bad;
        });
        film.add_pass(image);
        if (progress) progress(double(k + 1) / count);
    }
    return {rays.load(), invalid.load()};
}

template class Sppm<RgbTransport>;
template class Sppm<SpectralTransport>;

namespace {

std::vector<ParamInfo> progressive_photon_params() {
    std::vector<ParamInfo> p = path_params();
    p.push_back({"photon_count", ParamType::Integer, "0", "light paths per iteration (0: one per pixel; --photons wins)", "photonCount"});
    for (ParamInfo& r : progressive_radius_params()) p.push_back(std::move(r));
    return p;
}

}  // namespace

const IntegratorInfo& sppm_integrator() {
    static const IntegratorInfo info{
        "sppm", {}, "stochastic progressive photon mapping (Knaus-Zwicker iterations): photons + next-event estimation", false, true,
        progressive_photon_params(), [](const IntegratorOptions& o) { return make_for_transport<Sppm>(o); }, false, false};
    return info;
}

const IntegratorInfo& ppm_integrator() {
    static const IntegratorInfo info{
        "ppm", {}, "progressive photon mapping (Hachisuka 2008): fixed hit points through the pixel centres, photon passes, shrinking radius",
        false, true, progressive_photon_params(),
        [](const IntegratorOptions& o) { return make_for_transport<Sppm>(o, SppmFaults{}, CameraRays::PixelCentres); }, false, false};
    return info;
}

}  // namespace pathlab
