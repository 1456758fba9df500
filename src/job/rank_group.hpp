// The processes that render one image together, as the render loop sees them: ranks 0..size-1
// of which rank 0 (the root) writes the outputs. The render loop (job/renderer.cpp) runs the
// same code on every rank and calls these collectives at the same points on all of them; what
// it decides from their results is therefore the same everywhere.
//
// LocalRanks is one process alone (every collective is the identity); MpiRanks
// (distributed/mpi_ranks.hpp) is a group of MPI processes.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "render/film.hpp"

namespace pathlab {

class RankGroup {
public:
    virtual ~RankGroup() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    bool root() const { return rank() == 0; }
    // A name for messages: "rank 1 (host)".
    virtual std::string name() const = 0;

    // Element-wise maximum over the ranks, in place, on every rank.
    virtual void all_max(std::span<double> values) = 0;
    // Every rank's `values` (all of the same length), concatenated in rank order, on the root
    // (empty elsewhere).
    virtual std::vector<double> gather(std::span<const double> values) = 0;
    // Every rank's text, in rank order, on the root (empty elsewhere).
    virtual std::vector<std::string> gather_text(const std::string& text) = 0;
    // The root's text on every rank.
    virtual void broadcast_text(std::string& text) = 0;
    // Every rank's bytes (of any lengths, each below 2 GiB), in rank order, on every rank.
    virtual std::vector<std::string> all_gather(const std::string& bytes) = 0;
    // The films of all ranks summed (PixelSums::merge), chunk by chunk of at most
    // `chunk_pixels` pixels: on the root `use(first pixel, sums, count)` sees every chunk once,
    // in order; `film` is not changed.
    using ChunkUse = std::function<void(size_t first, const PixelSums* sums, size_t count)>;
    virtual void reduce_film(const Film& film, size_t chunk_pixels, const ChunkUse& use) = 0;
    // Ends every rank (MPI_Abort) after a failure on this one that the others cannot learn of
    // (they would wait for it in the next collective); LocalRanks returns (the caller goes on).
    virtual void abort(int code) = 0;

    // After a step that may fail on some ranks only (reading the scene, a checkpoint): the
    // largest of the ranks' codes, on every rank; on the root `messages` gets the distinct
    // messages of the failed ranks, one per line, with the ranks' names when they differ.
    int agree(int code, const std::string& message, std::string* messages) {
        double worst = code;
        all_max(std::span<double>(&worst, 1));
        if (worst == 0) return 0;
        const std::vector<std::string> texts = gather_text(code ? message : "");
        const std::vector<std::string> names = gather_text(name());
        if (root() && messages) {
            std::vector<std::string> distinct;
            for (const std::string& t : texts)
                if (!t.empty() && std::find(distinct.begin(), distinct.end(), t) == distinct.end()) distinct.push_back(t);
            for (size_t r = 0; r < texts.size(); ++r) {
                if (texts[r].empty()) continue;
                if (distinct.size() == 1) {
                    *messages += texts[r] + "\n";
                    break;
                }
                *messages += names[r] + ": " + texts[r] + "\n";
            }
        }
        return int(worst);
    }
};

class LocalRanks final : public RankGroup {
public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    std::string name() const override { return "rank 0"; }
    void all_max(std::span<double>) override {}
    std::vector<double> gather(std::span<const double> values) override { return {values.begin(), values.end()}; }
    std::vector<std::string> gather_text(const std::string& text) override { return {text}; }
    void broadcast_text(std::string&) override {}
    std::vector<std::string> all_gather(const std::string& bytes) override { return {bytes}; }
    void abort(int) override {}
    void reduce_film(const Film& film, size_t chunk_pixels, const ChunkUse& use) override {
        for (size_t first = 0; first < film.pixel_count(); first += chunk_pixels)
            use(first, film.data() + first, std::min(chunk_pixels, film.pixel_count() - first));
    }
};

}  // namespace pathlab
