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

// Reads one grid of a file as OpenVDB's stream reader reads each (io/Stream.cc): the header,
// then, at the grid's descriptor, the descriptor and the grid; an instance gets its parent's tree.
// Only that grid is read (the stream reader reads every grid, of any type, which vdb_file.cpp
// could not check).
class OneGridReader : public openvdb::io::Archive {
public:
    openvdb::GridBase::Ptr read(std::istream& is, int64_t descriptor, int64_t parent_descriptor) {
        readHeader(is);
        openvdb::io::setStreamMetadataPtr(is, metadata_, /*transfer=*/false);
        openvdb::io::setVersion(is, libraryVersion(), fileVersion());
        openvdb::io::setDataCompression(is, compression());
        openvdb::GridBase::Ptr grid = read_at(is, descriptor);
        if (parent_descriptor >= 0) grid->setTree(read_at(is, parent_descriptor)->baseTreePtr());
        openvdb::io::clearStreamMetadataPtr(is);
        return grid;
    }

private:
    // The stream's metadata (format, compression, ...): OpenVDB keeps a pointer to this pointer.
    openvdb::io::StreamMetadata::Ptr metadata_ = std::make_shared<openvdb::io::StreamMetadata>();

    static openvdb::GridBase::Ptr read_at(std::istream& is, int64_t descriptor) {
        is.seekg(descriptor);
        openvdb::io::GridDescriptor gd;
        gd.read(is);
        openvdb::GridBase::Ptr grid = openvdb::GridBase::createGrid(gd.gridType());
        grid->setSaveFloatAsHalf(gd.saveFloatAsHalf());
        Archive::readGrid(grid, gd, is);
        return grid;
    }
};

// vdb_file.cpp's read_vdb_file, the only caller, checked that `path` is a regular file and, for
// the grid at `descriptor` (and its parent's at `parent_descriptor`, or -1), every count and size
// OpenVDB reads from it, and chose it by name.
VdbGrid read_vdb(const std::string& path, int64_t descriptor, int64_t parent_descriptor) {
    initialise_openvdb();
    openvdb::GridBase::Ptr grid;
    // From a stream that throws at the end of the file too.
    try {
        std::ifstream in(path, std::ios::binary);
        in.exceptions(std::ios::failbit | std::ios::badbit);
        grid = OneGridReader().read(in, descriptor, parent_descriptor);
    } catch (const std::ios_base::failure&) {
        throw GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: its grid data runs past the end of the file", path));
    } catch (const std::bad_alloc&) {
        throw GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: its grid data claims more memory than there is", path));
    } catch (const std::exception& e) {
        throw GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: {}", path, e.what()));
    }
    if (const auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(grid)) return densify<openvdb::FloatGrid, 1>(*f, path);
    if (const auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid)) return densify<openvdb::Vec3SGrid, 3>(*v, path);
    throw GridFileError(fmt::format("grid file '{}': grid '{}' holds {} values; pathlab reads float and vec3s grids", path,
                                    grid->getName(), grid->valueType()));
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
extern "C" bool pathlab_openvdb_read_grid(const std::string* path, int64_t descriptor, int64_t parent_descriptor,
                                          pathlab::VdbGrid* out, std::string* error) {
    try {
        *out = pathlab::read_vdb(*path, descriptor, parent_descriptor);
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
