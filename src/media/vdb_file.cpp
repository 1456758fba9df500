// .vdb files through the OpenVDB module (openvdb_module.cpp, libpathlab_openvdb.so), loaded on
// first use: from $PATHLAB_OPENVDB_MODULE, else next to the running program, else where the
// build put it.
#include <dlfcn.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cctype>
#include <climits>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "media/grid_files.hpp"

#ifndef PATHLAB_OPENVDB_MODULE
#define PATHLAB_OPENVDB_MODULE ""
#endif

namespace pathlab {
namespace {

// read: the grid whose descriptor starts at the given byte, with the tree of the grid whose
// descriptor starts at the next (an instance's parent; -1: none).
using ReadFn = bool (*)(const std::string*, int64_t, int64_t, VdbGrid*, std::string*);
using WriteFn = bool (*)(const std::string*, const VoxelGrid*, const std::string*, double, std::string*);

struct OpenVdbModule {
    ReadFn read = nullptr;
    WriteFn write = nullptr;
    std::string error;  // why it could not be loaded
};

const OpenVdbModule& openvdb_module() {
    static const OpenVdbModule module = [] {
        OpenVdbModule m;
        std::vector<std::string> candidates;
        if (const char* env = std::getenv("PATHLAB_OPENVDB_MODULE"); env && *env) candidates.push_back(env);
        char exe[PATH_MAX];
        if (const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1); n > 0)
            candidates.push_back((std::filesystem::path(std::string(exe, size_t(n))).parent_path() / "libpathlab_openvdb.so").string());
        if (*PATHLAB_OPENVDB_MODULE) candidates.push_back(PATHLAB_OPENVDB_MODULE);
        std::vector<std::string> tried;
        for (const std::string& file : candidates) {
            std::error_code ec;
            if (!std::filesystem::exists(file, ec)) {
                tried.push_back(file + " (missing)");
                continue;
            }
            void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (!handle) {
                const char* why = dlerror();
                tried.push_back(fmt::format("{} ({})", file, why ? why : "dlopen failed"));
                continue;
            }
            m.read = reinterpret_cast<ReadFn>(dlsym(handle, "pathlab_openvdb_read_grid"));
            m.write = reinterpret_cast<WriteFn>(dlsym(handle, "pathlab_openvdb_write"));
            if (m.read && m.write) return m;
            tried.push_back(file + " (not pathlab's OpenVDB module)");
        }
        m.read = nullptr, m.write = nullptr;
        m.error = fmt::format("pathlab's OpenVDB module libpathlab_openvdb.so was not found: tried {}",
                              tried.empty() ? "nothing" : fmt::format("{}", fmt::join(tried, ", ")));
        return m;
    }();
    return module;
}


// Text read from a file, for a message: a corrupted file's names hold any bytes (control
// characters shown as \xNN).
std::string escaped(const std::string& text) {
    std::string shown;
    for (const unsigned char c : text) shown += (c >= 0x20 && c != 0x7f) ? std::string(1, char(c)) : fmt::format("\\x{:02x}", c);
    return shown;
}

// The size OpenVDB reads for a grid metadata value of a fixed-size type, whatever size the file
// gives (0: any size: strings, types it does not know). A file whose size disagrees would put
// OpenVDB's reading out of step with the file, reading lengths from the middle of values.
uint32_t fixed_metadata_size(const std::string& type) {
    static const std::vector<std::pair<std::string, uint32_t>> sizes = {
        {"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},  {"double", 8}, {"vec2i", 8},  {"vec2s", 8},
        {"vec2d", 16}, {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16}, {"vec4s", 16}, {"vec4d", 32},
        {"mat4s", 64}, {"mat4d", 128}};
    for (const auto& [name, size] : sizes)
        if (name == type) return size;
    return 0;
}

// A grid as the file's layout describes it.
struct VdbGridEntry {
    std::string name;    // as OpenVDB names it: the unique name without its "\x1e N" suffix
    std::string unique;  // the descriptor's name (unique in the file)
    std::string type;    // e.g. Tree_float_5_4_3, without "_HalfFloat"
    std::string parent;  // an instance's parent (its unique name), else ""
    uint64_t descriptor = 0, grid = 0, block = 0, end = 0;
    uint64_t transform = 0;    // where its transform starts (after its metadata)
    uint32_t compression = 0;  // OpenVDB's flags: 1 zip, 2 active mask, 4 blosc
    bool half = false;         // its metadata is_saved_as_half_float
};

// Reads a file's bytes for the checks: `at` the position, `limit` the end of the part being
// read (the file, a grid's header, a grid); every problem a GridFileError naming the file and
// the byte.
struct VdbBytes {
    std::string path;
    std::ifstream in;
    uint64_t size = 0, at = 0, limit = 0;

    GridFileError fail(const std::string& why) const {
        return GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: {} (at byte {} of {})", path, why, at, size));
    }
    void bytes(void* out, uint64_t n, const std::string& what) {
        if (n > limit - at) throw fail(fmt::format("{} ends inside its {}", limit == size ? "it" : "its part of the file", what));
        in.seekg(std::streamoff(at));
        in.read(static_cast<char*>(out), std::streamsize(n));
        if (!in) throw fail(fmt::format("its {} cannot be read", what));
        at += n;
    }
    template <typename T>
    T value(const std::string& what) {
        T v;
        bytes(&v, sizeof(T), what);
        return v;
    }
    void skip(uint64_t n, const std::string& what) {
        if (n > limit - at)
            throw fail(fmt::format("its {} claims {} bytes, more than {} left", what, n, limit == size ? "the file has" : "its part of the file has"));
        at += n;
    }
    void skip_string(const std::string& what) { skip(value<uint32_t>(what), what); }
    std::string string(const std::string& what) {
        const uint32_t n = value<uint32_t>(what);
        if (n > 4096) throw fail(fmt::format("its {} claims {} bytes", what, n));
        std::string s(n, '\0');
        bytes(s.data(), n, what);
        return s;
    }
};

// The layout of a .vdb file, checked before OpenVDB reads it (OpenVDB trusts it: a grid offset
// that points backwards made it loop forever, a file cut short inside its header too, a flipped
// metadata count or string length made it allocate gigabytes): the header (magic, file format 222
// to 224, with grid offsets, the UUID), the file's metadata, and for every grid its descriptor, its
// span (starting right after the descriptor, as OpenVDB writes it; data block and end after it,
// within the file), and the start of its data: the compression flags and every metadata entry
// (each string and value within the grid's header, fixed-size values of their size, the
// delayed-load table's counts within the file). The layout is OpenVDB's (io/Archive.cc,
// io/GridDescriptor.cc, Metadata.h, io/DelayedLoadMetadata.cc), file format 222 (OpenVDB 3) on.
std::vector<VdbGridEntry> check_vdb_layout(VdbBytes& r) {
    if (r.value<int64_t>("magic number") != 0x56444220) throw r.fail("no OpenVDB magic number");
    const uint32_t version = r.value<uint32_t>("file format version");
    if (version < 222 || version > 224)
        throw r.fail(fmt::format("file format version {}; pathlab reads 222 (OpenVDB 3) to 224", version));
    r.value<uint32_t>("library version"), r.value<uint32_t>("library version");
    if (r.value<char>("header") != 1) throw r.fail("its grids have no offsets (an OpenVDB 1 stream, not a file)");
    char uuid[36];
    r.bytes(uuid, 36, "UUID");
    for (int i = 0; i < 36; ++i)  // as OpenVDB reads it (boost's uuid >>): hex digits in 8-4-4-4-12
        if ((i == 8 || i == 13 || i == 18 || i == 23) ? uuid[i] != '-' : !std::isxdigit(static_cast<unsigned char>(uuid[i])))
            throw r.fail("its UUID is not 32 hexadecimal digits in groups of 8-4-4-4-12");
    const uint32_t metadata = r.value<uint32_t>("metadata count");
    if (metadata > r.size - r.at) throw r.fail(fmt::format("it claims {} metadata entries", metadata));
    for (uint32_t i = 0; i < metadata; ++i) r.skip_string("metadata name"), r.skip_string("metadata type"), r.skip_string("metadata value");
    const uint32_t grids = r.value<uint32_t>("grid count");
    if (grids > r.size - r.at) throw r.fail(fmt::format("it claims {} grids", grids));
    std::vector<VdbGridEntry> entries;
    for (uint32_t g = 0; g < grids; ++g) {
        VdbGridEntry e;
        e.descriptor = r.at;
        e.unique = r.string("grid name"), e.type = r.string("grid type"), e.parent = r.string("grid instance's parent name");
        e.name = e.unique.substr(0, e.unique.find('\x1e'));
        if (const std::string half = "_HalfFloat"; e.type.size() > half.size() && e.type.ends_with(half)) e.type.resize(e.type.size() - half.size());
        const int64_t grid = r.value<int64_t>("grid position"), written_block = r.value<int64_t>("grid position"),
                      end = r.value<int64_t>("grid position");
        // (An instance has no data block: OpenVDB leaves its position 0.)
        const int64_t block = e.parent.empty() || written_block != 0 ? written_block : end;
        if (!(int64_t(r.at) == grid && grid <= block && block <= end && uint64_t(end) <= r.size))
            throw r.fail(fmt::format("grid {} spans bytes {} (its data {}) to {}, not within its part of the file", g + 1, grid, block, end));
        e.grid = uint64_t(grid), e.block = uint64_t(block), e.end = uint64_t(end);
        r.limit = e.block;
        e.compression = r.value<uint32_t>("grid compression flags");
        const uint32_t count = r.value<uint32_t>("grid metadata count");
        if (count > r.limit - r.at) throw r.fail(fmt::format("grid {} claims {} metadata entries", g + 1, count));
        for (uint32_t i = 0; i < count; ++i) {
            const std::string name = escaped(r.string("grid metadata name")), type = r.string(fmt::format("grid metadata '{}''s type", name));
            const std::string what = fmt::format("grid metadata '{}' ({})", name, escaped(type));
            const uint32_t n = r.value<uint32_t>(what + "'s size");
            const uint64_t value = r.at;
            if (const uint32_t fixed = fixed_metadata_size(type); fixed != 0 && n != fixed) {
                r.skip(n, what);
                throw r.fail(fmt::format("its {} has {} bytes, not {}", what, n, fixed));
            }
            if (name == "is_saved_as_half_float") {  // how the tree's values are stored (the last entry counts)
                if (type != "bool") throw r.fail(fmt::format("its {} is not a bool", what));
                e.half = r.value<char>(what) != 0;
                continue;
            }
            r.skip(n, what);
            if (type != "__delayedload" || n == 0) continue;
            // The delayed-load table: a count (one entry per leaf node, each more than a byte of
            // the file), then a mask byte and a compressed size (8 bytes) per entry, each table
            // raw or blosc-compressed (its header's bytes 4-7: the uncompressed size).
            const uint64_t value_end = r.at;
            r.limit = value_end, r.at = value;
            const uint32_t leaves = r.value<uint32_t>(what + "'s count");
            if (leaves > r.size) throw r.fail(fmt::format("its {} claims {} leaf nodes", what, leaves));
            for (const uint64_t entry : {uint64_t(1), uint64_t(8)}) {
                const uint32_t packed = r.value<uint32_t>(what + "'s table size");
                if (entry == 8 && packed == UINT32_MAX) break;  // no compressed sizes
                if (packed == 0) {
                    r.skip(leaves * entry, what + "'s table");
                    continue;
                }
                const uint64_t table = r.at;
                r.skip(4, what + "'s blosc header");
                if (const uint32_t unpacked = r.value<uint32_t>(what + "'s blosc header"); unpacked != leaves * entry)
                    throw r.fail(fmt::format("its {} has a table of {} bytes for {} entries", what, unpacked, leaves));
                r.at = table;
                r.skip(packed, what + "'s table");
            }
            r.at = value_end, r.limit = e.block;
        }
        e.transform = r.at;
        entries.push_back(e);
        r.limit = r.size;
        r.at = e.end;
    }
    return entries;
}

// A grid's transform and tree, checked as OpenVDB reads them (Archive::readGrid, Transform::read
// and the maps' read, the nodes' readTopology and readBuffers, io::readCompressedValues and
// readData, for a 5-4-3 tree in file format 222 on, read from a stream that is not seekable), so
// that every count and size OpenVDB reads and allocates by is one the grid's bytes hold: masks
// and tiles within the grid, every compressed chunk no longer than what is left of the grid and
// (blosc) its header agreeing with it, the tree's nodes within a memory bound. OpenVDB
// allocates a compressed chunk's claimed size before reading it, so this must come first.
class VdbTreeCheck {
public:
    VdbTreeCheck(VdbBytes& r, const VdbGridEntry& g, uint64_t value_size, uint64_t half_size)
        : r_(r), g_(g), value_(value_size), stored_(g.half ? half_size : value_size) {}

    void transform() {
        r_.at = g_.transform, r_.limit = g_.end;
        const std::string map = r_.string(what("transform's map type"));
        // The maps' read(): Mat4d (affine, unitary), five Vec3d (scale), Vec3d (translation), six Vec3d.
        static const std::vector<std::pair<std::string, uint64_t>> sizes = {
            {"AffineMap", 128}, {"UnitaryMap", 128}, {"ScaleMap", 120}, {"UniformScaleMap", 120},
            {"TranslationMap", 24}, {"ScaleTranslateMap", 144}, {"UniformScaleTranslateMap", 144}};
        for (const auto& [name, size] : sizes)
            if (name == map) return r_.skip(size, what("transform"));
        if (map == "NonlinearFrustumMap")
            throw GridFileError(fmt::format("grid file '{}': grid '{}': only grids with a linear transform are supported (not frustum grids)",
                                            r_.path, escaped(g_.name)));
        throw r_.fail(what(fmt::format("transform is a '{}', not a map OpenVDB has", escaped(map))));
    }

    // After transform(): the tree's topology, then its leaves' buffers.
    void tree() {
        if (const int32_t buffers = r_.value<int32_t>(what("tree's buffer count")); buffers != 1)
            throw r_.fail(what(fmt::format("tree has {} buffers, not 1 (as every OpenVDB since 2.0 writes)", buffers)));
        r_.skip(value_, what("tree's background"));
        const uint32_t tiles = r_.value<uint32_t>(what("root's tile count")), children = r_.value<uint32_t>(what("root's child count"));
        if (tiles > (r_.limit - r_.at) / (12 + value_ + 1)) throw r_.fail(what(fmt::format("root claims {} tiles", tiles)));
        r_.skip(uint64_t(tiles) * (12 + value_ + 1), what("root's tiles"));
        node_bytes_ += uint64_t(tiles) * 64;
        // The root keeps its children in a map by origin (a second child of one origin replaces
        // the first), and reads their buffers in the map's order: only the leaf counts matter.
        std::map<std::array<int32_t, 3>, uint64_t> leaves;
        for (uint32_t c = 0; c < children; ++c) {
            std::array<int32_t, 3> origin;
            r_.bytes(origin.data(), 12, what("root child's origin"));
            leaves[origin] = internal(5);
        }
        uint64_t total = 0;
        for (const auto& [origin, n] : leaves) total += n;
        for (uint64_t l = 0; l < total; ++l) {
            const uint64_t active = mask(512, "leaf's value mask");
            values(512, active);
        }
    }

private:
    std::string what(const std::string& part) const { return fmt::format("grid '{}''s {}", escaped(g_.name), part); }

    // A node mask of `bits` bits: the number of bits on.
    uint64_t mask(uint64_t bits, const std::string& part) {
        std::vector<uint64_t> words(bits / 64);
        r_.bytes(words.data(), bits / 8, what(part));
        uint64_t on = 0;
        for (const uint64_t w : words) on += uint64_t(std::popcount(w));
        return on;
    }

    // An internal node of 2^(3 log2dim) slots (log2dim 5: its children internal nodes of log2dim
    // 4, whose children are leaves): returns the number of leaves below it.
    uint64_t internal(int log2dim) {
        const uint64_t slots = uint64_t(1) << (3 * log2dim);
        // In memory: a child pointer or value per slot (16 bytes at most for float and vec3s) and
        // a temporary array of the values while reading them.
        node_bytes_ += slots * (16 + value_);
        if (node_bytes_ > kMaxTreeBytes)
            throw r_.fail(what(fmt::format("tree would take more than {} GiB of memory", kMaxTreeBytes >> 30)));
        const uint64_t children = mask(slots, "internal node's child mask");
        const uint64_t active = mask(slots, "internal node's value mask");
        values(slots, active);
        uint64_t leaves = 0;
        for (uint64_t c = 0; c < children; ++c) {
            if (log2dim == 5) {
                leaves += internal(4);
            } else {
                r_.skip(64, what("leaf's value mask"));
                node_bytes_ += 512 * value_ + 96;
                if (node_bytes_ > kMaxTreeBytes)
                    throw r_.fail(what(fmt::format("tree would take more than {} GiB of memory", kMaxTreeBytes >> 30)));
                ++leaves;
            }
        }
        return leaves;
    }

    // io::readCompressedValues of a node of `slots` values, `active` of them active.
    void values(uint64_t slots, uint64_t active) {
        const int8_t metadata = r_.value<int8_t>(what("node's compression byte"));
        if (metadata == 2 || metadata == 4 || metadata == 5) r_.skip(value_, what("node's inactive value"));
        if (metadata == 5) r_.skip(value_, what("node's second inactive value"));
        if (metadata == 3 || metadata == 4 || metadata == 5) r_.skip(slots / 8, what("node's selection mask"));
        const uint64_t count = ((g_.compression & 2) && metadata != 6) ? active : slots;
        if (g_.half && count == 0) return;  // (OpenVDB's half reader reads nothing then)
        const uint64_t bytes = count * stored_;
        if (!(g_.compression & 5)) return r_.skip(bytes, what("node's values"));
        // A zip or blosc chunk: its size (negative: stored as it is), then its bytes.
        const int64_t n = r_.value<int64_t>(what("node's compressed size"));
        if (n <= 0) {
            if (uint64_t(0) - uint64_t(n) != bytes)
                throw r_.fail(what(fmt::format("node's values take {} bytes, not {}", uint64_t(0) - uint64_t(n), bytes)));
            return r_.skip(bytes, what("node's values"));
        }
        if (uint64_t(n) > r_.limit - r_.at) throw r_.fail(what(fmt::format("node's compressed values claim {} bytes, more than the grid has left", n)));
        if (g_.compression & 4) {  // blosc: its header's sizes (bytes 4-7 unpacked, 12-15 packed) are the chunk's
            uint32_t header[4] = {0, 0, 0, 0};
            if (n < 16) throw r_.fail(what(fmt::format("node's blosc chunk has {} bytes, less than its header", n)));
            r_.bytes(header, 16, what("node's blosc header"));
            r_.at -= 16;
            if (header[1] != bytes || header[3] != uint64_t(n))
                throw r_.fail(what(fmt::format("node's blosc chunk ({} bytes) has a header of a chunk of {} bytes holding {}; the node's values take {}",
                                                  n, header[3], header[1], bytes)));
        }
        r_.skip(uint64_t(n), what("node's compressed values"));
    }

    // What the tree's nodes may take in memory (the file's bytes bound it too, at about 64 times).
    static constexpr uint64_t kMaxTreeBytes = uint64_t(4) << 30;

    VdbBytes& r_;
    const VdbGridEntry& g_;
    const uint64_t value_, stored_;  // a value's bytes in memory, and as stored (half floats)
    uint64_t node_bytes_ = 0;
};

// The bytes of a value of the grid types pathlab reads, in memory and as half floats (0: a type
// pathlab does not read).
std::pair<uint64_t, uint64_t> value_bytes(const std::string& type) {
    if (type == "Tree_float_5_4_3") return {4, 2};
    if (type == "Tree_vec3s_5_4_3") return {12, 6};
    return {0, 0};
}

}  // namespace

VdbGrid read_vdb_file(const std::string& path, const std::string& grid_name) {
    const OpenVdbModule& m = openvdb_module();
    if (!m.read) throw GridFileError(fmt::format("grid file '{}': {}", path, m.error));
    require_regular_grid_file(path);  // before the checks open it (a named pipe: a hang)
    VdbBytes r{path, std::ifstream(path, std::ios::binary)};
    std::error_code ec;
    r.size = r.limit = std::filesystem::file_size(path, ec);
    if (ec || !r.in) throw GridFileError(fmt::format("grid file '{}': cannot read it{}", path, ec ? ": " + ec.message() : ""));
    const std::vector<VdbGridEntry> grids = check_vdb_layout(r);
    // The grid: by name (the last of that name, as OpenVDB's stream reader left it), "density",
    // or the only one.
    const VdbGridEntry* chosen = nullptr;
    std::vector<std::string> names;
    for (const VdbGridEntry& g : grids) {
        names.push_back(escaped(g.name));
        if (g.name == (grid_name.empty() ? "density" : grid_name)) chosen = &g;
    }
    if (!chosen && grid_name.empty() && grids.size() == 1) chosen = &grids.front();
    if (!chosen)
        throw GridFileError(fmt::format("grid file '{}': {}; its grids: {}", path,
                                        grid_name.empty() ? "no grid named 'density' (choose one with the 'grid' parameter)"
                                                          : fmt::format("no grid named '{}'", grid_name),
                                        names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
    const auto [value, half] = value_bytes(chosen->type);
    if (value == 0) {
        std::string type = chosen->type;  // Tree_<value type>_5_4_3, as OpenVDB names a grid type
        if (type.starts_with("Tree_") && type.ends_with("_5_4_3")) type = type.substr(5, type.size() - 11);
        throw GridFileError(fmt::format("grid file '{}': grid '{}' holds {} values; pathlab reads float and vec3s grids", path,
                                        escaped(chosen->name), escaped(type)));
    }
    // An instance shares the tree of its parent: OpenVDB reads the instance's transform and the
    // parent's whole grid.
    const VdbGridEntry* source = chosen;
    if (!chosen->parent.empty()) {
        source = nullptr;
        for (const VdbGridEntry& g : grids)
            if (g.unique == chosen->parent && g.parent.empty() && g.type == chosen->type) source = &g;
        if (!source)
            throw GridFileError(fmt::format("grid file '{}': grid '{}' is an instance of '{}', which the file has not as a grid of its type", path,
                                            escaped(chosen->name), escaped(chosen->parent)));
    }
    VdbTreeCheck(r, *chosen, value, half).transform();
    if (source != chosen) VdbTreeCheck(r, *source, value, half).transform();
    VdbTreeCheck(r, *source, value, half).tree();
    VdbGrid out;
    std::string error;
    const int64_t parent = source == chosen ? -1 : int64_t(source->descriptor);
    if (!m.read(&path, int64_t(chosen->descriptor), parent, &out, &error)) throw GridFileError(escaped(error));
    return out;
}

void write_vdb_file(const std::string& path, const VoxelGrid& grid, const std::string& grid_name, double voxel_size) {
    const OpenVdbModule& m = openvdb_module();
    if (!m.write) throw GridFileError(fmt::format("grid file '{}': {}", path, m.error));
    std::string error;
    if (!m.write(&path, &grid, &grid_name, voxel_size, &error)) throw GridFileError(error);
}

}  // namespace pathlab
