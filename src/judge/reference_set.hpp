// Where `pathlab check` finds the reference image of each built-in scene in a directory.
//
// File names tried, in this order, for scene i with name n and course acronym a (see
// `pathlab scenes`), e.g. scene 2 = ceiling-diffuse = ws_c_sdwd:
//   stems  "{i}-{n}" (what `pathlab reference` writes), "{i}" (the course's direct/0.png ...
//          direct/7.png), "{n}", "{a}", "{i}_{a}"
//   with the extensions .exr, .pfm, .hdr (linear) for each stem, then .png for each stem
//          (8-bit, the course's 2.2-gamma encoding)
// The first existing file wins. A linear reference "x.exr" may come with per-pixel standard
// errors in "x.stderr.exr" (written by `pathlab reference`), which the verdict then includes.
//
// A mapping file gives names explicitly, one scene per line, relative to the reference
// directory (or absolute); '#' starts a comment; scenes it does not name fall back to the
// names above:
//   # scene (index, name or acronym) = file
//   0 = cornell-point.hdr
//   ceiling-glossy = renders/glossy_ref.pfm
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pathlab {

enum class ReferenceKind {
    Linear,      // .exr, .pfm, .hdr
    Course8bit,  // .png: round(255 clamp(L, 0, 1)^(1/2.2)), judged by tools/course_reference.hpp
};

struct ReferenceFile {
    std::string path;
    ReferenceKind kind = ReferenceKind::Linear;
    std::string stderr_path;  // per-pixel standard errors of a linear reference; empty if none
};

struct ReferenceMappingError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// The file names tried for a built-in scene, in order (without directory).
std::vector<std::string> expected_reference_names(int scene);

// "dir/x.exr" -> "dir/x.stderr.exr" (the standard-error companion of a linear image).
std::string stderr_path_for(const std::string& image_path);

// Scene index -> file, as written in the mapping file. Throws ReferenceMappingError naming
// file:line for a malformed line or an unknown scene, and when the file cannot be read.
std::map<int, std::string> read_reference_mapping(const std::string& path);

// The reference for `scene` in `dir` (mapping entries first), or nullopt with `tried` set to
// what was looked for.
std::optional<ReferenceFile> find_reference(const std::string& dir, int scene, const std::map<int, std::string>& mapping,
                                            std::string* tried = nullptr);
// The reference of a scene file in `dir`: "{stem}" (what `pathlab reference` writes for
// scenes/{stem}.xml) with .exr, .pfm, .hdr, then .png.
std::optional<ReferenceFile> find_reference_named(const std::string& dir, const std::string& stem, std::string* tried = nullptr);

}  // namespace pathlab
