#include "app/command_arguments.hpp"

#include <cstdio>

#include <fmt/format.h>

#include "job/usage_error.hpp"

namespace pathlab {

bool parse_resolution(const std::string& text, int& width, int& height) {
    char x = 0;
    char rest = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &x, &height, &rest) != 3 || (x != 'x' && x != 'X')) return false;
    return width > 0 && height > 0 && width <= 1 << 15 && height <= 1 << 15;
}

void parse_resolution_option(const std::string& text, int& width, int& height) {
    width = height = 0;
    if (!text.empty() && !parse_resolution(text, width, height))
        throw UsageError(fmt::format("invalid --resolution '{}': expected WxH with positive integers, e.g. 512x512", text));
}

}  // namespace pathlab
