// The view page's files (src/view/page/), compiled into pathlab by cmake/embed_files.cmake, so
// that `pathlab view` serves exactly these and nothing from the disk.
#pragma once

#include <span>
#include <string_view>

namespace pathlab {

struct ViewAsset {
    std::string_view path;  // "/index.html", "/view.js", ...
    std::string_view bytes;
};
std::span<const ViewAsset> view_assets();

}  // namespace pathlab
