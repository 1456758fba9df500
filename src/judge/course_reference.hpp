// Comparison with the course's own 8-bit reference images (../shared/npgr010-refs/direct/):
// each channel of those is round(255 * clamp(L, 0, 1)^(1/2.2)).
//
// Per 16x16 block, pixels saturated in the reference (255 in any channel: emitters, the hot
// spot above the point light) are left out, and so are pixels within `saturated_margin`
// pixels of one: their values hinge on sub-pixel coverage of an emitter 30x brighter than
// white, or (next to an emitting ceiling) on a 1/d^2 singularity that uniform area sampling of
// the light resolves only after an impractical number of samples; the remaining reference pixels are decoded with
// (v/255)^2.2 and averaged, and so are the same pixels of the linear render. Both block means
// are then encoded the same way, and their difference is in grey levels. Encoding block means
// rather than single pixels keeps the comparison free of the noise bias that a concave
// encoding of noisy pixels has (Jensen's inequality), so a correct render passes at modest
// sample counts. Structural errors (a wrong cosine, Phong normalisation or light radiance)
// put blocks off by several levels.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "image/image.hpp"

namespace pathlab {

struct BlockComparison {
    int blocks = 0;                 // blocks with at least one pixel compared
    long pixels_compared = 0;
    double mean_abs_diff = 0;       // mean over blocks and channels of |difference|, grey levels
    double max_abs_diff = 0;        // worst block and channel
    double mean_signed_diff = 0;    // render minus reference, grey levels
    // With the render's standard errors: block-channels whose |difference| exceeds
    // 1 grey level (the reference's own quantisation) plus z_limit standard errors, where
    // z_limit is the two-sided normal quantile at 0.1% split over all blocks (Bonferroni).
    // A correct render has none, up to that false-alarm rate; a local structural error (a
    // highlight of the wrong strength, a missing shadow) shows up here even when the mean
    // over the image hardly moves.
    int block_channels = 0;
    int blocks_beyond_noise = 0;
    double z_limit = 0;
    double worst_excess = 0;  // max over blocks of (|diff| - 1) / se
    // What noise alone adds to mean_abs_diff: the mean over block-channels of E|N(0, se)| =
    // sqrt(2/pi) se (0 without standard errors).
    double mean_noise_levels = 0;
    // Of blocks_beyond_noise, those the render cannot resolve yet: no variance at all (no
    // sample found light there) while the reference is nearly black (below 1% of its mean
    // block level) but a few grey levels up, which the steep encoding near black makes of
    // radiances around 1e-5 (deep shadows seen by an estimator that rarely finds the light).
    int unresolved_block_channels = 0;
    std::string describe() const;

    // The verdict shared by the tests and `pathlab check`: the mean over blocks of |difference|
    // below one grey level, and (when standard errors were given) at most 0.5% of the
    // block-channels beyond their noise. The allowance exists because the standard error of a
    // heavy-tailed estimator is itself unreliable: a block that never drew the rare large
    // samples (next to an emitter, or a glossy reflection of the environment found by uniform
    // sampling) has a low mean and a small error. Correct renders of the 8 scenes show at most
    // 0.2%; a Phong lobe 20% too weak shows 2-3.4%.
    bool passes() const { return mean_abs_diff < 1.0 && blocks_beyond_noise <= 0.005 * block_channels; }

    // The verdict of `pathlab check`, which also has to pass correct renders at low sample
    // counts: as passes(), but the mean |difference| is taken beyond what the render's noise
    // explains (mean_abs_diff - mean_noise_levels < 1 level; |bias + noise| <= |bias| + |noise|,
    // so a bias of a level or more still fails however noisy the render is), and unresolved
    // block-channels are excused, up to 5% of them (an estimator black where the reference is
    // not fails: those blocks are not nearly black).
    bool passes_allowing_for_noise() const {
        return mean_abs_diff - mean_noise_levels < 1.0 &&
               blocks_beyond_noise - unresolved_block_channels <= 0.005 * block_channels &&
               unresolved_block_channels <= 0.05 * block_channels;
    }
};

constexpr float kCourseGamma = 2.2f;
constexpr int kCourseBlock = 16;
constexpr int kCourseSaturatedMargin = 3;
constexpr double kUnresolvedNegligibleFraction = 0.01;

// `render_se` (optional, may be empty) holds per-pixel standard errors of the render; it
// gives each block difference a standard error (propagated through the encoding's slope). Throws std::invalid_argument if sizes differ.
BlockComparison compare_with_course_reference(const Image& render, const Image8& reference, const Image& render_se = {},
                                              int saturated_margin = kCourseSaturatedMargin, int block = kCourseBlock,
                                              const std::vector<uint8_t>* excluded = nullptr);

}  // namespace pathlab
