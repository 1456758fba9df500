// The image-judging subcommands: `pathlab compare`, `reference`, `check` and `report`
// (README, "Judging images"). Each adds itself to the CLI11 app and runs from its options;
// bad usage throws UsageError (exit code 2).
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace pathlab {

struct CompareOptions {
    std::string a, b;  // B is the reference of relMSE
    double threshold = 0;
    bool threshold_given = false;
    std::string metric = "mean";
    std::string diff_path;
    double diff_scale = 0;  // 0: automatic
    bool json = false;
};
CLI::App* add_compare_command(CLI::App& app, CompareOptions& o);
// 0 agreement (or no threshold), 1 threshold exceeded.
int run_compare_command(const CompareOptions& o);

struct ReferenceOptions {
    std::string out_dir;
    std::string scenes = "all";
    std::string algorithm = "pt-mis";
    int spp = 0;  // 0: the default (kDefaultReferenceSpp), unless --time
    double time_limit = 0;
    std::string resolution;
    std::string seed = "4321";  // not the renderer's default 1234, so `check` renders independent samples
    int max_depth = -1;
    int threads = 0;
    bool quiet = false;
};
CLI::App* add_reference_command(CLI::App& app, ReferenceOptions& o);
int run_reference_command(const ReferenceOptions& o);

struct CheckOptions {
    std::string algorithm;
    std::string references;
    std::string mapping;
    std::string scenes = "all";
    int spp = 64;
    std::string resolution;
    std::string seed = "1234";
    int max_depth = -1;
    int threads = 0;
    std::string json_path;
    bool quiet = false;
};
CLI::App* add_check_command(CLI::App& app, CheckOptions& o);
// 0 when every scene with a reference is OK (or black by design) and at least one was
// compared; 1 otherwise.
int run_check_command(const CheckOptions& o);

struct ReportOptions {
    std::string scene;
    std::vector<std::string> algorithms;
    double time_limit = 0;
    int spp = 0;
    std::string output;
    std::string reference;
    int reference_spp = 1024;
    std::string reference_algorithm = "pt-mis";
    std::string resolution;
    std::string seed = "1234";
    int max_depth = -1;
    int threads = 0;
    bool quiet = false;
};
CLI::App* add_report_command(CLI::App& app, ReportOptions& o);
int run_report_command(const ReportOptions& o);

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
