#include "app/view_command.hpp"

#include <chrono>
#include <cstdio>
#include <thread>

#include <fmt/format.h>

#include "app/interrupt.hpp"
#include "image/image_io.hpp"
#include "job/output_paths.hpp"
#include "job/usage_error.hpp"
#include "view/view_server.hpp"
#include "view/view_session.hpp"

namespace pathlab {

CLI::App* add_view_command(CLI::App& app, ViewOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "view", "Watch a render converge in the browser: pathlab view [SCENE] [options], then open the address it prints");
    add_scene_arguments(*cmd, o.scenes);
    cmd->add_option("-a,--algorithm", o.algorithm, "The estimator (default: the scene file's <integrator>, else pt-mis); the page switches it");
    cmd->add_option("--compare", o.compare, "A second estimator rendering beside it (the A/B view); the page starts and stops it too");
    cmd->add_option("--sampler", o.sampler, "independent or sobol")->capture_default_str();
    cmd->add_option("--spp", o.spp, "Stop each render at this many samples per pixel (default: render until restarted or stopped)");
    cmd->add_option("--resolution", o.resolution, "WxH (default: the reference's size if given, else the scene's)");
    cmd->add_option("--seed", o.seed, "Random seed")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path (default: the scene file's, else unlimited)");
    add_threads_option(*cmd, o.threads);
    cmd->add_option("--reference", o.reference, "A reference image (.exr .pfm .hdr .png) of the same size: error image and RMSE-versus-time curve");
    cmd->add_option("-o,--output", o.output,
                    "Write A's image when its render ends: at --spp, when restarted, or at Ctrl-C ({algorithm} and {scene} expand)");
    cmd->add_option("--port", o.port, "Port (0: any free one)")->capture_default_str();
    cmd->add_option("--bind", o.bind, "Address to listen on; anything but loopback shows the render to the network (a warning says so)")
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", o.quiet, "Print only the address");
    cmd->footer("The page: the image as it converges (exposure, sRGB or false colour, zoom, the value under the cursor), the\n"
                "integrator and sampler of each of two renders (A and B), the reference, the error image and RMSE against time.\n"
                "Ctrl-C stops the renders (writing -o) and the server.");
    return cmd;
}

int run_view_command(const ViewOptions& o) {
    std::vector<SceneChoice> scenes = resolve_scene_arguments(o.scenes, "3");
    if (scenes.size() != 1) throw UsageError(fmt::format("pathlab view shows one scene; {} were given", scenes.size()));
    if (o.port < 0 || o.port > 65535) throw UsageError(fmt::format("--port must be from 0 to 65535, got {}", o.port));
    if (o.spp < 0) throw UsageError(fmt::format("--spp must be a positive number of samples, got {}", o.spp));

    ViewSession::Options s;
    s.scene = std::move(scenes.front());
    JobRequest& r = s.request;
    if (!o.algorithm.empty()) r.algorithm = o.algorithm;
    r.sampler = sampler_or_usage_error(o.sampler);
    r.seed = parse_seed_option(o.seed);
    r.max_depth = o.max_depth;
    parse_resolution_option(o.resolution, r.width, r.height);
    if (o.spp > 0) r.spp = uint64_t(o.spp);
    else r.time_limit = 1e9;  // until restarted or stopped (the page shows the time, not a budget)
    r.checkpoint_every = 0;
    if (!o.reference.empty()) {
        try {
            s.reference = image_format_for(o.reference) == ImageFormat::Png ? from_srgb8(read_png8(o.reference)) : read_image(o.reference);
        } catch (const ImageIoError& e) {
            throw UsageError(e.what());
        }
        s.reference_name = o.reference;
        if (o.resolution.empty()) r.width = s.reference->width(), r.height = s.reference->height();
    }
    if (!o.output.empty() && o.output.find('{') == std::string::npos) {
        OutputPaths paths;
        paths.scene_inputs(s.scene);
        if (!o.reference.empty()) paths.input(o.reference, "the reference");
        paths.output(o.output, "the output", /*image=*/true);
    }
    s.output = o.output;
    const bool quiet = o.quiet;
    s.say = [quiet](const std::string& m) {
        if (!quiet) fmt::print(stderr, "pathlab view: {}\n", m);
    };

    std::optional<tbb::global_control> thread_limit;
    limit_threads(thread_limit, o.threads);
    InterruptGuard interrupt;
    ViewSession session(std::move(s));
    if (!o.compare.empty()) session.start(1, o.compare, o.sampler);
    std::unique_ptr<ViewServer> server;
    try {
        server = std::make_unique<ViewServer>(session, o.bind, o.port);
    } catch (const std::runtime_error& e) {
        throw UsageError(fmt::format("{}; give another --port (0: any free one)", e.what()));
    }
    if (!is_loopback_address(o.bind))
        fmt::print(stderr, "pathlab view: warning: listening on {}: anyone who can reach this machine can see the render and restart it\n", o.bind);
    fmt::print("{}\n", server->url());
    std::fflush(stdout);
    if (!o.quiet) fmt::print(stderr, "pathlab view: {} at {} (Ctrl-C to stop)\n", session.scene().name, server->url());
    while (!InterruptGuard::flag().load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    server.reset();
    return 0;  // the session stops its renders (writing -o) as it goes
}

}  // namespace pathlab
