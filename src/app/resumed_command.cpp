#include "app/resumed_command.hpp"

#include <filesystem>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "job/usage_error.hpp"

namespace pathlab {
namespace {

// The options a checkpoint's command leaves out: the scene (recorded on its own), --resume, and
// --checkpoint (a resumed render goes on checkpointing to the file it resumes, not to where the
// first run did, unless --checkpoint is given again), and --display-server (where this run is
// watched, not what it renders).
bool recorded(const std::string& name) {
    return name != "--scene" && name != "--resume" && name != "--checkpoint" && name != "--display-server";
}

// Options naming files the render writes: recorded by absolute path, so that resuming from
// another folder writes where the first run did.
bool names_a_file(const std::string& name) {
    return name == "--output" || name == "--stats" || name == "--strategies" || name == "--ic-records";
}

}  // namespace

OptionGroups given_options(const CLI::App& app) {
    OptionGroups groups;
    for (const CLI::Option* opt : app.get_options()) {
        if (!opt->nonpositional() || opt->count() == 0) continue;
        const std::string name = opt->get_name();
        if (name.empty() || !recorded(name)) continue;
        if (opt->get_items_expected_max() == 0) {  // a flag
            groups.push_back({name});
            continue;
        }
        // One group per value: -D a=1 -D b=2, -o x.exr -o x.png.
        for (const std::string& value : opt->results())
            groups.push_back({name, names_a_file(name) && !value.empty() ? std::filesystem::absolute(value).lexically_normal().string() : value});
    }
    return groups;
}

std::string checkpoint_command(const SceneChoice& scene, const std::string& algorithm, const OptionGroups& given) {
    nlohmann::json command = nlohmann::json::array();
    const std::string where =
        scene.builtin || scene.file.empty() ? scene.name : std::filesystem::absolute(scene.file).lexically_normal().string();
    command.push_back(nlohmann::json::array({where}));
    for (const auto& group : given) {
        if (group.front() == "--algorithm") {
            if (!algorithm.empty()) command.push_back(nlohmann::json::array({"--algorithm", algorithm}));
            continue;
        }
        command.push_back(group);
    }
    return command.dump();
}

std::vector<std::string> resumed_arguments(const std::string& path, const std::string& command, const OptionGroups& now,
                                           const std::vector<std::string>& now_args) {
    if (command.empty())
        throw UsageError(fmt::format("{} does not record its command (an older pathlab wrote it): give its scene and options as "
                                     "when it started, with --resume {}",
                                     path, path));
    std::set<std::string> given;
    for (const auto& group : now) given.insert(group.front());
    std::vector<std::string> args;
    try {
        const nlohmann::json groups = nlohmann::json::parse(command);
        if (!groups.is_array() || groups.empty() || !groups[0].is_array() || groups[0].size() != 1) throw std::runtime_error("no scene");
        args.push_back(groups[0][0].get<std::string>());
        for (size_t i = 1; i < groups.size(); ++i) {
            const auto group = groups[i].get<std::vector<std::string>>();
            if (group.empty() || group.front().rfind("-", 0) != 0) throw std::runtime_error("not an option");
            if (given.count(group.front()) || !recorded(group.front())) continue;
            args.insert(args.end(), group.begin(), group.end());
        }
    } catch (const std::exception& e) {
        throw UsageError(fmt::format("{}: its recorded command is malformed ({}); give its scene and options with --resume {}", path,
                                     e.what(), path));
    }
    args.insert(args.end(), now_args.begin(), now_args.end());
    return args;
}

std::string shell_words(const std::vector<std::string>& words, size_t from) {
    std::string line;
    for (size_t i = from; i < words.size(); ++i) {
        const std::string& w = words[i];
        const bool plain = !w.empty() && w.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                                             "-_./=:,+@%") == std::string::npos;
        std::string quoted = "'";
        for (char c : w) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
        line += (line.empty() ? "" : " ") + (plain ? w : quoted + "'");
    }
    return line;
}

std::string command_line(const std::string& command) {
    std::vector<std::string> words{"pathlab", "render"};
    try {
        for (const auto& group : nlohmann::json::parse(command))
            for (const auto& word : group) words.push_back(word.get<std::string>());
    } catch (const std::exception&) {
        return "(malformed)";
    }
    return shell_words(words);
}

}  // namespace pathlab
