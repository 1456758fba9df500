#include "textures/registry.hpp"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "core/file_search.hpp"
#include "image/image_io.hpp"

namespace pathlab {
namespace {

const ParamInfo kToUv{"to_uv", ParamType::Transform, "", "applied to the surface's uv before the lookup (scale, rotate, translate)"};

UvTransform read_to_uv(Properties& p) {
    const std::optional<Transform> t = p.get_transform("to_uv");
    return t ? UvTransform::from(*t) : UvTransform();
}

const PluginInfo& bitmap_plugin() {
    static const PluginInfo info{
        "texture", "bitmap", "an image looked up at uv: PNG and JPEG (sRGB) or EXR, HDR, PFM (linear)",
        {{"filename", ParamType::String, "", "the image, relative to the scene file: .png, .jpg, .jpeg, .bmp, .exr, .hdr or .pfm"},
         {"filter_type", ParamType::String, "bilinear", "bilinear (the four nearest texels) or nearest"},
         {"wrap_mode", ParamType::String, "repeat", "uv outside [0, 1]: repeat, mirror or clamp"},
         {"raw", ParamType::Boolean, "false", "keep 8-bit values as stored instead of decoding sRGB (normal and bump maps)"},
         {"format", ParamType::String, "auto",
          "Mitsuba 3's storage precision (auto, variant, fixed): accepted; pathlab keeps the decoded values as 32-bit floats"},
         kToUv}};
    return info;
}
Texture read_bitmap(Properties& p, const TextureContext& ctx) {
    if (!p.has("filename")) p.fail("<texture type=\"bitmap\"> needs <string name=\"filename\" value=\"...\"/>");
    const std::string filter = p.get_string("filter_type"), wrap = p.get_string("wrap_mode");
    FilterType f = FilterType::Bilinear;
    if (filter == "nearest") f = FilterType::Nearest;
    else if (filter != "bilinear") p.fail("filter_type", fmt::format("unsupported filter_type '{}'; supported: bilinear, nearest", filter));
    WrapMode w = WrapMode::Repeat;
    if (wrap == "mirror") w = WrapMode::Mirror;
    else if (wrap == "clamp") w = WrapMode::Clamp;
    else if (wrap != "repeat") p.fail("wrap_mode", fmt::format("unsupported wrap_mode '{}'; supported: repeat, mirror, clamp", wrap));
    const bool raw = p.get_bool("raw");
    const std::string format = p.get_string("format");
    if (format != "auto" && format != "variant" && format != "fixed")
        p.fail("format", fmt::format("unsupported format '{}'; supported: auto, variant, fixed", format));
    const UvTransform to_uv = read_to_uv(p);
    if (!ctx.allow_files) p.fail("this loader does not read files (bitmap textures are disabled)");
    const std::string path =
        find_in_dirs(p.get_string("filename"), ctx.search_dirs.empty() ? std::vector<std::string>{ctx.base_dir} : ctx.search_dirs);
    try {
        Texture t(load_bitmap_texture(path, raw, f, w, to_uv));
        if (ctx.files_read) ctx.files_read->push_back(path);
        return t;
    } catch (const ImageIoError& e) {
        p.fail("filename", fmt::format("cannot read the texture: {}", e.what()));
    }
}

const PluginInfo& checkerboard_plugin() {
    static const PluginInfo info{"texture", "checkerboard", "two colours in a checker pattern, 2 x 2 squares per unit of uv",
                                 {{"color0", ParamType::Rgb, "0.4", "the squares at [0, 1/2]^2 and [1/2, 1]^2 (for a float parameter the other squares, as Mitsuba 3)"},
                                  {"color1", ParamType::Rgb, "0.2", "the other squares"},
                                  kToUv}};
    return info;
}
Texture read_checkerboard(Properties& p, const TextureContext&) {
    CheckerboardTexture c;
    c.color0 = p.get_rgb("color0");
    c.color1 = p.get_rgb("color1");
    c.to_uv = read_to_uv(p);
    return Texture(c);
}

// Mitsuba 3's rawconstant: one value everywhere, used as given (no colour conversion), e.g. the
// identity normal map (0.5, 0.5, 1).
const PluginInfo& rawconstant_plugin() {
    static const PluginInfo info{"texture", "rawconstant", "one value everywhere, as given (no colour conversion): e.g. a normal map's (0.5, 0.5, 1)",
                                 {{"value", ParamType::Point, "", "the value (a <vector> or <point>; required)"}}};
    return info;
}
Texture read_rawconstant(Properties& p, const TextureContext&) {
    if (!p.has("value")) p.fail("<texture type=\"rawconstant\"> needs <vector name=\"value\" value=\"x, y, z\"/>");
    const Vec3f v = p.get_point("value");
    return Texture(ConstantTexture{Rgb(v.x, v.y, v.z)});
}

// Mitsuba 3's mesh_attribute: the value of the mesh's own attribute (a PLY's extra vertex or
// face property) at the hit; which mesh is known only when a shape uses the material, so the
// shape's reader checks the attribute (scenefile/read_shape.cpp).
const PluginInfo& mesh_attribute_plugin() {
    static const PluginInfo info{"texture", "mesh_attribute",
                                 "the mesh's own attribute at the hit (a PLY's extra vertex property interpolated, or the face's): "
                                 "values in [0, 1]",
                                 {{"name", ParamType::String, "", "vertex_NAME or face_NAME, e.g. vertex_color (required)"},
                                  {"scale", ParamType::Float, "1", "multiplies the attribute"}}};
    return info;
}
Texture read_mesh_attribute(Properties& p, const TextureContext&) {
    if (!p.has("name")) p.fail("<texture type=\"mesh_attribute\"> needs <string name=\"name\" value=\"vertex_color\"/> (or another attribute)");
    const std::string name = p.get_string("name");
    if (!name.starts_with("vertex_") && !name.starts_with("face_"))
        p.fail("name", fmt::format("a mesh attribute's name starts with vertex_ or face_, not '{}'", name));
    const float scale = p.get_float("scale");
    if (!(scale >= 0) || !std::isfinite(scale)) p.fail("scale", fmt::format("scale must be finite and not negative, got {}", scale));
    return Texture(MeshAttributeTexture{name, scale});
}

}  // namespace

const std::vector<TexturePlugin>& texture_plugins() {
    static const std::vector<TexturePlugin> table = {
        {bitmap_plugin, read_bitmap},
        {checkerboard_plugin, read_checkerboard},
        {rawconstant_plugin, read_rawconstant},
        {mesh_attribute_plugin, read_mesh_attribute},
    };
    return table;
}

const TexturePlugin* find_texture_plugin(const std::string& type) {
    for (const TexturePlugin& t : texture_plugins())
        if (t.info().type == type) return &t;
    return nullptr;
}

std::string texture_type_names() {
    std::vector<std::string> names;
    for (const TexturePlugin& t : texture_plugins()) names.push_back(t.info().type);
    return fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace pathlab
