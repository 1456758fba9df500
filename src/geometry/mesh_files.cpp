#include "geometry/mesh_files.hpp"

#include <assimp/Importer.hpp>
#include <assimp/mesh.h>
#include <assimp/scene.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "core/input_file.hpp"

namespace pathlab {
namespace {

// Meshes larger than this are refused (a header claiming billions of vertices).
constexpr uint64_t kMaxElements = uint64_t(1) << 28;

void require_regular_file(const std::string& path) {
    try {
        require_input_file(path);
    } catch (const InputFileError& e) {
        throw MeshLoadError(fmt::format("cannot read mesh '{}': {}", path, e.what()));
    }
}

void check_finite(const MeshDesc& m, const std::string& path) {
    for (const Vec3f& p : m.positions)
        if (!is_finite(p)) throw MeshLoadError(fmt::format("mesh '{}' has a non-finite vertex", path));
    for (const Vec3f& n : m.normals)
        if (!is_finite(n)) throw MeshLoadError(fmt::format("mesh '{}' has a non-finite normal", path));
    for (const Vec2f& t : m.uvs)
        if (!std::isfinite(t.x) || !std::isfinite(t.y)) throw MeshLoadError(fmt::format("mesh '{}' has a non-finite texture coordinate", path));
    if (m.triangles.empty()) throw MeshLoadError(fmt::format("mesh '{}' has no faces", path));
}

// A PLY file read and checked before Assimp sees it (Assimp hangs on a header without end_header,
// crashes on some broken binary ones, and takes a list's count on trust: an ASCII face claiming
// 20 million indices, followed by 3, became a polygon of 20 million zeros, 2.8 GB): the header
// must start with "ply", give its format, end with end_header within kMaxPlyHeader bytes, and
// declare no more elements than the rest of the file can hold at their smallest (a binary
// property's size; an ASCII value at least "0 "); then the body is walked as the header
// describes it, and every list's count must be a count whose values the file holds.
constexpr size_t kMaxPlyHeader = size_t(1) << 20;

size_t ply_type_size(const std::string& type) {
    static const std::pair<const char*, size_t> sizes[] = {{"char", 1},   {"uchar", 1},   {"int8", 1},  {"uint8", 1},   {"short", 2},
                                                          {"ushort", 2}, {"int16", 2},   {"uint16", 2}, {"int", 4},     {"uint", 4},
                                                          {"int32", 4},  {"uint32", 4},  {"float", 4}, {"float32", 4}, {"double", 8},
                                                          {"float64", 8}};
    for (const auto& [name, size] : sizes)
        if (type == name) return size;
    return 0;
}

struct PlyProperty {
    std::string name;
    std::string type;       // a value's type (a list's items')
    size_t size = 0;        // a value's bytes (binary)
    size_t count_size = 0;  // a list's count's bytes; 0: not a list
    bool count_signed = false;
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

// What check_ply_file found: the format, the elements and where the body starts.
struct PlyLayout {
    bool binary = false, big_endian = false;
    std::vector<PlyElement> elements;
    uint64_t header_bytes = 0, body = 0;
};

// The body of a PLY file, read forward through a buffer.
class PlyBody {
public:
    PlyBody(std::ifstream& in, uint64_t size) : in_(in), left_(size) {}
    uint64_t left() const { return left_ + (end_ - at_); }
    bool byte(unsigned char& c) {
        if (at_ == end_ && !fill()) return false;
        c = static_cast<unsigned char>(buffer_[at_++]);
        return true;
    }
    bool bytes(void* out, size_t n) {
        auto* o = static_cast<char*>(out);
        for (size_t i = 0; i < n; ++i) {
            unsigned char c;
            if (!byte(c)) return false;
            o[i] = char(c);
        }
        return true;
    }
    bool skip(uint64_t n) {
        if (n > left()) return false;
        const uint64_t buffered = std::min<uint64_t>(n, end_ - at_);
        at_ += size_t(buffered), n -= buffered;
        if (n > 0) in_.seekg(std::streamoff(n), std::ios::cur), left_ -= n;
        return true;
    }
    // The next whitespace-separated word (ASCII), or false at the end of the file.
    bool word(std::string& out) {
        out.clear();
        unsigned char c;
        do {
            if (!byte(c)) return false;
        } while (std::isspace(c));
        do {
            if (out.size() < 64) out += char(c);
        } while (byte(c) && !std::isspace(c));
        return true;
    }

private:
    bool fill() {
        if (left_ == 0) return false;
        const size_t n = size_t(std::min<uint64_t>(left_, buffer_.size()));
        in_.read(buffer_.data(), std::streamsize(n));
        if (!in_) return false;
        left_ -= n, at_ = 0, end_ = n;
        return true;
    }
    std::ifstream& in_;
    uint64_t left_;  // bytes of the file not yet in the buffer
    std::vector<char> buffer_ = std::vector<char>(size_t(1) << 16);
    size_t at_ = 0, end_ = 0;
};

// n bytes of a binary PLY integer, in little-endian order, as an unsigned number.
uint64_t ply_unsigned(const unsigned char* b, size_t n) {
    uint64_t u = 0;
    for (size_t k = 0; k < n; ++k) u |= uint64_t(b[k]) << (8 * k);
    return u;
}

PlyLayout check_ply_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw MeshLoadError(fmt::format("cannot read mesh '{}'", path));
    const uint64_t file_size = std::filesystem::file_size(path);
    const auto fail = [&](int line, const std::string& what) {
        throw MeshLoadError(fmt::format("mesh '{}', header line {}: {}", path, line, what));
    };
    std::string text;
    bool binary = false, big_endian = false, format = false, ended = false;
    std::vector<PlyElement> elements;
    size_t header_bytes = 0;
    for (int line = 1; std::getline(in, text); ++line) {
        header_bytes += text.size() + 1;
        if (header_bytes > kMaxPlyHeader) fail(line, fmt::format("no end_header within the first {} bytes", kMaxPlyHeader));
        if (!text.empty() && text.back() == '\r') text.pop_back();
        std::istringstream words(text);
        std::string key;
        words >> key;
        if (line == 1) {
            if (key != "ply") fail(1, "a PLY file starts with the line 'ply'");
            continue;
        }
        if (key == "end_header") {
            ended = true;
            break;
        }
        if (key.empty() || key == "comment" || key == "obj_info") continue;
        if (key == "format") {
            std::string f;
            words >> f;
            if (f != "ascii" && f != "binary_little_endian" && f != "binary_big_endian")
                fail(line, fmt::format("unknown format '{}' (ascii, binary_little_endian or binary_big_endian)", f));
            binary = f != "ascii", big_endian = f == "binary_big_endian", format = true;
        } else if (key == "element") {
            std::string name, count;
            words >> name >> count;
            if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos || count.size() > 12)
                fail(line, fmt::format("element '{}' has no count", name));
            elements.push_back({name, std::stoull(count), {}});
            if (elements.back().count > kMaxElements) fail(line, fmt::format("element '{}' claims {} items: too large", name, elements.back().count));
        } else if (key == "property") {
            if (elements.empty()) fail(line, "a property before any element");
            std::string type;
            words >> type;
            PlyProperty p;
            if (type == "list") {
                std::string count_type, item_type;
                words >> count_type >> item_type;
                if (!ply_type_size(count_type) || !ply_type_size(item_type)) fail(line, "a list property needs two known types");
                if (count_type.find("float") != std::string::npos || count_type == "double") fail(line, "a list's count must have an integer type");
                p.size = ply_type_size(item_type), p.count_size = ply_type_size(count_type), p.type = item_type;
                p.count_signed = count_type[0] != 'u';
            } else {
                if (!ply_type_size(type)) fail(line, fmt::format("unknown property type '{}'", type));
                p.size = ply_type_size(type), p.type = type;
            }
            words >> p.name;
            elements.back().properties.push_back(p);
        } else {
            fail(line, fmt::format("unknown header line '{}'", text.substr(0, 40)));
        }
    }
    if (!ended) throw MeshLoadError(fmt::format("mesh '{}': the header has no end_header line (the file ends in it)", path));
    if (!format) throw MeshLoadError(fmt::format("mesh '{}': the header has no format line", path));
    uint64_t minimum_body = 0;
    for (const PlyElement& e : elements) {
        uint64_t item = 0;
        for (const PlyProperty& p : e.properties) item += binary ? (p.count_size ? p.count_size : p.size) : 2;
        minimum_body += e.count * item;
    }
    if (!binary && minimum_body > 0) --minimum_body;  // (the last value needs no separator after it)
    const uint64_t body = file_size > header_bytes ? file_size - header_bytes : 0;
    if (minimum_body > body)
        throw MeshLoadError(fmt::format("mesh '{}': the header's elements need at least {} bytes, the file holds {} after it", path, minimum_body, body));

    // The body, as the header describes it.
    PlyBody reader(in, body);
    std::string word;
    // An ASCII value must be a number (Assimp read "-1" followed by control characters as a
    // number and leaked its parser's state): a decimal or nan / inf, shown escaped when not.
    const auto ascii_value = [&](const PlyElement& e, uint64_t i, const PlyProperty& p) {
        const char* first = word.data() + (word.starts_with('+') ? 1 : 0);
        double v;
        const auto [end, ec] = std::from_chars(first, word.data() + word.size(), v);
        if (ec == std::errc() && end == word.data() + word.size() && first != end) return;
        std::string shown;
        for (const unsigned char c : word) shown += std::isprint(c) ? std::string(1, char(c)) : fmt::format("\\x{:02x}", c);
        throw MeshLoadError(fmt::format("mesh '{}': element '{}' (item {} of {}): its property '{}' is '{}', not a number", path, e.name,
                                        i + 1, e.count, p.name, shown));
    };
    for (const PlyElement& e : elements) {
        const bool lists = std::any_of(e.properties.begin(), e.properties.end(), [](const PlyProperty& p) { return p.count_size > 0; });
        if (binary && !lists) {  // fixed-size items, skipped at once
            uint64_t item = 0;
            for (const PlyProperty& p : e.properties) item += p.size;
            if (!reader.skip(e.count * item))
                throw MeshLoadError(fmt::format("mesh '{}': the file ends inside element '{}' ({} items of {} bytes)", path, e.name, e.count, item));
            continue;
        }
        for (uint64_t i = 0; i < e.count; ++i)
            for (const PlyProperty& p : e.properties) {
                const auto ends = [&](const std::string& inside) {
                    return MeshLoadError(fmt::format("mesh '{}': the file ends inside element '{}' (item {} of {}){}", path, e.name, i + 1, e.count, inside));
                };
                if (p.count_size == 0) {  // one value
                    if (binary ? !reader.skip(p.size) : !reader.word(word)) throw ends("");
                    if (!binary) ascii_value(e, i, p);
                    continue;
                }
                int64_t n = 0;
                if (binary) {
                    unsigned char b[8] = {};
                    if (!reader.bytes(b, p.count_size)) throw ends("");
                    if (big_endian) std::reverse(b, b + p.count_size);
                    const bool negative = p.count_signed && (b[p.count_size - 1] & 0x80);
                    n = negative ? -1 : int64_t(ply_unsigned(b, p.count_size));
                } else {
                    if (!reader.word(word)) throw ends("");
                    if (word.empty() || word.size() > 12 || word.find_first_not_of("0123456789") != std::string::npos)
                        throw MeshLoadError(fmt::format("mesh '{}': element '{}' (item {} of {}): its list '{}' has the count '{}', not a count",
                                                        path, e.name, i + 1, e.count, p.name, word));
                    n = int64_t(std::stoull(word));
                }
                const uint64_t least = binary ? p.size : 1;  // an ASCII value and a space, but the last
                if (n < 0 || uint64_t(n) > kMaxElements || uint64_t(n) * least > reader.left())
                    throw MeshLoadError(fmt::format("mesh '{}': element '{}' (item {} of {}): its list '{}' claims {} values, more than the "
                                                    "file holds after it ({} bytes)",
                                                    path, e.name, i + 1, e.count, p.name, n, reader.left()));
                for (int64_t k = 0; k < n; ++k) {
                    if (binary ? !reader.skip(p.size) : !reader.word(word))
                        throw ends(fmt::format(", in its list '{}' of {} values", p.name, n));
                    if (!binary) ascii_value(e, i, p);
                }
            }
    }
    return {binary, big_endian, std::move(elements), header_bytes, body};
}

// A binary PLY value of `type` (size bytes, already in the file's byte order reversed to
// little-endian) as a double.
double ply_binary_value(const unsigned char* b, const std::string& type) {
    const auto as = [&]<class V>(V) {
        V v;
        std::memcpy(&v, b, sizeof v);
        return double(v);
    };
    if (type == "char" || type == "int8") return as(int8_t());
    if (type == "uchar" || type == "uint8") return as(uint8_t());
    if (type == "short" || type == "int16") return as(int16_t());
    if (type == "ushort" || type == "uint16") return as(uint16_t());
    if (type == "int" || type == "int32") return as(int32_t());
    if (type == "uint" || type == "uint32") return as(uint32_t());
    if (type == "float" || type == "float32") return as(float());
    return as(double());
}

// The vertex and face properties a PLY file has beyond what Assimp reads (positions, normals,
// texture coordinates, the faces' indices), as Mitsuba 3 names them (core/mesh_attributes.hpp):
// "<base>_0", "<base>_1", ... one attribute of that many channels (1 or 3 are kept); r, g, b
// (or red, green, blue) "color", an unsigned char one divided by 255; any other single value an
// attribute of its own. Vertex values are spread to the corners of the triangles Assimp's faces
// become (fans (0, i, i + 1), in the file's order), face values to each triangle of their face.
MeshAttributes read_ply_attributes(const std::string& path, const PlyLayout& layout) {
    static const char* const kRead[] = {"x", "y", "z", "nx", "ny", "nz", "u", "v", "s", "t", "texture_u", "texture_v", "texture_s",
                                        "texture_t", "vertex_indices", "vertex_index", "alpha", "a"};
    struct Group {
        std::string name;
        std::vector<int> properties;  // the element's property indices, channel by channel
        bool bytes = false;            // unsigned char colour: divided by 255
    };
    const auto groups_of = [&](const PlyElement& e, const std::string& prefix) {
        std::vector<Group> groups;
        const auto find = [&](const std::string& n) {
            for (size_t i = 0; i < e.properties.size(); ++i)
                if (e.properties[i].name == n && !e.properties[i].count_size) return int(i);
            return -1;
        };
        std::vector<bool> used(e.properties.size(), false);
        for (const auto& rgb : {std::array<const char*, 3>{"r", "g", "b"}, std::array<const char*, 3>{"red", "green", "blue"}}) {
            const int r = find(rgb[0]), g = find(rgb[1]), b = find(rgb[2]);
            if (r < 0 || g < 0 || b < 0) continue;
            const bool bytes = e.properties[size_t(r)].type == "uchar" || e.properties[size_t(r)].type == "uint8";
            groups.push_back({prefix + "color", {r, g, b}, bytes});
            used[size_t(r)] = used[size_t(g)] = used[size_t(b)] = true;
        }
        for (size_t i = 0; i < e.properties.size(); ++i) {
            const PlyProperty& p = e.properties[i];
            if (used[i] || p.count_size || std::any_of(std::begin(kRead), std::end(kRead), [&](const char* k) { return p.name == k; })) continue;
            const size_t cut = p.name.rfind('_');
            if (cut != std::string::npos && p.name.substr(cut + 1) == "0") {  // base_0, base_1, ...
                const std::string base = p.name.substr(0, cut);
                Group g{prefix + base, {}, false};
                for (int k = 0;; ++k) {
                    const int j = find(base + "_" + std::to_string(k));
                    if (j < 0) break;
                    g.properties.push_back(j);
                    used[size_t(j)] = true;
                }
                if (g.properties.size() == 1 || g.properties.size() == 3) groups.push_back(std::move(g));
                continue;
            }
            if (cut != std::string::npos && p.name.find_first_not_of("0123456789", cut + 1) == std::string::npos) continue;  // base_k of a group
            groups.push_back({prefix + p.name, {int(i)}, false});
            used[i] = true;
        }
        return groups;
    };
    const PlyElement* vertex = nullptr;
    const PlyElement* face = nullptr;
    for (const PlyElement& e : layout.elements) {
        if (e.name == "vertex" && !vertex) vertex = &e;
        if (e.name == "face" && !face) face = &e;
    }
    if (!vertex || !face) return {};
    const std::vector<Group> vertex_groups = groups_of(*vertex, "vertex_"), face_groups = groups_of(*face, "face_");
    if (vertex_groups.empty() && face_groups.empty()) return {};

    std::ifstream in(path, std::ios::binary);
    in.seekg(std::streamoff(layout.header_bytes));
    PlyBody reader(in, layout.body);
    std::string word;
    const auto value = [&](const PlyProperty& p) {
        if (!layout.binary) {
            reader.word(word);
            double v = 0;
            std::from_chars(word.data() + (word.starts_with('+') ? 1 : 0), word.data() + word.size(), v);
            return v;
        }
        unsigned char b[8] = {};
        reader.bytes(b, p.size);
        if (layout.big_endian) std::reverse(b, b + p.size);
        return ply_binary_value(b, p.type);
    };
    const auto count = [&](const PlyProperty& p) {
        if (!layout.binary) {
            reader.word(word);
            return uint64_t(std::stoull(word));
        }
        unsigned char b[8] = {};
        reader.bytes(b, p.count_size);
        if (layout.big_endian) std::reverse(b, b + p.count_size);
        return ply_unsigned(b, p.count_size);
    };
    // Every element's values, kept for the vertex and face elements (check_ply_file walked the
    // same body, so the counts and lists hold).
    std::vector<std::vector<double>> vertex_values(vertex->properties.size()), face_values(face->properties.size());
    std::vector<std::vector<uint32_t>> polygons;
    for (const PlyElement& e : layout.elements) {
        const bool is_vertex = &e == vertex, is_face = &e == face;
        for (uint64_t i = 0; i < e.count; ++i)
            for (size_t k = 0; k < e.properties.size(); ++k) {
                const PlyProperty& p = e.properties[k];
                if (!p.count_size) {
                    const double v = value(p);
                    if (is_vertex) vertex_values[k].push_back(v);
                    if (is_face) face_values[k].push_back(v);
                    continue;
                }
                const uint64_t n = count(p);
                std::vector<uint32_t> list;
                for (uint64_t j = 0; j < n; ++j) {
                    const double v = value(p);  // (an index out of range is refused below)
                    list.push_back(v >= 0 && v < 4294967295.0 ? uint32_t(v) : 0xffffffffu);
                }
                if (is_face && (p.name == "vertex_indices" || p.name == "vertex_index")) polygons.push_back(std::move(list));
            }
    }
    MeshAttributes out;
    const auto spread = [&](const Group& g, bool per_face) {
        MeshAttribute a{g.name, per_face, int(g.properties.size()), {}};
        const auto& values = per_face ? face_values : vertex_values;
        const auto channel = [&](size_t c, size_t item) {
            const double v = values[size_t(g.properties[c])][item];
            return float(g.bytes ? v / 255.0 : v);
        };
        for (size_t f = 0; f < polygons.size(); ++f) {
            const std::vector<uint32_t>& poly = polygons[f];
            for (const uint32_t v : poly)
                if (v >= vertex->count)
                    throw MeshLoadError(fmt::format("mesh '{}': face {} refers to vertex {}, and the file has {}", path, f + 1, v, vertex->count));
            for (size_t i = 1; i + 1 < poly.size(); ++i)
                for (const uint32_t corner : {poly[0], poly[i], poly[i + 1]}) {
                    for (size_t c = 0; c < g.properties.size(); ++c) a.values.push_back(per_face ? channel(c, f) : channel(c, corner));
                    if (per_face) break;
                }
        }
        out.push_back(std::move(a));
    };
    for (const Group& g : vertex_groups) spread(g, false);
    for (const Group& g : face_groups) spread(g, true);
    return out;
}

}  // namespace

MeshDesc load_ply_mesh(const std::string& path) {
    require_regular_file(path);
    const PlyLayout layout = check_ply_file(path);
    Assimp::Importer importer;
    // No post-processing: Assimp's own steps would triangulate differently, join identical
    // vertices or reorder; the fan below is Mitsuba's.
    const aiScene* scene = importer.ReadFile(path, 0);
    if (!scene || !scene->mRootNode)
        throw MeshLoadError(fmt::format("cannot read mesh '{}': {}", path, importer.GetErrorString()));
    MeshDesc m;
    m.name = path;
    bool normals = true, uvs = true;
    for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
        normals = normals && scene->mMeshes[k]->HasNormals();
        uvs = uvs && scene->mMeshes[k]->HasTextureCoords(0);
    }
    for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
        const aiMesh* a = scene->mMeshes[k];
        const uint32_t base = uint32_t(m.positions.size());
        if (uint64_t(base) + a->mNumVertices > kMaxElements) throw MeshLoadError(fmt::format("mesh '{}' is too large", path));
        for (unsigned v = 0; v < a->mNumVertices; ++v) {
            m.positions.push_back({a->mVertices[v].x, a->mVertices[v].y, a->mVertices[v].z});
            if (normals) m.normals.push_back({a->mNormals[v].x, a->mNormals[v].y, a->mNormals[v].z});
            if (uvs) m.uvs.push_back({a->mTextureCoords[0][v].x, a->mTextureCoords[0][v].y});
        }
        for (unsigned f = 0; f < a->mNumFaces; ++f) {
            const aiFace& face = a->mFaces[f];
            for (unsigned i = 0; i < face.mNumIndices; ++i)
                if (face.mIndices[i] >= a->mNumVertices) throw MeshLoadError(fmt::format("mesh '{}' refers to a vertex that does not exist", path));
            for (unsigned i = 1; i + 1 < face.mNumIndices; ++i)
                m.triangles.push_back({base + face.mIndices[0], base + face.mIndices[i], base + face.mIndices[i + 1]});
        }
    }
    check_finite(m, path);
    m.attributes = read_ply_attributes(path, layout);
    for (const MeshAttribute& a : m.attributes) {
        const size_t items = a.per_face ? m.triangles.size() : 3 * m.triangles.size();
        if (a.values.size() != items * size_t(a.channels))
            throw MeshLoadError(fmt::format("mesh '{}': its attribute '{}' does not match the {} triangles Assimp read", path, a.name,
                                            m.triangles.size()));
        for (const float v : a.values)
            if (!std::isfinite(v)) throw MeshLoadError(fmt::format("mesh '{}': its attribute '{}' has a non-finite value", path, a.name));
    }
    return m;
}

namespace {

// The inflated bytes of one shape, read incrementally (never more than `limit` bytes).
class Inflater {
public:
    Inflater(const unsigned char* data, size_t size, const std::string& path) : path_(path) {
        std::memset(&z_, 0, sizeof z_);
        if (inflateInit(&z_) != Z_OK) throw MeshLoadError(fmt::format("mesh '{}': zlib failed to start", path));
        z_.next_in = const_cast<unsigned char*>(data);
        z_.avail_in = uInt(std::min<size_t>(size, 0xffffffffu));
    }
    ~Inflater() { inflateEnd(&z_); }
    void read(void* out, size_t bytes) {
        z_.next_out = static_cast<unsigned char*>(out);
        z_.avail_out = uInt(bytes);
        while (z_.avail_out > 0) {
            const int r = inflate(&z_, Z_NO_FLUSH);
            if (r == Z_STREAM_END && z_.avail_out > 0) throw MeshLoadError(fmt::format("mesh '{}': the compressed data ends early", path_));
            if (r != Z_OK && r != Z_STREAM_END) throw MeshLoadError(fmt::format("mesh '{}': corrupt compressed data (zlib error {})", path_, r));
        }
    }
    template <typename T>
    T get() {
        T v;
        read(&v, sizeof v);
        return v;
    }

private:
    z_stream z_;
    std::string path_;
};

enum SerializedFlags : uint32_t {
    kHasNormals = 0x0001,
    kHasUvs = 0x0002,
    kHasColors = 0x0008,
    kFaceNormals = 0x0010,
    kSinglePrecision = 0x1000,
    kDoublePrecision = 0x2000,
};

}  // namespace

MeshDesc load_serialized_mesh(const std::string& path, int shape_index) {
    std::string bytes;
    try {
        bytes = read_input_file(path, std::numeric_limits<uint64_t>::max());
    } catch (const InputFileError& e) {
        throw MeshLoadError(fmt::format("cannot read mesh '{}': {}", path, e.what()));
    }
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const size_t size = bytes.size();
    const auto bad = [&](const std::string& why) { return MeshLoadError(fmt::format("mesh '{}' is not a valid serialized file: {}", path, why)); };
    if (size < 8) throw bad("too short");
    uint16_t magic, version;
    std::memcpy(&magic, data, 2);
    std::memcpy(&version, data + 2, 2);
    if (magic != 0x041C) throw bad("no 0x041C header");
    if (version != 3 && version != 4) throw bad(fmt::format("format version {} (3 and 4 are read)", version));
    // The end of the file: the shapes' offsets, then their count.
    uint32_t count;
    std::memcpy(&count, data + size - 4, 4);
    const size_t offset_size = version == 4 ? 8 : 4;
    if (count == 0 || count > (size - 4) / offset_size) throw bad(fmt::format("a shape count of {}", count));
    if (shape_index < 0 || uint32_t(shape_index) >= count)
        throw MeshLoadError(fmt::format("mesh '{}' has {} shapes (shape_index 0 to {}), not shape {}", path, count, count - 1, shape_index));
    const size_t table = size - 4 - size_t(count) * offset_size;
    const auto offset_of = [&](uint32_t i) -> uint64_t {
        uint64_t o = 0;
        std::memcpy(&o, data + table + size_t(i) * offset_size, offset_size);
        return o;
    };
    const uint64_t begin = offset_of(uint32_t(shape_index));
    const uint64_t end = uint32_t(shape_index) + 1 < count ? offset_of(uint32_t(shape_index) + 1) : table;
    if (begin > end || end - begin < 4 || end > table) throw bad(fmt::format("shape {}'s offset {} is outside the file", shape_index, begin));
    uint16_t shape_magic, shape_version;
    std::memcpy(&shape_magic, data + begin, 2);
    std::memcpy(&shape_version, data + begin + 2, 2);
    if (shape_magic != 0x041C || shape_version != version) throw bad(fmt::format("shape {} has no valid header", shape_index));

    Inflater z(data + begin + 4, size_t(end - begin - 4), path);
    const uint32_t flags = z.get<uint32_t>();
    MeshDesc m;
    if (version == 4) {
        std::string name;
        for (char c; (c = z.get<char>()) != 0;) {
            if (name.size() > 4096) throw bad("a shape name longer than 4096 bytes");
            name += c;
        }
        m.name = name;
    }
    const uint64_t vertices = z.get<uint64_t>(), triangles = z.get<uint64_t>();
    if (vertices == 0 || triangles == 0 || vertices > kMaxElements || triangles > kMaxElements)
        throw bad(fmt::format("{} vertices and {} triangles", vertices, triangles));
    const bool dbl = (flags & kDoublePrecision) != 0;
    if (dbl == ((flags & kSinglePrecision) != 0)) throw bad("neither (or both) single and double precision flagged");
    // What the counts need, against what the shape's compressed bytes can hold (deflate expands
    // at most 1032 times): checked before anything is allocated (a 340-byte file claimed 2^28
    // triangles, 3 GiB).
    const uint64_t per_vertex = (3 + (flags & kHasNormals ? 3 : 0) + (flags & kHasUvs ? 2 : 0) + (flags & kHasColors ? 3 : 0)) * (dbl ? 8 : 4);
    const uint64_t needed = vertices * per_vertex + triangles * 3 * (vertices > 0xffffffffull ? 8 : 4), packed = end - begin - 4;
    if (needed > 1032 * packed)
        throw bad(fmt::format("shape {} claims {} vertices and {} triangles ({} bytes), more than its {} compressed bytes hold", shape_index,
                              vertices, triangles, needed, packed));
    const auto read_floats = [&](size_t n, float* out) {
        if (!dbl) return z.read(out, n * sizeof(float));
        std::vector<double> tmp(n);
        z.read(tmp.data(), n * sizeof(double));
        for (size_t i = 0; i < n; ++i) out[i] = float(tmp[i]);
    };
    m.positions.resize(size_t(vertices));
    read_floats(size_t(vertices) * 3, &m.positions[0].x);
    if (flags & kHasNormals) {
        m.normals.resize(size_t(vertices));
        read_floats(size_t(vertices) * 3, &m.normals[0].x);
    }
    if (flags & kHasUvs) {
        m.uvs.resize(size_t(vertices));
        read_floats(size_t(vertices) * 2, &m.uvs[0].x);
    }
    if (flags & kHasColors) {
        std::vector<float> colors(size_t(vertices) * 3);
        read_floats(colors.size(), colors.data());  // vertex colours: not used by pathlab
    }
    m.triangles.resize(size_t(triangles));
    if (vertices > 0xffffffffull) {
        std::vector<uint64_t> idx(size_t(triangles) * 3);
        z.read(idx.data(), idx.size() * 8);
        for (size_t i = 0; i < idx.size(); ++i) m.triangles[i / 3][i % 3] = uint32_t(idx[i]);
    } else {
        z.read(m.triangles.data(), size_t(triangles) * 12);
    }
    for (const auto& t : m.triangles)
        for (uint32_t v : t)
            if (v >= vertices) throw bad(fmt::format("a vertex index {} out of range ({} vertices)", v, vertices));
    if (flags & kFaceNormals) m.normals.clear();
    check_finite(m, path);
    return m;
}

std::string serialized_mesh_bytes(const MeshDesc& mesh, bool double_precision) {
    std::string raw;
    const auto put = [&](const void* p, size_t n) { raw.append(static_cast<const char*>(p), n); };
    const uint32_t flags = (mesh.normals.empty() ? 0u : uint32_t(kHasNormals)) | (mesh.uvs.empty() ? 0u : uint32_t(kHasUvs)) |
                           (double_precision ? uint32_t(kDoublePrecision) : uint32_t(kSinglePrecision));
    put(&flags, 4);
    put(mesh.name.c_str(), mesh.name.size() + 1);
    const uint64_t v = mesh.positions.size(), t = mesh.triangles.size();
    put(&v, 8);
    put(&t, 8);
    const auto floats = [&](const float* p, size_t n) {
        for (size_t i = 0; i < n; ++i) {
            if (double_precision) {
                const double d = p[i];
                put(&d, 8);
            } else {
                put(&p[i], 4);
            }
        }
    };
    floats(&mesh.positions[0].x, mesh.positions.size() * 3);
    if (!mesh.normals.empty()) floats(&mesh.normals[0].x, mesh.normals.size() * 3);
    if (!mesh.uvs.empty()) floats(&mesh.uvs[0].x, mesh.uvs.size() * 2);
    put(mesh.triangles.data(), mesh.triangles.size() * 12);
    uLongf packed_size = compressBound(uLong(raw.size()));
    std::string packed(packed_size, '\0');
    compress(reinterpret_cast<Bytef*>(packed.data()), &packed_size, reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()));
    packed.resize(packed_size);
    std::string out;
    const uint16_t magic = 0x041C, version = 4;
    out.append(reinterpret_cast<const char*>(&magic), 2);
    out.append(reinterpret_cast<const char*>(&version), 2);
    out += packed;
    const uint64_t offset = 0;
    const uint32_t count = 1;
    out.append(reinterpret_cast<const char*>(&offset), 8);
    out.append(reinterpret_cast<const char*>(&count), 4);
    return out;
}

}  // namespace pathlab
