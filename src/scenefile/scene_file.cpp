#include "scenefile/scene_file.hpp"

#include <pugixml.hpp>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "integrators/integrator.hpp"
#include "geometry/shape_meshes.hpp"

namespace pathlab {

SceneFileError::SceneFileError(std::string file_, int line_, int column_, const std::string& message_)
    : std::runtime_error(line_ > 0 ? fmt::format("{}:{}:{}: error: {}", file_, line_, column_, message_)
                                   : fmt::format("{}: error: {}", file_, message_)),
      file(std::move(file_)),
      line(line_),
      column(column_),
      message(message_) {}

namespace {

// Property element names (the value types of plugin parameters).
const std::set<std::string> kPropertyTags = {"float", "integer", "boolean", "string", "rgb",
                                             "spectrum", "point", "vector", "transform"};

// Refractive indices by name (a few of Mitsuba's, at 589 nm).
const char* const kBsdfTypes =
    "diffuse, phong, conductor, roughconductor, dielectric, roughdielectric, plastic, roughplastic, twosided";

const std::map<std::string, float> kNamedIors = {
    {"vacuum", 1.0f},       {"air", 1.000277f},    {"water", 1.3330f},   {"fused quartz", 1.458f},
    {"pyrex", 1.470f},      {"acrylic glass", 1.49f}, {"bk7", 1.5046f},  {"diamond", 2.419f},
    {"polypropylene", 1.49f},
};

class Loader {
public:
    Loader(const std::string& text, std::string file, std::string base_dir, const SceneDefines& defines, bool allow_files)
        : text_(text), file_(std::move(file)), base_dir_(std::move(base_dir)), defines_(defines), allow_files_(allow_files) {
        line_starts_.push_back(0);
        for (size_t i = 0; i < text_.size(); ++i)
            if (text_[i] == '\n') line_starts_.push_back(i + 1);
    }

    SceneDescription load() {
        pugi::xml_document doc;
        const pugi::xml_parse_result parsed = doc.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
        if (!parsed) fail_at(size_t(std::max<ptrdiff_t>(0, parsed.offset)), fmt::format("malformed XML: {}", parsed.description()));
        const pugi::xml_node scene = doc.document_element();
        if (std::string(scene.name()) != "scene") fail(scene, fmt::format("the root element must be <scene>, not <{}>", scene.name()));
        if (!scene.attribute("version")) fail(scene, "<scene> needs a version attribute, e.g. <scene version=\"3.0.0\">");
        check_attributes(scene, {"version"});

        desc_.name = std::filesystem::path(file_).stem().string();
        desc_.camera = Camera::look_along({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 39.3077f, FovAxis::X);  // Mitsuba's default sensor
        desc_.width = 768, desc_.height = 576;  // Mitsuba's default film
        for (pugi::xml_node n : scene.children()) {
            if (n.type() != pugi::node_element) continue;
            const std::string tag = n.name();
            if (tag == "default") read_default(n);
            else if (tag == "integrator") read_integrator(n);
            else if (tag == "sensor") read_sensor(n);
            else if (tag == "bsdf") read_named_bsdf(n);
            else if (tag == "shape") read_shape(n);
            else if (tag == "emitter") read_free_emitter(n);
            else fail(n, fmt::format("unsupported element <{}> in <scene>; supported: <default>, <integrator>, <sensor>, "
                                     "<bsdf>, <shape>, <emitter>", tag));
        }
        if (desc_.meshes.empty() && desc_.spheres.empty()) fail_file("the scene has no shapes");
        return std::move(desc_);
    }

private:
    // ---- errors ------------------------------------------------------------------------
    [[noreturn]] void fail_at(size_t offset, const std::string& message) const {
        const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
        const size_t line = size_t(it - line_starts_.begin());
        const size_t column = offset - line_starts_[line - 1] + 1;
        throw SceneFileError(file_, int(line), int(column), message);
    }
    // Errors point at the element's '<' (pugixml reports the offset of its name).
    [[noreturn]] void fail(const pugi::xml_node& n, const std::string& message) const {
        size_t offset = size_t(std::max<ptrdiff_t>(0, n.offset_debug()));
        if (n.type() == pugi::node_element && offset > 0 && offset <= text_.size() && text_[offset - 1] == '<') --offset;
        fail_at(offset, message);
    }
    [[noreturn]] void fail_file(const std::string& message) const { throw SceneFileError(file_, 0, 0, message); }

    void check_attributes(const pugi::xml_node& n, std::initializer_list<const char*> allowed) const {
        for (const pugi::xml_attribute a : n.attributes()) {
            if (std::find_if(allowed.begin(), allowed.end(), [&](const char* s) { return a.name() == std::string(s); }) ==
                allowed.end())
                fail(n, fmt::format("unexpected attribute '{}' on <{}>; allowed: {}", a.name(), n.name(),
                                    fmt::join(allowed, ", ")));
        }
    }

    // ---- attribute values with $name substitution ----------------------------------------
    std::string substitute(const pugi::xml_node& n, const std::string& value) const {
        std::string out;
        for (size_t i = 0; i < value.size();) {
            if (value[i] != '$') {
                out += value[i++];
                continue;
            }
            size_t j = i + 1;
            while (j < value.size() && (std::isalnum(static_cast<unsigned char>(value[j])) || value[j] == '_')) ++j;
            const std::string name = value.substr(i + 1, j - i - 1);
            if (name.empty()) fail(n, fmt::format("'$' must be followed by a parameter name in \"{}\"", value));
            const auto it = defines_.find(name);
            if (it == defines_.end())
                fail(n, fmt::format("undefined parameter ${} (define it with <default name=\"{}\" value=\"...\"/> or -D {}=...)",
                                    name, name, name));
            out += it->second;
            i = j;
        }
        return out;
    }
    std::string attr(const pugi::xml_node& n, const char* name) const {
        const pugi::xml_attribute a = n.attribute(name);
        if (!a) fail(n, fmt::format("<{}> needs a '{}' attribute", n.name(), name));
        return substitute(n, a.value());
    }
    std::optional<std::string> optional_attr(const pugi::xml_node& n, const char* name) const {
        const pugi::xml_attribute a = n.attribute(name);
        if (!a) return std::nullopt;
        return substitute(n, a.value());
    }

    // ---- number parsing ------------------------------------------------------------------
    double parse_number(const pugi::xml_node& n, const std::string& s) const {
        const char* b = s.data();
        const char* e = b + s.size();
        while (b < e && std::isspace(static_cast<unsigned char>(*b))) ++b;
        while (e > b && std::isspace(static_cast<unsigned char>(e[-1]))) --e;
        double v = 0;
        if (b < e && *b == '+') ++b;
        const auto [ptr, ec] = std::from_chars(b, e, v);
        if (b == e || ec != std::errc() || ptr != e || !std::isfinite(v))
            fail(n, fmt::format("'{}' is not a finite number", s));
        return v;
    }
    // A float parsed directly as float (so "0.5388500" gives the same float a C++ literal does).
    float parse_float(const pugi::xml_node& n, const std::string& s) const {
        const char* b = s.data();
        const char* e = b + s.size();
        while (b < e && std::isspace(static_cast<unsigned char>(*b))) ++b;
        while (e > b && std::isspace(static_cast<unsigned char>(e[-1]))) --e;
        if (b < e && *b == '+') ++b;
        float v = 0;
        const auto [ptr, ec] = std::from_chars(b, e, v);
        if (b == e || ec != std::errc() || ptr != e || !std::isfinite(v))
            fail(n, fmt::format("'{}' is not a finite number", s));
        return v;
    }
    std::vector<float> parse_floats(const pugi::xml_node& n, const std::string& s) const {
        std::vector<float> out;
        std::string item;
        for (size_t i = 0; i <= s.size(); ++i) {
            if (i == s.size() || s[i] == ',' || std::isspace(static_cast<unsigned char>(s[i]))) {
                if (!item.empty()) out.push_back(parse_float(n, item));
                item.clear();
            } else {
                item += s[i];
            }
        }
        return out;
    }
    Vec3f parse_vec3(const pugi::xml_node& n, const std::string& s, bool allow_scalar) const {
        const std::vector<float> v = parse_floats(n, s);
        if (v.size() == 3) return {v[0], v[1], v[2]};
        if (allow_scalar && v.size() == 1) return Vec3f(v[0]);
        fail(n, fmt::format("expected {}3 numbers, got \"{}\"", allow_scalar ? "1 or " : "", s));
    }
    // <point name x y z/> or value="x, y, z".
    Vec3f xyz(const pugi::xml_node& n) const {
        if (n.attribute("value")) return parse_vec3(n, attr(n, "value"), false);
        return {parse_float(n, attr(n, "x")), parse_float(n, attr(n, "y")), parse_float(n, attr(n, "z"))};
    }

    // ---- plugin properties -----------------------------------------------------------------
    struct Property {
        pugi::xml_node node;
        std::string tag;
        bool used = false;
    };
    class Properties {
    public:
        Properties(const Loader& l, const pugi::xml_node& plugin) : l_(l), plugin_(plugin) {
            for (pugi::xml_node c : plugin.children()) {
                if (c.type() != pugi::node_element || !kPropertyTags.count(c.name())) continue;
                const std::string name = l.attr(c, "name");
                if (props_.count(name)) l.fail(c, fmt::format("parameter '{}' is given twice", name));
                props_[name] = Property{c, c.name(), false};
            }
        }
        bool has(const std::string& name) const { return props_.count(name) > 0; }
        const pugi::xml_node& node(const std::string& name) const { return props_.at(name).node; }
        const pugi::xml_node* find(const std::string& name, std::initializer_list<const char*> tags) {
            const auto it = props_.find(name);
            if (it == props_.end()) return nullptr;
            Property& p = it->second;
            if (std::find_if(tags.begin(), tags.end(), [&](const char* t) { return p.tag == t; }) == tags.end())
                l_.fail(p.node, fmt::format("parameter '{}' must be given as <{}>, not <{}>", name, fmt::join(tags, "> or <"), p.tag));
            p.used = true;
            return &p.node;
        }
        float get_float(const std::string& name, float fallback) {
            const pugi::xml_node* n = find(name, {"float", "integer"});
            return n ? l_.parse_float(*n, l_.attr(*n, "value")) : fallback;
        }
        int get_int(const std::string& name, int fallback) {
            const pugi::xml_node* n = find(name, {"integer"});
            if (!n) return fallback;
            const double v = l_.parse_number(*n, l_.attr(*n, "value"));
            if (v != std::floor(v) || std::abs(v) > 1e9)
                l_.fail(*n, fmt::format("parameter '{}' must be an integer of at most 1e9 in magnitude, got {}", name, l_.attr(*n, "value")));
            return int(v);
        }
        bool get_bool(const std::string& name, bool fallback) {
            const pugi::xml_node* n = find(name, {"boolean"});
            if (!n) return fallback;
            const std::string v = l_.attr(*n, "value");
            if (v == "true") return true;
            if (v == "false") return false;
            l_.fail(*n, fmt::format("parameter '{}' must be true or false, not '{}'", name, v));
        }
        std::optional<std::string> get_string(const std::string& name) {
            const pugi::xml_node* n = find(name, {"string"});
            return n ? std::optional<std::string>(l_.attr(*n, "value")) : std::nullopt;
        }
        // A colour: <rgb value="r g b"> or a single value, <spectrum value="v">, or <float>.
        Rgb get_rgb(const std::string& name, const Rgb& fallback) {
            const pugi::xml_node* n = find(name, {"rgb", "spectrum", "float"});
            if (!n) return fallback;
            const Rgb c = l_.parse_vec3(*n, l_.attr(*n, "value"), true);
            if (min_component(c) < 0) l_.fail(*n, fmt::format("parameter '{}' must not be negative", name));
            return c;
        }
        std::optional<Vec3f> get_point(const std::string& name) {
            const pugi::xml_node* n = find(name, {"point", "vector"});
            return n ? std::optional<Vec3f>(l_.xyz(*n)) : std::nullopt;
        }
        // The <transform name=...> block, if any, and whether it is a single <lookat>.
        std::optional<Transform> get_transform(const std::string& name, const pugi::xml_node** block = nullptr) {
            const pugi::xml_node* n = find(name, {"transform"});
            if (!n) return std::nullopt;
            if (block) *block = n;
            return l_.read_transform(*n);
        }
        // Every parameter must have been used: the rest are named in an error.
        void check_all_used(std::initializer_list<const char*> supported) const {
            for (const auto& [name, p] : props_)
                if (!p.used)
                    l_.fail(p.node, fmt::format("unsupported parameter '{}' for <{} type=\"{}\">; supported: {}", name,
                                                plugin_.name(), plugin_.attribute("type").value(),
                                                supported.size() ? fmt::format("{}", fmt::join(supported, ", ")) : "none"));
        }

    private:
        const Loader& l_;
        pugi::xml_node plugin_;
        std::map<std::string, Property> props_;
    };

    // Child plugin elements of a plugin (everything that is not a property).
    std::vector<pugi::xml_node> plugin_children(const pugi::xml_node& n) const {
        std::vector<pugi::xml_node> out;
        for (pugi::xml_node c : n.children()) {
            if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata) {
                const std::string t = c.value();
                if (t.find_first_not_of(" \t\r\n") != std::string::npos) fail(c, "unexpected text");
                continue;
            }
            if (c.type() == pugi::node_element && !kPropertyTags.count(c.name())) out.push_back(c);
        }
        return out;
    }

    // ---- transforms ------------------------------------------------------------------------
    Transform read_transform(const pugi::xml_node& block) const {
        Transform t;
        for (pugi::xml_node op : block.children()) {
            if (op.type() != pugi::node_element) continue;
            const std::string tag = op.name();
            Transform step;
            if (tag == "translate") {
                check_attributes(op, {"x", "y", "z", "value"});
                step = Transform::translate(Vec3d(op.attribute("value") ? parse_vec3(op, attr(op, "value"), false) : xyz_default(op, 0)));
            } else if (tag == "scale") {
                check_attributes(op, {"x", "y", "z", "value"});
                step = Transform::scale(Vec3d(op.attribute("value") ? parse_vec3(op, attr(op, "value"), true) : xyz_default(op, 1)));
            } else if (tag == "rotate") {
                check_attributes(op, {"x", "y", "z", "value", "angle"});
                const Vec3f axis = op.attribute("value") ? parse_vec3(op, attr(op, "value"), false) : xyz_default(op, 0);
                if (!(length(axis) > 0)) fail(op, "<rotate> needs a non-zero axis (x, y, z or value)");
                step = Transform::rotate(Vec3d(axis), parse_number(op, attr(op, "angle")));
            } else if (tag == "matrix") {
                check_attributes(op, {"value"});
                const std::vector<float> v = parse_floats(op, attr(op, "value"));
                if (v.size() != 16 && v.size() != 9) fail(op, fmt::format("<matrix> needs 16 (or 9) numbers, got {}", v.size()));
                const int k = v.size() == 16 ? 4 : 3;
                for (int i = 0; i < k; ++i)
                    for (int j = 0; j < k; ++j) step.m[size_t(i)][size_t(j)] = v[size_t(i * k + j)];
                if (!step.is_affine_invertible()) fail(op, "<matrix> must be affine (last row 0 0 0 1) and invertible");
            } else if (tag == "lookat") {
                check_attributes(op, {"origin", "target", "up"});
                const Vec3f up = op.attribute("up") ? parse_vec3(op, attr(op, "up"), false) : Vec3f(0, 1, 0);
                const auto la = Transform::look_at(Vec3d(parse_vec3(op, attr(op, "origin"), false)),
                                                   Vec3d(parse_vec3(op, attr(op, "target"), false)), Vec3d(up));
                if (!la) fail(op, "<lookat> needs distinct origin and target and an up vector not parallel to the view");
                step = *la;
            } else {
                fail(op, fmt::format("unsupported transform <{}>; supported: <translate>, <rotate>, <scale>, <matrix>, <lookat>", tag));
            }
            t = step * t;  // later elements apply after earlier ones
        }
        if (!t.is_finite() || !t.is_affine_invertible()) fail(block, "the transform is not invertible");
        return t;
    }
    Vec3f xyz_default(const pugi::xml_node& n, float fallback) const {
        const auto get = [&](const char* k) { return n.attribute(k) ? parse_float(n, attr(n, k)) : fallback; };
        return {get("x"), get("y"), get("z")};
    }

    // ---- top-level elements -----------------------------------------------------------------
    void read_default(const pugi::xml_node& n) {
        check_attributes(n, {"name", "value"});
        const std::string name = attr(n, "name");
        if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
            fail(n, fmt::format("invalid parameter name '{}'", name));
        defines_.emplace(name, attr(n, "value"));  // -D values (already present) win
    }

    void read_integrator(const pugi::xml_node& n) {
        check_attributes(n, {"type"});
        if (have_integrator_) fail(n, "a scene can have only one <integrator>");
        have_integrator_ = true;
        const std::string type = attr(n, "type");
        std::string algorithm;
        if (type == "path") algorithm = "pt-mis";
        else if (type == "direct") algorithm = "direct-mis";
        else if (const IntegratorInfo* e = find_integrator(type)) algorithm = e->name;
        else
            fail(n, fmt::format("unsupported integrator type '{}'; supported: path (pt-mis), direct (direct-mis), or a "
                                "pathlab algorithm: {}", type, integrator_names()));
        desc_.algorithm = algorithm;
        if (!plugin_children(n).empty()) fail(plugin_children(n).front(), "an <integrator> has no nested plugins");
        Properties p(*this, n);
        if (const pugi::xml_node* d = p.find("max_depth", {"integer"})) {
            // Mitsuba counts path vertices after the camera (1: emitters only, 2: direct light);
            // pathlab counts bounces.
            const int depth = p.get_int("max_depth", -1);
            if (depth == -1) desc_.max_depth = -1;
            else if (depth >= 2) desc_.max_depth = depth - 1;
            else fail(*d, fmt::format("max_depth must be -1 (unlimited) or at least 2 (pathlab needs one bounce), got {}", depth));
        }
        p.check_all_used({"max_depth"});
    }

    void read_sensor(const pugi::xml_node& n) {
        check_attributes(n, {"type", "id"});
        if (have_sensor_) fail(n, "a scene can have only one <sensor>");
        have_sensor_ = true;
        const std::string type = attr(n, "type");
        if (type != "perspective") fail(n, fmt::format("unsupported sensor type '{}'; supported: perspective", type));
        Properties p(*this, n);
        const float fov = p.get_float("fov", 39.3077f);
        if (!(fov > 0 && fov < 180)) fail(n, fmt::format("fov must be between 0 and 180 degrees, got {}", fov));
        FovAxis axis = FovAxis::X;
        if (const auto a = p.get_string("fov_axis")) {
            static const std::map<std::string, FovAxis> kAxes = {{"x", FovAxis::X},           {"y", FovAxis::Y},
                                                                 {"smaller", FovAxis::Smaller}, {"larger", FovAxis::Larger},
                                                                 {"each", FovAxis::EachAxis}};
            const auto it = kAxes.find(*a);
            if (it == kAxes.end())
                fail(*p.find("fov_axis", {"string"}), fmt::format("unsupported fov_axis '{}'; supported: x, y, smaller, larger, "
                                                                  "each (pathlab: both axes span fov, as in the course)", *a));
            axis = it->second;
        }
        const pugi::xml_node* block = nullptr;
        const std::optional<Transform> to_world = p.get_transform("to_world", &block);
        desc_.camera = camera_from(to_world, block, fov, axis);
        p.check_all_used({"fov", "fov_axis", "to_world"});
        for (const pugi::xml_node& c : plugin_children(n)) {
            const std::string tag = c.name();
            if (tag == "film") read_film(c);
            else if (tag == "sampler") read_sampler(c);
            else fail(c, fmt::format("unsupported element <{}> in <sensor>; supported: <film>, <sampler>", tag));
        }
    }

    // A single <lookat> is evaluated in float exactly as the built-in scenes are (so a scene
    // file can reproduce them bit for bit); any other transform goes through the matrix.
    Camera camera_from(const std::optional<Transform>& to_world, const pugi::xml_node* block, float fov, FovAxis axis) const {
        if (!to_world) return Camera::look_along({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, fov, axis);
        std::vector<pugi::xml_node> ops;
        for (pugi::xml_node c : block->children())
            if (c.type() == pugi::node_element) ops.push_back(c);
        if (ops.size() == 1 && std::string(ops[0].name()) == "lookat") {
            const pugi::xml_node& op = ops[0];
            const Vec3f up = op.attribute("up") ? parse_vec3(op, attr(op, "up"), false) : Vec3f(0, 1, 0);
            return Camera::look_at(parse_vec3(op, attr(op, "origin"), false), parse_vec3(op, attr(op, "target"), false), up,
                                   fov, axis);
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

    void read_film(const pugi::xml_node& n) {
        check_attributes(n, {"type", "id"});
        const std::string type = attr(n, "type");
        if (type != "hdrfilm") fail(n, fmt::format("unsupported film type '{}'; supported: hdrfilm", type));
        Properties p(*this, n);
        desc_.width = p.get_int("width", 768);
        desc_.height = p.get_int("height", 576);
        if (desc_.width <= 0 || desc_.height <= 0 || desc_.width > 1 << 15 || desc_.height > 1 << 15)
            fail(n, fmt::format("film size must be between 1 and 32768, got {}x{}", desc_.width, desc_.height));
        p.check_all_used({"width", "height"});
        if (!plugin_children(n).empty()) fail(plugin_children(n).front(), "unsupported element in <film> (pathlab's film has no filter)");
    }

    void read_sampler(const pugi::xml_node& n) {
        check_attributes(n, {"type", "id"});
        const std::string type = attr(n, "type");
        if (type != "independent")
            fail(n, fmt::format("unsupported sampler type '{}'; supported: independent (choose pathlab's sampler with --sampler)", type));
        Properties p(*this, n);
        const int spp = p.get_int("sample_count", 4);
        if (spp <= 0) fail(n, fmt::format("sample_count must be positive, got {}", spp));
        desc_.spp = spp;
        p.check_all_used({"sample_count"});
        if (!plugin_children(n).empty()) fail(plugin_children(n).front(), "a <sampler> has no nested plugins");
    }

    // ---- BSDFs ----------------------------------------------------------------------------
    uint32_t add_material(const Material& m) {
        desc_.materials.push_back(m);
        return uint32_t(desc_.materials.size() - 1);
    }

    Material read_bsdf(const pugi::xml_node& n) {
        check_attributes(n, {"type", "id", "name"});
        const std::string type = attr(n, "type");
        if (type == "twosided") {
            std::vector<pugi::xml_node> inner = plugin_children(n);
            if (inner.size() != 1 || std::string(inner[0].name()) != "bsdf")
                fail(n, "<bsdf type=\"twosided\"> wraps exactly one nested <bsdf>");
            if (std::string(inner[0].attribute("type").value()) == "twosided")  // also bounds the recursion
                fail(inner[0], "a twosided BSDF cannot wrap another twosided BSDF");
            Properties(*this, n).check_all_used({});
            Material m = read_bsdf(inner[0]);
            if (m.is_dielectric())
                fail(inner[0], fmt::format("a {} cannot be wrapped in twosided (both of its sides already matter)", attr(inner[0], "type")));
            m.two_sided = true;
            return m;
        }
        if (!plugin_children(n).empty()) fail(plugin_children(n).front(), fmt::format("<bsdf type=\"{}\"> has no nested plugins", type));
        Properties p(*this, n);
        Material m;
        if (type == "diffuse") {
            m = make_phong(p.get_rgb("reflectance", Rgb(0.5f)));
            p.check_all_used({"reflectance"});
        } else if (type == "phong") {
            const Rgb kd = p.get_rgb(alias(p, "diffuse_reflectance", "diffuseReflectance"), Rgb(0.5f));
            const Rgb ks = p.get_rgb(alias(p, "specular_reflectance", "specularReflectance"), Rgb(0.2f));
            const float exponent = p.get_float("exponent", 30.0f);
            if (!(exponent >= 0)) fail(n, "the Phong exponent must not be negative");
            m = make_phong(kd, ks, exponent);
            p.check_all_used({"diffuse_reflectance", "specular_reflectance", "exponent"});
        } else if (type == "conductor") {
            m = make_conductor(conductor_ior(p, n), p.get_rgb(alias(p, "specular_reflectance", "specularReflectance"), Rgb(1.0f)));
            p.check_all_used({"material", "eta", "k", "specular_reflectance"});
        } else if (type == "roughconductor") {
            const MicrofacetDistribution d = microfacet(p, n);
            m = make_rough_conductor(d, conductor_ior(p, n),
                                     p.get_rgb(alias(p, "specular_reflectance", "specularReflectance"), Rgb(1.0f)));
            p.check_all_used({"distribution", "alpha", "alpha_u", "alpha_v", "material", "eta", "k", "specular_reflectance",
                              "sample_visible"});
        } else if (type == "dielectric") {
            const float int_ior = ior(p, alias(p, "int_ior", "intIOR"), 1.5046f);
            const float ext_ior = ior(p, alias(p, "ext_ior", "extIOR"), 1.000277f);
            m = make_dielectric(int_ior, ext_ior);
            p.check_all_used({"int_ior", "ext_ior"});
        } else if (type == "roughdielectric") {
            const MicrofacetDistribution d = microfacet(p, n);
            const float int_ior = ior(p, alias(p, "int_ior", "intIOR"), 1.5046f);
            const float ext_ior = ior(p, alias(p, "ext_ior", "extIOR"), 1.000277f);
            if (int_ior == ext_ior) fail(n, "int_ior and ext_ior are equal: the interface would be invisible");
            m = make_rough_dielectric(d, int_ior, ext_ior);
            p.check_all_used({"distribution", "alpha", "alpha_u", "alpha_v", "int_ior", "ext_ior", "sample_visible"});
        } else if (type == "plastic" || type == "roughplastic") {
            const bool rough = type == "roughplastic";
            const MicrofacetDistribution d = rough ? microfacet(p, n, /*anisotropic=*/false) : MicrofacetDistribution();
            const Rgb kd = p.get_rgb(alias(p, "diffuse_reflectance", "diffuseReflectance"), Rgb(0.5f));
            const Rgb ks = p.get_rgb(alias(p, "specular_reflectance", "specularReflectance"), Rgb(1.0f));
            const float int_ior = ior(p, alias(p, "int_ior", "intIOR"), 1.49f);
            const float ext_ior = ior(p, alias(p, "ext_ior", "extIOR"), 1.000277f);
            if (int_ior == ext_ior) fail(n, "int_ior and ext_ior are equal: the coating would be invisible");
            const bool nonlinear = p.get_bool("nonlinear", false);
            m = rough ? make_rough_plastic(d, kd, ks, int_ior, ext_ior, nonlinear) : make_plastic(kd, ks, int_ior, ext_ior, nonlinear);
            if (rough)
                p.check_all_used({"distribution", "alpha", "diffuse_reflectance", "specular_reflectance", "int_ior", "ext_ior",
                                  "nonlinear", "sample_visible"});
            else
                p.check_all_used({"diffuse_reflectance", "specular_reflectance", "int_ior", "ext_ior", "nonlinear"});
        } else {
            fail(n, fmt::format("unsupported bsdf type '{}'; supported: {}", type, kBsdfTypes));
        }
        m.two_sided = false;  // as in Mitsuba: black from behind unless wrapped in twosided
        return m;
    }
    // Mitsuba 0.6 spelled some parameters in camelCase (specularReflectance, alphaU, intIOR):
    // either spelling is accepted, not both.
    std::string alias(const Properties& p, const char* name, const char* old_name) const {
        if (!p.has(old_name)) return name;
        if (p.has(name)) fail(p.node(old_name), fmt::format("'{}' and '{}' are the same parameter; give one", name, old_name));
        return old_name;
    }

    // The microfacet distribution of a rough BSDF: distribution, alpha or alpha_u + alpha_v.
    MicrofacetDistribution microfacet(Properties& p, const pugi::xml_node& n, bool anisotropic = true) {
        MicrofacetType type = MicrofacetType::Beckmann;  // Mitsuba's default
        if (const auto d = p.get_string("distribution")) {
            if (*d == "ggx") type = MicrofacetType::GGX;
            else if (*d != "beckmann")
                fail(p.node("distribution"), fmt::format("unsupported distribution '{}'; supported: beckmann, ggx", *d));
        }
        const std::string au_name = alias(p, "alpha_u", "alphaU"), av_name = alias(p, "alpha_v", "alphaV");
        const bool uv = p.has(au_name) || p.has(av_name);
        if (uv && !anisotropic)
            fail(p.node(p.has(au_name) ? au_name : av_name), fmt::format("<bsdf type=\"{}\"> is isotropic: give alpha", attr(n, "type")));
        if (uv && p.has("alpha")) fail(p.node("alpha"), "give either alpha or alpha_u and alpha_v, not both");
        if (uv && !(p.has(au_name) && p.has(av_name))) fail(n, "anisotropic roughness needs both alpha_u and alpha_v");
        const auto roughness = [&](const std::string& name) {
            const float a = p.get_float(name, 0.1f);
            if (p.has(name) && !(a >= 0 && a <= 10)) fail(p.node(name), fmt::format("{} must be between 0 and 10, got {}", name, a));
            return a;
        };
        p.get_bool(alias(p, "sample_visible", "sampleVisible"), true);  // visible normals are always sampled
        if (uv) return MicrofacetDistribution(type, roughness(au_name), roughness(av_name));
        const float a = roughness("alpha");
        return MicrofacetDistribution(type, a, a);
    }

    // A conductor's complex index: material="name", or eta and k (Mitsuba's default: none).
    ComplexIor conductor_ior(Properties& p, const pugi::xml_node&) {
        const auto name = p.get_string("material");
        const bool explicit_ior = p.has("eta") || p.has("k");
        if (name && explicit_ior) fail(p.node("material"), "give either material or eta and k, not both");
        if (name) {
            const auto ior = named_conductor(*name);
            if (!ior) fail(p.node("material"), fmt::format("unknown conductor material '{}'; known: {}", *name, kNamedConductors));
            return *ior;
        }
        return ComplexIor{p.get_rgb("eta", Rgb(0.0f)), p.get_rgb("k", Rgb(1.0f))};
    }

    float ior(Properties& p, const std::string& name, float fallback) const {
        const pugi::xml_node* n = p.find(name, {"float", "string"});
        if (!n) return fallback;
        const std::string v = attr(*n, "value");
        if (std::string(n->name()) == "string") {
            const auto it = kNamedIors.find(v);
            if (it == kNamedIors.end()) {
                std::vector<std::string> names;
                for (const auto& [k, x] : kNamedIors) names.push_back(k);
                fail(*n, fmt::format("unknown material '{}' for {}; known: {}", v, name, fmt::join(names, ", ")));
            }
            return it->second;
        }
        const float x = parse_float(*n, v);
        if (!(x >= 1.0f && x < 10.0f)) fail(*n, fmt::format("{} must be between 1 and 10, got {}", name, x));
        return x;
    }

    void read_named_bsdf(const pugi::xml_node& n) {
        const auto id = optional_attr(n, "id");
        const uint32_t index = add_material(read_bsdf(n));
        if (id) {
            if (named_bsdfs_.count(*id)) fail(n, fmt::format("the id '{}' is already used", *id));
            named_bsdfs_[*id] = index;
        }
    }

    // ---- shapes -----------------------------------------------------------------------------
    void read_shape(const pugi::xml_node& n) {
        check_attributes(n, {"type", "id"});
        const std::string type = attr(n, "type");
        static const char* kShapes = "obj, rectangle, cube, disk, sphere";
        if (type != "obj" && type != "rectangle" && type != "cube" && type != "disk" && type != "sphere")
            fail(n, fmt::format("unsupported shape type '{}'; supported: {}", type, kShapes));

        std::optional<uint32_t> material;
        Rgb emission(0.0f);
        bool emitter = false;
        for (const pugi::xml_node& c : plugin_children(n)) {
            const std::string tag = c.name();
            if (tag == "bsdf" || tag == "ref") {
                if (material) fail(c, "a shape can have only one BSDF");
                if (tag == "bsdf") {
                    if (c.attribute("id")) fail(c, "a nested <bsdf> cannot have an id; declare it at the top level and use <ref>");
                    material = add_material(read_bsdf(c));
                } else {
                    check_attributes(c, {"id", "name"});
                    const std::string id = attr(c, "id");
                    const auto it = named_bsdfs_.find(id);
                    if (it == named_bsdfs_.end()) fail(c, fmt::format("no <bsdf> with id '{}' is declared before this reference", id));
                    material = it->second;
                }
            } else if (tag == "emitter") {
                check_attributes(c, {"type", "id", "name"});
                const std::string etype = attr(c, "type");
                if (etype != "area") fail(c, fmt::format("a shape's emitter must be of type 'area', not '{}'", etype));
                if (emitter) fail(c, "a shape can have only one emitter");
                if (!plugin_children(c).empty()) fail(plugin_children(c).front(), "an <emitter> has no nested plugins");
                Properties ep(*this, c);
                emission = ep.get_rgb("radiance", Rgb(1.0f));
                ep.check_all_used({"radiance"});
                emitter = true;
            } else {
                fail(c, fmt::format("unsupported element <{}> in <shape>; supported: <bsdf>, <ref>, <emitter>", tag));
            }
        }
        if (!material) {
            if (!default_material_) default_material_ = add_material([] { Material m = make_phong(Rgb(0.5f)); m.two_sided = false; return m; }());
            material = *default_material_;
        }

        Properties p(*this, n);
        const std::optional<Transform> to_world = p.get_transform("to_world");
        const bool flip = p.get_bool("flip_normals", false);
        if (type == "sphere") {
            SphereDesc s;
            Vec3d center(p.get_point("center").value_or(Vec3f(0.0f)));
            double radius = p.get_float("radius", 1.0f);
            if (!(radius > 0)) fail(n, "a sphere's radius must be positive");
            if (to_world) {
                const Transform& t = *to_world;
                const Vec3d a = t.vector({1, 0, 0}), b = t.vector({0, 1, 0}), c = t.vector({0, 0, 1});
                const double la = length(a), lb = length(b), lc = length(c);
                const double tol = 1e-5 * std::max({la, lb, lc});
                if (std::abs(la - lb) > tol || std::abs(la - lc) > tol || std::abs(dot(a, b)) > tol * la ||
                    std::abs(dot(a, c)) > tol * la || std::abs(dot(b, c)) > tol * lb)
                    fail(n, "a sphere's to_world may only translate, rotate and scale uniformly (spheres are exact, not meshes)");
                center = t.point(center);
                radius *= la;
            }
            s.center = Vec3f(center);
            s.radius = float(radius);
            s.material = *material;
            s.flip_normals = flip;
            s.emission = emission;
            p.check_all_used({"center", "radius", "to_world", "flip_normals"});
            desc_.spheres.push_back(s);
            return;
        }

        MeshDesc m;
        if (type == "obj") {
            const auto filename = p.get_string("filename");
            if (!filename) fail(n, "<shape type=\"obj\"> needs <string name=\"filename\" value=\"...\"/>");
            if (!allow_files_) fail(n, "this loader does not read files (obj shapes are disabled)");
            std::filesystem::path path(*filename);
            if (path.is_relative()) path = std::filesystem::path(base_dir_) / path;
            try {
                m = load_obj_mesh(path.string());
            } catch (const MeshLoadError& e) {
                fail(*p.find("filename", {"string"}), e.what());
            }
            m.name = *filename;
        } else if (type == "rectangle") {
            m = rectangle_mesh();
        } else if (type == "cube") {
            m = cube_mesh();
        } else {
            m = disk_mesh();
        }
        if (m.name.empty()) m.name = type;
        if (const auto id = optional_attr(n, "id")) m.name = *id;
        if (p.get_bool("face_normals", false)) use_face_normals(m);
        if (to_world) transform_mesh(m, *to_world);
        if (flip) flip_mesh_normals(m);
        for (const Vec3f& v : m.positions)
            if (!is_finite(v)) fail(n, "the shape has a non-finite vertex after its transform");
        m.material = *material;
        m.emission = emission;
        p.check_all_used({"filename", "to_world", "flip_normals", "face_normals"});
        desc_.meshes.push_back(std::move(m));
    }

    // ---- lights not attached to shapes ----------------------------------------------------------
    void read_free_emitter(const pugi::xml_node& n) {
        check_attributes(n, {"type", "id"});
        const std::string type = attr(n, "type");
        if (!plugin_children(n).empty()) fail(plugin_children(n).front(), "an <emitter> has no nested plugins");
        Properties p(*this, n);
        if (type == "point") {
            Vec3f position = p.get_point("position").value_or(Vec3f(0.0f));
            if (const auto t = p.get_transform("to_world")) position = Vec3f(t->point(Vec3d(position)));
            desc_.lights.emplace_back(PointLight{position, p.get_rgb("intensity", Rgb(1.0f))});
            p.check_all_used({"position", "intensity", "to_world"});
        } else if (type == "constant") {
            for (const FreeLight& l : desc_.lights)
                if (std::holds_alternative<EnvironmentLight>(l)) fail(n, "a scene can have only one constant emitter");
            desc_.lights.emplace_back(EnvironmentLight{p.get_rgb("radiance", Rgb(1.0f))});
            p.check_all_used({"radiance"});
        } else if (type == "directional") {
            Vec3d dir(p.get_point("direction").value_or(Vec3f(0, 0, 1)));
            if (const auto t = p.get_transform("to_world")) dir = t->vector(dir);
            if (!(length(dir) > 0)) fail(n, "a directional emitter needs a non-zero direction");
            desc_.lights.emplace_back(DirectionalLight{Vec3f(normalize(dir)), p.get_rgb("irradiance", Rgb(1.0f))});
            p.check_all_used({"direction", "irradiance", "to_world"});
        } else if (type == "area") {
            fail(n, "an area emitter belongs inside a <shape>");
        } else {
            fail(n, fmt::format("unsupported emitter type '{}'; supported: point, constant, directional (and area inside a "
                                "shape)", type));
        }
    }

    const std::string& text_;
    std::string file_, base_dir_;
    SceneDefines defines_;
    bool allow_files_;
    std::vector<size_t> line_starts_;
    SceneDescription desc_;
    std::map<std::string, uint32_t> named_bsdfs_;
    std::optional<uint32_t> default_material_;
    bool have_sensor_ = false, have_integrator_ = false;
};

}  // namespace

SceneDescription load_scene_text(const std::string& text, const std::string& file_name, const std::string& base_dir,
                                 const SceneDefines& defines, bool allow_files) {
    return Loader(text, file_name, base_dir, defines, allow_files).load();
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
