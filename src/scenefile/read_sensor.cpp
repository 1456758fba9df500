// <sensor type="perspective|thinlens|orthographic"> with its nested <film type="hdrfilm"> (and
// its <rfilter>) and <sampler>, and the medium it sits in (a nested <medium>, or
// <ref name="medium" id="..."/>).
#include <cmath>

#include <fmt/format.h>

#include "render/film.hpp"
#include "samplers/sampler.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

FovAxis read_fov_axis(Properties& p) {
    static const std::map<std::string, FovAxis> kAxes = {{"x", FovAxis::X},           {"y", FovAxis::Y},
                                                         {"smaller", FovAxis::Smaller}, {"larger", FovAxis::Larger},
                                                         {"each", FovAxis::EachAxis},  {"diagonal", FovAxis::Diagonal}};
    const std::string a = p.get_string("fov_axis");
    const auto it = kAxes.find(a);
    if (it == kAxes.end())
        p.fail("fov_axis", fmt::format("unsupported fov_axis '{}'; supported: x, y, diagonal, smaller, larger, each (pathlab: both "
                                       "axes span fov, as in the course)", a));
    return it->second;
}

// The camera of a to_world transform. A single <lookat> is evaluated in float exactly as the
// built-in scenes are (so a scene file can reproduce them bit for bit); any other transform
// goes through the matrix.
Camera camera_from(const XmlSource& xml, const std::optional<Transform>& to_world, const pugi::xml_node* block, float fov,
                   FovAxis axis) {
    if (!to_world) return Camera::look_along({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, fov, axis);
    std::vector<pugi::xml_node> ops;
    for (pugi::xml_node c : block->children())
        if (c.type() == pugi::node_element) ops.push_back(c);
    if (ops.size() == 1 && std::string(ops[0].name()) == "lookat") {
        const pugi::xml_node& op = ops[0];
        const Vec3f up = op.attribute("up") ? xml.parse_vec3(op, xml.attr(op, "up"), false) : Vec3f(0, 1, 0);
        return Camera::look_at(xml.parse_vec3(op, xml.attr(op, "origin"), false), xml.parse_vec3(op, xml.attr(op, "target"), false),
                               up, fov, axis);
    }
    const Transform& t = *to_world;
    const Vec3d left = t.vector({1, 0, 0}), up = t.vector({0, 1, 0}), dir = t.vector({0, 0, 1});
    Camera c;
    c.position = Vec3f(t.point({0, 0, 0}));
    c.forward = Vec3f(normalize(dir));
    c.right = Vec3f(normalize(-left));  // Mitsuba's camera +x points left in the image
    c.up = Vec3f(normalize(up));
    c.fov_degrees = fov;
    c.fov_axis = axis;
    return c;
}

void read_rfilter(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    const std::vector<PluginInfo>& plugins = rfilter_plugins();
    const auto it = std::find_if(plugins.begin(), plugins.end(), [&](const PluginInfo& p) { return p.type == type; });
    if (it == plugins.end()) {
        std::vector<std::string> names;
        for (const PluginInfo& p : plugins) names.push_back(p.type);
        xml.fail(n, fmt::format("unsupported rfilter type '{}'; supported: {}", type, fmt::join(names, ", ")));
    }
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "an <rfilter> has no nested plugins");
    Properties p = xml.properties(n, *it);
    b.desc.filter = reading([&] {
        FilterDesc f = read_rfilter(p);
        p.check_all_used();
        return f;
    });
}

void read_film(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    if (type != hdrfilm_plugin().type)
        xml.fail(n, fmt::format("unsupported film type '{}'; supported: hdrfilm (pathlab writes the formats -o names: .exr, .hdr, "
                                ".pfm, tone-mapped .png)", type));
    Properties p = xml.properties(n, hdrfilm_plugin());
    int full_width = 0, full_height = 0;
    reading([&] {
        full_width = p.get_int("width");
        full_height = p.get_int("height");
        if (full_width <= 0 || full_height <= 0 || full_width > 1 << 15 || full_height > 1 << 15)
            p.fail(fmt::format("film size must be between 1 and 32768, got {}x{}", full_width, full_height));
        const std::string format = p.get_string("file_format");
        static const std::map<std::string, std::string> kFormats = {{"openexr", "openexr"}, {"exr", "openexr"}, {"rgbe", "rgbe"},
                                                                    {"hdr", "rgbe"},         {"pfm", "pfm"}};
        if (!kFormats.count(format))
            p.fail("file_format", fmt::format("unsupported file_format '{}'; supported: openexr, rgbe, pfm (and -o any of .exr, .hdr, .pfm, .png)", format));
        b.desc.file_format = kFormats.at(format);
        const std::string pixels = p.get_string("pixel_format");
        if (pixels != "rgb" && pixels != "rgba")
            p.fail("pixel_format", fmt::format("unsupported pixel_format '{}'; supported: rgb, rgba (written as rgb)", pixels));
        if (pixels == "rgba") xml.note(n, "pixel_format rgba: pathlab writes RGB without an alpha channel");
        const std::string component = p.get_string("component_format");
        if (component != "float32" && component != "float16")
            p.fail("component_format", fmt::format("unsupported component_format '{}'; supported: float32, float16 (written as float32)", component));
        if (component == "float16") xml.note(n, "component_format float16: pathlab writes 32-bit floats");
        const int x0 = p.get_int("crop_offset_x"), y0 = p.get_int("crop_offset_y");
        const int w = p.has("crop_width") ? p.get_int("crop_width") : full_width - x0;
        const int h = p.has("crop_height") ? p.get_int("crop_height") : full_height - y0;
        if (x0 < 0 || y0 < 0 || w <= 0 || h <= 0 || x0 + w > full_width || y0 + h > full_height)
            p.fail(fmt::format("the crop window {}x{} at ({}, {}) does not fit in the {}x{} film", w, h, x0, y0, full_width, full_height));
        b.desc.width = w, b.desc.height = h;
        Camera& c = b.desc.camera;
        c.window_x0 = float(x0) / float(full_width), c.window_x1 = float(x0 + w) / float(full_width);
        c.window_y0 = float(y0) / float(full_height), c.window_y1 = float(y0 + h) / float(full_height);
        if (w == full_width) c.window_x0 = 0, c.window_x1 = 1;
        if (h == full_height) c.window_y0 = 0, c.window_y1 = 1;
        if (p.get_bool("sample_border"))
            xml.note(n, "sample_border: pathlab normalises a filtered border pixel by the filter's weight inside the image instead");
        p.get_bool("banner");
        p.get_bool("attach_log");
        p.check_all_used();
        return 0;
    });
    // A <film> without an <rfilter> has Mitsuba's default filter, a Gaussian of standard deviation
    // 0.5 pixels (mitsuba3 src/render/film.cpp; Mitsuba 0.6 alike), as its author saw the scene
    // rendered; a scene without a <film> renders on pathlab's own film (box).
    b.desc.filter = FilterDesc{"gaussian", 4 * 0.5, 0.5};
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        if (std::string(c.name()) != "rfilter") xml.fail(c, fmt::format("unsupported element <{}> in <film>; supported: <rfilter>", c.name()));
        read_rfilter(xml, c, b);
    }
}

void read_sampler(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    const PluginInfo* plugin = type == independent_plugin().type ? &independent_plugin() : nullptr;
    for (const PluginInfo& other : other_sampler_plugins())
        if (other.type == type) plugin = &other;
    if (!plugin)
        xml.fail(n, fmt::format("unsupported sampler type '{}'; supported: independent, stratified, multijitter, orthogonal, "
                                "ldsampler, halton, hammersley, sobol (the pattern is pathlab's --sampler)", type));
    if (plugin != &independent_plugin())
        xml.note(n, fmt::format("sampler '{}': its sample_count is used; the pattern is pathlab's (--sampler independent or sobol)", type));
    Properties p = xml.properties(n, *plugin);
    reading([&] {
        const int spp = p.get_int("sample_count");
        if (spp <= 0) p.fail(fmt::format("sample_count must be positive, got {}", spp));
        b.desc.spp = spp;
        for (const ParamInfo& q : plugin->params)
            if (q.name != "sample_count" && p.has(q.name)) {
                p.given(q.name);
                xml.note(n, fmt::format("sampler parameter '{}' is accepted and ignored (pathlab's --seed and --sampler decide)", q.name));
            }
        p.check_all_used();
        return 0;
    });
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "a <sampler> has no nested plugins");
}

// The field of view along the film's diagonal from focal_length ("50mm" or 50, the default when
// neither fov nor focal_length is given): the diagonal of a 35 mm film, 36 x 24 mm, whatever the
// film's own aspect (Mitsuba 3's parse_fov in src/render/sensor.cpp, as Mitsuba 0.6 did).
float diagonal_fov_of_focal_length(Properties& p) {
    std::string text = p.get_string("focal_length");
    if (text.size() > 2 && text.substr(text.size() - 2) == "mm") text.resize(text.size() - 2);
    const auto f = parse_float_text(text);
    if (!f || !(*f > 0)) p.fail("focal_length", fmt::format("focal_length must be a positive length like \"50mm\", got '{}'", p.get_string("focal_length")));
    return float(2 * std::atan(std::sqrt(36.0 * 36 + 24 * 24) / (2 * *f)) * 180 / 3.14159265358979323846);
}

}  // namespace

void use_default_sensor(SceneBuilder& b) {
    Properties camera(perspective_plugin(), {}), film(hdrfilm_plugin(), {});
    b.desc.camera = Camera::look_along({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, diagonal_fov_of_focal_length(camera), FovAxis::Diagonal);
    b.desc.width = film.get_int("width");
    b.desc.height = film.get_int("height");
}

void read_sensor(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    if (b.have_sensor) xml.fail(n, "a scene can have only one <sensor>");
    b.have_sensor = true;
    const std::string type = xml.attr(n, "type");
    const PluginInfo* plugin = type == "perspective" ? &perspective_plugin() : type == "thinlens" ? &thinlens_plugin()
                             : type == "orthographic" ? &orthographic_plugin() : nullptr;
    if (!plugin) xml.fail(n, fmt::format("unsupported sensor type '{}'; supported: perspective, thinlens, orthographic", type));
    Properties p = xml.properties(n, *plugin);
    pugi::xml_node found;
    for (pugi::xml_node c : n.children("transform"))
        if (std::string(c.attribute("name").value()) == "to_world" || std::string(c.attribute("name").value()) == "toWorld") found = c;
    const pugi::xml_node* block = found ? &found : nullptr;
    reading([&] {
        Camera c;
        if (type == "orthographic") {
            c = camera_from(xml, p.get_transform("to_world"), block, 45, FovAxis::X);
            c.kind = CameraKind::Orthographic;
            if (const auto t = p.get_transform("to_world")) {
                c.ortho_half_x = float(length(t->vector({1, 0, 0})));
                c.ortho_half_y = float(length(t->vector({0, 1, 0})));
            }
        } else {
            if (p.has("focal_length") && p.has("fov")) p.fail("focal_length", "give fov or focal_length, not both");
            const bool given_fov = p.has("fov");
            if (!given_fov && p.has("fov_axis")) {
                read_fov_axis(p);  // checked, then ignored as Mitsuba does
                xml.note(n, "fov_axis is ignored without fov: focal_length's field of view spans the film's diagonal");
            }
            const float fov = given_fov ? p.get_float("fov") : diagonal_fov_of_focal_length(p);
            if (!(fov > 0 && fov < 180)) p.fail(fmt::format("fov must be between 0 and 180 degrees, got {}", fov));
            const FovAxis axis = given_fov ? read_fov_axis(p) : FovAxis::Diagonal;
            c = camera_from(xml, p.get_transform("to_world"), block, fov, axis);
            c.principal_x = p.get_float("principal_point_offset_x");
            c.principal_y = p.get_float("principal_point_offset_y");
            if (!(std::abs(c.principal_x) <= 10 && std::abs(c.principal_y) <= 10))
                p.fail("the principal point's offset must be at most 10 film widths");
            if (type == "thinlens") {
                c.kind = CameraKind::ThinLens;
                if (!p.has("aperture_radius") || !p.has("focus_distance"))
                    p.fail("a thinlens sensor needs aperture_radius and focus_distance");
                c.aperture_radius = p.get_float("aperture_radius");
                c.focus_distance = p.get_float("focus_distance");
                if (!(c.aperture_radius >= 0)) p.fail("aperture_radius", "aperture_radius must not be negative");
                if (!(c.focus_distance > 0)) p.fail("focus_distance", "focus_distance must be positive");
            }
        }
        if (p.has("near_clip")) c.near_clip = p.get_float("near_clip");
        if (p.has("far_clip")) c.far_clip = p.get_float("far_clip");
        if (!(c.near_clip >= 0 && c.far_clip > c.near_clip)) p.fail("near_clip must be at least 0 and far_clip beyond it");
        if (p.get_float("shutter_open") != 0 || p.get_float("shutter_close") != 0)
            xml.note(n, "shutter_open/shutter_close: pathlab's scenes do not move, so the shutter changes nothing");
        // The film's window (read below) is kept.
        const Camera& old = b.desc.camera;
        c.window_x0 = old.window_x0, c.window_x1 = old.window_x1, c.window_y0 = old.window_y0, c.window_y1 = old.window_y1;
        b.desc.camera = c;
        p.check_all_used();
        return 0;
    });
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name();
        if (tag == "film") read_film(xml, c, b);
        else if (tag == "sampler") read_sampler(xml, c, b);
        else if (tag == "medium" || tag == "ref") {  // the medium the camera sits in
            if (b.desc.camera_medium >= 0) xml.fail(c, "a sensor can be in only one medium");
            if (tag == "ref") xml.check_attributes(c, {"id", "name"});
            b.desc.camera_medium = tag == "medium" ? read_medium(xml, c, b) : medium_reference(xml, c, b);
        } else xml.fail(c, fmt::format("unsupported element <{}> in <sensor>; supported: <film>, <sampler>, <medium>, <ref> (to a medium)", tag));
    }
}

}  // namespace pathlab
