// The XML side of scene files, shared by every element reader: the parsed document, positions
// (file:line:column) for errors, $name substitution, attributes, and the Properties of an
// element (its <float>, <rgb>, <transform>, ... children, read for the element's plugin).
#pragma once

#include <pugixml.hpp>

#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/properties.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab {

// What every file of one load shares (the main file and its <include>s): the $name values, the
// folders that file names are searched in, whether files may be read at all, the scene's
// version, the notes about what was accepted but ignored, and what the scene's identity is made
// of (the $name parameters used and every file read).
struct LoadContext {
    SceneDefines defines;
    SceneParameters used;                   // the $name parameters substituted, with their values
    std::vector<std::string> files;         // every file read: the main file, includes, spectra, meshes, emitters' files
    std::vector<std::string> search_paths;  // <path> folders, the latest first
    std::string scene_dir = ".";            // the main file's folder, searched last
    bool allow_files = true;
    int version_major = 3, version_minor = 0;  // <scene version>: 0.5 to 3.x
    std::vector<std::string> notes;         // "file:line:column: note: ..."
};

class XmlSource {
public:
    XmlSource(const std::string& text, std::string file, SceneDefines defines);
    XmlSource(const std::string& text, std::string file, std::shared_ptr<LoadContext> context);

    // The document's root element (parsing errors are SceneFileErrors).
    pugi::xml_node root();
    const std::string& file() const { return file_; }
    // The folder of this file (relative names in it are searched there first).
    std::string dir() const;
    LoadContext& context() const { return *context_; }
    // A file a scene refers to: an absolute name, or the first that exists of this file's
    // folder, the <path> folders (the latest first) and the main scene file's folder. Fails at
    // `n` naming the folders searched; with files disabled (the fuzzer) fails too.
    std::string find_file(const pugi::xml_node& n, const std::string& name, const char* what) const;
    // The folders find_file searches, in order.
    std::vector<std::string> search_dirs() const;
    // A note (printed by the command line): something accepted and ignored, or changed.
    void note(const pugi::xml_node& n, const std::string& message) const;

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
    // A <spectrum>, <srgb> or <blackbody> as the text of an rgb value; the spectrum itself (not
    // of an <srgb>, nor of a uniform value but a version 3 emitter's) is also given back as `spectrum`.
    std::string spectrum_value(const pugi::xml_node& c, const PluginInfo& plugin, std::shared_ptr<const SampledSpectrum>& spectrum) const;
    std::string substitute(const pugi::xml_node& n, const std::string& value) const;
    Vec3f xyz_default(const pugi::xml_node& n, float fallback) const;

    const std::string& text_;
    std::string file_;
    std::shared_ptr<LoadContext> context_;
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
