// Writes .vdb files for the grid reader's tests with OpenVDB itself, in the forms other programs
// write and pathlab's own writer does not: half floats, zip and no compression, vec3s values,
// several grids (one of a type pathlab does not read), an instance sharing another grid's tree,
// tiles, inactive values of several kinds. Every grid's voxel (i, j, k) holds value(i, j, k)
// below (vec3s: value, 2 value, 3 value) over i in [-5, 14], j in [-3, 8], k in [-2, 5]: across
// the origin, so that the root has several children. Usage: vdb_fixture_writer DIR
#include <openvdb/openvdb.h>

#include <cstdio>
#include <string>

namespace {

// Exact in half floats too (multiples of 1/4 below 2048).
float value(int i, int j, int k) { return 0.25f * float((i + 5) + 2 * (j + 3) + 3 * (k + 2)) + 0.25f; }

template <typename GridT, typename F>
typename GridT::Ptr make(const std::string& name, double voxel, F&& at) {
    auto grid = GridT::create();
    grid->setName(name);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    auto acc = grid->getAccessor();
    for (int k = -2; k <= 5; ++k)
        for (int j = -3; j <= 8; ++j)
            for (int i = -5; i <= 14; ++i) acc.setValue(openvdb::Coord(i, j, k), at(i, j, k));
    return grid;
}

void write(const std::string& path, const openvdb::GridCPtrVec& grids, uint32_t compression) {
    openvdb::io::File file(path);
    file.setCompression(compression);
    file.write(grids);
    file.close();
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: vdb_fixture_writer DIR\n");
        return 2;
    }
    openvdb::initialize();
    const std::string dir = argv[1];
    using openvdb::io::COMPRESS_ACTIVE_MASK, openvdb::io::COMPRESS_BLOSC, openvdb::io::COMPRESS_ZIP, openvdb::io::COMPRESS_NONE;
    const auto scalar = [](int i, int j, int k) { return value(i, j, k); };
    const auto vector = [](int i, int j, int k) { return openvdb::Vec3s(value(i, j, k), 2 * value(i, j, k), 3 * value(i, j, k)); };

    auto half = make<openvdb::FloatGrid>("density", 0.5, scalar);
    half->setSaveFloatAsHalf(true);
    write(dir + "/half.vdb", {half}, COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK);
    write(dir + "/zip.vdb", {make<openvdb::Vec3SGrid>("density", 0.5, vector)}, COMPRESS_ZIP | COMPRESS_ACTIVE_MASK);
    write(dir + "/raw.vdb", {make<openvdb::FloatGrid>("density", 0.5, scalar)}, COMPRESS_NONE);

    // An int32 grid first (pathlab does not read its type, nor needs to), then the density, then
    // "smoke": an instance of the density's tree with voxels twice as large.
    auto labels = make<openvdb::Int32Grid>("labels", 0.5, [](int i, int j, int k) { return i * j * k; });
    auto density = make<openvdb::FloatGrid>("density", 0.5, scalar);
    auto smoke = openvdb::FloatGrid::create(density->treePtr());
    smoke->setName("smoke");
    smoke->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
    write(dir + "/multi.vdb", {labels, density, smoke}, COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK);

    // Tiles: an active 16^3 block of one value (pruned to a tile of an internal node), and
    // inactive voxels of other values than the background (stored as a leaf's inactive values).
    auto tiles = openvdb::FloatGrid::create(0.0f);
    tiles->setName("density");
    tiles->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    tiles->fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(15)), 2.0f, /*active=*/true);
    auto acc = tiles->getAccessor();
    for (int i = 16; i < 24; ++i) acc.setValueOff(openvdb::Coord(i, 0, 0), i % 2 ? -1.0f : 3.0f);
    acc.setValue(openvdb::Coord(20, 1, 1), 5.0f);
    tiles->tree().prune();
    write(dir + "/tiles.vdb", {tiles}, COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK);
    return 0;
}
