// The verdict of `pathlab check`: is a render of a scene consistent with its reference?
//
// Against a linear reference (.exr/.pfm/.hdr) the measure is the course grader's, the signed
// mean difference d_c = mean(render - reference) per channel, but it is judged against its own
// noise instead of a fixed tolerance. Pixels are independent, so the standard error of d_c is
//   se_c = sqrt(sum_p se_render(p)^2 + sum_p se_reference(p)^2) / N,
// with the render's per-pixel standard errors estimated from its sample variance (and the
// reference's from its .stderr companion, when it has one; else it is taken as exact). The
// render passes when |d_c| / se_c stays below the two-sided normal quantile at a false-alarm
// rate of 1e-3 per scene, split over the 3 channels. A correct render passes at any sample
// count (its d_c is pure noise); a biased one fails once its bias exceeds a few standard
// errors, which at 512x512 and 64 spp is a small fraction of a percent.
//
// Against the course's 8-bit PNG references the block comparison of tools/course_reference.hpp
// decides (BlockComparison::passes()).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "image/image.hpp"
#include "judge/reference_set.hpp"

namespace pathlab {

struct LinearCheck {
    std::array<double, 3> mean_diff{};  // render - reference, per channel
    std::array<double, 3> std_error{};  // of mean_diff
    std::array<double, 3> z{};          // mean_diff / std_error (infinite when the error is 0 and the difference not)
    std::array<double, 3> reference_mean{};
    double z_limit = 0;
    bool reference_has_errors = false;
    bool passes() const;
    std::string describe() const;
};

constexpr double kCheckFalseAlarmRate = 1e-3;

// `reference_se` may be empty (an exact reference). Throws ImageSizeMismatch when sizes differ.
// Pixels marked in `excluded` (if given) are left out.
LinearCheck check_against_linear_reference(const Image& render, const Image& render_se, const Image& reference,
                                           const Image& reference_se = {}, const std::vector<uint8_t>* excluded = nullptr);

enum class Verdict { Ok, Fail, Missing, BlackByDesign, Error };
const char* verdict_name(Verdict v);  // "OK", "FAIL", "MISSING", "BLACK-BY-DESIGN", "ERROR"

struct SceneVerdict {
    Verdict verdict = Verdict::Error;
    std::string detail;  // one line: the figures behind the verdict, or what went wrong
};

// A reference read into memory: the course's 8-bit image, or a linear one with its standard
// errors (empty when it has none).
struct LoadedReference {
    ReferenceKind kind = ReferenceKind::Linear;
    Image8 course;
    Image linear, linear_se;
    int width() const { return kind == ReferenceKind::Course8bit ? course.width : linear.width(); }
    int height() const { return kind == ReferenceKind::Course8bit ? course.height : linear.height(); }
};
// Throws ImageIoError naming the file that cannot be read.
LoadedReference load_reference(const ReferenceFile& reference);

// Judges the render (mean and per-pixel standard errors) against the reference, leaving out the
// pixels marked in `excluded` (those an integrator leaves black by design). Size mismatches
// (and, in the second form, unreadable files) give Verdict::Error with the reason.
SceneVerdict judge_render(const Image& mean, const Image& std_error, const LoadedReference& reference,
                          const std::vector<uint8_t>* excluded = nullptr);
SceneVerdict judge_render(const Image& mean, const Image& std_error, const ReferenceFile& reference);

}  // namespace pathlab
