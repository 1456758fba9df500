// The XML side of scene files, shared by every element reader: the parsed document, positions
// (file:line:column) for errors, $name substitution, attributes, and the Properties of an
// element (its <float>, <rgb>, <transform>, ... children, read for the element's plugin).
#pragma once

#include <pugixml.hpp>

#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "core/properties.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab {

class XmlSource {
public:
    XmlSource(const std::string& text, std::string file, SceneDefines defines);

    // The document's root element (parsing errors are SceneFileErrors).
    pugi::xml_node root();
    const std::string& file() const { return file_; }

    // ---- errors: at an element's '<', or an offset -----------------------------------------
    [[noreturn]] void fail(const pugi::xml_node& n, const std::string& message) const;
    [[noreturn]] void fail_at(size_t offset, const std::string& message) const;
    [[noreturn]] void fail_file(const std::string& message) const;
    SourceLocation where(const pugi::xml_node& n) const;

    // ---- attributes ------------------------------------------------------------------------
    void check_attributes(const pugi::xml_node& n, std::initializer_list<const char*> allowed) const;
    std::string attr(const pugi::xml_node& n, const char* name) const;  // required, after $substitution
    std::optional<std::string> optional_attr(const pugi::xml_node& n, const char* name) const;
    // <default name value>: a value for $name (command-line -D values win).
    void define(const pugi::xml_node& n);
    // The $name parameters substituted so far, with their values.
    const SceneParameters& used_parameters() const { return used_; }

    // ---- values ----------------------------------------------------------------------------
    float parse_float(const pugi::xml_node& n, const std::string& s) const;
    double parse_number(const pugi::xml_node& n, const std::string& s) const;
    Vec3f parse_vec3(const pugi::xml_node& n, const std::string& s, bool allow_scalar) const;
    Transform read_transform(const pugi::xml_node& block) const;

    // The property children of a plugin element, for that plugin. Every error (a duplicate, a
    // malformed transform) is a SceneFileError at the child.
    Properties properties(const pugi::xml_node& plugin_node, const PluginInfo& plugin) const;
    // The child elements that are plugins, not properties (unexpected text is an error).
    std::vector<pugi::xml_node> plugin_children(const pugi::xml_node& n) const;
    // Converts a PropertyError (from a plugin's reader) into a SceneFileError.
    [[noreturn]] static void rethrow(const PropertyError& e);

private:
    std::string substitute(const pugi::xml_node& n, const std::string& value) const;
    Vec3f xyz_default(const pugi::xml_node& n, float fallback) const;

    const std::string& text_;
    std::string file_;
    SceneDefines defines_;
    mutable SceneParameters used_;
    std::vector<size_t> line_starts_;
    pugi::xml_document doc_;
};

// Runs a plugin reader; its PropertyErrors become SceneFileErrors.
template <typename F>
auto reading(F&& f) {
    try {
        return f();
    } catch (const PropertyError& e) {
        XmlSource::rethrow(e);
    }
}

}  // namespace pathlab
