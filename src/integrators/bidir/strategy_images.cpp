#include "integrators/bidir/strategy_images.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "core/memory.hpp"
#include "image/image_io.hpp"

namespace pathlab {

void StrategyImages::begin_pass(int width, int height, int chunks) {
    const size_t pixels = size_t(width) * size_t(height), n = size_t(count(max_length_));
    if (width != width_ || height != height_ || weighted_.empty()) {
        // Two films and two pass images per strategy, and the montage write() makes (floats,
        // then 8-bit PNG pixels).
        const double per_strategy = double(pixels) * double(2 * sizeof(PixelSums) + 2 * sizeof(Vec3d));
        const double montage = double((max_length_ + 2) * (width + kGap)) * double((max_length_ + 1) * (height + kGap)) * (sizeof(Rgb) + 3);
        check_memory(
            double(n) * per_strategy + montage,
            [&] {
                return fmt::format("--strategies images of paths up to {} bounces ({} strategies, {} images at {}x{})", max_length_, n, 2 * n,
                                   width, height);
            },
            [&](uint64_t available) {
                int fits = 0;
                while (double(count(fits + 1)) * per_strategy <= double(available)) ++fits;
                return fmt::format(": lower --strategies-depth (at most {} fits)", fits);
            });
        width_ = width, height_ = height;
        weighted_.assign(n, Film(width, height));
        unweighted_.assign(n, Film(width, height));
    }
    pass_weighted_.assign(n * pixels, Vec3d(0.0));
    pass_unweighted_.assign(n * pixels, Vec3d(0.0));
    if (lists_.size() < size_t(chunks)) lists_.resize(size_t(chunks));
    chunks_ = chunks;
    for (int c = 0; c < chunks; ++c) lists_[size_t(c)].clear();
}

void StrategyImages::finish_pass() {
    const size_t pixels = size_t(width_) * size_t(height_);
    for (int c = 0; c < chunks_; ++c)
        for (const StrategySplat& s : lists_[size_t(c)]) {
            pass_weighted_[size_t(s.strategy) * pixels + s.pixel] += Vec3d(s.weighted);
            pass_unweighted_[size_t(s.strategy) * pixels + s.pixel] += Vec3d(s.unweighted);
        }
    for (size_t k = 0; k < weighted_.size(); ++k) {
        weighted_[k].add_pass(pass_weighted_.data() + k * pixels, pixels);
        unweighted_[k].add_pass(pass_unweighted_.data() + k * pixels, pixels);
    }
}

void StrategyImages::write() const {
    if (weighted_.empty()) return;
    namespace fs = std::filesystem;
    const int gap = kGap, cols = max_length_ + 2, rows = max_length_ + 1;
    for (const bool weighted : {true, false}) {
        Image montage(cols * (width_ + gap) - gap, rows * (height_ + gap) - gap);
        for (int n = 0; n <= max_length_; ++n)
            for (int s = 0; s <= n + 1; ++s) {
                const int t = n + 2 - s;
                if (s == 1 && t == 1) continue;
                const Film& film = weighted ? weighted_[size_t(index(s, t))] : unweighted_[size_t(index(s, t))];
                const Image mean = film.mean();
                const std::string stem = fmt::format("n{}-s{}-t{}-{}", n, s, t, weighted ? "weighted" : "unweighted");
                write_image(mean, (fs::path(dir_) / (stem + ".exr")).string());
                write_image(film.standard_error(), (fs::path(dir_) / (stem + ".stderr.exr")).string());
                for (int y = 0; y < height_; ++y)
                    for (int x = 0; x < width_; ++x)
                        montage.at(s * (width_ + gap) + x, n * (height_ + gap) + y) = mean.at(x, y);
            }
        write_image(montage, (fs::path(dir_) / (weighted ? "montage-weighted.png" : "montage-unweighted.png")).string());
    }
}

}  // namespace pathlab
