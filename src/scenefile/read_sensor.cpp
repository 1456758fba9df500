// <sensor type="perspective"> with its nested <film type="hdrfilm"> and <sampler type="independent">,
// and the medium it sits in (a nested <medium>, or <ref name="medium" id="..."/>).
#include <fmt/format.h>

#include "render/film.hpp"
#include "samplers/sampler.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

FovAxis read_fov_axis(Properties& p) {
    static const std::map<std::string, FovAxis> kAxes = {
        {"x", FovAxis::X}, {"y", FovAxis::Y}, {"smaller", FovAxis::Smaller}, {"larger", FovAxis::Larger}, {"each", FovAxis::EachAxis}};
    const std::string a = p.get_string("fov_axis");
    const auto it = kAxes.find(a);
    if (it == kAxes.end())
        p.fail("fov_axis", fmt::format("unsupported fov_axis '{}'; supported: x, y, smaller, larger, each (pathlab: both axes "
                                       "span fov, as in the course)", a));
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

void read_film(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id"});
    const std::string type = xml.attr(n, "type");
    if (type != hdrfilm_plugin().type) xml.fail(n, fmt::format("unsupported film type '{}'; supported: hdrfilm", type));
    Properties p = xml.properties(n, hdrfilm_plugin());
    reading([&] {
        b.desc.width = p.get_int("width");
        b.desc.height = p.get_int("height");
        if (b.desc.width <= 0 || b.desc.height <= 0 || b.desc.width > 1 << 15 || b.desc.height > 1 << 15)
            p.fail(fmt::format("film size must be between 1 and 32768, got {}x{}", b.desc.width, b.desc.height));
        p.check_all_used();
        return 0;
    });
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "unsupported element in <film> (pathlab's film has no filter)");
}

void read_sampler(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id"});
    const std::string type = xml.attr(n, "type");
    if (type != independent_plugin().type)
        xml.fail(n, fmt::format("unsupported sampler type '{}'; supported: independent (choose pathlab's sampler with --sampler)", type));
    Properties p = xml.properties(n, independent_plugin());
    reading([&] {
        const int spp = p.get_int("sample_count");
        if (spp <= 0) p.fail(fmt::format("sample_count must be positive, got {}", spp));
        b.desc.spp = spp;
        p.check_all_used();
        return 0;
    });
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "a <sampler> has no nested plugins");
}

}  // namespace

void use_default_sensor(SceneBuilder& b) {
    Properties camera(perspective_plugin(), {}), film(hdrfilm_plugin(), {});
    b.desc.camera = Camera::look_along({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, camera.get_float("fov"), read_fov_axis(camera));
    b.desc.width = film.get_int("width");
    b.desc.height = film.get_int("height");
}

void read_sensor(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id"});
    if (b.have_sensor) xml.fail(n, "a scene can have only one <sensor>");
    b.have_sensor = true;
    const std::string type = xml.attr(n, "type");
    if (type != perspective_plugin().type) xml.fail(n, fmt::format("unsupported sensor type '{}'; supported: perspective", type));
    Properties p = xml.properties(n, perspective_plugin());
    const pugi::xml_node* block = nullptr;
    pugi::xml_node found;
    for (pugi::xml_node c : n.children("transform"))
        if (std::string(c.attribute("name").value()) == "to_world") found = c;
    if (found) block = &found;
    reading([&] {
        const float fov = p.get_float("fov");
        if (!(fov > 0 && fov < 180)) p.fail(fmt::format("fov must be between 0 and 180 degrees, got {}", fov));
        const FovAxis axis = read_fov_axis(p);
        b.desc.camera = camera_from(xml, p.get_transform("to_world"), block, fov, axis);
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
