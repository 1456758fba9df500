// `pathlab SCENE [options]` (or `pathlab render SCENE [options]`): render built-in scenes or
// scene files with one or several estimators.
#pragma once

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

#include "app/command_arguments.hpp"
#include "app/resumed_command.hpp"
#include "job/render_job.hpp"

namespace pathlab {

struct RenderCommandOptions {
    SceneArguments scenes;
    std::string algorithm = "pt-mis";  // one or a comma-separated list; a scene file's <integrator> is used unless given
    bool algorithm_given = false;
    int spp = 0;
    bool spp_given = false;  // otherwise 64, or unlimited when --time is given
    double time_limit = 0;
    std::string resolution;  // "WxH"; empty: the scene's own
    std::string seed = "1234";
    std::string sampler = "independent";
    int threads = 0;
    std::vector<std::string> outputs;
    float exposure = 0;
    std::string stats_path;
    int max_depth = -1;
    bool max_depth_given = false;
    int rr_depth = 3;
    bool rr_depth_given = false;
    bool quiet = false;
    bool spectral = false;
    std::string mis = "balance";
    std::optional<std::string> light_sampler;
    std::optional<std::string> null_depth;  // --null-depth count|skip
    std::optional<int> ris_candidates;
    std::optional<float> light_split;
    std::string strategies_dir;
    int strategies_depth = 4;
    std::optional<int64_t> photons;
    std::optional<float> photon_radius;
    std::optional<double> photon_alpha;
    std::optional<std::string> volume_estimate;
    bool no_merging = false;      // vcm: connections only (= bdpt)
    bool no_connections = false;  // vcm: merging only (= bpm)
    std::optional<int> ic_rays;
    std::optional<float> ic_error;
    bool ic_no_gradients = false;
    std::string ic_records;
    std::optional<int> pbgi_surfels;
    std::optional<float> pbgi_cutoff;
    std::optional<int> pbgi_bounces;
    std::optional<int> pbgi_resolution;
    std::optional<int> pbgi_direct_samples;
    std::optional<int> pbgi_spacing;
    std::optional<int> guiding_spp;
    bool guiding_rr = false;
    std::string guiding_fraction;
    std::string guiding;
    std::optional<std::string> estimators;
    std::optional<int64_t> photon_beams;
    std::optional<float> beam_radius;
    std::string checkpoint;          // --checkpoint FILE
    double checkpoint_every = kDefaultCheckpointEvery;  // --checkpoint-every SECONDS
    std::string resume;              // --resume FILE
    uint64_t first_sample = 0;       // --first-sample N
    std::string display_server;      // --display-server HOST[:PORT] (tev)
    std::string aovs;                // --aovs albedo,normal,... (EXR layers)
    std::optional<int> mlt_chains;         // --chains (pssmlt)
    std::optional<int> mlt_bootstrap;      // --bootstrap
    std::optional<float> mlt_large_step;   // --large-step
    std::optional<float> mlt_sigma;        // --sigma
    OptionGroups given;              // the options given, which checkpoints record (resumed_command.hpp)
};

class RankGroup;

void add_render_options(CLI::App& app, RenderCommandOptions& opt);
// Validates the options (exit code 2 on bad usage) and runs the renders; `ranks` (null: this
// process alone) are the processes of an MPI job rendering each image together, of which rank 0
// writes the outputs, the checkpoints and the summary.
int run_render_command(const RenderCommandOptions& opt, RankGroup* ranks = nullptr);

}  // namespace pathlab
