#include "judge/reference_manifest.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/input_file.hpp"
#include "image/image_io.hpp"
#include "job/render_job.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

nlohmann::json read_manifest(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(path, ec))) return nlohmann::json::object();
    const auto fail = [&](const std::string& why) {
        return ManifestError(fmt::format("{}: {} (fix it, or remove it and render the references again)", path.string(), why));
    };
    std::string text;
    try {
        text = read_input_file(path.string(), uint64_t(1) << 28);
    } catch (const InputFileError& e) {
        throw fail(e.what());
    }
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        throw fail(fmt::format("not valid JSON: {}", e.what()));
    }
    if (!j.is_object()) throw fail("not a JSON object");
    if (j.contains("scenes")) {
        if (!j["scenes"].is_array()) throw fail("its \"scenes\" is not an array");
        for (const nlohmann::json& e : j["scenes"]) {
            if (!e.is_object()) throw fail("an entry of \"scenes\" is not an object");
            if (!e.contains("file") || !e["file"].is_string()) throw fail("an entry of \"scenes\" has no \"file\" name");
            const std::string file = e["file"].get<std::string>();
            if (e.contains("index") && !e["index"].is_number_integer()) throw fail(fmt::format("the entry of '{}': its index is not a whole number", file));
            // The fields check compares: of the wrong type they were read as absent, and a
            // reference of any size or sample count PASSED.
            if (e.contains("resolution")) {
                const nlohmann::json& r = e["resolution"];
                if (!r.is_array() || r.size() != 2 || !r[0].is_number_unsigned() || !r[1].is_number_unsigned() || r[0].get<uint64_t>() < 1 ||
                    r[1].get<uint64_t>() < 1 || r[0].get<uint64_t>() > (1u << 16) || r[1].get<uint64_t>() > (1u << 16))
                    throw fail(fmt::format("the entry of '{}': its resolution is not [width, height] in pixels", file));
            }
            for (const char* key : {"spp", "seed", "invalid_samples"})
                if (e.contains(key) && !e[key].is_number_unsigned())
                    throw fail(fmt::format("the entry of '{}': its {} is not a whole number of at least 0", file, key));
            if (e.contains("max_depth") && !e["max_depth"].is_number_integer())
                throw fail(fmt::format("the entry of '{}': its max_depth is not a whole number", file));
            for (const char* key : {"scene", "algorithm", "family", "scene_hash", "scene_file"})
                if (e.contains(key) && !e[key].is_string()) throw fail(fmt::format("the entry of '{}': its {} is not a string", file, key));
            try {
                (void)reference_record_from_json(e);
            } catch (const nlohmann::json::exception& x) {
                throw fail(fmt::format("the entry of '{}': {}", file, x.what()));
            }
        }
    }
    return j;
}

std::string describe_scene(const ReferenceRecord& r) {
    if (r.index) return fmt::format("scene {} {}", *r.index, r.scene);
    return r.scene_file.empty() ? r.scene : r.scene_file;
}

std::string describe_scene(const SceneChoice& s) {
    if (s.builtin) return fmt::format("scene {} {}", *s.builtin, s.name);
    return s.file.empty() ? s.name : s.file;
}

std::string describe_parameters(const std::map<std::string, std::string>& p) {
    std::vector<std::string> items;
    for (const auto& [name, value] : p) items.push_back(name + "=" + value);
    return items.empty() ? "none" : fmt::format("{}", fmt::join(items, " "));
}

}  // namespace

nlohmann::json to_json(const ReferenceRecord& r) {
    nlohmann::json j = {{"file", r.file}, {"scene", r.scene}};
    if (r.index) j["index"] = *r.index;
    if (!r.scene_file.empty()) {
        j["scene_file"] = r.scene_file;
        j["scene_hash"] = r.scene_hash;
        j["parameters"] = r.parameters;
    }
    if (!r.stderr_file.empty()) j["stderr_file"] = r.stderr_file;
    if (!r.preview.empty()) j["preview"] = r.preview;
    j.update({{"algorithm", r.algorithm},
              {"family", r.family},
              {"max_depth", r.max_depth},
              {"resolution", {r.width, r.height}},
              {"spp", r.spp},
              {"seed", r.seed},
              {"seconds", r.seconds},
              {"invalid_samples", r.invalid_samples},
              {"interrupted", r.interrupted}});
    return j;
}

ReferenceRecord reference_record_from_json(const nlohmann::json& j) {
    ReferenceRecord r;
    if (!j.is_object()) return r;
    r.file = j.value("file", "");
    r.scene = j.value("scene", "");
    if (j.contains("index") && j["index"].is_number_integer()) r.index = j["index"].get<int>();
    r.scene_file = j.value("scene_file", "");
    r.scene_hash = j.value("scene_hash", "");
    if (j.contains("parameters") && j["parameters"].is_object())
        for (const auto& [k, v] : j["parameters"].items())
            if (v.is_string()) r.parameters[k] = v.get<std::string>();
    r.algorithm = j.value("algorithm", "");
    r.max_depth = j.value("max_depth", -1);
    r.family = j.value("family", "");
    if (r.family.empty() && !r.algorithm.empty())
        if (const IntegratorInfo* info = find_integrator(r.algorithm)) r.family = integrator_family(*info, r.max_depth);
    if (j.contains("resolution") && j["resolution"].is_array() && j["resolution"].size() == 2) {
        r.width = j["resolution"][0].get<int>();
        r.height = j["resolution"][1].get<int>();
    }
    r.spp = j.value("spp", uint64_t(0));
    r.seed = j.value("seed", uint64_t(0));
    r.seconds = j.value("seconds", 0.0);
    r.invalid_samples = j.value("invalid_samples", uint64_t(0));
    r.interrupted = j.value("interrupted", false);
    r.stderr_file = j.value("stderr_file", "");
    r.preview = j.value("preview", "");
    return r;
}

std::optional<ReferenceRecord> find_reference_record(const std::string& image_path) {
    const fs::path p(image_path);
    const nlohmann::json manifest = read_manifest(p.parent_path() / "manifest.json");
    if (!manifest.contains("scenes") || !manifest["scenes"].is_array()) return std::nullopt;
    const std::string name = p.filename().string();
    for (const nlohmann::json& e : manifest["scenes"])
        if (e.is_object() && e.value("file", "") == name) return reference_record_from_json(e);
    return std::nullopt;
}

void check_manifest(const std::string& dir) { (void)read_manifest(fs::path(dir) / "manifest.json"); }

void record_reference(const std::string& dir, const ReferenceRecord& record) {
    const fs::path path = fs::path(dir) / "manifest.json";
    nlohmann::json manifest = read_manifest(path);
    nlohmann::json entries = manifest.contains("scenes") && manifest["scenes"].is_array() ? manifest["scenes"] : nlohmann::json::array();
    for (auto it = entries.begin(); it != entries.end();)
        it = (it->is_object() && it->value("file", "") == record.file) ? entries.erase(it) : it + 1;
    entries.push_back(to_json(record));
    std::stable_sort(entries.begin(), entries.end(), [](const nlohmann::json& a, const nlohmann::json& b) {
        const int ia = a.value("index", 1 << 20), ib = b.value("index", 1 << 20);
        return ia != ib ? ia < ib : a.value("file", "") < b.value("file", "");
    });
    manifest["pathlab_version"] = PATHLAB_VERSION;
    manifest["scenes"] = entries;
    write_text_file(path.string(), manifest.dump(2) + "\n");
}

std::string reference_mismatch(const ReferenceRecord& r, const std::string& image_path, const SceneChoice& scene,
                               const std::string& family, int width, int height) {
    const std::string redo = "render a matching one with `pathlab reference`, or leave the reference out";
    // The scene: built-in by index; a scene file by its hash (every file it read, its parameters).
    const bool same_scene = scene.builtin ? (r.index && *r.index == *scene.builtin)
                                          : (!r.index && !r.scene_hash.empty() && r.scene_hash == scene.hash);
    // A built-in scene's index and name must agree (an edited or mixed-up manifest).
    if (same_scene && scene.builtin && !r.scene.empty() && r.scene != scene.name)
        return fmt::format("{} is a reference of scene {} by its manifest entry's index, but of {} by its name: the manifest is "
                           "inconsistent; {}",
                           image_path, *r.index, r.scene, redo);
    if (!same_scene) {
        std::string why = fmt::format("{} is a reference of {}, not of {}", image_path, describe_scene(r), describe_scene(scene));
        if (!scene.builtin && !r.index && r.scene == scene.name) {
            why = r.parameters != scene.parameters
                      ? fmt::format("{} is a reference of {} with the parameters {}, not {}", image_path, describe_scene(r),
                                    describe_parameters(r.parameters), describe_parameters(scene.parameters))
                      : fmt::format("{} is a reference of {} as it was then (hash {}); it or a file it reads has changed since (hash {})",
                                    image_path, describe_scene(r), r.scene_hash.empty() ? "unknown" : r.scene_hash, scene.hash);
        }
        return why + ": " + redo;
    }
    if (width > 0 && height > 0 && r.width > 0 && (r.width != width || r.height != height))
        return fmt::format("{} is {}x{}, the render {}x{}: {}", image_path, r.width, r.height, width, height, redo);
    if (!r.family.empty() && r.family != family)
        return fmt::format("{} was rendered with {} ({}); this estimator converges to {}: {}", image_path, r.algorithm, r.family,
                           family, redo);
    return "";
}

}  // namespace pathlab
