#include "core/properties.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

namespace pathlab {

const char* param_type_name(ParamType t) {
    switch (t) {
        case ParamType::Float: return "float";
        case ParamType::Integer: return "integer";
        case ParamType::Boolean: return "boolean";
        case ParamType::String: return "string";
        case ParamType::Rgb: return "rgb";
        case ParamType::Point: return "point";
        case ParamType::Transform: return "transform";
        case ParamType::FloatOrString: return "float or string";
    }
    return "?";
}

const ParamInfo* PluginInfo::find(const std::string& name) const {
    for (const ParamInfo& p : params)
        if (p.name == name || (!p.old_name.empty() && p.old_name == name)) return &p;
    return nullptr;
}

std::string PluginInfo::param_names() const {
    std::vector<std::string> names;
    for (const ParamInfo& p : params) names.push_back(p.name);
    return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

namespace {

std::string_view trimmed(const std::string& s) {
    size_t b = 0, e = s.size();
    while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
    while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
    if (b < e && s[b] == '+') ++b;
    return std::string_view(s).substr(b, e - b);
}

// The elements a parameter of each type may be given as.
std::vector<const char*> allowed_tags(ParamType t) {
    switch (t) {
        case ParamType::Float: return {"float", "integer"};
        case ParamType::Integer: return {"integer"};
        case ParamType::Boolean: return {"boolean"};
        case ParamType::String: return {"string"};
        case ParamType::Rgb: return {"rgb", "spectrum", "float"};
        case ParamType::Point: return {"point", "vector"};
        case ParamType::Transform: return {"transform"};
        case ParamType::FloatOrString: return {"float", "string"};
    }
    return {};
}

}  // namespace

std::optional<float> parse_float_text(const std::string& s) {
    const std::string_view t = trimmed(s);
    float v = 0;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc() || ptr != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

std::optional<double> parse_double_text(const std::string& s) {
    const std::string_view t = trimmed(s);
    double v = 0;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc() || ptr != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

std::optional<std::vector<float>> parse_float_list(const std::string& s) {
    std::vector<float> out;
    std::string item;
    for (size_t i = 0; i <= s.size(); ++i) {
        if (i == s.size() || s[i] == ',' || std::isspace(static_cast<unsigned char>(s[i]))) {
            if (!item.empty()) {
                const auto v = parse_float_text(item);
                if (!v) return std::nullopt;
                out.push_back(*v);
            }
            item.clear();
        } else {
            item += s[i];
        }
    }
    return out;
}

void Properties::set(const std::string& name, Value v) {
    const ParamInfo* p = plugin_->find(name);
    const std::string key = p ? p->name : name;
    if (const auto it = spelled_.find(key); it != spelled_.end()) {
        if (it->second != name)  // the same parameter under its two spellings
            throw PropertyError(v.where, fmt::format("'{}' and '{}' are the same parameter; give one", p->name, p->old_name));
        throw PropertyError(v.where, fmt::format("parameter '{}' is given twice", name));
    }
    values_[key] = std::move(v);
    spelled_[key] = name;
}

bool Properties::has(const std::string& name) const {
    const ParamInfo* p = plugin_->find(name);
    return values_.count(p ? p->name : name) > 0;
}

const ParamInfo& Properties::declared(const std::string& name) const {
    const ParamInfo* p = plugin_->find(name);
    if (!p) throw std::logic_error(fmt::format("{} '{}' reads the undeclared parameter '{}'", plugin_->kind, plugin_->type, name));
    return *p;
}

Properties::Value* Properties::lookup(const std::string& name) {
    const ParamInfo& p = declared(name);
    const auto it = values_.find(p.name);
    if (it == values_.end()) return nullptr;
    Value& v = it->second;
    std::vector<const char*> tags = allowed_tags(p.type);
    if (p.texture_slot >= 0) tags.push_back("texture");
    if (std::find_if(tags.begin(), tags.end(), [&](const char* t) { return v.tag == t; }) == tags.end())
        throw PropertyError(v.where, fmt::format("parameter '{}' must be given as <{}>, not <{}>", spelled_.at(p.name),
                                                 fmt::join(tags, "> or <"), v.tag));
    v.used = true;
    return &v;
}

std::string Properties::text_or_default(const std::string& name, Value*& v) {
    v = lookup(name);
    if (v) return v->text;
    const ParamInfo& p = declared(name);
    if (p.default_value.empty())
        throw std::logic_error(fmt::format("{} '{}' reads '{}', which has no default, without has()", plugin_->kind,
                                           plugin_->type, name));
    return p.default_value;
}

float Properties::get_float(const std::string& name) {
    Value* v = nullptr;
    const std::string text = text_or_default(name, v);
    const auto f = parse_float_text(text);
    if (!f) throw PropertyError(v ? v->where : where_, fmt::format("'{}' is not a finite number", text));
    return *f;
}

int Properties::get_int(const std::string& name) {
    Value* v = nullptr;
    const std::string text = text_or_default(name, v);
    const auto d = parse_double_text(text);
    if (!d) throw PropertyError(v ? v->where : where_, fmt::format("'{}' is not a finite number", text));
    if (*d != std::floor(*d) || std::abs(*d) > 1e9)
        throw PropertyError(v ? v->where : where_,
                            fmt::format("parameter '{}' must be an integer of at most 1e9 in magnitude, got {}", name, text));
    return int(*d);
}

bool Properties::get_bool(const std::string& name) {
    Value* v = nullptr;
    const std::string text = text_or_default(name, v);
    if (text == "true") return true;
    if (text == "false") return false;
    throw PropertyError(v ? v->where : where_, fmt::format("parameter '{}' must be true or false, not '{}'", name, text));
}

std::string Properties::get_string(const std::string& name) {
    Value* v = nullptr;
    return text_or_default(name, v);
}

bool Properties::is_string(const std::string& name) {
    Value* v = lookup(name);
    if (v) return v->tag == "string";
    const auto d = parse_float_text(declared(name).default_value);
    return !d.has_value();
}

Rgb Properties::get_rgb(const std::string& name) {
    Value* v = nullptr;
    const std::string text = text_or_default(name, v);
    const SourceLocation& at = v ? v->where : where_;
    const auto list = parse_float_list(text);
    if (!list) throw PropertyError(at, fmt::format("'{}' is not a finite number", text));
    if (list->size() != 1 && list->size() != 3) throw PropertyError(at, fmt::format("expected 1 or 3 numbers, got \"{}\"", text));
    const Rgb c = list->size() == 3 ? Rgb((*list)[0], (*list)[1], (*list)[2]) : Rgb((*list)[0]);
    if (min_component(c) < 0) throw PropertyError(at, fmt::format("parameter '{}' must not be negative", name));
    return c;
}

Vec3f Properties::get_point(const std::string& name) {
    Value* v = nullptr;
    const std::string text = text_or_default(name, v);
    if (v && v->xyz_given) return v->xyz;
    const SourceLocation& at = v ? v->where : where_;
    const auto list = parse_float_list(text);
    if (!list) throw PropertyError(at, fmt::format("'{}' is not a finite number", text));
    if (list->size() != 3) throw PropertyError(at, fmt::format("expected 3 numbers, got \"{}\"", text));
    return {(*list)[0], (*list)[1], (*list)[2]};
}

std::optional<Transform> Properties::get_transform(const std::string& name) {
    Value* v = lookup(name);
    if (!v) return std::nullopt;
    return v->transform;
}

const Properties::Value* Properties::given(const std::string& name) { return lookup(name); }

void Properties::fail(const std::string& name, const std::string& message) const {
    const ParamInfo* p = plugin_->find(name);
    const auto it = values_.find(p ? p->name : name);
    throw PropertyError(it != values_.end() ? it->second.where : where_, message);
}

void Properties::fail(const std::string& message) const { throw PropertyError(where_, message); }

void Properties::check_all_used() const {
    for (const auto& [key, v] : values_)
        if (!v.used)
            throw PropertyError(v.where, fmt::format("unsupported parameter '{}' for <{} type=\"{}\">; supported: {}",
                                                     spelled_.at(key), plugin_->kind, plugin_->type, plugin_->param_names()));
}

}  // namespace pathlab
