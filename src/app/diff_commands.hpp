// The differentiable-rendering subcommands (docs/differentiable.md): `pathlab params SCENE`
// lists a scene's differentiable parameters, `pathlab gradient` writes forward-mode images
// dI/dtheta and reverse-mode gradients, `pathlab optimize` recovers parameters from a target.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace pathlab {

struct ParamsOptions {
    std::string scene;
    std::vector<std::string> defines;  // -D name=value
    bool json = false;
};
CLI::App* add_params_command(CLI::App& app, ParamsOptions& o);
int run_params_command(const ParamsOptions& o);

// What gradient and optimize share: the scene, its parameters, the render of each evaluation.
struct DiffCommonOptions {
    std::string scene;
    std::string params;               // comma-separated names
    std::vector<std::string> initial;  // name=v or name=r,g,b: start values
    int spp = 4;
    std::string seed = "1234";
    int max_depth = -1;
    int rr_depth = 3;
    std::string resolution;           // default: the target's size (optimize) or 64x64 (gradient)
    std::vector<std::string> defines;  // -D name=value
    int threads = 0;                   // 0: all cores
};

struct GradientOptions {
    DiffCommonOptions common;
    std::string out_dir = "out/gradient";
    std::string target;  // with a target: dLoss/dtheta of the L2 loss, else of the mean pixel value
};
CLI::App* add_gradient_command(CLI::App& app, GradientOptions& o);
int run_gradient_command(const GradientOptions& o);

struct OptimizeOptions {
    DiffCommonOptions common;
    std::string target;
    int iterations = 50;
    double lr = 0.02;
    std::string optimizer = "adam";
    std::string loss = "l2";
    std::string region;  // x0,y0,x1,y1
    bool seed_per_iteration = false;
    int save_every = 10;
    std::string out_dir = "out/optimize";
    bool quiet = false;
};
CLI::App* add_optimize_command(CLI::App& app, OptimizeOptions& o);
int run_optimize_command(const OptimizeOptions& o);

}  // namespace pathlab
