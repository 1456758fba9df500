// One image per BDPT strategy (s, t), weighted and unweighted, for paths of up to L bounces
// (`--strategies DIR`), and a montage laid out like Veach's thesis figure 10.3: a row per path
// length (0 to L bounces, top to bottom), a column per number of light vertices s (t = length +
// 2 - s), black where no strategy exists (t = 0, and s = t = 1, which bdpt does not use);
// columns labelled s=K, rows n=K with the factor that row is scaled by (the median luminance of
// its lit pixels to 0.18: each row has an exposure of its own, since longer paths carry less
// light).
// The weighted images of one length add up to that length's part of the bdpt image. Each is a
// film of its own (one sample per pixel and pass), so each carries its standard errors.
//
// Files: DIR/n{length}-s{s}-t{t}-weighted.exr, ...-unweighted.exr, DIR/montage-weighted.png
// and DIR/montage-unweighted.png.
#pragma once

#include <string>
#include <vector>

#include "image/image_io.hpp"
#include "render/film.hpp"

namespace pathlab {

struct StrategySplat {
    uint32_t pixel;
    uint16_t strategy;
    Rgb weighted, unweighted;
};

class StrategyImages {
public:
    StrategyImages(int max_length, std::string dir) : max_length_(max_length), dir_(std::move(dir)) {}

    int max_length() const { return max_length_; }
    static int index(int s, int t) {
        const int n = s + t - 2;
        return n * (n + 3) / 2 + s;
    }
    static int count(int max_length) { return (max_length + 1) * (max_length + 4) / 2; }
    // The deepest set written: 32 bounces are 594 strategies, 2,376 files and a montage of
    // 34x33 cells; more is no figure anyone reads (and 1024 bounces were 2 million files).
    static constexpr int kMaxLength = 32;

    void begin_pass(int width, int height, int chunks);
    std::vector<StrategySplat>& chunk(int c) { return lists_[size_t(c)]; }
    // Adds the chunks' contributions in chunk order, then the pass to every strategy's films.
    void finish_pass();
    // Writes every strategy's images and the montages (throws ImageIoError).
    void write() const;
    // The weighted images so far as channels n{length}-s{s}-t{t}.R/G/B (--display-server's
    // extra layers); none before the first pass.
    std::vector<ExrChannel> weighted_channels() const;

    const Film& weighted(int s, int t) const { return weighted_[size_t(index(s, t))]; }
    const Film& unweighted(int s, int t) const { return unweighted_[size_t(index(s, t))]; }

private:
    int max_length_;
    std::string dir_;
    int width_ = 0, height_ = 0, chunks_ = 0;
    std::vector<Film> weighted_, unweighted_;
    std::vector<std::vector<StrategySplat>> lists_;
    std::vector<Vec3d> pass_weighted_, pass_unweighted_;  // strategy-major
    static constexpr int kGap = 2;                        // black pixels between montage cells
};

}  // namespace pathlab
