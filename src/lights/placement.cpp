#include "lights/placement.hpp"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "core/file_search.hpp"

namespace pathlab {

std::string emitter_file(Properties& p, const EmitterContext& ctx, const char* what) {
    if (!p.has("filename")) p.fail(fmt::format("<emitter type=\"{}\"> needs <string name=\"filename\" value=\"...\"/>", what));
    const std::string filename = p.get_string("filename");
    if (!ctx.allow_files) p.fail("filename", fmt::format("this loader does not read files ({} emitters are disabled)", what));
    return find_in_dirs(filename, ctx.search_dirs.empty() ? std::vector<std::string>{ctx.base_dir} : ctx.search_dirs);
}

Frame rotation_frame(Properties& p, const char* what) {
    const auto t = p.get_transform("to_world");
    if (!t) return Frame();
    const Vec3d x = t->vector({1, 0, 0}), y = t->vector({0, 1, 0}), z = t->vector({0, 0, 1});
    const double lx = length(x), ly = length(y), lz = length(z);
    const double scale = std::max({lx, ly, lz});
    const auto close = [](double a, double b) { return std::abs(a - b) <= 1e-4 * std::max(a, b); };
    const bool orthogonal = std::abs(dot(x, y)) <= 1e-4 * lx * ly && std::abs(dot(y, z)) <= 1e-4 * ly * lz &&
                            std::abs(dot(z, x)) <= 1e-4 * lz * lx;
    if (!(scale > 0) || !close(lx, ly) || !close(ly, lz) || !orthogonal)
        p.fail("to_world", fmt::format("the to_world of a {} emitter must be a rotation (with a uniform scale and a translation at "
                                       "most): a shear or a non-uniform scale would distort its directions",
                                       what));
    Frame f;
    f.s = Vec3f(x / lx), f.t = Vec3f(y / ly), f.n = Vec3f(z / lz);
    return f;
}

}  // namespace pathlab
