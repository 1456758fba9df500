// OpenVDB grids (format: grid_files.hpp): the only file that includes OpenVDB's headers, built as
// a module of its own (libpathlab_openvdb.so) that vdb_file.cpp loads the first time a .vdb file
// is read or written. Linking libopenvdb into pathlab itself cost every run of every program
// ~0.25 s and 28 MiB at startup (the dynamic linker's relocations of the library), whether it
// read a .vdb file or not. The module's two entry points report errors as text.
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <fstream>
#include <mutex>

#include <fmt/format.h>

#include "media/grid_files.hpp"

namespace pathlab {
namespace {

void initialise_openvdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

// Densifies the active values of `grid` over their bounding box (inactive voxels: 0).
template <typename GridT, int Channels>
VdbGrid densify(const GridT& grid, const std::string& path) {
    const auto fail = [&](const std::string& why) { return GridFileError(fmt::format("grid file '{}': grid '{}': {}", path, grid.getName(), why)); };
    if (!grid.transform().isLinear()) throw fail("only grids with a linear transform are supported (not frustum grids)");
    if (!(grid.background() == typename GridT::ValueType(openvdb::zeroVal<typename GridT::ValueType>())))
        throw fail("its background value must be 0 (pathlab's grids are 0 outside their active voxels)");
    const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (box.empty()) throw fail("it has no active voxels");
    const openvdb::Coord lo = box.min(), dim = box.dim();
    VdbGrid out;
    VoxelGrid& g = out.grid;
    g.res = {dim.x(), dim.y(), dim.z()};
    g.channels = Channels;
    const double values = double(dim.x()) * double(dim.y()) * double(dim.z()) * Channels;
    if (values > double(kMaxGridValues))
        throw fail(fmt::format("its active voxels span {}x{}x{}, more than pathlab loads ({} values)", dim.x(), dim.y(), dim.z(), kMaxGridValues));
    g.data.assign(size_t(values), 0.0f);
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        const openvdb::CoordBBox b = it.getBoundingBox();  // one voxel, or a tile
        float v[3];
        if constexpr (Channels == 1) {
            v[0] = float(*it);
        } else {
            for (int c = 0; c < 3; ++c) v[c] = float((*it)[c]);
        }
        for (int c = 0; c < Channels; ++c)
            if (!std::isfinite(v[c]) || v[c] < 0)
                throw fail(fmt::format("voxel ({}, {}, {}) is {}: grid values must be finite and not negative", b.min().x(),
                                       b.min().y(), b.min().z(), v[c]));
        for (int z = b.min().z(); z <= b.max().z(); ++z)
            for (int y = b.min().y(); y <= b.max().y(); ++y)
                for (int x = b.min().x(); x <= b.max().x(); ++x) {
                    const size_t i = ((size_t(z - lo.z()) * size_t(dim.y()) + size_t(y - lo.y())) * size_t(dim.x()) + size_t(x - lo.x()));
                    for (int c = 0; c < Channels; ++c) g.data[i * Channels + size_t(c)] = v[c];
                }
    }
    // pathlab's unit cube to OpenVDB's index space: voxel i sits at unit (i - lo + 1/2) / dim, so
    // index = lo - 1/2 + unit * dim; then OpenVDB's (linear) index-to-world map, as a matrix.
    const Transform unit_to_index =
        Transform::translate(Vec3d(lo.x() - 0.5, lo.y() - 0.5, lo.z() - 0.5)) * Transform::scale(Vec3d(dim.x(), dim.y(), dim.z()));
    const openvdb::math::Transform& xf = grid.transform();
    const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
    Transform index_to_world;
    for (int col = 0; col < 3; ++col) {
        openvdb::Vec3d e(0, 0, 0);
        e[col] = 1;
        const openvdb::Vec3d c = xf.indexToWorld(e) - o;
        for (int row = 0; row < 3; ++row) index_to_world.m[size_t(row)][size_t(col)] = c[row];
    }
    for (int row = 0; row < 3; ++row) index_to_world.m[size_t(row)][3] = o[row];
    if (!index_to_world.is_affine_invertible()) throw fail("its transform is not invertible");
    out.unit_to_world = index_to_world * unit_to_index;
    return out;
}

// (vdb_file.cpp's read_vdb_file, the only caller, checked that `path` is a regular file.)
VdbGrid read_vdb(const std::string& path, const std::string& grid_name) {
    initialise_openvdb();
    openvdb::GridPtrVecPtr grids;
    // OpenVDB's stream reader, from a stream that throws at the end of the file: its loops over
    // counts read from the file (tiles, children, metadata) do not run on past the file's bytes.
    // (vdb_file.cpp checked the layout it trusts, grid by grid, before.)
    try {
        std::ifstream in(path, std::ios::binary);
        in.exceptions(std::ios::failbit | std::ios::badbit);
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        grids = stream.getGrids();
    } catch (const std::ios_base::failure&) {
        throw GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: its grid data runs past the end of the file", path));
    } catch (const std::bad_alloc&) {
        throw GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: its grid data claims more memory than there is", path));
    } catch (const std::exception& e) {
        throw GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: {}", path, e.what()));
    }
    std::vector<std::string> names;
    openvdb::GridBase::Ptr chosen;
    for (const auto& g : *grids) names.push_back(g->getName());
    for (const auto& g : *grids)
        if (g->getName() == (grid_name.empty() ? "density" : grid_name)) chosen = g;
    if (!chosen && grid_name.empty() && grids->size() == 1) chosen = grids->front();
    if (!chosen)
        throw GridFileError(fmt::format("grid file '{}': {}; its grids: {}", path,
                                        grid_name.empty() ? "no grid named 'density' (choose one with the 'grid' parameter)"
                                                          : fmt::format("no grid named '{}'", grid_name),
                                        names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
    if (const auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(chosen)) return densify<openvdb::FloatGrid, 1>(*f, path);
    if (const auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(chosen)) return densify<openvdb::Vec3SGrid, 3>(*v, path);
    throw GridFileError(fmt::format("grid file '{}': grid '{}' holds {} values; pathlab reads float and vec3s grids", path,
                                    chosen->getName(), chosen->valueType()));
}

void write_vdb(const std::string& path, const VoxelGrid& g, const std::string& grid_name, double voxel_size) {
    if (g.channels != 1) throw GridFileError(fmt::format("grid file '{}': pathlab writes 1-channel .vdb grids", path));
    initialise_openvdb();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(grid_name);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel_size));
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto acc = grid->getAccessor();
    for (int z = 0; z < g.res[2]; ++z)
        for (int y = 0; y < g.res[1]; ++y)
            for (int x = 0; x < g.res[0]; ++x)
                if (const float v = g.at(x, y, z, 0); v != 0) acc.setValue(openvdb::Coord(x, y, z), v);
    try {
        openvdb::io::File file(path);
        file.write({grid});
        file.close();
    } catch (const std::exception& e) {
        throw GridFileError(fmt::format("grid file '{}': cannot write it: {}", path, e.what()));
    }
}

}  // namespace
}  // namespace pathlab

// The module's entry points (vdb_file.cpp declares their types): true on success; otherwise
// `error` holds the message.
extern "C" bool pathlab_openvdb_read(const std::string* path, const std::string* grid_name, pathlab::VdbGrid* out,
                                     std::string* error) {
    try {
        *out = pathlab::read_vdb(*path, *grid_name);
        return true;
    } catch (const std::exception& e) {
        *error = e.what();
        return false;
    }
}

extern "C" bool pathlab_openvdb_write(const std::string* path, const pathlab::VoxelGrid* grid, const std::string* grid_name,
                                      double voxel_size, std::string* error) {
    try {
        pathlab::write_vdb(*path, *grid, *grid_name, voxel_size);
        return true;
    } catch (const std::exception& e) {
        *error = e.what();
        return false;
    }
}
