#include "app/cli.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>

#include <fmt/format.h>

#include "app/command_arguments.hpp"
#include "app/diff_commands.hpp"
#include "app/render_command.hpp"
#include "app/resumed_command.hpp"
#include "app/tool_commands.hpp"
#include "app/view_command.hpp"
#include "job/checkpoint.hpp"
#include "job/rank_group.hpp"
#include "job/usage_error.hpp"
#include "integrators/integrator.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/plugin_reference.hpp"

namespace pathlab {
namespace {

// Every long option of `app` (and its subcommands' names), for "unknown option" messages.
std::string valid_options(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::Option* o : app.get_options()) {
        std::string n = o->get_name(false, true);
        if (!n.empty()) names.push_back(n);
    }
    for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
    return fmt::format("{}", fmt::join(names, ", "));
}

void print_scenes() {
    for (const BuiltinSceneInfo& s : builtin_scenes()) fmt::print("{}  {:<16} {}\n", s.index, s.name, s.summary);
}

void print_algorithms() {
    for (const IntegratorInfo& e : integrators()) {
        const std::string alias = e.aliases.empty() ? "" : fmt::format("({})", fmt::join(e.aliases, "/"));
        fmt::print("{:<14} {:<5} {}\n", e.name, alias, e.summary);
    }
    fmt::print("\nParticipating media (scenes with a <medium>): {}; the others refuse such scenes.\n", media_integrator_names());
    fmt::print("Spectral mode (--spectral): {}.\n", spectral_integrator_names());
    fmt::print("Light sampling at shading points (--light-sampler uniform|power|bvh|ris): {}.\n", light_sampling_integrator_names());
    fmt::print("A straight pass through thin glass or a mask's hole as no bounce (--null-depth skip, Mitsuba's volpath): {}; the others "
               "count it, and refuse skip with a finite --max-depth in scenes that have such surfaces.\n",
               null_skipping_integrator_names());
}

}  // namespace

int run_cli(int argc, const char* const* argv, RankGroup* ranks, bool resuming) {
    CLI::App app{"pathlab: a physically based Monte Carlo renderer and light-transport laboratory.\n"
                 "Renders the 8 NPGR010 Cornell-box scenes (or scene files) with a chosen estimator.\n"
                 "Usage: pathlab SCENE [options]   (or pathlab render SCENE [options]; pathlab COMMAND --help)\n"
                 "e.g.   pathlab 3 -a pt-mis --spp 256 -o glossy.png",
                 "pathlab"};
    app.set_version_flag("--version", PATHLAB_VERSION);
    app.require_subcommand(0, 1);
    app.footer(kInterruptHelp);

    RenderCommandOptions render_opt;
    add_render_options(app, render_opt);
    CLI::App* render_cmd = app.add_subcommand("render", "Render scenes (the same as without a command): pathlab render SCENE [options]");
    add_render_options(*render_cmd, render_opt);
    render_cmd->footer(kInterruptHelp);
    CLI::App* scenes_cmd = app.add_subcommand("scenes", "List the built-in scenes, one per line");
    CLI::App* algorithms_cmd = app.add_subcommand("algorithms", "List the estimators (--algorithm values)");
    CLI::App* plugins_cmd =
        app.add_subcommand("plugins", "The scene-file elements and their parameters (Markdown tables, as in docs/scene-files.md)");
    CompareOptions compare_opt;
    CLI::App* compare_cmd = add_compare_command(app, compare_opt);
    ReferenceOptions reference_opt;
    CLI::App* reference_cmd = add_reference_command(app, reference_opt);
    CheckOptions check_opt;
    CLI::App* check_cmd = add_check_command(app, check_opt);
    ReportOptions report_opt;
    CLI::App* report_cmd = add_report_command(app, report_opt);
    ConvertOptions convert_opt;
    CLI::App* convert_cmd = add_convert_command(app, convert_opt);
    InfoOptions info_opt;
    CLI::App* info_cmd = add_info_command(app, info_opt);
    MergeOptions merge_opt;
    CLI::App* merge_cmd = add_merge_command(app, merge_opt);
    ParamsOptions params_opt;
    CLI::App* params_cmd = add_params_command(app, params_opt);
    GradientOptions gradient_opt;
    CLI::App* gradient_cmd = add_gradient_command(app, gradient_opt);
    OptimizeOptions optimize_opt;
    CLI::App* optimize_cmd = add_optimize_command(app, optimize_opt);
    ViewOptions view_opt;
    CLI::App* view_cmd = add_view_command(app, view_opt);

    // No arguments: the usage, not a render of everything.
    if (argc <= 1) {
        fmt::print(stderr, "{}", app.help());
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::Success& e) {
        return app.exit(e);
    } catch (const CLI::ExtrasError& e) {
        // Name the options of the subcommand that was given, if any.
        const std::vector<CLI::App*> given = app.get_subcommands();
        const CLI::App& scope = given.empty() ? app : *given.front();
        fmt::print(stderr, "pathlab: {}\nValid options{}: {}\n(see pathlab {}--help)\n", e.what(),
                   given.empty() ? "" : " of " + scope.get_name(), valid_options(scope),
                   given.empty() ? "" : scope.get_name() + " ");
        return 2;
    } catch (const CLI::ParseError& e) {
        fmt::print(stderr, "pathlab: {}\n(see pathlab --help)\n", e.what());
        return 2;
    }

    const bool rendering = app.get_subcommands().empty() || *render_cmd;
    if (rendering) render_opt.given = given_options(*render_cmd ? *render_cmd : app);

    try {
        // `pathlab --resume r.ckpt [options]`: the render the checkpoint records, with these options.
        if (rendering && !render_opt.resume.empty() && scene_spec(render_opt.scenes).empty() && !resuming) {
            if (ranks && ranks->size() > 1)
                throw UsageError("across processes, --resume needs the render's scene and options again (give them as when it started)");
            CheckpointInfo info;
            try {
                info = read_checkpoint_info(render_opt.resume);
            } catch (const CheckpointError& e) {
                throw UsageError(e.what());
            }
            std::vector<std::string> now(argv + 1, argv + argc);
            if (*render_cmd) now.erase(std::find(now.begin(), now.end(), std::string("render")));
            std::vector<std::string> args = resumed_arguments(render_opt.resume, info.command, render_opt.given, now);
            args.insert(args.begin(), {argv[0], "render"});
            const bool quiet = std::find_if(args.begin(), args.end(), [](const std::string& a) { return a == "-q" || a == "--quiet"; }) != args.end();
            if (!quiet) fmt::print(stderr, "pathlab: continuing {}: pathlab {}\n", render_opt.resume, shell_words(args, 1));
            std::vector<const char*> again;
            for (const std::string& a : args) again.push_back(a.c_str());
            return run_cli(int(again.size()), again.data(), ranks, /*resuming=*/true);
        }
        if (ranks && ranks->size() > 1 && !app.get_subcommands().empty() && !*render_cmd)
            throw UsageError(fmt::format("only rendering runs across processes; start `pathlab {}` without mpirun",
                                         app.get_subcommands().front()->get_name()));
        if (*scenes_cmd) {
            print_scenes();
            return 0;
        }
        if (*algorithms_cmd) {
            print_algorithms();
            return 0;
        }
        if (*plugins_cmd) {
            fmt::print("{}", plugin_reference_markdown());
            return 0;
        }
        if (*compare_cmd) return run_compare_command(compare_opt);
        if (*reference_cmd) return run_reference_command(reference_opt);
        if (*check_cmd) return run_check_command(check_opt);
        if (*report_cmd) return run_report_command(report_opt);
        if (*convert_cmd) return run_convert_command(convert_opt);
        if (*info_cmd) return run_info_command(info_opt);
        if (*merge_cmd) return run_merge_command(merge_opt);
        if (*params_cmd) return run_params_command(params_opt);
        if (*gradient_cmd) return run_gradient_command(gradient_opt);
        if (*optimize_cmd) return run_optimize_command(optimize_opt);
        if (*view_cmd) return run_view_command(view_opt);
        return run_render_command(render_opt, ranks);
    } catch (const UsageError& e) {
        fmt::print(stderr, "pathlab: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "pathlab: error: {}\n", e.what());
        return 1;
    }
}

}  // namespace pathlab
