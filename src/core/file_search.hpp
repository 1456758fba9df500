// Resolving a relative file name of a scene file against an ordered list of folders (the
// scene file's folder, its <path> folders), shared by the shapes and emitters that read files.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace pathlab {

// `name` itself when absolute; else the first of `dirs` where it exists, else its place in the
// first folder, so that the reader's error names a path. `dirs` must not be empty.
inline std::string find_in_dirs(const std::string& name, const std::vector<std::string>& dirs) {
    const std::filesystem::path p(name);
    if (p.is_absolute()) return name;
    std::error_code ec;
    for (const std::string& d : dirs)
        if (std::filesystem::exists(std::filesystem::path(d) / p, ec)) return (std::filesystem::path(d) / p).string();
    return (std::filesystem::path(dirs.front()) / p).string();
}

}  // namespace pathlab
