// Primary-sample-space Metropolis light transport (Kelemen, Szirmay-Kalos, Antal and Csonka
// 2002) over pt-mis: a path is pt-mis's pixel sample made from a vector of uniform numbers X
// (the first two: the raster position over the whole image; then the lens, the wavelengths in
// spectral mode, and every number the path tracer draws), and Markov chains over X
// (samplers/primary_samples.hpp: large and small steps) visit paths in proportion to their
// scalar contribution I(X) (the luminance of |R|, |G|, |B|, so that I > 0 wherever the path
// carries light).
//
// The estimate. With b = the integral of I over primary sample space, a chain whose states X_k
// are distributed as I / b estimates pixel j's value as (pixels * b / M) * sum_k 1_j(X_k) L(X_k)
// / I(X_k) over M states. Expected-value splatting (Veach's thesis, 11.4): at each step both the
// proposal Y and the current state X are splatted, weighted by the acceptance probability a and
// 1 - a, whichever the chain keeps.
//
// One pass = pixels mutations, spread over --chains chains, so a pass costs about one pt-mis
// sample per pixel and adds one sample of every pixel. Each pass is a pure function of (seed,
// pass): it draws its own bootstrap of --bootstrap independent paths, estimates b from them
// and starts every chain from one of them chosen in proportion to I (resampling). That start is
// exact, not only asymptotically: for the pool's estimate b^ and a start X_0 resampled from it,
// E[b^ g(X_0) / I(X_0)] is the integral of g for any g, and a kernel that keeps I / b invariant
// keeps it so for every later state. So every pass is an unbiased estimate, passes are
// independent, and the film's standard errors over passes are right (no start-up bias to burn
// in, no normalisation error that more passes would not average out).
//
// Chains run in parallel, each splatting into its own list; the lists are added in chain order,
// so the image does not depend on the thread count. The chains' number, the bootstrap's size and
// the mutations are the options: --chains, --bootstrap, --large-step, --sigma.
#include "integrators/mlt/pssmlt.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "integrators/integrators.hpp"
#include "integrators/path/pt_mis.hpp"

namespace pathlab {

namespace {

// Streams of the render's numbers, apart from each other and from every pixel's.
constexpr uint64_t kBootstrapStream = 0x6d6c742d626f6f74ull;  // "mlt-boot"
constexpr uint64_t kChainStream = 0x6d6c742d63686169ull;      // "mlt-chai"
constexpr uint64_t kNormalisationPass = ~uint64_t(0);          // prepare()'s bootstrap, for the metadata

uint64_t stream_seed(uint64_t seed, uint64_t pass, uint64_t stream) { return mix64(mix64(seed ^ stream) + pass); }

}  // namespace

double mlt_contribution(const Vec3d& c) {
    return 0.2126 * std::abs(c.x) + 0.7152 * std::abs(c.y) + 0.0722 * std::abs(c.z);
}

template <class T>
Pssmlt<T>::Pssmlt(const IntegratorOptions& o, PssmltFaults faults) : options_(limited_to_length(o)), rules_(options_), faults_(faults) {}

template <class T>
typename Pssmlt<T>::PathSample Pssmlt<T>::evaluate(const RenderContext& ctx, PrimarySamples& state) const {
    Sampler sampler(state);
    const Vec2f u = sampler.next2d();
    PathSample p;
    p.raster = {std::min(u.x * float(ctx.width), std::nextafter(float(ctx.width), 0.0f)),
                std::min(u.y * float(ctx.height), std::nextafter(float(ctx.height), 0.0f))};
    const Ray ray = ctx.camera.needs_lens_sample() ? ctx.camera.generate(p.raster.x, p.raster.y, sampler.next2d())
                                                   : ctx.camera.generate(p.raster.x, p.raster.y);
    WavelengthsOf<T> wl = T::camera_wavelengths(sampler);
    const auto L = pt_mis_camera_radiance(ctx.scene, ray, sampler, rules_, wl, false, options_.only_length, options_.hide_emitters);
    p.colour = film_colour(L, wl);
    if (!is_finite(p.colour)) {
        p.colour = Vec3d(0.0), p.invalid = true;
        return p;
    }
    p.contribution = mlt_contribution(p.colour);
    return p;
}

template <class T>
double Pssmlt<T>::bootstrap(const RenderContext& ctx, uint64_t pass, int n, std::vector<double>& cumulative, uint64_t& invalid,
                            std::atomic<uint64_t>& rays) {
    weights_.resize(size_t(n));
    const uint64_t seed = stream_seed(ctx.seed, pass, kBootstrapStream);
    std::atomic<uint64_t> bad{0};
    // In as many parts as there are chains, each with a chain's state (no allocation once warm).
    const int parts = int(states_.size());
    tbb::parallel_for(tbb::blocked_range<int>(0, parts, 1), [&](const tbb::blocked_range<int>& r) {
        for (int part = r.begin(); part != r.end(); ++part) {
            const uint64_t rays_before = Scene::rays_traced_by_this_thread();
            PrimarySamples& state = states_[size_t(part)];
            uint64_t local_bad = 0;
            for (int i = int(int64_t(n) * part / parts); i < int(int64_t(n) * (part + 1) / parts); ++i) {
                state.restart(seed, uint64_t(i));
                state.start_iteration(true);
                const PathSample p = evaluate(ctx, state);
                local_bad += p.invalid;
                weights_[size_t(i)] = p.contribution;
            }
            bad += local_bad;
            rays += Scene::rays_traced_by_this_thread() - rays_before;
        }
    });
    invalid += bad.load();
    cumulative.resize(size_t(n));
    double sum = 0;
    for (int i = 0; i < n; ++i) cumulative[size_t(i)] = sum += weights_[size_t(i)];
    return sum / double(n);
}

template <class T>
void Pssmlt<T>::make_states(const RenderContext& ctx) {
    const size_t chains = std::min<size_t>(size_t(options_.mlt_chains), ctx.pixel_count());
    if (states_.size() != chains) states_.assign(chains, PrimarySamples(options_.mlt_sigma, options_.mlt_large_step));
}

template <class T>
void Pssmlt<T>::prepare(const RenderContext& ctx, const PassProgress&) {
    make_states(ctx);
    // b from a bootstrap of its own, 16 times a pass's: the figure the image's metadata states.
    const int n = int(std::min<int64_t>(int64_t(options_.mlt_bootstrap) * 16, 1 << 24));
    std::vector<double> cumulative;
    uint64_t invalid = 0;
    std::atomic<uint64_t> rays{0};
    normalisation_ = bootstrap(ctx, kNormalisationPass, n, cumulative, invalid, rays);
}

template <class T>
PassCounters Pssmlt<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    const size_t pixels = ctx.pixel_count();
    make_states(ctx);
    const int chains = int(states_.size());
    std::atomic<uint64_t> rays{0}, invalid{0}, accepted{0}, proposed{0};
    const bool filtered = ctx.filter && !ctx.filter->is_box();
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        uint64_t bad = 0;
        const double b = bootstrap(ctx, pass, options_.mlt_bootstrap, cumulative_, bad, rays);
        invalid += bad;
        pass_.begin(pixels, chains);
        if (b > 0) {
            // Each path's weight: pixels * b / M with M = pixels mutations in the pass.
            const double scale = b;
            const uint64_t boot_seed = stream_seed(ctx.seed, pass, kBootstrapStream);
            const uint64_t chain_seed = stream_seed(ctx.seed, pass, kChainStream);
            std::atomic<int> chains_done{0};
            tbb::parallel_for(tbb::blocked_range<int>(0, chains, 1), [&](const tbb::blocked_range<int>& range) {
                for (int c = range.begin(); c != range.end(); ++c) {
                    const uint64_t chain_rays_before = Scene::rays_traced_by_this_thread();
                    PrimarySamples& state = states_[size_t(c)];
                    SplatList& out = pass_.chunk(c);
                    const auto splat = [&](const PathSample& p, double weight) {
                        if (weight <= 0) return;
                        const Rgb v(p.colour * (weight * scale));
                        if (filtered) out.add_at(p.raster, v);
                        else out.add(uint32_t(size_t(p.raster.y) * size_t(ctx.width) + size_t(p.raster.x)), v);
                    };
                    // The start: a bootstrap path chosen in proportion to I, made again from its numbers.
                    Pcg32 pick(chain_seed, uint64_t(c));
                    const double u = double(pick.next_float()) * cumulative_.back();
                    const size_t start = std::min(size_t(std::upper_bound(cumulative_.begin(), cumulative_.end(), u) - cumulative_.begin()),
                                                  cumulative_.size() - 1);
                    state.restart(boot_seed, uint64_t(start));
                    state.start_iteration(true);
                    PathSample x = evaluate(ctx, state);
                    state.accept();
                    state.reseed(chain_seed, uint64_t(chains) + uint64_t(c));
                    // This chain's share of the pass's mutations.
                    const size_t steps = pixels / size_t(chains) + (size_t(c) < pixels % size_t(chains) ? 1 : 0);
                    double x_weight = 0;  // X's expected-value weight, splatted when the chain leaves X
                    uint64_t chain_accepted = 0, chain_invalid = 0;
                    for (size_t m = 0; m < steps; ++m) {
                        state.start_iteration();
                        const PathSample y = evaluate(ctx, state);
                        chain_invalid += y.invalid;
                        const double a = y.contribution <= 0 ? 0.0 : x.contribution <= 0 ? 1.0 : std::min(1.0, y.contribution / x.contribution);
                        if (a > 0) splat(y, a / y.contribution);
                        if (a < 1 && !faults_.drop_current_weight) x_weight += (1 - a) / x.contribution;
                        if (double(state.uniform()) < a) {
                            state.accept();
                            splat(x, x_weight);
                            x = y, x_weight = 0;
                            ++chain_accepted;
                        } else {
                            state.reject();
                        }
                    }
                    splat(x, x_weight);
                    accepted += chain_accepted, proposed += steps, invalid += chain_invalid;
                    rays += Scene::rays_traced_by_this_thread() - chain_rays_before;
                    if (progress) progress((double(k) + double(++chains_done) / chains) / count);
                }
            });
        }
        pass_.finish(film, ctx.filter, Vec2f(0.0f, 0.0f));
    }
    accepted_ += accepted.load(), proposed_ += proposed.load();
    return {rays.load(), invalid.load()};
}

template <class T>
std::vector<IntegratorStatistic> Pssmlt<T>::statistics() const {
    return {{"mlt normalisation", normalisation_, true},
            {"acceptance", proposed_ ? double(accepted_) / double(proposed_) : 0.0}};
}

template class Pssmlt<RgbTransport>;
template class Pssmlt<SpectralTransport>;

const IntegratorInfo& pssmlt_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"pssmlt",
                         {},
                         "primary-sample-space Metropolis light transport (Kelemen 2002) over pt-mis: Markov chains of large and small steps, "
                         "expected-value splatting",
                         false,
                         true,
                         path_params(),
                         [](const IntegratorOptions& o) { return make_for_transport<Pssmlt>(o); }};
        i.samples_lights = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
