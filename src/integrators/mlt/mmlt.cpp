// Multiplexed Metropolis light transport (Hachisuka, Kaplanyan and Dachsbacher 2014) over
// bdpt: a state is a path length d (bounces, the state's label, which mutations keep) and three
// streams of uniform numbers: the camera subpath's (first the strategy, then the raster
// position over the whole image, the wavelengths in spectral mode, the hero channel in media,
// the walk), the light subpath's and the connection's (next-event estimation's light point,
// transmittance estimates). The first number picks one of bdpt's n_d strategies (s, t) with
// s + t = d + 2 uniformly (n_d = d + 2: s = 0 .. d + 1, t >= 1; at d = 0 s = 0, t = 2, and in
// scenes with media s = t = 1 too, as bdpt has it); the camera subpath is traced to t vertices, the light subpath to s, and
// the strategy's contribution is bdpt's connection times its MIS weight times n_d. So the
// contribution a chain follows is the part of the path that this strategy samples well: the
// chain moves between strategies as it moves between paths, and a path that only one strategy
// finds (a caustic, light through a door ajar) is explored with that one.
//
// Its sum over the strategies of a length is bdpt's estimate of that length, and bdpt's weights
// sum to one over the strategies that make a path, so the chains converge to bdpt's image at
// the same --max-depth (markov_chains.hpp: every pass unbiased). Russian roulette is off: the
// subpaths' lengths are the state's. The chains cover the lengths 0 .. --max-depth (only
// --only-length's with it); an unlimited depth has no last length, so mmlt asks for one.
#include "integrators/mlt/mmlt.hpp"

#include <algorithm>
#include <cmath>

#include "integrators/integrators.hpp"

namespace pathlab {

template <class T>
IntegratorOptions Mmlt<T>::bdpt_options(IntegratorOptions o) {
    o = limited_to_length(o);
    o.rr_depth = -1;  // each subpath's length is the state's
    o.strategies_dir.clear();
    return o;
}

template <class T>
Mmlt<T>::Mmlt(const IntegratorOptions& o, ChainFaults faults)
    : options_(bdpt_options(o)),
      bdpt_(options_),
      first_length_(options_.only_length >= 0 ? options_.only_length : 0),
      lengths_(bdpt_.max_bounces() - first_length_ + 1),
      chains_(options_, /*streams=*/3, lengths_, faults),
      faults_(faults) {}

template <class T>
ChainSample Mmlt<T>::evaluate(const RenderContext& ctx, PrimarySamples& state, int chain) {
    Sampler camera_numbers(state, 0), light_numbers(state, 1), connection_numbers(state, 2);
    const int d = first_length_ + int(state.label());
    const int strategies = d == 0 ? (Bdpt<T>::connects_emitters_to_camera(ctx.scene) ? 2 : 1) : d + 2;
    const int s = std::min(int(camera_numbers.next1d() * float(strategies)), strategies - 1), t = d + 2 - s;
    const Vec2f raster = raster_anywhere(ctx, camera_numbers.next2d());
    const WavelengthsOf<T> wl = T::camera_wavelengths(camera_numbers);
    const int hero = ctx.scene.has_media() ? hero_channel(wl, [&] { return camera_numbers.next1d(); }) : -1;
    ChainSample p;
    p.raster = raster;
    if (options_.hide_emitters && d == 0) return p;
    auto& [camera, light] = subpaths_[size_t(chain)];
    bdpt_.camera_subpath_at(ctx, raster, camera_numbers, wl, camera, t, nullptr, hero);
    if (int(camera.size()) < t) return p;
    light.clear();
    if (s >= 2 || t == 1) {  // (s = 1, t > 1 samples its light point in the connection; s = 0 has none)
        bdpt_.light_subpath(ctx, light_numbers, wl, light, nullptr, hero, s);
        if (int(light.size()) < s) return p;
    }
    const StrategyResult<T> r = bdpt_.connect(ctx, light, s, camera, t, connection_numbers, wl);
    if (is_black(r.L)) return p;
    return chain_sample(r.splat ? r.raster : raster,
                        film_colour(r.L * (r.weight * (faults_.drop_strategy_count ? 1.0f : float(strategies))), wl));
}

template <class T>
void Mmlt<T>::make_subpaths() {
    if (!subpaths_.empty()) return;
    subpaths_.resize(size_t(std::max(1, options_.mlt_chains)));
    for (auto& [camera, light] : subpaths_) {
        camera.reserve(size_t(bdpt_.max_camera_vertices()));
        light.reserve(size_t(bdpt_.max_light_vertices()));
    }
}

template <class T>
void Mmlt<T>::prepare(const RenderContext& ctx, const PassProgress&) {
    make_subpaths();
    chains_.prepare(ctx, [this](const RenderContext& c, PrimarySamples& state, int chain) { return evaluate(c, state, chain); });
}

template <class T>
PassCounters Mmlt<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    make_subpaths();
    return chains_.render_passes(ctx, film, first, count, progress,
                                 [this](const RenderContext& c, PrimarySamples& state, int chain) { return evaluate(c, state, chain); });
}

template class Mmlt<RgbTransport>;
template class Mmlt<SpectralTransport>;

namespace {

// The path tracers' parameters, but a finite depth needed and no Russian roulette.
std::vector<ParamInfo> mmlt_params() {
    std::vector<ParamInfo> p = path_params();
    for (ParamInfo& i : p) {
        if (i.name == "max_depth")
            i.doc = "longest path in Mitsuba's convention, 2 direct light only (pathlab's bounces: max_depth - 1); -1 (unlimited) is "
                    "refused: the chains run per path length";
        if (i.name == "rr_depth") i.doc = "accepted and ignored: mmlt's subpaths have the lengths of its states (no Russian roulette)";
    }
    return p;
}

}  // namespace

const IntegratorInfo& mmlt_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"mmlt",
                         {},
                         "multiplexed Metropolis light transport (Hachisuka 2014) over bdpt's strategies: Markov chains per path length "
                         "that choose the strategy as part of the state, expected-value splatting",
                         false,
                         true,
                         mmlt_params(),
                         [](const IntegratorOptions& o) { return make_for_transport<Mmlt>(o); },
                         /*any_camera=*/false};
        i.media = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
