// `pathlab view [SCENE] [options]`: the render converging in the browser (view/view_server.hpp),
// served on 127.0.0.1 until Ctrl-C.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
#include <string>

#include "app/command_arguments.hpp"

namespace pathlab {

struct ViewOptions {
    SceneArguments scenes;  // one scene; default: the built-in scene 3
    std::string algorithm;  // default: the scene file's <integrator>, else pt-mis
    std::string compare;    // slot B's algorithm, started at once
    std::string sampler = "independent";
    int spp = 0;            // each render stops at this many; 0: until restarted or stopped
    std::string resolution;
    std::string seed = "1234";
    std::optional<int> max_depth;
    int threads = 0;
    std::string reference;  // an image of the same size
    std::string output;     // written when slot A's render ends (done, restarted, or at Ctrl-C)
    std::string bind = "127.0.0.1";
    int port = kDefaultViewPort;
    bool quiet = false;
    static constexpr int kDefaultViewPort = 14159;  // beside tev's 14158
};
CLI::App* add_view_command(CLI::App& app, ViewOptions& o);
// Serves until SIGINT or SIGTERM, then stops the renders (writing the output) and returns 0.
int run_view_command(const ViewOptions& o);

}  // namespace pathlab
