#include "job/renderer.hpp"

#include <chrono>
#include <algorithm>
#include <new>
#include <span>
#include <stdexcept>

#include <fmt/format.h>

#include "core/memory.hpp"
#include "render/progress.hpp"

namespace pathlab {
namespace {

void resolve_size(const Scene& scene, const RenderSettings& s, int& w, int& h) {
    w = s.width > 0 ? s.width : scene.default_width();
    h = s.height > 0 ? s.height : scene.default_height();
    if (w <= 0 || h <= 0 || s.width < 0 || s.height < 0)
        throw std::invalid_argument(fmt::format("resolution must be positive, got {}x{}", w, h));
}

}  // namespace

Film make_film(int w, int h) {
    const uint64_t pixels = uint64_t(w) * uint64_t(h), bytes = pixels * kRenderBytesPerPixel;
    const uint64_t available = available_memory();
    if (available > 0 && bytes > available)
        throw FilmTooLarge(fmt::format("a {}x{} render needs {:.1f} GiB of memory ({} bytes per pixel for the film and its "
                                       "images), but only {:.1f} GiB is available",
                                       w, h, gib(bytes), kRenderBytesPerPixel, gib(available)));
    try {
        return Film(w, h);
    } catch (const std::bad_alloc&) {
        throw FilmTooLarge(fmt::format("a {}x{} render needs {:.1f} GiB of memory ({} bytes per pixel for the film and its "
                                       "images), more than could be allocated",
                                       w, h, gib(bytes), kRenderBytesPerPixel));
    }
}


RenderResult render(const Scene& scene, Integrator& integrator, const RenderSettings& settings) {
    int w, h;
    resolve_size(scene, settings, w, h);
    RenderResult result{make_film(w, h), {}};
    result.stats = render_into(scene, integrator, settings, result.film);
    return result;
}

RenderStats render_into(const Scene& scene, Integrator& integrator, const RenderSettings& settings, Film& film) {
    int w, h;
    resolve_size(scene, settings, w, h);
    if (film.width() != w || film.height() != h)
        throw std::invalid_argument(fmt::format("the film is {}x{}, the render {}x{}", film.width(), film.height(), w, h));
    if (settings.spp <= 0 && settings.time_limit <= 0)
        throw std::invalid_argument("a render needs a positive sample count or time limit");
    if (settings.aovs) {
        if (settings.aovs->width() != w || settings.aovs->height() != h)
            throw std::invalid_argument(fmt::format("the AOV film is {}x{}, the render {}x{}", settings.aovs->width(), settings.aovs->height(), w, h));
        if (!integrator.records_aovs()) throw std::invalid_argument("this integrator records no AOVs");
        if (settings.ranks && settings.ranks->size() > 1) throw std::invalid_argument("AOVs are recorded in one process only");
    }
    const uint64_t first = settings.first_sample;
    if (settings.spp > UINT64_MAX - first) throw std::invalid_argument(fmt::format("sample indices {} + {} wrap round", first, settings.spp));
    const PassSet target = settings.spp > 0 ? PassSet::range(first, first + settings.spp) : PassSet::range(first, UINT64_MAX);
    if (!target.contains(settings.done))
        throw std::invalid_argument(fmt::format("the film holds passes {} outside the render's passes {}", settings.done.to_string(),
                                                target.to_string()));

    LocalRanks alone;
    RankGroup& ranks = settings.ranks ? *settings.ranks : alone;
    const int rank_count = ranks.size(), me = ranks.rank();
    const PerspectiveCamera camera(scene.camera(), w, h);
    const PixelFilter filter(scene.description().filter, w, h);
    // prepare()'s exchange between the ranks, in pieces of at most 256 MiB from each (MPI counts
    // are ints): every rank's bytes on every rank.
    PrepareRanks prepare_ranks{me, rank_count, [&ranks, rank_count](const std::string& mine) {
                                   constexpr size_t kPiece = size_t(1) << 28;
                                   double rounds = double((mine.size() + kPiece - 1) / kPiece);
                                   ranks.all_max(std::span<double>(&rounds, 1));
                                   std::vector<std::string> all(static_cast<size_t>(rank_count));
                                   for (size_t k = 0; k < size_t(rounds); ++k) {
                                       const std::vector<std::string> pieces =
                                           ranks.all_gather(k * kPiece < mine.size() ? mine.substr(k * kPiece, kPiece) : std::string());
                                       for (size_t r = 0; r < all.size(); ++r) all[r] += pieces[r];
                                   }
                                   return all;
                               }};
    const RenderContext ctx{scene, camera, w, h, settings.seed, settings.sampler, settings.tile_size, &filter, settings.aovs, &prepare_ranks};
    const bool show_progress = settings.progress && ranks.root();
    Progress progress(show_progress);
    const auto start = std::chrono::steady_clock::now();
    const auto seconds_since_start = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    PassProgress on_prepare;
    if (show_progress) on_prepare = [&](double fraction) { progress.update(0.0, 0, fmt::format("preparing: {:.0f}%", 100 * fraction)); };
    integrator.prepare(ctx, on_prepare);

    RenderStats st;
    st.resumed_spp = settings.done.count();
    PassSet done = settings.done;
    uint64_t batch = 1, my_spp = 0;
    double my_seconds = 0, last_checkpoint = 0, last_display = -1, my_display_seconds = 0;
    // The ranks' films summed into `into` on the root (chunks of 64Ki pixels, 10 MiB); every rank calls it.
    const auto sum_ranks_into = [&](Film& into) {
        ranks.reduce_film(film, size_t(1) << 16, [&](size_t first_pixel, const PixelSums* sums, size_t count) {
            std::copy(sums, sums + count, into.data() + first_pixel);
        });
    };
    // The film as it is, to settings.display (on the root; the ranks' films summed first).
    const auto show = [&](const RenderStats& stats) {
        if (rank_count == 1) return settings.display(film, stats);
        Film sum = ranks.root() ? Film(w, h) : Film();
        sum_ranks_into(sum);
        if (ranks.root()) settings.display(sum, stats);
    };
    const uint64_t pixels = uint64_t(w) * uint64_t(h);
    while (true) {
        // This round: the next passes still to do, one contiguous part per rank.
        const uint64_t left = settings.spp > 0 ? settings.spp - done.count() : UINT64_MAX;
        if (left == 0) break;
        const uint64_t round_size = std::min(left, batch * uint64_t(rank_count));
        const PassSet round = target.minus(done).first(round_size);
        const PassSet mine = round.part(me, rank_count);
        const double round_start = seconds_since_start();
        const uint64_t done_before = done.count();
        uint64_t mine_done = 0;
        for (const PassRange& r : mine.ranges()) {
            PassProgress on_progress;
            if (show_progress)
                on_progress = [&](double fraction_of_call) {
                    // The whole round advances about as this rank's part does.
                    const double part = (double(mine_done) + double(r.size()) * fraction_of_call) / double(mine.count());
                    const double within = double(done_before) + double(round.count()) * part;
                    double fraction = settings.spp > 0 ? within / double(settings.spp) : 0;
                    if (settings.time_limit > 0) fraction = std::max(fraction, seconds_since_start() / settings.time_limit);
                    progress.update(std::min(fraction, 1.0), uint64_t((within - double(st.resumed_spp)) * double(pixels)),
                                    fmt::format("{} spp", done_before));
                };
            const PassCounters c = integrator.render_passes(ctx, film, r.begin, int(r.size()), on_progress);
            mine_done += r.size();
            st.rays += c.rays;
            st.invalid_samples += c.invalid_samples;
        }
        const double my_round_seconds = seconds_since_start() - round_start;
        my_spp += mine.count(), my_seconds += my_round_seconds;
        done.insert(round);
        // The collective of the round: the slowest part, the time spent, any rank interrupted.
        double shared[4] = {my_round_seconds, seconds_since_start(), settings.cancel && settings.cancel->load() ? 1.0 : 0.0, my_display_seconds};
        ranks.all_max(shared);
        const double round_seconds = shared[0];
        st.seconds = shared[1];
        st.spp = done.count();
        st.passes = done;
        st.samples = (st.spp - st.resumed_spp) * pixels;
        if (settings.after_pass && rank_count == 1) settings.after_pass(film, st);
        // The image to the viewer: every display_every seconds, or less often when showing it
        // costs over 5% of the time (a large film; the slowest rank's cost, so all ranks agree).
        if (settings.display && (last_display < 0 || st.seconds - last_display >= std::max(settings.display_every, 20 * shared[3]))) {
            const double t0 = seconds_since_start();
            show(st);
            my_display_seconds = seconds_since_start() - t0;
            last_display = st.seconds;
        }
        if (shared[2] > 0) {
            st.interrupted = true;
            break;
        }
        if (settings.checkpoint && settings.checkpoint_every > 0 && st.seconds - last_checkpoint >= settings.checkpoint_every &&
            done.count() < (settings.spp > 0 ? settings.spp : UINT64_MAX)) {
            const double t0 = seconds_since_start();
            if (settings.checkpoint(ranks, film, done, st)) ++st.checkpoints;
            else ++st.failed_checkpoints;
            st.checkpoint_seconds += seconds_since_start() - t0;
            last_checkpoint = st.seconds;
        }
        // Stop when another round would end further past the budget than stopping now ends short of it.
        const uint64_t per_rank = (round.count() + uint64_t(rank_count) - 1) / uint64_t(rank_count);
        if (settings.time_limit > 0) {
            const double per_pass = round_seconds / double(per_rank);
            const double time_left = settings.time_limit - st.seconds;
            if (time_left <= 0.5 * per_pass) break;
            batch = std::max<uint64_t>(1, std::min<uint64_t>(batch, uint64_t(time_left / per_pass)));
        }
        if (round_seconds < 0.05 && batch < (1u << 20)) batch *= 2;
    }
    progress.finish();
    st.spp = done.count();
    st.passes = done;
    st.samples = (st.spp - st.resumed_spp) * pixels;

    if (rank_count > 1) {
        // The ranks' films summed into the root's.
        const double t0 = seconds_since_start();
        sum_ranks_into(film);
        st.reduce_seconds = seconds_since_start() - t0;
        const double mine_figures[4] = {double(my_spp), my_seconds, double(st.rays), double(st.invalid_samples)};
        const std::vector<double> all = ranks.gather(mine_figures);
        const std::vector<std::string> names = ranks.gather_text(ranks.name());
        if (ranks.root()) {
            st.rays = st.invalid_samples = 0;
            for (int r = 0; r < rank_count; ++r) {
                const double* f = &all[size_t(4 * r)];
                st.ranks.push_back({names[size_t(r)], uint64_t(f[0]), f[1], uint64_t(f[2])});
                st.rays += uint64_t(f[2]);
                st.invalid_samples += uint64_t(f[3]);
            }
        }
        st.seconds = seconds_since_start();
    } else {
        st.ranks.push_back({ranks.name(), my_spp, my_seconds, st.rays});
    }
    if (ranks.root()) {
        if (settings.display) settings.display(film, st);
        integrator.finish(ctx);
        if (settings.checkpoint) {
            const double t0 = seconds_since_start();
            st.last_checkpoint_failed = !settings.checkpoint(alone, film, done, st);
            if (st.last_checkpoint_failed) ++st.failed_checkpoints;
            else ++st.checkpoints;
            st.checkpoint_seconds += seconds_since_start() - t0;
        }
    }
    st.integrator = integrator.statistics();
    return st;
}

}  // namespace pathlab
