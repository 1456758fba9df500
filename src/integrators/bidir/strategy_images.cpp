#include "integrators/bidir/strategy_images.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "core/memory.hpp"
#include "image/image_io.hpp"
#include "image/image_text.hpp"

namespace pathlab {

void StrategyImages::begin_pass(int width, int height, int chunks) {
    const size_t pixels = size_t(width) * size_t(height), n = size_t(count(max_length_));
    if (width != width_ || height != height_ || weighted_.empty()) {
        // Two films and two pass images per strategy, the mean images write() keeps for the
        // montage, and the montage (floats, then 8-bit PNG pixels; its label margins are small).
        const double per_strategy = double(pixels) * double(2 * sizeof(PixelSums) + 2 * sizeof(Vec3d) + sizeof(Rgb));
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

std::vector<ExrChannel> StrategyImages::weighted_channels() const {
    std::vector<ExrChannel> out;
    if (weighted_.empty()) return out;
    for (int n = 0; n <= max_length_; ++n)
        for (int s = 0; s <= n + 1; ++s) {
            const int t = n + 2 - s;
            if (s == 1 && t == 1) continue;
            const Image mean = weighted_[size_t(index(s, t))].mean();
            for (int c = 0; c < 3; ++c) {
                ExrChannel ch{fmt::format("n{}-s{}-t{}.{}", n, s, t, "RGB"[c]), std::vector<float>(mean.pixel_count())};
                for (size_t i = 0; i < mean.pixel_count(); ++i) ch.values[i] = mean[i][c];
                out.push_back(std::move(ch));
            }
        }
    return out;
}

void StrategyImages::write() const {
    if (weighted_.empty()) return;
    namespace fs = std::filesystem;
    const int gap = kGap, cols = max_length_ + 2, rows = max_length_ + 1;
    for (const bool weighted : {true, false}) {
        std::vector<Image> means(weighted_.size());
        for (int n = 0; n <= max_length_; ++n)
            for (int s = 0; s <= n + 1; ++s) {
                const int t = n + 2 - s;
                if (s == 1 && t == 1) continue;
                const Film& film = weighted ? weighted_[size_t(index(s, t))] : unweighted_[size_t(index(s, t))];
                Image& mean = means[size_t(index(s, t))] = film.mean();
                const std::string stem = fmt::format("n{}-s{}-t{}-{}", n, s, t, weighted ? "weighted" : "unweighted");
                write_image(mean, (fs::path(dir_) / (stem + ".exr")).string());
                write_image(film.standard_error(), (fs::path(dir_) / (stem + ".stderr.exr")).string());
            }
        // Each row (one path length) is scaled so that the median luminance of its lit pixels
        // is 0.18: longer paths carry less light, and one exposure for all left them black (the
        // median, not the mean: a row's fireflies and a directly seen light would set a mean).
        // The row's factor is in its label; the cells of one row share it, so they compare.
        std::vector<float> gain(size_t(rows), 1.0f);
        std::vector<std::string> row_labels(static_cast<size_t>(rows));
        int label_width = 0;
        for (int n = 0; n <= max_length_; ++n) {
            std::vector<float> lit;
            for (int s = 0; s <= n + 1; ++s) {
                if (s == 1 && n == 0) continue;
                const Image& mean = means[size_t(index(s, n + 2 - s))];
                for (size_t i = 0; i < mean.pixel_count(); ++i)
                    if (const float y = luminance(mean[i]); y > 0 && std::isfinite(y)) lit.push_back(y);
            }
            if (!lit.empty()) {
                std::nth_element(lit.begin(), lit.begin() + lit.size() / 2, lit.end());
                gain[size_t(n)] = 0.18f / lit[lit.size() / 2];
            }
            row_labels[size_t(n)] = fmt::format("n={} x{:.3g}", n, gain[size_t(n)]);
            label_width = std::max(label_width, text_width(row_labels[size_t(n)]) + 4);
        }
        // Column labels (s) along the top, row labels (bounces n, gain) on the left; t = n + 2 - s.
        const int left = label_width, top = kTextHeight + 2;
        Image montage(left + cols * (width_ + gap) - gap, top + rows * (height_ + gap) - gap);
        for (int s = 0; s < cols; ++s) draw_text(montage, left + s * (width_ + gap) + 2, 1, fmt::format("s={}", s), Rgb(1.0f));
        for (int n = 0; n <= max_length_; ++n) {
            draw_text(montage, 1, top + n * (height_ + gap) + 1, row_labels[size_t(n)], Rgb(1.0f));
            for (int s = 0; s <= n + 1; ++s) {
                if (s == 1 && n == 0) continue;
                const Image& mean = means[size_t(index(s, n + 2 - s))];
                for (int y = 0; y < height_; ++y)
                    for (int x = 0; x < width_; ++x)
                        montage.at(left + s * (width_ + gap) + x, top + n * (height_ + gap) + y) = mean.at(x, y) * gain[size_t(n)];
            }
        }
        write_image(montage, (fs::path(dir_) / (weighted ? "montage-weighted.png" : "montage-unweighted.png")).string());
    }
}

}  // namespace pathlab
