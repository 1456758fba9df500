#include "scenefile/xml_source.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <fmt/format.h>

#include "core/input_file.hpp"
#include "core/spectrum.hpp"

namespace pathlab {
namespace {

// Property element names (the value types of plugin parameters).
const std::set<std::string> kPropertyTags = {"float", "integer", "boolean", "string", "rgb",    "spectrum",
                                             "point", "vector",  "transform", "srgb",   "blackbody"};

std::string rgb_text(const Vec3d& c) { return fmt::format("{}, {}, {}", float(c.x), float(c.y), float(c.z)); }

// sRGB's transfer function, decoded (Mitsuba 0.6's <srgb>).
double srgb_to_linear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

std::shared_ptr<LoadContext> make_context(SceneDefines defines) {
    auto context = std::make_shared<LoadContext>();
    context->defines = std::move(defines);
    return context;
}

}  // namespace

XmlSource::XmlSource(const std::string& text, std::string file, SceneDefines defines)
    : XmlSource(text, std::move(file), make_context(std::move(defines))) {}

XmlSource::XmlSource(const std::string& text, std::string file, std::shared_ptr<LoadContext> context)
    : text_(text), file_(std::move(file)), context_(std::move(context)) {
    line_starts_.push_back(0);
    for (size_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') line_starts_.push_back(i + 1);
}

pugi::xml_node XmlSource::root() {
    const pugi::xml_parse_result parsed = doc_.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed) fail_at(size_t(std::max<ptrdiff_t>(0, parsed.offset)), fmt::format("malformed XML: {}", parsed.description()));
    return doc_.document_element();
}

SourceLocation XmlSource::where(const pugi::xml_node& n) const {
    // Errors point at the element's '<' (pugixml reports the offset of its name).
    size_t offset = size_t(std::max<ptrdiff_t>(0, n.offset_debug()));
    if (n.type() == pugi::node_element && offset > 0 && offset <= text_.size() && text_[offset - 1] == '<') --offset;
    const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    const size_t line = size_t(it - line_starts_.begin());
    return {file_, int(line), int(offset - line_starts_[line - 1] + 1)};
}

void XmlSource::fail_at(size_t offset, const std::string& message) const {
    const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    const size_t line = size_t(it - line_starts_.begin());
    throw SceneFileError(file_, int(line), int(offset - line_starts_[line - 1] + 1), message);
}

void XmlSource::fail(const pugi::xml_node& n, const std::string& message) const {
    const SourceLocation w = where(n);
    throw SceneFileError(file_, w.line, w.column, message);
}

void XmlSource::fail_file(const std::string& message) const { throw SceneFileError(file_, 0, 0, message); }

void XmlSource::rethrow(const PropertyError& e) { throw SceneFileError(e.where.file, e.where.line, e.where.column, e.message); }

void XmlSource::check_attributes(const pugi::xml_node& n, std::initializer_list<const char*> allowed) const {
    for (const pugi::xml_attribute a : n.attributes()) {
        if (std::find_if(allowed.begin(), allowed.end(), [&](const char* s) { return a.name() == std::string(s); }) == allowed.end())
            fail(n, fmt::format("unexpected attribute '{}' on <{}>; allowed: {}", a.name(), n.name(), fmt::join(allowed, ", ")));
    }
}

std::string XmlSource::substitute(const pugi::xml_node& n, const std::string& value) const {
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
        const auto it = context_->defines.find(name);
        if (it == context_->defines.end())
            fail(n, fmt::format("undefined parameter ${} (define it with <default name=\"{}\" value=\"...\"/> or -D {}=...)", name,
                                name, name));
        out += it->second;
        context_->used[name] = it->second;
        i = j;
    }
    return out;
}

std::string XmlSource::attr(const pugi::xml_node& n, const char* name) const {
    const pugi::xml_attribute a = n.attribute(name);
    if (!a) fail(n, fmt::format("<{}> needs a '{}' attribute", n.name(), name));
    return substitute(n, a.value());
}

std::optional<std::string> XmlSource::optional_attr(const pugi::xml_node& n, const char* name) const {
    const pugi::xml_attribute a = n.attribute(name);
    if (!a) return std::nullopt;
    return substitute(n, a.value());
}

void XmlSource::define(const pugi::xml_node& n) {
    check_attributes(n, {"name", "value"});
    const std::string name = attr(n, "name");
    if (name.empty() ||
        !std::all_of(name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
        fail(n, fmt::format("invalid parameter name '{}'", name));
    context_->defines.emplace(name, attr(n, "value"));  // -D values (and earlier <default>s) win
}

std::string XmlSource::dir() const {
    const std::filesystem::path p(file_);
    return p.has_parent_path() ? p.parent_path().string() : context_->scene_dir;
}

std::vector<std::string> XmlSource::search_dirs() const {
    std::vector<std::string> dirs{dir()};
    for (const std::string& d : context_->search_paths) dirs.push_back(d);
    dirs.push_back(context_->scene_dir);
    std::vector<std::string> unique;
    for (const std::string& d : dirs)
        if (std::find(unique.begin(), unique.end(), d) == unique.end()) unique.push_back(d);
    return unique;
}

std::string XmlSource::find_file(const pugi::xml_node& n, const std::string& name, const char* what) const {
    if (!context_->allow_files) fail(n, fmt::format("this loader does not read files ({} '{}')", what, name));
    if (name.empty()) fail(n, fmt::format("an empty {} name", what));
    const std::filesystem::path p(name);
    std::error_code ec;
    if (p.is_absolute()) {
        if (!std::filesystem::exists(p, ec)) fail(n, fmt::format("{} '{}' does not exist", what, name));
        context_->files.push_back(name);
        return name;
    }
    const std::vector<std::string> dirs = search_dirs();
    for (const std::string& d : dirs) {
        const std::filesystem::path candidate = std::filesystem::path(d) / p;
        if (std::filesystem::exists(candidate, ec)) {
            context_->files.push_back(candidate.string());
            return candidate.string();
        }
    }
    fail(n, fmt::format("cannot find {} '{}' (searched: {})", what, name, fmt::join(dirs, ", ")));
}

void XmlSource::note(const pugi::xml_node& n, const std::string& message) const {
    const SourceLocation w = where(n);
    context_->notes.push_back(fmt::format("{}:{}:{}: note: {}", w.file, w.line, w.column, message));
}

double XmlSource::parse_number(const pugi::xml_node& n, const std::string& s) const {
    const auto v = parse_double_text(s);
    if (!v) fail(n, fmt::format("'{}' is not a finite number", s));
    return *v;
}

float XmlSource::parse_float(const pugi::xml_node& n, const std::string& s) const {
    const auto v = parse_float_text(s);
    if (!v) fail(n, fmt::format("'{}' is not a finite number", s));
    return *v;
}

Vec3f XmlSource::parse_vec3(const pugi::xml_node& n, const std::string& s, bool allow_scalar) const {
    const auto v = parse_float_list(s);
    if (!v) {
        // Name the item that is not a number, as a list parser would.
        std::string item;
        for (size_t i = 0; i <= s.size(); ++i) {
            if (i == s.size() || s[i] == ',' || std::isspace(static_cast<unsigned char>(s[i]))) {
                if (!item.empty()) parse_float(n, item);
                item.clear();
            } else {
                item += s[i];
            }
        }
    }
    if (v && v->size() == 3) return {(*v)[0], (*v)[1], (*v)[2]};
    if (v && allow_scalar && v->size() == 1) return Vec3f((*v)[0]);
    fail(n, fmt::format("expected {}3 numbers, got \"{}\"", allow_scalar ? "1 or " : "", s));
}

Vec3f XmlSource::xyz_default(const pugi::xml_node& n, float fallback) const {
    const auto get = [&](const char* k) { return n.attribute(k) ? parse_float(n, attr(n, k)) : fallback; };
    return {get("x"), get("y"), get("z")};
}

Transform XmlSource::read_transform(const pugi::xml_node& block) const {
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
            const auto v = parse_float_list(attr(op, "value"));
            if (!v) parse_vec3(op, attr(op, "value"), false);  // names the item that is not a number
            if (v->size() != 16 && v->size() != 9) fail(op, fmt::format("<matrix> needs 16 (or 9) numbers, got {}", v->size()));
            const int k = v->size() == 16 ? 4 : 3;
            for (int i = 0; i < k; ++i)
                for (int j = 0; j < k; ++j) step.m[size_t(i)][size_t(j)] = (*v)[size_t(i * k + j)];
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

Properties XmlSource::properties(const pugi::xml_node& plugin_node, const PluginInfo& plugin) const {
    Properties p(plugin, where(plugin_node));
    for (pugi::xml_node c : plugin_node.children()) {
        if (c.type() != pugi::node_element || !kPropertyTags.count(c.name())) continue;
        const std::string name = attr(c, "name");
        Properties::Value v;
        v.tag = c.name();
        v.where = where(c);
        if (v.tag == "transform") {
            v.transform = read_transform(c);
        } else if ((v.tag == "point" || v.tag == "vector") && !c.attribute("value")) {
            v.xyz = {parse_float(c, attr(c, "x")), parse_float(c, attr(c, "y")), parse_float(c, attr(c, "z"))};
            v.xyz_given = true;
            v.text = "x y z";
        } else if (v.tag == "spectrum" || v.tag == "srgb" || v.tag == "blackbody") {
            v.text = spectrum_value(c, plugin, v.spectrum);
            if (v.tag != "spectrum" || c.attribute("type")) v.tag = "rgb";
        } else {
            v.text = attr(c, "value");
            // Numbers and lists are checked here, where the element is, whatever reads them.
            if (v.tag == "float" || v.tag == "integer") parse_number(c, v.text);
            if (v.tag == "rgb" || v.tag == "spectrum") parse_vec3(c, v.text, true);
            if (v.tag == "point" || v.tag == "vector") parse_vec3(c, v.text, false);
        }
        try {
            p.set(name, std::move(v));
        } catch (const PropertyError& e) {
            rethrow(e);
        }
    }
    return p;
}

std::string XmlSource::spectrum_value(const pugi::xml_node& c, const PluginInfo& plugin,
                                      std::shared_ptr<const SampledSpectrum>& spectrum) const {
    const std::string tag = c.name(), name = attr(c, "name");
    // Mitsuba's RGB mode: an emitter's spectrum is an illuminant; an index of refraction is
    // unbounded; anything else is a reflectance under D65 (core/spectrum.hpp).
    const bool emitter = plugin.kind == "emitter";
    const bool unbounded = name == "eta" || name == "k" || name == "int_ior" || name == "ext_ior" || name == "intIOR" || name == "extIOR";
    const SpectrumUse use = emitter ? SpectrumUse::Illuminant : unbounded ? SpectrumUse::Unbounded : SpectrumUse::Reflectance;
    // The spectrum is kept for spectral mode (emitters' and reflectances', docs/spectral.md);
    // RGB mode reads the text.
    const auto convert = [&](const SampledSpectrum& s) {
        spectrum = std::make_shared<const SampledSpectrum>(s);
        bool clamped = false;
        const Vec3d rgb = spectrum_to_linear_srgb(s, use, &clamped);
        if (clamped) note(c, fmt::format("the spectrum's sRGB colour was out of gamut and is clamped to {}", rgb_text(rgb)));
        return rgb_text(rgb);
    };
    if (tag == "srgb") {  // Mitsuba 0.6: gamma-encoded sRGB, as numbers or #rrggbb
        check_attributes(c, {"name", "value"});
        std::string value = attr(c, "value");
        Vec3d rgb;
        if (!value.empty() && value[0] == '#') {
            const auto hex = [&](size_t i) {
                const std::string h = value.substr(i, 2);
                if (h.size() != 2 || !std::isxdigit(static_cast<unsigned char>(h[0])) || !std::isxdigit(static_cast<unsigned char>(h[1])))
                    fail(c, fmt::format("'{}' is not a colour #rrggbb", value));
                return std::stoi(h, nullptr, 16) / 255.0;
            };
            if (value.size() != 7) fail(c, fmt::format("'{}' is not a colour #rrggbb", value));
            rgb = {hex(1), hex(3), hex(5)};
        } else {
            rgb = Vec3d(parse_vec3(c, value, true));
        }
        for (int i = 0; i < 3; ++i) rgb[i] = srgb_to_linear(rgb[i]);
        return rgb_text(rgb);
    }
    // A black body of `text` kelvin ("5000" or "5000K"), Planck's law in W / (m^2 sr nm).
    const auto kelvin_of = [&](const pugi::xml_node& at, std::string t) {
        if (!t.empty() && (t.back() == 'K' || t.back() == 'k')) t.pop_back();
        const double kelvin = parse_number(at, t);
        if (!(kelvin >= 100 && kelvin <= 1e6)) fail(at, fmt::format("a black body's temperature must be 100 K to 1e6 K, got {}", kelvin));
        return kelvin;
    };
    if (tag == "spectrum" && c.attribute("type")) {
        // Mitsuba 3: <spectrum type="blackbody" name><float name="temperature" value/></spectrum>.
        check_attributes(c, {"name", "type"});
        const std::string type = attr(c, "type");
        if (type != "blackbody") fail(c, fmt::format("unsupported spectrum type '{}'; supported: blackbody (or a value, or a filename)", type));
        std::optional<double> kelvin;
        for (const pugi::xml_node& k : c.children()) {
            if (k.type() == pugi::node_pcdata || k.type() == pugi::node_cdata) fail(k, "unexpected text");
            if (k.type() != pugi::node_element) continue;
            if (std::string(k.name()) != "float" || std::string(k.attribute("name").value()) != "temperature")
                fail(k, "a blackbody spectrum takes one parameter, <float name=\"temperature\" value=\"...\"/> (in kelvin)");
            check_attributes(k, {"name", "value"});
            if (kelvin) fail(k, "the temperature is given twice");
            kelvin = kelvin_of(k, attr(k, "value"));
        }
        if (!kelvin) fail(c, "a blackbody spectrum needs <float name=\"temperature\" value=\"...\"/> (in kelvin)");
        return convert(blackbody_spectrum(*kelvin));
    }
    if (tag == "blackbody") {  // Mitsuba 0.6: <blackbody name temperature="5000K" scale="1"/>
        check_attributes(c, {"name", "temperature", "scale", "multiplier"});
        const double kelvin = kelvin_of(c, attr(c, "temperature"));
        double scale = 1;
        if (c.attribute("scale")) scale = parse_number(c, attr(c, "scale"));
        if (c.attribute("multiplier")) scale = parse_number(c, attr(c, "multiplier"));
        if (!(scale >= 0)) fail(c, "a black body's scale must not be negative");
        SampledSpectrum s = blackbody_spectrum(kelvin);
        for (double& v : s.values) v *= scale;
        return convert(s);
    }
    check_attributes(c, {"name", "value", "filename"});
    SampledSpectrum s;
    if (c.attribute("filename")) {
        if (c.attribute("value")) fail(c, "a <spectrum> has a value or a filename, not both");
        const std::string path = find_file(c, attr(c, "filename"), "spectrum file");
        // A spectrum of more than 16 MiB of text is no measured spectrum (it was read cut short,
        // silently: the spectrum of its first 16 MiB).
        std::string text;
        try {
            text = read_input_file(path, uint64_t(1) << 24);
        } catch (const InputFileError& e) {
            fail(c, fmt::format("cannot read the spectrum file '{}': {}", path, e.what()));
        }
        const std::string why = parse_spectrum_file(text, s);
        if (!why.empty()) fail(c, fmt::format("spectrum file '{}': {}", path, why));
        return convert(s);
    }
    const std::string value = attr(c, "value");
    if (value.find(':') == std::string::npos) {
        const float v = parse_float(c, value);
        // Mitsuba 3 turns an emitter's uniform spectrum into the sRGB of illuminant E (a flat
        // spectrum); Mitsuba 0.6 kept it grey.
        if (emitter && context_->version_major >= 3) {
            spectrum = std::make_shared<const SampledSpectrum>(
                SampledSpectrum{{kCieMinWavelength, kCieMaxWavelength}, {double(v), double(v)}});
            return rgb_text(xyz_to_linear_srgb(Vec3d(1.0)) * double(v));
        }
        return value;
    }
    const std::string why = parse_spectrum_pairs(value, s);
    if (!why.empty()) fail(c, why);
    return convert(s);
}

std::vector<pugi::xml_node> XmlSource::plugin_children(const pugi::xml_node& n) const {
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

}  // namespace pathlab
