#include "job/output_paths.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "image/image_io.hpp"
#include "job/scene_choice.hpp"
#include "job/usage_error.hpp"

namespace pathlab {

std::string OutputPaths::key(const std::string& path) {
    std::error_code ec;
    const std::filesystem::path p = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec);
    return ec ? path : p.string();
}

void OutputPaths::input(const std::string& path, const std::string& what) { inputs_.push_back({path, key(path), what}); }

void OutputPaths::scene_inputs(const SceneChoice& scene) {
    if (!scene.file.empty()) input(scene.file, "the scene file");
    for (const std::string& f : scene.files)
        if (f != scene.file) input(f, fmt::format("a file {} reads,", std::filesystem::path(scene.file).filename().string()));
}

void OutputPaths::output(const std::string& path, const std::string& what, bool image) {
    const std::string k = key(path);
    for (const Entry& in : inputs_)
        if (in.key == k)
            throw UsageError(fmt::format("{} {} is {} {}: it would be overwritten; choose another name", what, path, in.what, in.path));
    for (const Entry& out : outputs_)
        if (out.key == k)
            throw UsageError(fmt::format("{} {} is also {} {}: choose another name for one of them", what, path, out.what, out.path));
    try {
        if (image) check_writable_image_path(path);
        else check_writable_path(path);
    } catch (const ImageIoError& e) {
        throw UsageError(fmt::format("{}: {}", what, e.what()));
    }
    outputs_.push_back({path, k, what});
}

}  // namespace pathlab
