// Reading and writing voxel grids: Mitsuba's binary .vol format and OpenVDB's .vdb.
//
// .vol (Mitsuba 0.6 and 3, little endian): bytes 0-2 "VOL", byte 3 the version (3), then
// int32 encoding (1 = float32, the only one Mitsuba 3 reads), int32 xres, yres, zres, int32
// channels (1 or 3 here; Mitsuba also has 6), 6 float32 bounding box (xmin ymin zmin xmax ymax
// zmax; Mitsuba 3 ignores it, so does pathlab: a grid fills the unit cube moved by to_world),
// then xres * yres * zres * channels float32 values, data[((z * yres + y) * xres + x) * channels + c].
//
// .vdb (OpenVDB, libopenvdb): one FloatGrid or Vec3SGrid, densified over the bounding box of
// its active voxels. OpenVDB puts voxel (i, j, k)'s value at the index-space point (i, j, k),
// which its transform (linear transforms only) takes to the file's world space.
//
// Every problem is a GridFileError whose message names the file: a missing or non-regular
// file, a wrong magic, version, encoding or channel count, dimensions that are not positive or
// whose data does not fit in the file (truncated) or does not fill it (trailing bytes), a
// NaN, infinite or negative value (named by its voxel), a grid too large for memory.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "core/transform.hpp"
#include "media/voxel_grid.hpp"

namespace pathlab {

struct GridFileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// The largest grid pathlab loads (voxels x channels), so that a file cannot ask for more
// memory than a render machine has: 2^28 floats, 1 GiB.
inline constexpr size_t kMaxGridValues = size_t(1) << 28;

// A .vol file's bytes (`name` is used in messages). The fuzzer's entry point.
VoxelGrid parse_vol(std::string_view bytes, const std::string& name);
VoxelGrid read_vol_file(const std::string& path);
// Writes a grid as a .vol file (bounding box: the unit cube); throws GridFileError on failure.
void write_vol_file(const std::string& path, const VoxelGrid& grid);

// A GridFileError unless `path` names a regular file (checked before a reader opens it: opening
// a named pipe waits for a writer).
void require_regular_grid_file(const std::string& path);

// A grid of a .vdb file and where it lies: `unit_to_world` maps pathlab's unit cube of the
// grid (see voxel_grid.hpp) to the file's world space.
struct VdbGrid {
    VoxelGrid grid;
    Transform unit_to_world;
};
// The grid named `grid_name`; with "", the one named "density", or else the file's only grid.
VdbGrid read_vdb_file(const std::string& path, const std::string& grid_name = "");
// Writes `grid` (1 channel) as a FloatGrid named `grid_name` whose voxel (i, j, k) is the grid's
// voxel (i, j, k) and whose voxels measure `voxel_size` (index-to-world: a uniform scale);
// zero voxels are left inactive. For the tests and tools.
void write_vdb_file(const std::string& path, const VoxelGrid& grid, const std::string& grid_name, double voxel_size);

}  // namespace pathlab
