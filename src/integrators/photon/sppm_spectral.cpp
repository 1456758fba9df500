// sppm and ppm in spectral mode (docs/spectral.md "Spectral photon mapping"): sppm.cpp's
// iteration (the same light paths, camera paths, radius schedule and random streams) with every
// path of a pass at the pass's wavelengths, photons of spectral power, and each pixel's pass
// sample converted by the film's estimator before it reaches the film. Kept apart from sppm.cpp
// so that RGB mode's translation unit and its photon loop stay exactly as they were.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>

#include "integrators/common/path_rules.hpp"
#include "integrators/photon/photon_grid.hpp"
#include "integrators/photon/progressive_radius.hpp"
#include "integrators/photon/spectral_photon_methods.hpp"
#include "integrators/photon/spectral_photons.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab {

namespace {

// sppm.cpp's streams: light path j of a pass, and its chunks.
uint64_t light_path_stream(size_t path) { return uint64_t(path) + (uint64_t(1) << 41); }
size_t paths_per_chunk(size_t paths) { return std::max<size_t>(64, paths / 256); }

class SppmSpectral final : public Integrator {
public:
    SppmSpectral(const IntegratorOptions& options, bool pixel_centres)
        : options_(limited_to_length(options)), pixel_centres_(pixel_centres),
          max_bounces_(options_.max_depth < 0 ? kMaxBounces : std::min(options_.max_depth, kMaxBounces)) {}

    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) override {
        const size_t pixels = ctx.pixel_count();
        const size_t paths = options_.photons > 0 ? size_t(options_.photons) : pixels;
        const double r1 = initial_photon_radius(ctx, options_), alpha = options_.photon_alpha;
        image_.resize(pixels);
        std::atomic<uint64_t> rays{0}, invalid{0};
        for (int k = 0; k < count; ++k) {
            const uint64_t pass = first + uint64_t(k);
            const SampledWavelengths wl = pass_wavelengths(ctx, pass);
            const float r = float(progressive_radius(r1, alpha, pass + 1));
            rays += trace_photons(ctx, pass, paths, wl);
            grid_.build(photons_, r);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 64), [&](const tbb::blocked_range<size_t>& range) {
                const uint64_t before = Scene::rays_traced_by_this_thread();
                uint64_t bad = 0;
                for (size_t p = range.begin(); p != range.end(); ++p) {
                    const Vec3d rgb = camera_sample(ctx, p, pass, r, paths, wl);
                    if (std::isfinite(rgb.x) && std::isfinite(rgb.y) && std::isfinite(rgb.z)) image_[p] = rgb;
                    else image_[p] = Vec3d(0.0), ++bad;
                }
                rays += Scene::rays_traced_by_this_thread() - before;
                invalid += bad;
            });
            film.add_pass(image_);
            if (progress) progress(double(k + 1) / count);
        }
        return {rays.load(), invalid.load()};
    }

private:
    // The photons of one iteration (sppm.cpp's trace_photons at the wavelengths wl), in chunk order.
    uint64_t trace_photons(const RenderContext& ctx, uint64_t pass, size_t paths, const SampledWavelengths& wl) {
        const size_t per_chunk = paths_per_chunk(paths), chunks = (paths + per_chunk - 1) / per_chunk;
        chunk_photons_.resize(chunks);
        chunk_powers_.resize(chunks);
        std::atomic<uint64_t> rays{0};
        const int max_vertices = max_bounces_ + 1;
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            const uint64_t rays_before = Scene::rays_traced_by_this_thread();
            std::vector<Photon>& out = chunk_photons_[c];
            std::vector<SpectralPower>& powers = chunk_powers_[c];
            out.clear(), powers.clear();
            for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
                Sampler sampler(ctx.seed, light_path_stream(j), pass, ctx.sampler);
                trace_spectral_light_path(ctx.scene, sampler, wl, max_vertices, options_.rr_depth, [&](const SpectralPhotonVertex& y) {
                    // y_2, y_3, ...: y_1 is direct light, next-event estimation's.
                    if (y.photon.vertex < 2 || int(y.photon.vertex) > max_bounces_) return;
                    out.push_back(y.photon);
                    powers.push_back({y.beta, y.hero_only});
                });
            }
            rays += Scene::rays_traced_by_this_thread() - rays_before;
        });
        photons_.clear(), powers_.clear();
        for (size_t c = 0; c < chunks; ++c) {
            photons_.insert(photons_.end(), chunk_photons_[c].begin(), chunk_photons_[c].end());
            powers_.insert(powers_.end(), chunk_powers_[c].begin(), chunk_powers_[c].end());
        }
        return rays.load();
    }

    // One pixel's sample of the pass (sppm.cpp's camera_sample at the pass's wavelengths), as
    // the film's linear sRGB.
    Vec3d camera_sample(const RenderContext& ctx, size_t pixel, uint64_t pass, float r, size_t paths,
                        const SampledWavelengths& pass_wl) const {
        const Scene& scene = ctx.scene;
        Sampler sampler(ctx.seed, pixel, pass, ctx.sampler);
        const Vec2f jitter = pixel_centres_ ? Vec2f(0.5f, 0.5f) : sampler.next2d();
        const float px = float(pixel % size_t(ctx.width)), py = float(pixel / size_t(ctx.width));
        const Ray ray = ctx.camera.generate(px + jitter.x, py + jitter.y);
        SampledWavelengths wl = pass_wl;  // this camera path's: a dispersive interface would reduce it
        Spectrum4 L(0.0f);
        const auto counts = [&](int length) {
            return (options_.only_length < 0 || options_.only_length == length) && !(options_.hide_emitters && length == 0);
        };
        const auto x = trace_to_visible_point_spectral(scene, ray, sampler, max_bounces_, max_bounces_ + 1, counts, L, wl);
        if (!x) return spectral_sample_to_linear_srgb(L, wl);
        const ShadingPoint& sp = x->sp;
        const Spectrum4& beta = x->beta;
        const int t = x->t;
        if (counts(t)) {
            L += beta * estimate_light_sample_spectral(scene, sp, sampler, /*mis=*/true, wl);
            if (const auto s = spectral_sample(sp, sampler.next2d(), wl)) {
                EmitterHit found;
                L += beta * estimate_bsdf_sample_mis_spectral(scene, sp, *s, spectral_sample_value(sp, *s, wl), found, wl);
            }
        }
        const float norm = float(paths) * kPi * r * r;
        SpectralMergeSum sum;
        grid_.for_each_within(sp.p, r, [&](const Photon& ph) {
            const int bounces = t + int(ph.vertex) - 1;
            if (bounces > max_bounces_ || !counts(bounces)) return;
            const SpectralPower& power = powers_[size_t(&ph - photons_.data())];
            sum.add(merge_bsdf_spectral(sp, ph.wi, wl), power);
        });
        L += beta * sum.total(wl) / norm;
        return spectral_sample_to_linear_srgb(L, wl);
    }

    IntegratorOptions options_;
    bool pixel_centres_;
    int max_bounces_;
    std::vector<std::vector<Photon>> chunk_photons_;
    std::vector<std::vector<SpectralPower>> chunk_powers_;
    std::vector<Photon> photons_;
    std::vector<SpectralPower> powers_;
    PhotonGrid grid_;
    std::vector<Vec3d> image_;
};

}  // namespace

std::unique_ptr<Integrator> make_spectral_sppm(const IntegratorOptions& options, bool pixel_centres) {
    return std::make_unique<SppmSpectral>(options, pixel_centres);
}

}  // namespace pathlab
