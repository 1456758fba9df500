// Plugin parameters: every plugin (BSDF, light, shape, integrator, sensor, film, sampler)
// declares its parameters once, next to its code, as a PluginInfo (names as Mitsuba 3 spells
// them, the value type, the default and one line of documentation). The scene-file reader
// fills a Properties with what a file gives; the plugin reads it through its declaration, so
// the default written in the declaration is the only one there is, and the tables of docs/scene-files.md
// and `pathlab plugins` print the same declarations.
//
// Reading a parameter that the plugin did not declare is a programming error (std::logic_error);
// a value of the wrong type, an unreadable number or an undeclared parameter given in a file is
// a PropertyError that names where it was given.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/spectrum.hpp"
#include "core/transform.hpp"
#include "core/vec.hpp"

namespace pathlab {

// Where a value was given: file, line and column (1-based; 0 when unknown).
struct SourceLocation {
    std::string file;
    int line = 0, column = 0;
};

struct PropertyError : std::runtime_error {
    PropertyError(SourceLocation where_, const std::string& message_)
        : std::runtime_error(message_), where(std::move(where_)), message(message_) {}
    SourceLocation where;
    std::string message;
};

enum class ParamType {
    Float,          // <float> (or <integer>)
    Integer,        // <integer>
    Boolean,        // <boolean>
    String,         // <string>
    Rgb,            // <rgb>, <spectrum> with one value, or <float>
    Point,          // <point> or <vector>
    Transform,      // <transform>
    FloatOrString,  // <float> or <string> (an index of refraction by value or by name)
};
const char* param_type_name(ParamType t);  // "float", "rgb", ... as docs/scene-files.md shows them

struct ParamInfo {
    std::string name;           // Mitsuba 3's name
    ParamType type = ParamType::Float;
    std::string default_value;  // as it would be written in a file; empty: none (optional)
    std::string doc;            // one line
    std::string old_name = {};  // Mitsuba 0.6's camelCase spelling, accepted too
    // 0 or more: a texture may give this parameter (a <texture> or <ref> child of the plugin's
    // element); the number says which of the model's parameters it sets (bsdfs/material.hpp).
    int texture_slot = -1;
};

struct PluginInfo {
    std::string kind;     // "bsdf", "emitter", "shape", "integrator", "sensor", "film", "sampler"
    std::string type;     // the type attribute, e.g. "roughconductor"
    std::string summary;  // one line
    std::vector<ParamInfo> params;
    std::string notes = {};  // what docs/scene-files.md adds below the table (may be empty)

    const ParamInfo* find(const std::string& name) const;
    std::string param_names() const;  // "a, b, c" for error messages
};

class Properties {
public:
    struct Value {
        std::string tag;    // the element that gave it: float, integer, boolean, string, rgb, spectrum, point, vector,
                            // transform, or texture (text: the texture's largest value, read as a constant)
        std::string text;   // its value attribute, after $name substitution
        Vec3f xyz{0.0f};    // point/vector given as x, y, z attributes (xyz_given)
        bool xyz_given = false;
        pathlab::Transform transform;  // for tag "transform"
        // A value given as a spectrum (<spectrum> with wavelengths, a file or a type, <blackbody>;
        // an emitter's uniform <spectrum> in a version 3 file): the spectrum itself, which `text`
        // holds as its linear sRGB (null otherwise).
        std::shared_ptr<const SampledSpectrum> spectrum;
        SourceLocation where;
        bool used = false;
    };

    Properties(const PluginInfo& plugin, SourceLocation where) : plugin_(&plugin), where_(std::move(where)) {}

    // Adds a given value under the name the file used; a name given twice is a PropertyError.
    void set(const std::string& name, Value v);

    const PluginInfo& plugin() const { return *plugin_; }
    const SourceLocation& where() const { return where_; }
    // True when the parameter (or its old spelling) was given.
    bool has(const std::string& name) const;

    // Typed reads. A parameter that was not given takes its declared default; one with no
    // default must be tested with has() first (reading it anyway is a logic_error).
    float get_float(const std::string& name);
    int get_int(const std::string& name);
    bool get_bool(const std::string& name);
    std::string get_string(const std::string& name);
    Rgb get_rgb(const std::string& name);  // must not be negative
    Vec3f get_point(const std::string& name);
    std::optional<pathlab::Transform> get_transform(const std::string& name);
    // Whether a <float>/<string> parameter was given as a string (FloatOrString), read as text.
    bool is_string(const std::string& name);
    // The value as given (for readers that need the raw form, e.g. a single <lookat>).
    const Value* given(const std::string& name);

    // A PropertyError at the parameter's location (or the plugin's, when it was not given).
    [[noreturn]] void fail(const std::string& name, const std::string& message) const;
    [[noreturn]] void fail(const std::string& message) const;
    // Every given parameter must have been read: the others are named in a PropertyError.
    void check_all_used() const;

private:
    const ParamInfo& declared(const std::string& name) const;
    // The given value of `name` (checking its element against the declared type), or null.
    Value* lookup(const std::string& name);
    std::string text_or_default(const std::string& name, Value*& v);

    const PluginInfo* plugin_;
    SourceLocation where_;
    std::map<std::string, Value> values_;    // by declared name (or as given, if undeclared)
    std::map<std::string, std::string> spelled_;  // the name as the file spelled it
};

// Number parsing shared by the scene-file reader and Properties: a float parsed as a float
// (so "0.5388500" gives the float a C++ literal does), doubles, lists of floats and vectors.
// Each returns nothing for text that is not a finite number (or list of them).
std::optional<float> parse_float_text(const std::string& s);
std::optional<double> parse_double_text(const std::string& s);
std::optional<std::vector<float>> parse_float_list(const std::string& s);

}  // namespace pathlab
