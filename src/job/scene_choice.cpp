#include "job/scene_choice.hpp"

#include <xxhash.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <fmt/format.h>

#include "core/input_file.hpp"
#include "job/usage_error.hpp"
#include "scenefile/gltf_scene.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab {

bool looks_like_scene_file(const std::string& key) {
    return (key.size() > 4 && key.compare(key.size() - 4, 4, ".xml") == 0) || is_gltf_path(key);
}

SceneChoice builtin_scene_choice(int index) {
    SceneChoice c{builtin_scenes()[size_t(index)].name, std::to_string(index), index, "", make_builtin_scene(index), {}, {}, ""};
    c.hash = scene_hash(c);
    return c;
}

SceneChoice scene_choice_of(SceneDescription desc) {
    std::string name = desc.name;
    SceneChoice c{name, name, std::nullopt, "", std::move(desc), {}, {}, ""};
    c.hash = scene_hash(c);
    return c;
}

namespace {

class Hasher {
public:
    Hasher() : state_(XXH3_createState()) { XXH3_64bits_reset(state_); }
    ~Hasher() { XXH3_freeState(state_); }
    Hasher(const Hasher&) = delete;
    Hasher& operator=(const Hasher&) = delete;
    void bytes(const void* p, size_t n) { XXH3_64bits_update(state_, p, n); }
    template <class T>
    void values(const std::vector<T>& v) {
        const uint64_t n = v.size();
        bytes(&n, sizeof n);
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
    void text(const std::string& s) {
        const uint64_t n = s.size();
        bytes(&n, sizeof n);
        bytes(s.data(), s.size());
    }
    void floats(std::initializer_list<float> f) {
        for (float x : f) bytes(&x, sizeof x);
    }
    std::string hex() const { return fmt::format("{:016x}", XXH3_64bits_digest(state_)); }

private:
    XXH3_state_t* state_;
};

}  // namespace

std::string scene_hash(const SceneChoice& c) {
    Hasher h;
    h.text(c.builtin ? fmt::format("builtin:{}", *c.builtin) : "");
    // Every file read, in the order read, by content; one that cannot be read counts as empty.
    std::vector<std::string> files = c.files;
    if (files.empty() && !c.file.empty()) files.push_back(c.file);
    const uint64_t count = files.size();
    h.bytes(&count, sizeof count);
    for (const std::string& f : files) {
        std::string text;
        try {
            text = read_input_file(f, std::numeric_limits<uint64_t>::max());
        } catch (const InputFileError&) {
        }
        h.text(text);
    }
    for (const auto& [name, value] : c.parameters) h.text(name + "=" + value);
    const SceneDescription& d = c.description;
    h.text(d.name);
    h.floats({d.camera.position.x, d.camera.position.y, d.camera.position.z, d.camera.forward.x, d.camera.forward.y,
              d.camera.forward.z, d.camera.up.x, d.camera.up.y, d.camera.up.z, d.camera.fov_degrees});
    // Vec3f, Vec2f and the triangles' index triples have no padding.
    static_assert(sizeof(Vec3f) == 12 && sizeof(Vec2f) == 8 && sizeof(std::array<uint32_t, 3>) == 12);
    for (const MeshDesc& m : d.meshes) {
        h.values(m.positions), h.values(m.normals), h.values(m.uvs), h.values(m.triangles);
        h.bytes(&m.material, sizeof m.material);
        h.floats({m.emission.x, m.emission.y, m.emission.z});
    }
    for (const SphereDesc& s : d.spheres) {
        h.floats({s.center.x, s.center.y, s.center.z, s.radius, s.emission.x, s.emission.y, s.emission.z});
        h.bytes(&s.material, sizeof s.material);
        const uint8_t flip = s.flip_normals;
        h.bytes(&flip, 1);
    }
    const uint64_t counts[2] = {d.materials.size(), d.lights.size()};
    h.bytes(counts, sizeof counts);
    return h.hex();
}

namespace {

// A -D name that no scene of the list uses is a typo (`-D sp=8` for spp) or meant for another
// scene: an error that lists what the scenes take.
void check_defines_used(const std::vector<SceneChoice>& scenes, const SceneDefines& defines) {
    for (const auto& define : defines) {
        const std::string& name = define.first;  // not a binding: the lambda captures it (clang 14)
        if (std::any_of(scenes.begin(), scenes.end(), [&](const SceneChoice& s) { return s.parameters.count(name) > 0; })) continue;
        std::string listing;
        bool builtin = false;
        for (const SceneChoice& s : scenes) {
            if (s.file.empty()) {
                builtin = true;
                continue;
            }
            std::vector<std::string> params;
            for (const auto& [p, v] : s.parameters) params.push_back(fmt::format("{} (now {})", p, v));
            listing += fmt::format("\n  {}: {}", s.file, params.empty() ? "none (no $name in it)" : fmt::format("{}", fmt::join(params, ", ")));
        }
        if (builtin) listing += "\n  the built-in scenes take no parameters";
        throw UsageError(fmt::format("-D {}={}: no scene uses ${}. The scenes' parameters:{}", name, define.second, name, listing));
    }
}

}  // namespace

std::vector<SceneChoice> resolve_scenes(const std::string& spec, const SceneDefines& defines, bool allow_files) {
    std::vector<SceneChoice> out;
    if (spec == "all") {
        for (const BuiltinSceneInfo& s : builtin_scenes()) out.push_back(builtin_scene_choice(s.index));
        check_defines_used(out, defines);
        return out;
    }
    for (const std::string& key : split_comma_list(spec)) {
        if (allow_files && looks_like_scene_file(key)) {
            try {
                const std::string stem = std::filesystem::path(key).stem().string();
                SceneFileInputs inputs;
                SceneDescription description = load_scene_file(key, defines, &inputs);
                SceneChoice c{stem, stem, std::nullopt, key, std::move(description), std::move(inputs.parameters),
                              std::move(inputs.files), ""};
                c.hash = scene_hash(c);
                out.push_back(std::move(c));
            } catch (const SceneFileError& e) {
                throw UsageError(e.what());
            }
        } else if (key == "all") {
            for (const BuiltinSceneInfo& s : builtin_scenes()) out.push_back(builtin_scene_choice(s.index));
        } else {
            out.push_back(builtin_scene_choice(builtin_scene_or_usage_error(key, allow_files)));
        }
    }
    check_defines_used(out, defines);
    return out;
}

std::vector<std::string> split_comma_list(const std::string& spec) {
    std::vector<std::string> items;
    size_t start = 0;
    while (start <= spec.size()) {
        const size_t comma = std::min(spec.find(',', start), spec.size());
        items.push_back(spec.substr(start, comma - start));
        start = comma + 1;
    }
    return items;
}

int builtin_scene_or_usage_error(const std::string& key, bool scene_files_allowed) {
    if (const auto index = find_builtin_scene(key)) return *index;
    std::string valid;
    for (const BuiltinSceneInfo& s : builtin_scenes()) valid += fmt::format("\n  {} {}", s.index, s.name);
    throw UsageError(fmt::format("unknown scene '{}'. Valid scenes (index or name, comma-separated, or 'all'){}:{}", key,
                                 scene_files_allowed ? ", or a scene file ending in .xml (or a glTF scene: .gltf, .glb)" : "", valid));
}

std::vector<int> parse_builtin_scene_list(const std::string& spec) {
    std::vector<int> scenes;
    if (spec == "all") {
        for (const BuiltinSceneInfo& s : builtin_scenes()) scenes.push_back(s.index);
        return scenes;
    }
    for (const std::string& key : split_comma_list(spec)) {
        const int index = builtin_scene_or_usage_error(key, /*scene_files_allowed=*/false);
        if (std::find(scenes.begin(), scenes.end(), index) == scenes.end()) scenes.push_back(index);
    }
    return scenes;
}

}  // namespace pathlab
