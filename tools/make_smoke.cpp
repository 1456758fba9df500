// Writes the procedural smoke grid of scenes/smoke.xml (tools/smoke_grid.hpp) as a Mitsuba .vol file.
//   build/tools/pathlab_make_smoke scenes/volumes/smoke.vol [resolution, default 32]
#include <cstdio>
#include <cstdlib>

#include "media/grid_files.hpp"
#include "smoke_grid.hpp"

int main(int argc, char** argv) {
    if (argc < 2 || argc > 3) {
        std::fprintf(stderr, "usage: %s OUTPUT.vol [RESOLUTION]\n", argv[0]);
        return 2;
    }
    const int res = argc == 3 ? std::atoi(argv[2]) : 32;
    if (res < 2 || res > 512) {
        std::fprintf(stderr, "resolution must be between 2 and 512\n");
        return 2;
    }
    try {
        pathlab::write_vol_file(argv[1], pathlab::tools::smoke_grid(res));
    } catch (const pathlab::GridFileError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
