// The command a checkpoint continues: `pathlab --resume r.ckpt` alone carries on the render the
// checkpoint holds. A checkpoint records its render's command (its scene, a file by its absolute
// path, and the options given: -a naming that render's estimator, outputs by absolute path, and
// not --checkpoint, since a resumed render checkpoints to the file it resumes), as JSON:
//   [["/abs/scene.xml"], ["-a", "bdpt"], ["--spp", "256"], ["-D", "x=1"], ["-q"]]
// Resuming without a scene runs that command with the options given now replacing its own;
// whatever then differs from the checkpoint's render (scene, estimator, its options, size, seed,
// sampler) is refused as for any --resume.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "job/scene_choice.hpp"

namespace pathlab {

using OptionGroups = std::vector<std::vector<std::string>>;  // each: an option's name, then its values

// The render options given to `app` (a parsed command), each as its name and values, but for
// the scene (positional or --scene) and --resume, which a checkpoint's command supplies itself.
OptionGroups given_options(const CLI::App& app);

// The JSON a checkpoint records for the render of `scene` with `algorithm` ("" when -a was not
// given: the scene file's own) and the options given.
std::string checkpoint_command(const SceneChoice& scene, const std::string& algorithm, const OptionGroups& given);

// The arguments (without the program's name) that continue the checkpoint `path` whose recorded
// command is `command`: its scene, its options but those in `now`, then `now_args` (the
// arguments given now). Throws UsageError for a checkpoint without a command (an older
// pathlab's) or with a malformed one.
std::vector<std::string> resumed_arguments(const std::string& path, const std::string& command, const OptionGroups& now,
                                           const std::vector<std::string>& now_args);

// The command as one line a shell reads back ("pathlab render SCENE --algorithm bdpt ...").
std::string command_line(const std::string& command);
// words[from..] as a shell reads them back (quoted where needed).
std::string shell_words(const std::vector<std::string>& words, size_t from = 0);

}  // namespace pathlab
