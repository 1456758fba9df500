// The image-judging subcommands: `pathlab compare`, `reference`, `check` and `report`
// (README, "Judging images"), and the image tools `convert` and `info`. Each adds itself to the
// CLI11 app and runs from its options; bad usage throws UsageError (exit code 2). The scene
// commands take their scenes (SceneArguments) and -a lists the same way as the renderer.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/command_arguments.hpp"

namespace pathlab {

struct CompareOptions {
    std::string a, b;  // B is the reference of relMSE
    double threshold = 0;
    bool threshold_given = false;
    std::string metric = "mean";
    std::string diff_path;
    double diff_scale = 0;  // 0: automatic
    bool json = false;
    bool strict = false;  // refuse renders of different scenes (by their EXR metadata) instead of warning
    // Mitsuba 3's render test (judge/pixel_z_test.hpp): B's per-sample variance image and A's samples per pixel.
    std::string z_test_variance;
    uint64_t z_test_spp = 0;
    double z_test_alpha = 0.01;
};
CLI::App* add_compare_command(CLI::App& app, CompareOptions& o);
// 0 agreement (or no threshold), 1 threshold exceeded.
int run_compare_command(const CompareOptions& o);

struct ReferenceOptions {
    std::string out_dir;               // may hold {algorithm} (required for several)
    SceneArguments scenes;             // default: all built-in scenes
    std::string algorithm = "pt-mis";  // one or a comma-separated list
    int spp = 0;  // 0: the default (kDefaultReferenceSpp), unless --time
    double time_limit = 0;
    std::string resolution;
    std::string seed = "4321";  // not the renderer's default 1234, so `check` renders independent samples
    std::optional<int> max_depth;  // default: the scene file's, else -1 (unlimited)
    int threads = 0;
    bool quiet = false;
};
CLI::App* add_reference_command(CLI::App& app, ReferenceOptions& o);
int run_reference_command(const ReferenceOptions& o);

struct CheckOptions {
    std::string algorithm;  // one or a comma-separated list
    std::string references;
    std::string mapping;
    SceneArguments scenes;  // default: all built-in scenes
    int spp = 64;
    std::string resolution;
    std::string seed = "1234";
    std::optional<int> max_depth;  // default: the scene file's, else -1 (unlimited)
    int threads = 0;
    std::string json_path;
    bool quiet = false;
};
CLI::App* add_check_command(CLI::App& app, CheckOptions& o);
// 0 when every scene with a reference is OK (or black by design) and at least one was
// compared; 1 otherwise.
int run_check_command(const CheckOptions& o);

struct ReportOptions {
    SceneArguments scenes;   // several: one report each (-o then needs {scene})
    std::string algorithms;  // -a/--algorithm (or --algorithms): one or a comma-separated list
    double time_limit = 0;
    int spp = 0;
    std::string output;
    std::string reference;   // an image (one scene), or a directory of references (as check's)
    int reference_spp = 1024;
    std::string reference_algorithm = "pt-mis";
    std::string resolution;
    std::string seed = "1234";
    std::optional<int> max_depth;  // default: the scene file's, else -1 (unlimited)
    int threads = 0;
    bool quiet = false;
    std::vector<std::string> crops;  // --crop X,Y,W,H: inset crops, magnified
    std::string guide_pixel;         // --guide-pixel X,Y: what ppg learned at that pixel's first hit
};
CLI::App* add_report_command(CLI::App& app, ReportOptions& o);
int run_report_command(const ReportOptions& o);

// `pathlab convert IN OUT`: any of .exr .hdr .pfm .png to any, with an exposure and a crop.
struct ConvertOptions {
    std::string input, output;
    float exposure = 0;  // stops: the values are scaled by 2^exposure (for every output format)
    std::string crop;    // "X,Y,W,H" in pixels from the top left; empty: the whole image
};
CLI::App* add_convert_command(CLI::App& app, ConvertOptions& o);
int run_convert_command(const ConvertOptions& o);

// `pathlab info IMG...`: size, channels, metadata (every header attribute), per-channel mean,
// minimum and maximum, NaN/Inf counts.
struct InfoOptions {
    std::vector<std::string> images;
    bool json = false;
};
CLI::App* add_info_command(CLI::App& app, InfoOptions& o);
int run_info_command(const InfoOptions& o);

// `pathlab merge OUT.exr IN...`: one image from renders of the same scene and settings with
// disjoint passes or different seeds (app/merge_command.cpp).
struct MergeOptions {
    std::string output;
    std::vector<std::string> inputs;
    bool quiet = false;
};
CLI::App* add_merge_command(CLI::App& app, MergeOptions& o);
int run_merge_command(const MergeOptions& o);


}  // namespace pathlab
