#include "scenefile/scene_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "scenefile/readers.hpp"

namespace pathlab {

SceneFileError::SceneFileError(std::string file_, int line_, int column_, const std::string& message_)
    : std::runtime_error(line_ > 0 ? fmt::format("{}:{}:{}: error: {}", file_, line_, column_, message_)
                                   : fmt::format("{}: error: {}", file_, message_)),
      file(std::move(file_)),
      line(line_),
      column(column_),
      message(message_) {}

SceneDescription load_scene_text(const std::string& text, const std::string& file_name, const std::string& base_dir,
                                 const SceneDefines& defines, bool allow_files) {
    XmlSource xml(text, file_name, defines);
    const pugi::xml_node scene = xml.root();
    if (std::string(scene.name()) != "scene") xml.fail(scene, fmt::format("the root element must be <scene>, not <{}>", scene.name()));
    if (!scene.attribute("version")) xml.fail(scene, "<scene> needs a version attribute, e.g. <scene version=\"3.0.0\">");
    xml.check_attributes(scene, {"version"});

    SceneBuilder b;
    b.shapes = ShapeContext{base_dir, allow_files};
    b.desc.name = std::filesystem::path(file_name).stem().string();
    use_default_sensor(b);  // Mitsuba's default sensor and film, unless the file has its own
    for (pugi::xml_node n : scene.children()) {
        if (n.type() != pugi::node_element) continue;
        const std::string tag = n.name();
        if (tag == "default") xml.define(n);
        else if (tag == "integrator") read_integrator(xml, n, b);
        else if (tag == "sensor") read_sensor(xml, n, b);
        else if (tag == "bsdf") read_named_bsdf(xml, n, b);
        else if (tag == "texture") read_named_texture(xml, n, b);
        else if (tag == "shape") read_shape(xml, n, b);
        else if (tag == "emitter") read_free_emitter(xml, n, b);
        else xml.fail(n, fmt::format("unsupported element <{}> in <scene>; supported: <default>, <integrator>, <sensor>, "
                                     "<bsdf>, <texture>, <shape>, <emitter>", tag));
    }
    if (b.desc.meshes.empty() && b.desc.spheres.empty()) xml.fail_file("the scene has no shapes");
    return std::move(b.desc);
}

SceneDescription load_scene_file(const std::string& path, const SceneDefines& defines) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
        throw SceneFileError(path, 0, 0, "not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw SceneFileError(path, 0, 0, fmt::format("cannot open the scene file: {}", std::strerror(errno)));
    std::ostringstream text;
    text << in.rdbuf();
    const std::filesystem::path p(path);
    return load_scene_text(text.str(), path, p.has_parent_path() ? p.parent_path().string() : ".", defines);
}

}  // namespace pathlab
