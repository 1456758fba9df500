#include <cmath>

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "app/tool_commands.hpp"
#include "job/usage_error.hpp"
#include "image/image_io.hpp"
#include "judge/false_colour.hpp"
#include "judge/image_compare.hpp"
#include "judge/image_compare_json.hpp"
#include "judge/pixel_z_test.hpp"

namespace pathlab {
namespace {

// The image, and for a render's .exr the scene it is of ("name (hash)"; empty when unknown).
Image read_input(const std::string& path, std::string& scene) {
    try {
        if (image_format_for(path) != ImageFormat::Exr) return read_image(path);
        ExrExtras extras;
        Image img = read_exr(path, extras);
        std::string name, hash;
        for (const auto& [k, v] : extras.attributes) {
            if (k == "pathlab:scene") name = v;
            if (k == "pathlab:sceneHash") hash = v;
        }
        if (!hash.empty()) scene = fmt::format("{} ({})", name, hash);
        return img;
    } catch (const ImageIoError& e) {
        throw UsageError(e.what());  // names the file
    }
}

void print_table(const CompareOptions& o, const ImageDifference& d) {
    fmt::print("A: {}\nB: {} (reference)\n{}x{} pixels\n", o.a, o.b, d.width, d.height);
    fmt::print("{:<22}{:>13}{:>13}{:>13}{:>13}\n", "", "R", "G", "B", "all");
    const auto row = [&](const char* name, auto get) {
        fmt::print("{:<22}{:>13.6g}{:>13.6g}{:>13.6g}{:>13.6g}\n", name, get(d.channel[0]), get(d.channel[1]),
                   get(d.channel[2]), get(d.all));
    };
    row("mean diff (A - B)", [](const ChannelStatistics& s) { return s.mean_diff; });
    row("mean |A - B|", [](const ChannelStatistics& s) { return s.mae; });
    row("RMSE", [](const ChannelStatistics& s) { return s.rmse; });
    row("relMSE", [](const ChannelStatistics& s) { return s.relmse; });
    row("max |A - B|", [](const ChannelStatistics& s) { return s.max_abs_diff; });
    fmt::print("NaN/Inf pixel-channels: A {} NaN, {} Inf; B {} NaN, {} Inf{}\n", d.nan_a, d.inf_a, d.nan_b, d.inf_b,
               d.non_finite() ? " (left out of the statistics)" : "");
}

}  // namespace

CLI::App* add_compare_command(CLI::App& app, CompareOptions& o) {
    CLI::App* cmd = app.add_subcommand("compare", "Statistics of the difference of two images A and B (.exr/.hdr/.pfm, any mix)");
    cmd->add_option("A", o.a, "Image A (e.g. your render)")->required();
    cmd->add_option("B", o.b, "Image B (the reference)")->required();
    cmd->add_option_function<double>("--threshold", [&o](const double& v) { o.threshold = v, o.threshold_given = true; },
                                     "Exit with code 1 when the --metric exceeds this (or an image has NaN/Inf)");
    cmd->add_option("--metric", o.metric,
                    fmt::format("Statistic for --threshold: {} (mean: the largest per-channel |mean difference|, the grader's measure)",
                                kImageMetricNames))
        ->capture_default_str();
    cmd->add_option("--diff", o.diff_path, "Write a false-colour PNG of the signed luminance difference A - B (blue: A darker, red: A brighter)");
    cmd->add_option("--diff-scale", o.diff_scale, "Difference shown at full colour in --diff (default: the 99th percentile of |difference|)");
    cmd->add_flag("--json", o.json, "Print the results as JSON");
    cmd->add_flag("--strict", o.strict, "Refuse (exit 2) two renders of different scenes, by their EXRs' scene hashes (default: a warning), and an image that does not say its scene");
    cmd->add_option("--z-test", o.z_test_variance,
                    "Judge A as Mitsuba 3's render tests do, given this image of B's per-sample variance: a z-test per pixel and "
                    "channel in XYZ at a Sidak-corrected --alpha, passing when 99.75% of them pass (exit code 1 if not); needs --spp");
    cmd->add_option("--spp", o.z_test_spp, "--z-test: A's samples per pixel")->check(CLI::PositiveNumber);
    cmd->add_option("--alpha", o.z_test_alpha, "--z-test: the false-alarm rate of the whole image")
        ->check(CLI::Range(1e-12, 0.5))
        ->capture_default_str();
    return cmd;
}

namespace {

int run_z_test(const CompareOptions& o, const Image& a, const Image& b) {
    if (o.z_test_spp == 0) throw UsageError("--z-test needs --spp, the samples per pixel of A");
    std::string unused;
    const Image var = read_input(o.z_test_variance, unused);
    PixelZTestOptions zo;
    zo.spp = o.z_test_spp, zo.alpha = o.z_test_alpha;
    PixelZTest t;
    try {
        t = pixel_z_test(a, b, var, zo);
    } catch (const std::invalid_argument&) {
        throw UsageError(fmt::format("{} is {}x{}, {} {}x{} and {} {}x{}: the images and the variance must have one size", o.a,
                                     a.width(), a.height(), o.b, b.width(), b.height(), o.z_test_variance, var.width(),
                                     var.height()));
    }
    if (o.json) {
        nlohmann::json j = {{"a", o.a},
                            {"b", o.b},
                            {"variance", o.z_test_variance},
                            {"spp", o.z_test_spp},
                            {"alpha", o.z_test_alpha},
                            {"alpha_per_test", t.alpha_per_test},
                            {"tested", t.tested},
                            {"passed", t.passed},
                            {"pass_fraction", t.pass_fraction()},
                            {"min_p_value", t.min_p_value},
                            {"mean_relative_diff", t.mean_relative_diff},
                            {"pass", t.pass}};
        fmt::print("{}\n", j.dump(2));
    } else {
        fmt::print("{}: {:.2f}% of {} pixel-channels pass the z-test at {:.3g} (Sidak, alpha {:g} over the image; 99.75% needed); "
                   "mean of A - B in XYZ {:+.2f}% of B; min p-value {:.3g}\n",
                   t.pass ? "PASS" : "FAIL", 100 * t.pass_fraction(), t.tested, t.alpha_per_test, o.z_test_alpha,
                   100 * t.mean_relative_diff, t.min_p_value);
    }
    return t.pass ? 0 : 1;
}

}  // namespace

int run_compare_command(const CompareOptions& o) {
    double unused = 0;
    if (!image_metric(ImageDifference{}, o.metric, unused))
        throw UsageError(fmt::format("unknown --metric '{}'. Valid metrics: {}", o.metric, kImageMetricNames));
    if (o.threshold_given && !(o.threshold >= 0)) throw UsageError("--threshold must be zero or positive");
    if (o.diff_scale < 0 || !std::isfinite(o.diff_scale)) throw UsageError("--diff-scale must be positive");
    if (!o.diff_path.empty()) {
        try {
            if (image_format_for(o.diff_path) != ImageFormat::Png)
                throw UsageError(fmt::format("--diff {}: the difference picture is written as .png", o.diff_path));
            check_writable_image_path(o.diff_path);
        } catch (const ImageIoError& e) {
            throw UsageError(e.what());
        }
    }
    std::string scene_a, scene_b;
    const Image a = read_input(o.a, scene_a), b = read_input(o.b, scene_b);
    // Renders of different scenes (both EXRs say which, by the scene's hash): a warning, or with
    // --strict a refusal. The numbers would say nothing of either render.
    // --strict compares only renders that say they are of one scene: an image without the hash
    // (a PNG, another renderer's EXR) cannot show it.
    if (o.strict)
        for (const auto& [file, scene] : {std::pair{o.a, scene_a}, std::pair{o.b, scene_b}})
            if (scene.empty())
                throw UsageError(fmt::format("{} does not say which scene it renders (no pathlab:sceneHash: not a pathlab EXR): "
                                             "--strict compares only renders of one scene",
                                             file));
    if (!scene_a.empty() && !scene_b.empty() && scene_a != scene_b) {
        const std::string why = fmt::format("{} is a render of {}, {} of {}: images of different scenes", o.a, scene_a, o.b, scene_b);
        if (o.strict) throw UsageError(why + " (--strict)");
        fmt::print(stderr, "pathlab: warning: {}\n", why);
    }
    if (!o.z_test_variance.empty()) return run_z_test(o, a, b);
    if (o.z_test_spp != 0) throw UsageError("--spp is for --z-test");
    ImageDifference d;
    try {
        d = compare_images(a, b);
    } catch (const ImageSizeMismatch&) {
        throw UsageError(fmt::format("{} is {}x{} but {} is {}x{}: images of different sizes cannot be compared", o.a,
                                     a.width(), a.height(), o.b, b.width(), b.height()));
    }
    double value = 0;
    image_metric(d, o.metric, value);
    const bool pass = !o.threshold_given || (value <= o.threshold && d.non_finite() == 0);

    double scale = 0;
    if (!o.diff_path.empty()) {
        scale = o.diff_scale > 0 ? o.diff_scale : difference_scale(a, b);
        write_png8(false_colour_difference(a, b, scale), o.diff_path);
    }

    if (o.json) {
        nlohmann::json j = {{"a", o.a}, {"b", o.b}};
        j.update(image_difference_json(d));
        if (o.threshold_given) j["threshold"] = {{"metric", o.metric}, {"value", value}, {"limit", o.threshold}, {"pass", pass}};
        if (!o.diff_path.empty()) j["diff"] = {{"path", o.diff_path}, {"scale", scale}};
        fmt::print("{}\n", j.dump(2));
    } else {
        print_table(o, d);
        if (!o.diff_path.empty())
            fmt::print("{}: luminance difference A - B, blue -{:.4g} .. grey 0 .. red +{:.4g} (green: NaN/Inf)\n", o.diff_path,
                       scale, scale);
        if (o.threshold_given)
            fmt::print("{}: {} = {:.6g} {} threshold {:.6g}{}\n", pass ? "PASS" : "FAIL", o.metric, value,
                       value <= o.threshold ? "<=" : ">", o.threshold, d.non_finite() ? ", but NaN/Inf present" : "");
    }
    return pass ? 0 : 1;
}

}  // namespace pathlab
