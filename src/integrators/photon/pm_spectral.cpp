// pm in spectral mode (docs/spectral.md "Spectral photon mapping"). RGB mode's pm builds its
// photon maps once, in prepare(); at fixed wavelengths that would fix every pass's colour
// sampling too, an error more passes never remove. So here each pass draws its wavelengths
// (pass_wavelengths), traces pm's full photon count at them (the same light paths as pm.cpp's,
// each pass from its own sample index), builds the global and caustic k-d trees, and renders one
// sample per pixel with pm.cpp's estimator (direct light, caustic map, one-bounce final
// gathering into the global map) at those wavelengths. The estimator per pass is exactly RGB
// pm's, with the same bias at a photon count; the price is the photon pass in every pass
// (measured in the docs). pm is a PixelIntegrator in RGB mode; this one owns its passes (the
// pass loop must come before the pixels), with the tile loop's jitter, lens sample and
// reconstruction filter.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>

#include "integrators/common/path_rules.hpp"
#include "integrators/photon/photon_grid.hpp"
#include "integrators/photon/spectral_photon_methods.hpp"
#include "integrators/photon/spectral_photons.hpp"
#include "render/pixel_filter.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab {
namespace {

constexpr size_t kGlobalK = 50, kCausticK = 20;  // pm.cpp's
constexpr int kMaxDiracChain = 16;

// A photon map: RGB mode's photons (positions, directions, vertex) searched by the k-d tree,
// and their spectral powers at the same indices.
struct PhotonList {
    std::vector<Photon> photons;
    std::vector<SpectralPower> powers;
    void clear() { photons.clear(), powers.clear(); }
    void push(const SpectralPhotonVertex& y, float inv_paths) {
        photons.push_back(y.photon);
        powers.push_back({y.beta * inv_paths, y.hero_only});
    }
    void append(const PhotonList& o) {
        photons.insert(photons.end(), o.photons.begin(), o.photons.end());
        powers.insert(powers.end(), o.powers.begin(), o.powers.end());
    }
};
struct SpectralPhotonMap : PhotonList {
    PhotonKdTree tree;
};

class PhotonMapperSpectral final : public Integrator {
public:
    explicit PhotonMapperSpectral(const IntegratorOptions& options)
        : options_(limited_to_length(options)),
          max_bounces_(options_.max_depth < 0 ? kMaxBounces : std::min(options_.max_depth, kMaxBounces)) {}

    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) override {
        const int w = ctx.width;
        const size_t pixels = ctx.pixel_count();
        const bool filtered = ctx.filter && !ctx.filter->is_box();
        const bool lens = ctx.camera.needs_lens_sample();
        image_.resize(pixels);
        std::atomic<uint64_t> rays{0}, invalid{0};
        for (int k = 0; k < count; ++k) {
            const uint64_t pass = first + uint64_t(k);
            const SampledWavelengths wl = pass_wavelengths(ctx, pass);
            rays += build_maps(ctx, pass, wl);
            const Vec2f shift = filtered ? filter_shift(ctx, pass) : Vec2f(0.0f, 0.0f);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 64), [&](const tbb::blocked_range<size_t>& range) {
                const uint64_t before = Scene::rays_traced_by_this_thread();
                uint64_t bad = 0;
                for (size_t p = range.begin(); p != range.end(); ++p) {
                    const int x = int(p % size_t(w)), y = int(p / size_t(w));
                    // PixelIntegrator's camera sample: the jitter (drawn and replaced by the
                    // pass's lattice shift under a filter), then the lens sample.
                    Sampler sampler(ctx.seed, p, pass, ctx.sampler);
                    const Vec2f jitter = sampler.next2d();
                    const float sx = float(x) + (filtered ? shift.x : jitter.x), sy = float(y) + (filtered ? shift.y : jitter.y);
                    const Ray ray = lens ? ctx.camera.generate(sx, sy, sampler.next2d()) : ctx.camera.generate(sx, sy);
                    SampledWavelengths cam_wl = wl;
                    const Spectrum4 L = radiance(ctx.scene, ray, sampler, cam_wl);
                    const Vec3d rgb = spectral_sample_to_linear_srgb(L, cam_wl);
                    if (std::isfinite(rgb.x) && std::isfinite(rgb.y) && std::isfinite(rgb.z)) image_[p] = rgb;
                    else image_[p] = Vec3d(0.0), ++bad;
                }
                rays += Scene::rays_traced_by_this_thread() - before;
                invalid += bad;
            });
            if (filtered) {
                ctx.filter->filter_pass(image_, shift, filtered_);
                film.add_pass(filtered_);
            } else {
                film.add_pass(image_);
            }
            if (progress) progress(double(k + 1) / count);
        }
        return {rays.load(), invalid.load()};
    }

    std::vector<IntegratorStatistic> statistics() const override {
        return {{"global photons (last pass)", double(global_.photons.size())}, {"caustic photons (last pass)", double(caustic_.photons.size())}};
    }

private:
    // pm.cpp's prepare() for one pass: its light paths from sample index `pass` at the wavelengths wl.
    uint64_t build_maps(const RenderContext& ctx, uint64_t pass, const SampledWavelengths& wl) {
        const size_t paths = options_.photons > 0 ? size_t(options_.photons) : 8 * ctx.pixel_count();
        const size_t per_chunk = std::max<size_t>(256, paths / 256), chunks = (paths + per_chunk - 1) / per_chunk;
        chunk_global_.resize(chunks), chunk_caustic_.resize(chunks);
        const float inv_paths = 1.0f / float(paths);
        const int max_vertices = max_bounces_ + 1;
        std::atomic<uint64_t> rays{0};
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            const uint64_t rays_before = Scene::rays_traced_by_this_thread();
            PhotonList& global = chunk_global_[c];
            PhotonList& caustic = chunk_caustic_[c];
            global.clear(), caustic.clear();
            for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
                Sampler sampler(ctx.seed, uint64_t(j) + (uint64_t(3) << 41), pass, ctx.sampler);
                trace_spectral_light_path(ctx.scene, sampler, wl, max_vertices, options_.rr_depth, [&](const SpectralPhotonVertex& y) {
                    global.push(y, inv_paths);
                    if (y.photon.vertex >= 2 && y.through_dirac_only) caustic.push(y, inv_paths);
                });
            }
            rays += Scene::rays_traced_by_this_thread() - rays_before;
        });
        global_.clear(), caustic_.clear();
        for (size_t c = 0; c < chunks; ++c) global_.append(chunk_global_[c]), caustic_.append(chunk_caustic_[c]);
        global_.tree.build(global_.photons, 0);
        caustic_.tree.build(caustic_.photons, 0);
        return rays.load();
    }

    // pm.cpp's estimate() at the wavelengths wl.
    Spectrum4 estimate(const SpectralPhotonMap& map, size_t k, const ShadingPoint& sp, int t, const SampledWavelengths& wl) const {
        uint32_t indices[kGlobalK];
        float dist2[kGlobalK];
        float r2 = 0;
        SpectralMergeSum sum;
        const auto add = [&](uint32_t i) {
            const Photon& ph = map.photons[i];
            if (t + int(ph.vertex) - 1 > max_bounces_) return;
            sum.add(merge_bsdf_spectral(sp, ph.wi, wl), map.powers[i]);
        };
        if (options_.photon_radius > 0) {
            r2 = options_.photon_radius * options_.photon_radius;
            map.tree.for_each_within(sp.p, options_.photon_radius, [&](const Photon& ph) { add(uint32_t(&ph - map.photons.data())); });
        } else {
            const size_t n = map.tree.nearest(sp.p, std::min(k, kGlobalK), indices, dist2);
            if (n < 2) return Spectrum4(0.0f);
            r2 = dist2[n - 1];
            for (size_t i = 0; i + 1 < n; ++i) add(indices[i]);
        }
        if (!(r2 > 0)) return Spectrum4(0.0f);
        return sum.total(wl) / (kPi * r2);
    }

    // pm.cpp's radiance() at the wavelengths wl.
    Spectrum4 radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, SampledWavelengths& wl) const {
        const auto counts = [&](int length) {
            return (options_.only_length < 0 || options_.only_length == length) && !(options_.hide_emitters && length == 0);
        };
        Spectrum4 L(0.0f);
        const auto x = trace_to_visible_point_spectral(scene, camera_ray, sampler, max_bounces_, kMaxDiracChain, counts, L, wl);
        if (!x) return L;
        const ShadingPoint& sp = x->sp;
        const Spectrum4& beta = x->beta;
        const int t = x->t;
        if (counts(t)) L += beta * estimate_light_sample_spectral(scene, sp, sampler, /*mis=*/true, wl);
        if (options_.only_length < 0) L += beta * estimate(caustic_, kCausticK, sp, t, wl);
        const auto g = spectral_sample(sp, sampler.next2d(), wl);
        if (!g) return L;
        const Spectrum4 gf = spectral_sample_value(sp, *g, wl);
        EmitterHit found;
        const Spectrum4 emission = estimate_bsdf_sample_mis_spectral(scene, sp, *g, gf, found, wl);
        if (counts(t)) L += beta * emission;
        if (!found.hit || t + 1 > max_bounces_ || options_.only_length >= 0) return L;
        Spectrum4 gbeta = beta * gf * (std::abs(g->wo.z) / g->pdfW);
        Intersection ghit = found.isect;
        Vec3f gdir = sp.frame.to_world(g->wo);
        for (int u = t + 1; u - 1 <= max_bounces_ && u <= t + kMaxDiracChain; ++u) {
            const ShadingPoint gp = make_shading_point(scene, ghit, gdir);
            if (gp.material->is_black()) return L;
            if (!gp.material->is_delta()) return L + gbeta * estimate(global_, kGlobalK, gp, u, wl);
            const auto s = spectral_sample(gp, sampler.next2d(), wl);
            if (!s) return L;
            gbeta *= spectral_sample_value(gp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
            gdir = gp.frame.to_world(s->wo);
            if (!scene.intersect(gp.spawn(s->wo), ghit)) return L;
        }
        return L;
    }

    IntegratorOptions options_;
    int max_bounces_;
    std::vector<PhotonList> chunk_global_, chunk_caustic_;
    SpectralPhotonMap global_, caustic_;
    std::vector<Vec3d> image_, filtered_;
};

}  // namespace

std::unique_ptr<Integrator> make_spectral_pm(const IntegratorOptions& options) { return std::make_unique<PhotonMapperSpectral>(options); }

}  // namespace pathlab
