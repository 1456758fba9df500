#include "judge/check.hpp"

#include <cmath>

#include <fmt/format.h>

#include "image/image_io.hpp"
#include "judge/image_statistics.hpp"
#include "judge/course_reference.hpp"
#include "judge/image_compare.hpp"

namespace pathlab {
namespace {

void check_size(const Image& a, const Image& b, const char* what) {
    if (a.width() != b.width() || a.height() != b.height())
        throw ImageSizeMismatch(fmt::format("the render is {}x{} but {} is {}x{}", a.width(), a.height(), what, b.width(), b.height()));
}

}  // namespace

bool LinearCheck::passes() const {
    for (double v : z)
        if (!(std::abs(v) <= z_limit)) return false;
    return true;
}

std::string LinearCheck::describe() const {
    std::string channels;
    for (int c = 0; c < 3; ++c) {
        const double rel = reference_mean[size_t(c)] != 0 ? 100.0 * mean_diff[size_t(c)] / reference_mean[size_t(c)] : 0.0;
        channels += fmt::format("{}{}: {:+.3g} ({:+.2f}%, z {:+.2f})", c ? ", " : "", "RGB"[c], mean_diff[size_t(c)], rel, z[size_t(c)]);
    }
    return fmt::format("mean diff {}; |z| limit {:.2f}{}", channels, z_limit,
                       reference_has_errors ? "" : " (reference taken as exact)");
}

LinearCheck check_against_linear_reference(const Image& render, const Image& render_se, const Image& reference,
                                           const Image& reference_se, const std::vector<uint8_t>* excluded) {
    check_size(render, reference, "the reference");
    check_size(render, render_se, "its standard-error image");
    LinearCheck out;
    out.reference_has_errors = reference_se.pixel_count() > 0;
    if (out.reference_has_errors) check_size(render, reference_se, "the reference's standard-error image");
    const double n = double(render.pixel_count());
    for (int c = 0; c < 3; ++c) {
        double diff = 0, var = 0, ref = 0;
        for (size_t i = 0; i < render.pixel_count(); ++i) {
            if (excluded && i < excluded->size() && (*excluded)[i]) continue;
            diff += double(render[i][c]) - reference[i][c];
            ref += reference[i][c];
            var += double(render_se[i][c]) * render_se[i][c];
            if (out.reference_has_errors) var += double(reference_se[i][c]) * reference_se[i][c];
        }
        const size_t k = size_t(c);
        out.mean_diff[k] = diff / n;
        out.reference_mean[k] = ref / n;
        out.std_error[k] = std::sqrt(var) / n;
        out.z[k] = out.std_error[k] > 0 ? out.mean_diff[k] / out.std_error[k] : (diff == 0 ? 0.0 : INFINITY);
    }
    out.z_limit = normal_quantile_two_sided(kCheckFalseAlarmRate / 3);
    return out;
}

const char* verdict_name(Verdict v) {
    switch (v) {
        case Verdict::Ok: return "OK";
        case Verdict::Fail: return "FAIL";
        case Verdict::Missing: return "MISSING";
        case Verdict::BlackByDesign: return "BLACK-BY-DESIGN";
        case Verdict::Error: return "ERROR";
    }
    return "?";
}

LoadedReference load_reference(const ReferenceFile& reference) {
    LoadedReference r;
    r.kind = reference.kind;
    if (reference.kind == ReferenceKind::Course8bit) {
        r.course = read_png8(reference.path);
    } else {
        r.linear = read_image(reference.path);
        if (!reference.stderr_path.empty()) r.linear_se = read_image(reference.stderr_path);
    }
    return r;
}

SceneVerdict judge_render(const Image& mean, const Image& std_error, const LoadedReference& reference,
                          const std::vector<uint8_t>* excluded) {
    try {
        if (reference.kind == ReferenceKind::Course8bit) {
            const BlockComparison cmp = compare_with_course_reference(mean, reference.course, std_error, kCourseSaturatedMargin,
                                                                      kCourseBlock, excluded);
            return {cmp.passes_allowing_for_noise() ? Verdict::Ok : Verdict::Fail, cmp.describe()};
        }
        const LinearCheck cmp = check_against_linear_reference(mean, std_error, reference.linear, reference.linear_se, excluded);
        return {cmp.passes() ? Verdict::Ok : Verdict::Fail, cmp.describe()};
    } catch (const std::exception& e) {  // size mismatch
        return {Verdict::Error, e.what()};
    }
}

SceneVerdict judge_render(const Image& mean, const Image& std_error, const ReferenceFile& reference) {
    try {
        return judge_render(mean, std_error, load_reference(reference));
    } catch (const std::exception& e) {  // unreadable file
        return {Verdict::Error, e.what()};
    }
}

}  // namespace pathlab
