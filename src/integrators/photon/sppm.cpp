#include "integrators/photon/sppm.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>

#include "integrators/common/media_lighting.hpp"
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
      max_bounces_(bounce_limit(options_.max_depth)), light_paths_(options_) {}

template <class T>
double Sppm<T>::radius(double r1, double alpha, uint64_t i) { return progressive_radius(r1, alpha, i); }

template <class T>
float Sppm<T>::initial_radius(const RenderContext& ctx) const { return initial_photon_radius(ctx, options_); }

template <class T>
uint64_t Sppm<T>::trace_photons(const RenderContext& ctx, uint64_t pass, size_t paths, const WavelengthsOf<T>& wl, int hero) {
    const size_t per_chunk = paths_per_chunk(paths), chunks = (paths + per_chunk - 1) / per_chunk;
    const bool media = ctx.scene.has_media();
    // (each photon: its chunk's copy and the pass's, their densities in media, the grid's four arrays)
    if (&ctx.scene != checked_scene_) {
        check_photon_memory<PathVertex<T>>(rays_ == CameraRays::Jittered ? "sppm" : "ppm", paths,
                                           2 * (sizeof(Photon<T>) + (media ? sizeof(ColourOf<T>) : 0)) + 24, "--photons",
                                           [&](size_t j, std::vector<PathVertex<T>>& path) {
                                               Sampler sampler(ctx.seed, light_path_stream(j), pass, ctx.sampler);
                                               light_paths_.light_subpath(ctx, sampler, wl, path, nullptr, hero);
                                           });
        checked_scene_ = &ctx.scene;
    }
    chunk_photons_.resize(chunks);
    chunk_r_.resize(chunks);
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const uint64_t rays_before = Scene::rays_traced_by_this_thread();
        std::vector<PathVertex<T>>& path = paths_.local();  // keeps its capacity from pass to pass
        std::vector<Photon<T>>& out = chunk_photons_[c];
        std::vector<ColourOf<T>>& out_r = chunk_r_[c];
        out.clear(), out_r.clear();
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            Sampler sampler(ctx.seed, light_path_stream(j), pass, ctx.sampler);
            light_paths_.light_subpath(ctx, sampler, wl, path, nullptr, hero);
            // y_2, y_3, ...: y_1 is direct light, next-event estimation's; in media with beams
            // also y_1 (the camera path gathers light along its rays, with no light sample there).
            for (size_t v = 1; v < path.size(); ++v) {
                const PathVertex<T>& y = path[v];
                const bool in_medium = y.kind == VertexKind::Medium;
                if (v < (in_medium && options_.volume_beam ? 1u : 2u)) continue;
                if (!(y.kind == VertexKind::Surface || in_medium) || !y.connectible() || int(v) > max_bounces_) continue;
                out.push_back({y.p, in_medium ? y.dir : y.sp.frame.to_world(y.sp.wi), y.beta, uint16_t(v), y.dispersed, photon_medium(y)});
                if (media) out_r.push_back(y.r);
            }
        }
        rays += Scene::rays_traced_by_this_thread() - rays_before;
    });
    photons_.clear(), photon_r_.clear();
    for (const auto& c : chunk_photons_) photons_.insert(photons_.end(), c.begin(), c.end());
    for (const auto& c : chunk_r_) photon_r_.insert(photon_r_.end(), c.begin(), c.end());
    // The bounds of the photons in media (where a beam may find any).
    medium_photons_ = 0;
    medium_lo_ = Vec3f(kInf), medium_hi_ = Vec3f(-kInf);
    for (const Photon<T>& ph : photons_)
        if (ph.in_medium()) ++medium_photons_, medium_lo_ = min(medium_lo_, ph.p), medium_hi_ = max(medium_hi_, ph.p);
    return rays.load();
}

template <class T>
Ray Sppm<T>::pixel_ray(const RenderContext& ctx, size_t pixel, Sampler& sampler) const {
    const Vec2f jitter = rays_ == CameraRays::Jittered ? sampler.next2d() : Vec2f(0.5f, 0.5f);
    const float px = float(pixel % size_t(ctx.width)), py = float(pixel / size_t(ctx.width));
    return ctx.camera.generate(px + jitter.x, py + jitter.y);
}

template <class T>
ColourOf<T> Sppm<T>::gather(const Scene& scene, const ScatterVertex& v, const ShadingPoint& sp, const ColourOf<T>& r_camera, int t, float r,
                            size_t paths, const WavelengthsOf<T>& wl) const {
    using Colour = ColourOf<T>;
    const bool in_medium = v.phase != nullptr;
    // Photons of the same medium only (in a medium; a ball may reach across a boundary).
    const int16_t gathered_medium = in_medium ? int16_t(v.medium) : int16_t(-1);
    const bool camera_dispersed = wl.secondary_terminated();
    MergeSum<T> sum;
    grid_.for_each_within(v.p, r, [&](uint32_t i) {
        const Photon<T>& ph = photons_[i];
        if (ph.medium != gathered_medium) return;
        const int bounces = t + int(ph.vertex) - 1;
        if (bounces > max_bounces_ || !counts(bounces)) return;
        Colour f;
        if (in_medium) {
            f = Colour(phase_eval(*v.phase, v.wi, ph.wi));
        } else {
            const Vec3f wo = sp.frame.to_local(ph.wi);
            f = bsdf_colour(sp, wo, sp.material->eval(sp, sp.wi, wo), wl);
        }
        // The spectral MIS over the hero channel both subpaths shared.
        sum.add(f * ph.power / path_density_of(photon_r_[i] * r_camera, ph.dispersed || camera_dispersed), ph.dispersed);
    });
    const float pi = faults_.no_pi_in_kernel ? 1.0f : kPi;
    if (!in_medium) return sum.total(wl) / (float(paths) * pi * r * r);
    // The camera path's throughput includes sigma_s here, as the photons' do at theirs: the path's, once.
    const Colour inv_sigma_s = divide_where_positive(Colour(1.0f), medium_view(scene.medium(v.medium), wl).coefficients(v.p).sigma_s);
    const float norm = float(paths) * (faults_.volume_kernel_as_disc ? pi * r * r : 4.0f / 3.0f * pi * r * r * r);
    return inv_sigma_s * sum.total(wl) / norm;
}

template <class T>
ColourOf<T> Sppm<T>::beam(const Vec3f& o, const Vec3f& d, float tmax, int32_t medium, const TransmittanceTrack<ColourOf<T>>& Tr,
                          const PhaseFunction& phase, int t, float r, size_t paths, const WavelengthsOf<T>& wl) const {
    using Colour = ColourOf<T>;
    // The part of the ray within r of the medium photons' bounds.
    float t0 = 0, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        const float lo = medium_lo_[a] - r, hi = medium_hi_[a] + r;
        if (d[a] == 0) {
            if (o[a] < lo || o[a] > hi) return Colour(0.0f);
            continue;
        }
        float ta = (lo - o[a]) / d[a], tb = (hi - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    if (!(t0 < t1)) return Colour(0.0f);
    // Pieces of length r along it, each searched with the ball around its middle that holds
    // every point within r of it; a photon counts in the piece its projection falls in (once).
    const float step = r, query = r * std::sqrt(1.25f), r2 = r * r;
    const bool camera_dispersed = wl.secondary_terminated();
    const Vec3f wi = -d;
    MergeSum<T> sum;
    for (float a = t0; a < t1; a += step) {
        const float b = std::min(a + step, t1);
        grid_.for_each_within(o + d * (0.5f * (a + b)), query, [&](uint32_t i) {
            const Photon<T>& ph = photons_[i];
            if (ph.medium != medium) return;
            const Vec3f op = ph.p - o;
            const float tp = dot(op, d);
            if (!(tp >= a && tp < b) || dot(op, op) - tp * tp > r2) return;
            const int bounces = t + int(ph.vertex) - 1;
            if (bounces > max_bounces_ || !counts(bounces)) return;
            // The camera side is not sampled by distance here: the photon's densities alone.
            const Colour Tp = faults_.beam_without_transmittance ? Colour(1.0f) : Tr.at(tp);
            const Colour c = Tp * phase_eval(phase, wi, ph.wi) * ph.power / path_density_of(photon_r_[i], ph.dispersed || camera_dispersed);
            sum.add(c, ph.dispersed);
        });
    }
    // The photon's disc (Jarosz et al. 2008): 1 / (pi r^2).
    return sum.total(wl) / (float(paths) * (faults_.no_pi_in_kernel ? 1.0f : kPi) * r2);
}

template <class T>
Vec3d Sppm<T>::camera_sample_in_media(const RenderContext& ctx, size_t pixel, uint64_t pass, float r, size_t paths,
                                      const WavelengthsOf<T>& pass_wl, int hero) const {
    using Colour = ColourOf<T>;
    const Scene& scene = ctx.scene;
    Sampler sampler(ctx.seed, pixel, pass, ctx.sampler);
    Ray ray = pixel_ray(ctx, pixel, sampler);
    WavelengthsOf<T> wl = pass_wl;  // this camera path's: a dispersive interface would reduce it
    MediumState<T> st{sampler, wl};
    st.hero = hero;
    Colour L(0.0f);
    // Through media and Dirac lobes to the first other scattering point (the emission found on
    // the way is seen directly or through Dirac lobes only: no other strategy has it). With
    // beams the camera path does not scatter in media: it gathers the photons along each piece
    // of ray in a medium, and goes on with the piece's transmittance.
    const auto beams = [&](const Vec3f& o, const Vec3f& d, float tmax, int32_t medium, const TransmittanceTrack<Colour>& Tr,
                           const PhaseFunction& phase, int t) {
        return medium_photons_ > 0 ? beam(o, d, tmax, medium, Tr, phase, t, r, paths, wl) : Colour(0.0f);
    };
    const auto counts = [this](int length) { return this->counts(length); };
    const MediaWalkRules rules{1, max_bounces_, max_bounces_ + 1, options_.volume_beam, true};
    const auto x = trace_to_visible_point_in_media<T>(scene, ray, scene.camera_medium(), Colour(1.0f), sampler, st, rules, counts, beams, L, wl);
    if (!x) return film_colour(L, wl);
    // The visible point: the photons (with the camera path's distance densities as they are
    // here), and direct light by volpath's MIS pair.
    const ScatterVertex v = x->vertex(scene);
    const Colour& beta = x->beta;
    const int t = x->t;
    L += beta * gather(scene, v, x->sp, st.r, t, r, paths, wl);
    if (counts(t)) {
        L += beta * estimate_light(scene, v, sampler, st, /*mis=*/true, wl) / st.density();
        const ScatterSample<T> n = sample_scatter(scene, v, sampler, st, /*mis=*/true, wl);
        if (n.sampled) L += beta * n.next_seg * n.found / st.density();
    }
    return film_colour(L, wl);
}

template <class T>
Vec3d Sppm<T>::camera_sample(const RenderContext& ctx, size_t pixel, uint64_t pass, float r, size_t paths,
                             const WavelengthsOf<T>& pass_wl) const {
    using Colour = ColourOf<T>;
    const Scene& scene = ctx.scene;
    Sampler sampler(ctx.seed, pixel, pass, ctx.sampler);
    Ray ray = pixel_ray(ctx, pixel, sampler);
    WavelengthsOf<T> wl = pass_wl;  // this camera path's: a dispersive interface would reduce it
    Colour L(0.0f);
    const auto counts = [this](int length) { return this->counts(length); };
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
        // In media, one hero channel for every path of the iteration (see sppm.hpp).
        const int hero = Bdpt<T>::sample_hero(ctx, pixels, pass, wl);
        rays += trace_photons(ctx, pass, paths, wl, hero);
        const bool media = ctx.scene.has_media();
        // (a beam's searches reach up to 1.12 r from their centres)
        grid_.build(photons_, media ? 1.2f * r : r);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 64), [&](const tbb::blocked_range<size_t>& range) {
            const uint64_t before = Scene::rays_traced_by_this_thread();
            uint64_t bad = 0;
            for (size_t p = range.begin(); p != range.end(); ++p) {
                const Vec3d L = media ? camera_sample_in_media(ctx, p, pass, r, paths, wl, hero) : camera_sample(ctx, p, pass, r, paths, wl);
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
    p.push_back({"volume_estimate", ParamType::String, "beam",
                 "in media: beam (the beam radiance estimate along the camera rays) or points (the 3D kernel at the camera path's first "
                 "scattering point); --volume-estimate wins"});
    return p;
}

}  // namespace

const IntegratorInfo& sppm_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"sppm", {}, "stochastic progressive photon mapping (Knaus-Zwicker iterations): photons + next-event estimation",
                         false, true, progressive_photon_params(), [](const IntegratorOptions& o) { return make_for_transport<Sppm>(o); },
                         false, false};
        i.media = true;
        i.samples_lights = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

const IntegratorInfo& ppm_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"ppm", {}, "progressive photon mapping (Hachisuka 2008): fixed hit points through the pixel centres, photon passes, shrinking radius",
                         false, true, progressive_photon_params(),
                         [](const IntegratorOptions& o) { return make_for_transport<Sppm>(o, SppmFaults{}, CameraRays::PixelCentres); },
                         false, false};
        i.media = true;
        i.samples_lights = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
