#include "integrators/photon/pm.hpp"

#include <atomic>

#include <tbb/parallel_for.h>

#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/photon/visible_point.hpp"

namespace pathlab {
namespace {

constexpr size_t kGlobalK = 50, kCausticK = 20;
constexpr int kMaxDiracChain = 16;  // Dirac lobes followed in a row before giving up

}  // namespace

PhotonMapper::PhotonMapper(const IntegratorOptions& options, PmFaults faults)
    : options_(limited_to_length(options)), faults_(faults),
      max_bounces_(options_.max_depth < 0 ? kMaxBounces : std::min(options_.max_depth, kMaxBounces)), light_paths_(options_) {}

void PhotonMapper::prepare(const RenderContext& ctx, const PassProgress& progress) {
    // The maps depend on the scene and the seed only: a continued render keeps them.
    if (prepared_scene_ == &ctx.scene && prepared_seed_ == ctx.seed) return;
    const size_t paths = options_.photons > 0 ? size_t(options_.photons) : 8 * ctx.pixel_count();
    const size_t per_chunk = std::max<size_t>(256, paths / 256), chunks = (paths + per_chunk - 1) / per_chunk;
    std::vector<std::vector<Photon>> global(chunks), caustic(chunks);
    std::atomic<size_t> chunks_done{0};
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        std::vector<PathVertex> path;
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            // The photon pass's streams: apart from every pixel's.
            Sampler sampler(ctx.seed, uint64_t(j) + (uint64_t(3) << 41), 0, ctx.sampler);
            light_paths_.light_subpath(ctx, sampler, path);
            bool through_dirac_only = true;  // y_1 .. y_{v-1} all Dirac
            for (size_t v = 1; v < path.size(); ++v) {
                const PathVertex& y = path[v];
                if (y.kind != VertexKind::Surface) break;
                if (y.connectible()) {
                    const Photon ph{y.p, y.sp.frame.to_world(y.sp.wi), y.beta / float(paths), uint16_t(std::min<size_t>(v, 65535))};
                    global[c].push_back(ph);
                    if (v >= 2 && through_dirac_only) caustic[c].push_back(ph);
                }
                through_dirac_only &= y.delta;
            }
        }
        // The k-d trees' building after the tracing: about a tenth of the work.
        if (progress) progress(0.9 * double(++chunks_done) / double(chunks));
    });
    global_.clear(), caustic_.clear();
    for (size_t c = 0; c < chunks; ++c) {
        global_.insert(global_.end(), global[c].begin(), global[c].end());
        caustic_.insert(caustic_.end(), caustic[c].begin(), caustic[c].end());
    }
    global_map_.build(global_, 0);
    caustic_map_.build(caustic_, 0);
    prepared_scene_ = &ctx.scene, prepared_seed_ = ctx.seed;
    if (progress) progress(1.0);
}

Rgb PhotonMapper::estimate(const PhotonKdTree& map, size_t k, const ShadingPoint& sp, int t) const {
    uint32_t indices[kGlobalK];
    float dist2[kGlobalK];
    float r2 = 0;
    Rgb sum(0.0f);
    const auto add = [&](const Photon& ph) {
        if (t + int(ph.vertex) - 1 > max_bounces_) return;  // the whole path must stay within the depth
        sum += sp.material->eval(sp, sp.wi, sp.frame.to_local(ph.wi)) * ph.power;
    };
    if (options_.photon_radius > 0) {
        r2 = options_.photon_radius * options_.photon_radius;
        map.for_each_within(sp.p, options_.photon_radius, add);
    } else {
        // The k nearest; the k-th sets the disc and is left out of the sum, which makes the
        // estimate of a uniform density unbiased ((k - 1) / (pi r_k^2); with all k it is k / (k - 1)
        // too bright).
        const size_t n = map.nearest(sp.p, std::min(k, kGlobalK), indices, dist2);
        if (n < 2) return Rgb(0.0f);
        r2 = dist2[n - 1];
        for (size_t i = 0; i + 1 < n; ++i) add(map.photon(indices[i]));
    }
    if (!(r2 > 0)) return Rgb(0.0f);
    return sum / ((faults_.no_pi_in_kernel ? 1.0f : kPi) * r2);
}

Rgb PhotonMapper::radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler) const {
    const auto counts = [&](int length) {
        return (options_.only_length < 0 || options_.only_length == length) && !(options_.hide_emitters && length == 0);
    };
    Rgb L(0.0f);
    const auto x = trace_to_visible_point(scene, camera_ray, sampler, max_bounces_, kMaxDiracChain, counts, L);
    if (!x) return L;
    const ShadingPoint& sp = x->sp;
    const Rgb& beta = x->beta;
    const int t = x->t;
    // x: direct light (a light sample and the gathering ray's BSDF sample, combined by the
    // balance heuristic as in direct-mis: light sampling alone has infinite variance next to
    // an area light), caustics, and one bounce of final gathering into the global map.
    if (counts(t)) L += beta * estimate_light_sample(scene, sp, sampler, /*mis=*/true);
    if (options_.only_length < 0) L += beta * estimate(caustic_map_, kCausticK, sp, t);
    const auto g = sp.material->sample(sp, sp.wi, sampler.next2d());
    if (!g) return L;
    EmitterHit found;
    const Rgb emission = estimate_bsdf_sample_mis(scene, sp, *g, found);
    if (counts(t)) L += beta * emission;
    if (!found.hit || t + 1 > max_bounces_ || options_.only_length >= 0) return L;
    Rgb gbeta = beta * g->f * (std::abs(g->wo.z) / g->pdfW);
    Intersection ghit = found.isect;
    Vec3f gdir = sp.frame.to_world(g->wo);
    for (int u = t + 1; u - 1 <= max_bounces_ && u <= t + kMaxDiracChain; ++u) {
        const ShadingPoint gp = make_shading_point(scene, ghit, gdir);
        if (gp.material->is_black()) return L;
        if (!gp.material->is_delta()) return L + gbeta * estimate(global_map_, kGlobalK, gp, u);
        const auto s = gp.material->sample(gp, gp.wi, sampler.next2d());
        if (!s) return L;
        gbeta *= s->f * (std::abs(s->wo.z) / s->pdfW);
        gdir = gp.frame.to_world(s->wo);
        if (!scene.intersect(gp.spawn(s->wo), ghit)) return L;  // the environment is direct light (counted at x)
    }
    return L;
}

const IntegratorInfo& pm_integrator() {
    static const IntegratorInfo info{"pm", {"photonmapper"}, "photon mapping (Jensen): global and caustic maps, k-nearest estimates, final gathering", false,
                                     true,
                                     [] {
                                         std::vector<ParamInfo> p = path_params();
                                         p.push_back({"photon_count", ParamType::Integer, "0",
                                                      "light paths of the photon maps (0: 8 per pixel; --photons wins)", "photonCount"});
                                         return p;
                                     }(),
                                     [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
                                         return std::make_unique<PhotonMapper>(o);
                                     }};
    return info;
}

}  // namespace pathlab
