#include "scenefile/scene_file.hpp"
#include "scenefile/gltf_scene.hpp"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/input_file.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {

SceneFileError::SceneFileError(std::string file_, int line_, int column_, const std::string& message_)
    : std::runtime_error(line_ > 0 ? fmt::format("{}:{}:{}: error: {}", file_, line_, column_, message_)
                                   : fmt::format("{}: error: {}", file_, message_)),
      file(std::move(file_)),
      line(line_),
      column(column_),
      message(message_) {}

void SceneBuilder::name(const XmlSource& xml, const pugi::xml_node& n, const std::string& id, const std::string& kind, std::any value) {
    if (const auto it = named.find(id); it != named.end())
        xml.fail(n, fmt::format("the id '{}' is already used (by the <{}> at {}:{})", id, it->second.kind, it->second.where.file,
                                it->second.where.line));
    named[id] = NamedObject{kind, xml.where(n), std::move(value)};
}

const NamedObject& SceneBuilder::resolve(const XmlSource& xml, const pugi::xml_node& ref, const std::string& expected) const {
    xml.check_attributes(ref, {"id", "name"});
    const std::string id = xml.attr(ref, "id");
    const auto it = named.find(id);
    if (it == named.end()) xml.fail(ref, fmt::format("no <{}> with id '{}' is declared before this reference", expected, id));
    if (it->second.kind != expected)
        xml.fail(ref, fmt::format("'{}' is a <{}> (declared at {}:{}), but a <{}> is expected here", id, it->second.kind,
                                  it->second.where.file, it->second.where.line, expected));
    return it->second;
}

std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> out;
    std::string item;
    for (size_t i = 0; i <= text.size(); ++i) {
        if (i == text.size() || text[i] == ',' || std::isspace(static_cast<unsigned char>(text[i]))) {
            if (!item.empty()) out.push_back(item);
            item.clear();
        } else {
            item += text[i];
        }
    }
    return out;
}

namespace {

// Mitsuba's format versions that pathlab reads: 0.5 and 0.6 (camelCase names accepted), 2.x, 3.x.
void read_version(XmlSource& xml, const pugi::xml_node& scene) {
    const std::string v = xml.attr(scene, "version");
    int major = -1, minor = 0, patch = 0;
    char extra = 0;
    const int got = std::sscanf(v.c_str(), "%d.%d.%d%c", &major, &minor, &patch, &extra);
    const bool ok = got >= 1 && got <= 3 && major >= 0 && minor >= 0 && patch >= 0 &&
                    ((major == 0 && minor >= 5) || major == 2 || major == 3) && !(got == 1 && major == 0);
    if (!ok)
        xml.fail(scene, fmt::format("unsupported scene version '{}'; supported: Mitsuba 0.5 and 0.6 (camelCase names), 2.x and 3.x "
                                    "(e.g. version=\"3.0.0\")", v));
    xml.context().version_major = major;
    xml.context().version_minor = minor;
}

struct Loader {
    std::shared_ptr<LoadContext> context;
    SceneBuilder b;
    std::vector<std::string> chain;  // the files being read: the main file, then each include
    // The whole include tree's files and bytes: a file that includes another many times over,
    // nested, multiplies them (as entity expansion does in XML), where depth and loops are fine.
    size_t includes = 0;
    uint64_t included_bytes = 0;
    static constexpr size_t kMaxIncludes = 4096;
    static constexpr uint64_t kMaxIncludedBytes = uint64_t(256) << 20;

    void read_children(XmlSource& xml, const pugi::xml_node& scene);
    void include(XmlSource& xml, const pugi::xml_node& n);
    void read_mode(XmlSource& xml, const pugi::xml_node& n);
};

// <default name="mode" value="spectral"/> (or "rgb"; -D mode=... wins, as for every default):
// the render mode the scene asks for (--spectral also sets it).
void Loader::read_mode(XmlSource& xml, const pugi::xml_node& n) {
    const std::string mode = xml.context().defines.at("mode");
    if (mode == "spectral") b.desc.spectral = true;
    else if (mode == "rgb") b.desc.spectral = false;
    else xml.fail(n, fmt::format("unknown mode '{}'. Valid modes: rgb, spectral", mode));
}

void Loader::read_children(XmlSource& xml, const pugi::xml_node& scene) {
    for (pugi::xml_node n : scene.children()) {
        if (n.type() == pugi::node_pcdata || n.type() == pugi::node_cdata) {
            if (std::string(n.value()).find_first_not_of(" \t\r\n") != std::string::npos) xml.fail(n, "unexpected text");
            continue;
        }
        if (n.type() != pugi::node_element) continue;
        const std::string tag = n.name();
        if (tag == "default") {
            xml.define(n);
            if (xml.attr(n, "name") == "mode") read_mode(xml, n);
        }
        else if (tag == "path") {
            xml.check_attributes(n, {"value"});
            const std::string value = xml.attr(n, "value");
            std::filesystem::path dir(value);
            if (dir.is_relative()) dir = std::filesystem::path(xml.dir()) / dir;
            std::error_code ec;
            if (context->allow_files && !std::filesystem::is_directory(dir, ec)) xml.fail(n, fmt::format("<path>: folder '{}' not found", dir.string()));
            context->search_paths.insert(context->search_paths.begin(), dir.string());  // searched before earlier ones
        } else if (tag == "include") include(xml, n);
        else if (tag == "alias") {
            xml.check_attributes(n, {"id", "as"});
            const std::string id = xml.attr(n, "id"), as = xml.attr(n, "as");
            const auto it = b.named.find(id);
            if (it == b.named.end()) xml.fail(n, fmt::format("<alias>: no object with id '{}' is declared before it", id));
            b.name(xml, n, as, it->second.kind, it->second.value);
        } else if (tag == "integrator") read_integrator(xml, n, b);
        else if (tag == "sensor") read_sensor(xml, n, b);
        else if (tag == "bsdf") read_named_bsdf(xml, n, b);
        else if (tag == "texture") read_named_texture(xml, n, b);
        else if (tag == "shape") read_shape(xml, n, b);
        else if (tag == "emitter") read_free_emitter(xml, n, b);
        else if (tag == "medium")
            read_named_medium(xml, n, b);
        else
            xml.fail(n, fmt::format("unsupported element <{}> in <scene>; supported: <default>, <path>, <include>, <alias>, "
                                    "<integrator>, <sensor>, <bsdf>, <texture>, <shape>, <emitter>, <medium>", tag));
    }
}

void Loader::include(XmlSource& xml, const pugi::xml_node& n) {
    xml.check_attributes(n, {"filename"});
    const std::string path = xml.find_file(n, xml.attr(n, "filename"), "included file");
    std::error_code ec;
    const std::string canonical = std::filesystem::weakly_canonical(path, ec).string();
    for (const std::string& f : chain)
        if (f == canonical) {
            std::vector<std::string> names;
            for (const std::string& c : chain) names.push_back(std::filesystem::path(c).filename().string());
            names.push_back(std::filesystem::path(canonical).filename().string());
            xml.fail(n, fmt::format("include loop: {}", fmt::join(names, " includes ")));
        }
    if (chain.size() >= 64) xml.fail(n, "includes nested more than 64 deep");
    if (++includes > kMaxIncludes)
        xml.fail(n, fmt::format("more than {} includes in all (files included many times over, nested?)", kMaxIncludes));
    std::string content;
    try {
        content = read_input_file(path, kMaxIncludedBytes);
    } catch (const InputFileError& e) {
        xml.fail(n, fmt::format("cannot read the included file '{}': {}", path, e.what()));
    }
    included_bytes += content.size();
    if (included_bytes > kMaxIncludedBytes)
        xml.fail(n, fmt::format("the includes bring more than {} MiB of scene text in all (files included many times over, nested?)",
                                kMaxIncludedBytes >> 20));
    XmlSource inner(content, path, context);
    const pugi::xml_node root = inner.root();
    if (std::string(root.name()) != "scene") inner.fail(root, fmt::format("an included file's root element must be <scene>, not <{}>", root.name()));
    inner.check_attributes(root, {"version"});
    chain.push_back(canonical);
    read_children(inner, root);
    chain.pop_back();
}

}  // namespace

SceneDescription load_scene_text(const std::string& text, const std::string& file_name, const std::string& base_dir,
                                 const SceneDefines& defines, bool allow_files, SceneFileInputs* inputs) {
    Loader loader;
    loader.context = std::make_shared<LoadContext>();
    loader.context->defines = defines;
    loader.context->scene_dir = base_dir;
    loader.context->allow_files = allow_files;
    XmlSource xml(text, file_name, loader.context);
    const pugi::xml_node scene = xml.root();
    if (std::string(scene.name()) != "scene") xml.fail(scene, fmt::format("the root element must be <scene>, not <{}>", scene.name()));
    if (!scene.attribute("version")) xml.fail(scene, "<scene> needs a version attribute, e.g. <scene version=\"3.0.0\">");
    xml.check_attributes(scene, {"version"});
    read_version(xml, scene);

    SceneBuilder& b = loader.b;
    b.shapes = ShapeContext{base_dir, allow_files};
    b.shapes.files_read = &loader.context->files;
    b.desc.name = std::filesystem::path(file_name).stem().string();
    use_default_sensor(b);  // Mitsuba's default sensor and film, unless the file has its own
    std::error_code ec;
    loader.chain.push_back(std::filesystem::weakly_canonical(file_name, ec).string());
    loader.read_children(xml, scene);
    if (b.desc.meshes.empty() && b.desc.spheres.empty() && b.desc.instances.empty()) xml.fail_file("the scene has no shapes");
    b.desc.notes = loader.context->notes;
    if (inputs) inputs->parameters = loader.context->used, inputs->files = loader.context->files;
    return std::move(b.desc);
}

SceneDescription load_scene_file(const std::string& path, const SceneDefines& defines, SceneFileInputs* inputs) {
    if (is_gltf_path(path)) return load_gltf_scene(path, defines, inputs);
    std::string text;
    try {
        text = read_input_file(path, Loader::kMaxIncludedBytes);  // as much as its includes may bring
    } catch (const InputFileError& e) {
        throw SceneFileError(path, 0, 0, fmt::format("cannot open the scene file: {}", e.what()));
    }
    const std::filesystem::path p(path);
    SceneDescription d = load_scene_text(text, path, p.has_parent_path() ? p.parent_path().string() : ".", defines, true, inputs);
    if (inputs) inputs->files.insert(inputs->files.begin(), path);
    return d;
}

}  // namespace pathlab
