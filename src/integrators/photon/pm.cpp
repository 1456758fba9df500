#include "integrators/photon/pm.hpp"

#include <atomic>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "integrators/common/camera_ray.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/photon/visible_point.hpp"
#include "render/pixel_filter.hpp"

namespace pathlab {
namespace {

constexpr size_t kGlobalK = 50, kCausticK = 20, kVolumeK = 50, kMaxK = 50;
// A beam's photons: each ball the radius of its photon's 16 nearest. A ray gathers ~k^(2/3) as many
// photons; at k = 50 (the points' k) fog-box.xml renders 2.6x slower with more bias (the balls
// reach further past the fog's walls), for noise a beam averages away.
constexpr size_t kBeamK = 16;
constexpr int kMaxDiracChain = 16;  // Dirac lobes followed in a row before giving up

// The photons of a radiance estimate at p: add(i) for those within `radius` when it is given,
// else for the k nearest but the k-th, whose distance sets the kernel (leaving it out of the sum
// makes the estimate of a uniform density unbiased: (k - 1) / (pi r_k^2) on a surface,
// (k - 1) / (4/3 pi r_k^3) in a volume; with all k it is k / (k - 1) too bright). Returns the
// kernel's squared radius, 0 with fewer than 2 photons.
template <typename Add>
float gather_photons(const PhotonKdTree& map, const Vec3f& p, float radius, size_t k, const Add& add) {
    if (radius > 0) {
        map.for_each_within(p, radius, add);
        return radius * radius;
    }
    uint32_t indices[kMaxK];
    float dist2[kMaxK];
    const size_t n = map.nearest(p, std::min(k, kMaxK), indices, dist2);
    if (n < 2) return 0;
    for (size_t i = 0; i + 1 < n; ++i) add(indices[i]);
    return dist2[n - 1];
}

}  // namespace

template <class T>
PhotonMapper<T>::PhotonMapper(const IntegratorOptions& options, PmFaults faults)
    : options_(limited_to_length(options)), faults_(faults),
      max_bounces_(bounce_limit(options_.max_depth)), light_paths_(options_) {}

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
    const bool media = ctx.scene.has_media();
    // (each photon: its chunk's copy and the map's, the k-d tree's index, in media a ball)
    check_photon_memory<PathVertex<T>>("pm", paths, 2 * sizeof(Photon<T>) + 48, "--photons", [&](size_t j, std::vector<PathVertex<T>>& path) {
        Sampler sampler(ctx.seed, uint64_t(j) + (uint64_t(3) << 41), pass, ctx.sampler);
        light_paths_.light_subpath(ctx, sampler, wl, path);
    });
    chunk_global_.resize(chunks), chunk_caustic_.resize(chunks), chunk_volume_.resize(chunks);
    std::atomic<size_t> chunks_done{0};
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const uint64_t rays_before = Scene::rays_traced_by_this_thread();
        std::vector<Photon<T>>& global = chunk_global_[c];
        std::vector<Photon<T>>& caustic = chunk_caustic_[c];
        std::vector<Photon<T>>& volume = chunk_volume_[c];
        global.clear(), caustic.clear(), volume.clear();
        std::vector<PathVertex<T>> path;
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            // The photon pass's streams: apart from every pixel's.
            Sampler sampler(ctx.seed, uint64_t(j) + (uint64_t(3) << 41), pass, ctx.sampler);
            light_paths_.light_subpath(ctx, sampler, wl, path);
            bool through_dirac_only = true;  // y_1 .. y_{v-1} all Dirac
            for (size_t v = 1; v < path.size(); ++v) {
                const PathVertex<T>& y = path[v];
                if (y.kind != VertexKind::Surface && y.kind != VertexKind::Medium) break;
                if (y.connectible()) {
                    // In media each light path is its own spectral MIS over its hero channel: its density divides its power.
                    const ColourOf<T> power = media ? y.beta / (float(paths) * path_density_of(y.r, y.dispersed)) : y.beta / float(paths);
                    if (y.kind == VertexKind::Medium) {
                        volume.push_back({y.p, y.dir, power, uint16_t(v), y.dispersed, photon_medium(y)});
                    } else {
                        const Photon<T> ph{y.p, y.sp.frame.to_world(y.sp.wi), power, uint16_t(v), y.dispersed};
                        global.push_back(ph);
                        if (v >= 2 && through_dirac_only) caustic.push_back(ph);
                    }
                }
                through_dirac_only &= y.delta;
            }
        }
        rays += Scene::rays_traced_by_this_thread() - rays_before;
        // The k-d trees' building after the tracing: about a tenth of the work.
        if (progress) progress(0.9 * double(++chunks_done) / double(chunks));
    });
    global_.clear(), caustic_.clear(), volume_.clear();
    for (size_t c = 0; c < chunks; ++c) {
        global_.insert(global_.end(), chunk_global_[c].begin(), chunk_global_[c].end());
        caustic_.insert(caustic_.end(), chunk_caustic_[c].begin(), chunk_caustic_[c].end());
        volume_.insert(volume_.end(), chunk_volume_[c].begin(), chunk_volume_[c].end());
    }
    global_map_.build(global_, 0);
    caustic_map_.build(caustic_, 0);
    volume_map_.build(volume_, 0);
    if (options_.volume_beam && !volume_.empty()) {
        // The beams' balls: each photon's the radius of its kBeamK nearest (itself among them), or --radius.
        std::vector<float> radii(volume_.size(), options_.photon_radius);
        if (!(options_.photon_radius > 0))
            tbb::parallel_for(tbb::blocked_range<size_t>(0, volume_.size(), 1024), [&](const tbb::blocked_range<size_t>& range) {
                uint32_t indices[kBeamK];
                float dist2[kBeamK];
                for (size_t i = range.begin(); i != range.end(); ++i) {
                    const size_t n = volume_map_.nearest(volume_[i].p, kBeamK, indices, dist2);
                    radii[i] = std::sqrt(dist2[n - 1]);
                }
            });
        volume_balls_.build(Positions::of(volume_), radii);
    } else {
        volume_balls_ = BallTree{};
    }
    return rays.load();
}

template <class T>
PassCounters PhotonMapper<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    // PixelIntegrator's sampling (the jitter, replaced by the pass's lattice shift under a
    // filter; the lens sample), pass by pass, since a pass may need its own maps first.
    const int w = ctx.width;
    const size_t pixels = ctx.pixel_count();
    const bool filtered = ctx.filter && !ctx.filter->is_box();
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
                const Ray ray = camera_ray(ctx.camera, sx, sy, sampler);
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
    std::vector<IntegratorStatistic> s;
    if constexpr (T::spectral)
        s = {{"global photons (last pass)", double(global_.size())}, {"caustic photons (last pass)", double(caustic_.size())}};
    if (!volume_.empty()) s.push_back({T::spectral ? "volume photons (last pass)" : "volume photons", double(volume_.size())});
    return s;
}

template <class T>
ColourOf<T> PhotonMapper<T>::estimate(const std::vector<Photon<T>>& photons, const PhotonKdTree& map, size_t k, const ShadingPoint& sp,
                                      int t, const WavelengthsOf<T>& wl) const {
    MergeSum<T> sum;
    const auto add = [&](uint32_t i) {
        const Photon<T>& ph = photons[i];
        if (t + int(ph.vertex) - 1 > max_bounces_) return;  // the whole path must stay within the depth
        const Vec3f wo = sp.frame.to_local(ph.wi);
        sum.add(bsdf_colour(sp, wo, sp.material->eval(sp, sp.wi, wo), wl) * ph.power, ph.dispersed);
    };
    const float r2 = gather_photons(map, sp.p, options_.photon_radius, k, add);
    if (!(r2 > 0)) return ColourOf<T>(0.0f);
    return sum.total(wl) / ((faults_.no_pi_in_kernel ? 1.0f : kPi) * r2);
}

template <class T>
ColourOf<T> PhotonMapper<T>::radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, WavelengthsOf<T>& wl) const {
    using Colour = ColourOf<T>;
    if (scene.has_media()) return radiance_in_media(scene, camera_ray, sampler, wl);
    const auto counts = [this](int length) { return length_counts(options_, length); };
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

template <class T>
ColourOf<T> PhotonMapper<T>::volume_estimate(const Scene& scene, const ScatterVertex& v, int t, int first_vertex,
                                             const WavelengthsOf<T>& wl) const {
    using Colour = ColourOf<T>;
    MergeSum<T> sum;
    const auto add = [&](uint32_t i) {
        const Photon<T>& ph = volume_[i];
        if (ph.medium != v.medium || int(ph.vertex) < first_vertex || t + int(ph.vertex) - 1 > max_bounces_) return;
        sum.add(Colour(phase_eval(*v.phase, v.wi, ph.wi)) * ph.power, ph.dispersed);
    };
    // (photons of another medium, or of the light paths this estimate does not take, are left
    // out after the search)
    const float r = std::sqrt(gather_photons(volume_map_, v.p, options_.photon_radius, kVolumeK, add));
    if (!(r > 0)) return Colour(0.0f);
    // The camera path's throughput includes sigma_s here, as the photons' do at theirs: the path's, once.
    const Colour inv_sigma_s = divide_where_positive(Colour(1.0f), medium_view(scene.medium(v.medium), wl).coefficients(v.p).sigma_s);
    const float pi = faults_.no_pi_in_kernel ? 1.0f : kPi;
    return inv_sigma_s * sum.total(wl) / (faults_.volume_kernel_as_disc ? pi * r * r : 4.0f / 3.0f * pi * r * r * r);
}

template <class T>
ColourOf<T> PhotonMapper<T>::beam_estimate(const Vec3f& o, const Vec3f& d, float tmax, int32_t medium,
                                           const TransmittanceTrack<ColourOf<T>>& Tr, const PhaseFunction& phase, int t,
                                           const WavelengthsOf<T>& wl) const {
    using Colour = ColourOf<T>;
    const float pi = faults_.no_pi_in_kernel ? 1.0f : kPi;
    MergeSum<T> sum;
    volume_balls_.for_each_along(o, d, tmax, [&](uint32_t i, float s) {
        const Photon<T>& ph = volume_[i];
        // (a ball of radius 0: a photon whose neighbours all lie on it, no disc to spread it on)
        if (ph.medium != medium || t + int(ph.vertex) - 1 > max_bounces_ || !(volume_balls_.radius2(i) > 0)) return;
        const Colour Ts = faults_.beam_without_transmittance ? Colour(1.0f) : Tr.at(s);
        // The photon's disc across the ray: 1 / (pi r_p^2).
        sum.add(Ts * phase_eval(phase, -d, ph.wi) * ph.power / (pi * volume_balls_.radius2(i)), ph.dispersed);
    });
    return sum.total(wl);
}

template <class T>
ColourOf<T> PhotonMapper<T>::radiance_in_media(const Scene& scene, const Ray& camera_ray, Sampler& sampler, WavelengthsOf<T>& wl) const {
    using Colour = ColourOf<T>;
    const auto counts = [this](int length) { return length_counts(options_, length); };
    const bool photons = options_.only_length < 0;  // the estimates take paths of every length
    MediumState<T> st{sampler, wl};
    Colour L(0.0f);
    // Photon estimates are divided by the camera path's channels' densities as they stand when
    // they are made (the walk multiplies them in as it samples distances).
    const auto beams = [&](const Vec3f& o, const Vec3f& d, float tmax, int32_t medium, const TransmittanceTrack<Colour>& Tr,
                           const PhaseFunction& phase, int t) {
        return photons ? beam_estimate(o, d, tmax, medium, Tr, phase, t, wl) / st.density() : Colour(0.0f);
    };
    const bool use_beams = options_.volume_beam;
    const auto x = trace_to_visible_point_in_media<T>(scene, camera_ray, scene.camera_medium(), Colour(1.0f), sampler, st,
                                                      {1, max_bounces_, kMaxDiracChain, use_beams, true}, counts, beams, L, wl);
    if (!x) return L;
    const ScatterVertex v = x->vertex(scene);
    const Colour& beta = x->beta;
    const int t = x->t;
    // Direct light: a light sample and a BSDF or phase sample, by the balance heuristic.
    if (counts(t)) L += beta * estimate_light(scene, v, sampler, st, /*mis=*/true, wl) / st.density();
    if (x->in_medium()) {
        if (counts(t)) {
            const ScatterSample<T> n = sample_scatter(scene, v, sampler, st, /*mis=*/true, wl);
            if (n.sampled) L += beta * n.next_seg * n.found / st.density();
        }
        // The rest: the volume map's photons after one bounce at least.
        if (photons) L += beta * volume_estimate(scene, v, t, 2, wl) / st.density();
        return L;
    }
    // A surface: caustics, direct light, and one bounce of final gathering along the BSDF sample.
    if (photons) L += beta * estimate(caustic_, caustic_map_, kCausticK, x->sp, t, wl) / st.density();
    const Colour r_x = st.r;
    const ScatterSample<T> n = sample_scatter(scene, v, sampler, st, /*mis=*/true, wl);
    if (!n.sampled) return L;
    if (counts(t)) L += beta * n.next_seg * n.found / st.density();
    if (!photons || t + 1 > max_bounces_) return L;
    // The gathering ray walks anew (with beams it gathers along its pieces; with points it may
    // stop in a medium): the sample's own walk was by distance sampling and found emission only.
    st.r = r_x;
    const auto g = trace_to_visible_point_in_media<T>(scene, n.ray, n.medium, beta * n.weight, sampler, st,
                                                      {t + 1, max_bounces_, kMaxDiracChain, use_beams, false}, counts, beams, L, wl);
    if (!g) return L;
    if (g->in_medium()) return L + g->beta * volume_estimate(scene, g->vertex(scene), g->t, 1, wl) / st.density();
    return L + g->beta * estimate(global_, global_map_, kGlobalK, g->sp, g->t, wl) / st.density();
}

template class PhotonMapper<RgbTransport>;
template class PhotonMapper<SpectralTransport>;

const IntegratorInfo& pm_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"pm", {"photonmapper"}, "photon mapping (Jensen): global, caustic and volume maps, k-nearest estimates, final gathering",
                         false, true,
                         [] {
                             std::vector<ParamInfo> p = path_params();
                             p.push_back({"photon_count", ParamType::Integer, "0",
                                          "light paths of the photon maps (0: 8 per pixel; --photons wins)", "photonCount"});
                             p.push_back({"volume_estimate", ParamType::String, "beam",
                                          "in media: beam (the beam radiance estimate along the camera rays, each photon's ball the radius of its 16 "
                                          "nearest) or points (the 3D kernel of the 50 nearest at the camera path's scattering points); "
                                          "--volume-estimate wins"});
                             return p;
                         }(),
                         [](const IntegratorOptions& o) { return make_for_transport<PhotonMapper>(o); }};
        i.media = true;
        i.samples_lights = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
