#include "distributed.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "distributed/mpi_ranks.hpp"
#include "job/checkpoint.hpp"

namespace pathlab::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// mpirun as on one machine, as root if need be.
std::string mpirun(int ranks) {
    return fmt::format("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --allow-run-as-root --oversubscribe -n {}", ranks);
}

// A film of random accumulators (their values do not change what moves or merges).
Film random_film(int size, uint32_t seed) {
    Film film(size, size);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 4);
    for (size_t i = 0; i < film.pixel_count(); ++i)
        for (int k = 0; k < 4; ++k) film.add(i, Vec3d(u(rng), u(rng), u(rng)));
    return film;
}

std::string pathlab_binary(const std::string& self) {
    const fs::path bench = fs::absolute(fs::path(self));
    return (bench.parent_path().parent_path() / "pathlab").string();
}

}  // namespace

void distributed_reduce_worker(const std::vector<int>& film_sizes, int repeats, int argc, char** argv) {
    const std::unique_ptr<MpiSession> mpi = MpiSession::join(argc, argv);
    if (!mpi) throw std::runtime_error("run under mpirun");
    RankGroup& ranks = mpi->ranks();
    for (const int size : film_sizes) {
        Film film = random_film(size, uint32_t(ranks.rank() + 1));
        std::vector<double> times;
        for (int r = 0; r < repeats; ++r) {
            double t = 0;
            ranks.all_max(std::span<double>(&t, 1));  // start together
            const auto start = Clock::now();
            // Into the root's own film, chunk by chunk, as the renderer does (one film per rank).
            ranks.reduce_film(film, size_t(1) << 16, [&](size_t first, const PixelSums* sums, size_t n) {
                std::copy(sums, sums + n, film.data() + first);
            });
            double mine = seconds_since(start);
            ranks.all_max(std::span<double>(&mine, 1));
            times.push_back(mine);
        }
        if (ranks.root()) std::printf("reduce %d %.6f\n", size, median(times));
    }
}

void distributed_suite(const DistributedOptions& o, const std::string& self) {
    const std::string pathlab = pathlab_binary(self);
    const fs::path dir = fs::temp_directory_path() / fmt::format("pathlab_bench_distributed_{}", ::getpid());
    fs::create_directories(dir);

    // 1. Speedup of 2 ranks x 1 thread over 1 process x 2 threads.
    fmt::print("## Two MPI ranks against one process, at equal total threads\n\n");
    const std::string render = fmt::format("--scene {} --resolution {}x{} --spp {} --seed 1 -q -o {}", o.scene, o.size, o.size, o.spp,
                                           (dir / "out.exr").string());
    fmt::print("`{} {} --threads 2` against `{} {} {} --threads 1` ({} runs each, alternating; medians)\n\n", pathlab, render, mpirun(2), pathlab,
               render, o.repeats);
    std::vector<double> one_wall, two_wall, one_render, two_render, two_reduce;
    for (int r = 0; r < o.repeats; ++r)
        for (const bool two : {false, true}) {
            const std::string stats = (dir / "stats.json").string();
            const std::string cmd = fmt::format("{}{} {} --threads {} --stats {}", two ? mpirun(2) + " " : "", pathlab, render, two ? 1 : 2, stats);
            const auto start = Clock::now();
            if (std::system(cmd.c_str()) != 0) throw std::runtime_error("failed: " + cmd);
            const double wall = seconds_since(start);
            const nlohmann::json j = nlohmann::json::parse(std::ifstream(stats));
            (two ? two_wall : one_wall).push_back(wall);
            (two ? two_render : one_render).push_back(j["seconds"].get<double>());
            if (two) two_reduce.push_back(j["reduce_seconds"].get<double>());
        }
    fmt::print("| | 1 process x 2 threads | 2 ranks x 1 thread | speedup of 2 ranks |\n|---|---|---|---|\n");
    fmt::print("| render (passes + reduction), s | {:.3f} | {:.3f} | {:.3f} |\n", median(one_render), median(two_render),
               median(one_render) / median(two_render));
    fmt::print("| wall clock (process start, scene load, output), s | {:.3f} | {:.3f} | {:.3f} |\n", median(one_wall), median(two_wall),
               median(one_wall) / median(two_wall));
    fmt::print("| film reduction ({}x{}), s | - | {:.4f} | |\n\n", o.size, o.size, median(two_reduce));

    // 2. The film reduction across 2 ranks (mpirun of this program's worker).
    fmt::print("## Film reduction across 2 ranks (MPI_Reduce of the exact accumulators, 160 bytes per pixel)\n\n");
    std::string sizes;
    for (int s : o.film_sizes) sizes += (sizes.empty() ? "" : ",") + std::to_string(s);
    const std::string worker = fmt::format("{} {} distributed-reduce-worker --film-sizes {} --repeats {}", mpirun(2),
                                           fs::absolute(self).string(), sizes, o.repeats);
    fmt::print("`{}`\n\n| film | bytes per rank | reduction, s (median) | GB/s |\n|---|---|---|---|\n", worker);
    FILE* p = popen(worker.c_str(), "r");
    char line[256];
    while (p && std::fgets(line, sizeof line, p)) {
        int size = 0;
        double t = 0;
        if (std::sscanf(line, "reduce %d %lf", &size, &t) == 2) {
            const double bytes = double(size) * size * sizeof(PixelSums);
            fmt::print("| {}x{} | {:.0f} MiB | {:.4f} | {:.2f} |\n", size, size, bytes / (1 << 20), t, bytes / t * 1e-9);
        }
    }
    if (p) pclose(p);
    fmt::print("\n");

    // 3. Checkpoints: write (atomically, fsynced) and read (checksum verified).
    fmt::print("## Checkpoints\n\n| film | size | write (fsync, rename), s | read (verified), s | in-process merge of two films, s |\n|---|---|---|---|---|\n");
    for (const int size : o.film_sizes) {
        const Film film = random_film(size, 1);
        const std::string path = (dir / "bench.ckpt").string();
        CheckpointInfo info;
        info.identity.fields = {{"scene", "bench"}};
        info.passes = PassSet::range(0, 4);
        info.width = info.height = size;
        std::vector<double> write, read, merge;
        LocalRanks alone;
        const int repeats = size > 2048 ? std::min(o.repeats, 3) : o.repeats;
        for (int r = 0; r < repeats; ++r) {
            auto start = Clock::now();
            write_checkpoint(path, alone, film, info);
            write.push_back(seconds_since(start));
            start = Clock::now();
            Checkpoint c = read_checkpoint(path);
            read.push_back(seconds_since(start));
            start = Clock::now();
            c.film.merge(film);
            merge.push_back(seconds_since(start));
        }
        fmt::print("| {}x{} | {:.1f} MiB | {:.3f} | {:.3f} | {:.3f} |\n", size, size, double(fs::file_size(path)) / (1 << 20), median(write),
                   median(read), median(merge));
        fs::remove(path);
    }
    fmt::print("\n");

    // 4. What the exact accumulation costs next to adding doubles (one thread).
    fmt::print("## The film's exact accumulation against plain doubles (one thread, 512x512, 16 passes)\n\n");
    {
        const int size = 512, passes = 16;
        std::vector<Vec3d> pass(size_t(size) * size);
        std::mt19937 rng(3);
        std::uniform_real_distribution<double> u(0, 2);
        for (Vec3d& v : pass) v = Vec3d(float(u(rng)), float(u(rng)), float(u(rng)));
        // Pass-major (add_pass: every pixel once per pass, the film streamed from memory) and
        // pixel-major (pixel integrators: a pixel's samples of a batch in a row, in cache).
        std::vector<double> exact_t[2], plain_t[2];
        for (int r = 0; r < o.repeats; ++r)
            for (int major = 0; major < 2; ++major) {
                const auto order = [&](auto&& add) {
                    if (major == 0)
                        for (int k = 0; k < passes; ++k)
                            for (size_t i = 0; i < pass.size(); ++i) add(i);
                    else
                        for (size_t i = 0; i < pass.size(); ++i)
                            for (int k = 0; k < passes; ++k) add(i);
                };
                Film film(size, size);
                auto start = Clock::now();
                order([&](size_t i) { film.add(i, pass[i]); });
                exact_t[major].push_back(seconds_since(start));
                std::vector<Vec3d> sum(pass.size()), sq(pass.size());
                std::vector<uint64_t> count(pass.size());
                start = Clock::now();
                order([&](size_t i) { sum[i] += pass[i], sq[i] += pass[i] * pass[i], ++count[i]; });
                plain_t[major].push_back(seconds_since(start));
                if (sum[7].x < 0 || film.count(7) == 0) std::printf("?");
            }
        const double n = double(passes) * size * size;
        fmt::print("| accumulation, ns per sample (RGB value and square) | pass-major (add_pass) | pixel-major (pixel integrators) |\n"
                   "|---|---|---|\n| exact (render/exact_sum.hpp) | {:.1f} | {:.1f} |\n| plain double sums (before) | {:.1f} | {:.1f} |\n\n",
                   median(exact_t[0]) / n * 1e9, median(exact_t[1]) / n * 1e9, median(plain_t[0]) / n * 1e9, median(plain_t[1]) / n * 1e9);
    }
    fs::remove_all(dir);
}

}  // namespace pathlab::bench
