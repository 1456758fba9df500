#include "geometry/shape_meshes.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <climits>
#include <map>
#include <string_view>
#include <tuple>
#include <vector>

#include <fmt/format.h>

#include "core/input_file.hpp"

namespace pathlab {

MeshDesc rectangle_mesh() {
    MeshDesc m;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // Mitsuba 3: uv = ((x + 1) / 2, (y + 1) / 2)
    m.triangles = {{0, 1, 2}, {2, 3, 0}};
    return m;
}

MeshDesc cube_mesh() {
    // The corners (bit 0: x, bit 1: y, bit 2: z), and two counter-clockwise (seen from
    // outside) triangles of them per face.
    Vec3f corner[8];
    for (int i = 0; i < 8; ++i) corner[i] = {i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f};
    const uint32_t faces[6][6] = {{0, 2, 3, 3, 1, 0},   // z = -1
                                  {4, 5, 7, 7, 6, 4},   // z = +1
                                  {0, 1, 5, 5, 4, 0},   // y = -1
                                  {2, 6, 7, 7, 3, 2},   // y = +1
                                  {0, 4, 6, 6, 2, 0},   // x = -1
                                  {1, 3, 7, 7, 5, 1}};  // x = +1
    // Each face mapped onto [0, 1]^2 as Mitsuba 3's cube maps it (its vertex table), u and v
    // as functions of the corner's coordinates on that face.
    const auto face_uv = [](int face, const Vec3f& p) -> Vec2f {
        const auto h = [](float c) { return (c + 1) * 0.5f; };   // -1 -> 0, 1 -> 1
        const auto r = [](float c) { return (1 - c) * 0.5f; };   // -1 -> 1, 1 -> 0
        switch (face) {
            case 0: return {r(p.y), h(p.x)};  // z = -1
            case 1: return {h(p.y), h(p.x)};  // z = +1
            case 2: return {h(p.z), h(p.x)};  // y = -1
            case 3: return {r(p.x), r(p.z)};  // y = +1
            case 4: return {h(p.y), h(p.z)};  // x = -1
            default: return {h(p.y), r(p.z)};  // x = +1
        }
    };
    // Four vertices per face (so that each face has its own uv); the triangles keep their
    // corners and their order, so the geometry is exactly what it was without uv.
    MeshDesc m;
    for (int f = 0; f < 6; ++f) {
        uint32_t local[8];
        std::fill(local, local + 8, UINT32_MAX);
        for (int k = 0; k < 6; k += 3) {
            std::array<uint32_t, 3> tri;
            for (int j = 0; j < 3; ++j) {
                const uint32_t c = faces[f][k + j];
                if (local[c] == UINT32_MAX) {
                    local[c] = uint32_t(m.positions.size());
                    m.positions.push_back(corner[c]);
                    m.uvs.push_back(face_uv(f, corner[c]));
                }
                tri[size_t(j)] = local[c];
            }
            m.triangles.push_back(tri);
        }
    }
    return m;
}

MeshDesc disk_mesh(int segments) {
    MeshDesc m;
    m.positions.push_back({0, 0, 0});
    for (int i = 0; i < segments; ++i) {
        const double phi = 2 * 3.14159265358979323846 * i / segments;
        m.positions.push_back({float(std::cos(phi)), float(std::sin(phi)), 0});
    }
    for (int i = 0; i < segments; ++i) m.triangles.push_back({0, uint32_t(1 + i), uint32_t(1 + (i + 1) % segments)});
    m.uv_map = UvMap::Disk;
    return m;
}

MeshDesc cylinder_mesh(int segments) {
    MeshDesc m;
    for (int i = 0; i < segments; ++i) {
        const double phi = 2 * 3.14159265358979323846 * i / segments;
        const Vec3f c(float(std::cos(phi)), float(std::sin(phi)), 0);
        m.positions.push_back(c);
        m.positions.push_back({c.x, c.y, 1});
        m.normals.push_back(c);
        m.normals.push_back(c);
    }
    for (int i = 0; i < segments; ++i) {
        const uint32_t a = uint32_t(2 * i), b = uint32_t(2 * ((i + 1) % segments));
        m.triangles.push_back({a, b, b + 1});  // counter-clockwise seen from outside
        m.triangles.push_back({b + 1, a + 1, a});
    }
    return m;
}

namespace {

// What tinyobjloader 2.0.0rc10 gets wrong, taken care of line by line before it parses the text:
// - undefined behaviour (found by fuzz_obj): a skin-weight line ("vw", a tinyobjloader
//   extension) converts its joint index from float to int unchecked (inf, 1e10), and a number's
//   exponent of exactly 2147483648 or 2147483649 overflows an int. pathlab does not use skin
//   weights: those lines become comments. No mesh needs an exponent of 10 digits: such a number
//   is refused;
// - numbers read as other numbers, silently: "nan" and "inf" as 0 in a vertex, and a face index
//   past 32 bits wrapped (4294967299 is vertex 3). Refused with the line.
void prepare_obj_text(std::string& text, const std::string& path) {
    const auto digit = [](char c) { return c >= '0' && c <= '9'; };
    size_t line = 1;
    for (size_t i = 0; i < text.size();) {
        const size_t end = std::min(text.find_first_of("\r\n", i), text.size());
        size_t first = i;
        while (first < end && (text[first] == ' ' || text[first] == '\t')) ++first;
        if (first + 2 < text.size() && text[first] == 'v' && text[first + 1] == 'w' && (text[first + 2] == ' ' || text[first + 2] == '\t'))
            text[first] = '#';
        for (size_t e = i; e < end; ++e) {
            if (!((text[e] == 'e' || text[e] == 'E') && e > 0 && (digit(text[e - 1]) || text[e - 1] == '.'))) continue;
            size_t j = e + 1;
            if (j < text.size() && (text[j] == '+' || text[j] == '-')) ++j;
            while (j < text.size() && text[j] == '0') ++j;
            size_t digits = 0;
            while (j + digits < text.size() && digit(text[j + digits])) ++digits;
            if (digits >= 10) throw MeshLoadError(fmt::format("cannot read mesh '{}': a number with an exponent of {} digits", path, digits));
        }
        const char c0 = first < end ? text[first] : '#';
        std::vector<std::string_view> tokens;  // only for the lines below (a few per mesh line)
        if (c0 == 'v' || c0 == 'f' || c0 == 'l' || c0 == 'p')
            for (size_t j = first; j < end;) {
                while (j < end && (text[j] == ' ' || text[j] == '\t')) ++j;
                const size_t k = j;
                while (j < end && text[j] != ' ' && text[j] != '\t') ++j;
                if (j > k) tokens.emplace_back(text.data() + k, j - k);
            }
        const auto fail = [&](const std::string& why) {
            return MeshLoadError(fmt::format("cannot read mesh '{}': line {}: {}", path, line, why));
        };
        if (!tokens.empty() && (tokens[0] == "v" || tokens[0] == "vn" || tokens[0] == "vt")) {
            for (size_t t = 1; t < tokens.size(); ++t) {
                std::string_view w = tokens[t];
                if (!w.empty() && (w[0] == '+' || w[0] == '-')) w.remove_prefix(1);
                if (!w.empty() && (w[0] == 'n' || w[0] == 'N' || w[0] == 'i' || w[0] == 'I'))
                    throw fail(fmt::format("'{}' is not a finite number", tokens[t]));
            }
        } else if (!tokens.empty() && (tokens[0] == "f" || tokens[0] == "l" || tokens[0] == "p")) {
            for (size_t t = 1; t < tokens.size(); ++t)
                for (size_t a = 0; a <= tokens[t].size();) {
                    const size_t b = std::min(tokens[t].find('/', a), tokens[t].size());
                    size_t digits = 0;
                    uint64_t value = 0;
                    for (size_t c = a; c < b; ++c)
                        if (digit(tokens[t][c]) && ++digits <= 12) value = value * 10 + uint64_t(tokens[t][c] - '0');
                    if (digits > 10 || value > uint64_t(INT32_MAX)) throw fail(fmt::format("index '{}' is out of range", tokens[t].substr(a, b - a)));
                    a = b + 1;
                }
        }
        i = end;
        if (i < text.size()) {
            if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
            ++i, ++line;
        }
    }
}

}  // namespace

MeshDesc load_obj_mesh(const std::string& path) {
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    config.mtl_search_path = "";
    // The file is parsed from memory with no material library: ParseFromFile would open any
    // file a `mtllib` line names (`mtllib ../../dev/zero` hung the loader), and pathlab takes
    // materials from the scene file, never from .mtl files.
    std::string text;
    try {
        text = read_input_file(path, std::numeric_limits<uint64_t>::max());
    } catch (const InputFileError& e) {
        throw MeshLoadError(fmt::format("cannot read mesh '{}': {}", path, e.what()));
    }
    prepare_obj_text(text, path);
    tinyobj::ObjReader reader;
    if (!reader.ParseFromString(text, "", config)) {
        std::string why = reader.Error();
        while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
        throw MeshLoadError(fmt::format("cannot read mesh '{}': {}", path, why.empty() ? "unknown error" : why));
    }
    const tinyobj::attrib_t& a = reader.GetAttrib();
    MeshDesc m;
    m.name = path;
    const size_t vertex_count = a.vertices.size() / 3;
    bool all_normals = !a.normals.empty(), all_uvs = !a.texcoords.empty();
    size_t faces = 0;
    for (const tinyobj::shape_t& s : reader.GetShapes()) {
        faces += s.mesh.num_face_vertices.size();
        for (const tinyobj::index_t& i : s.mesh.indices) {
            all_normals = all_normals && i.normal_index >= 0;
            all_uvs = all_uvs && i.texcoord_index >= 0;
        }
    }
    if (faces == 0) throw MeshLoadError(fmt::format("mesh '{}' has no faces", path));
    for (size_t v = 0; v < vertex_count; ++v) {
        const Vec3f p(a.vertices[3 * v], a.vertices[3 * v + 1], a.vertices[3 * v + 2]);
        if (!is_finite(p)) throw MeshLoadError(fmt::format("mesh '{}': vertex {} is not finite", path, v + 1));
    }

    // Without normals and texture coordinates the file's vertex list is used as it is; with
    // them, one vertex per distinct (position, normal, uv) triple. Texture coordinates are used
    // when every face has them, with v flipped (v' = 1 - v), as Mitsuba reads OBJ files.
    const bool split = all_normals || all_uvs;
    std::map<std::tuple<int, int, int>, uint32_t> remap;
    const auto vertex = [&](const tinyobj::index_t& i) -> uint32_t {
        if (i.vertex_index < 0 || size_t(i.vertex_index) >= vertex_count)
            throw MeshLoadError(fmt::format("mesh '{}' refers to a vertex that does not exist", path));
        if (!split) return uint32_t(i.vertex_index);
        const auto key = std::make_tuple(i.vertex_index, all_normals ? i.normal_index : -1, all_uvs ? i.texcoord_index : -1);
        const auto [it, added] = remap.emplace(key, uint32_t(m.positions.size()));
        if (added) {
            const size_t v = size_t(i.vertex_index);
            m.positions.push_back({a.vertices[3 * v], a.vertices[3 * v + 1], a.vertices[3 * v + 2]});
            if (all_normals) {
                const size_t n = size_t(i.normal_index);
                if (3 * n + 2 >= a.normals.size())
                    throw MeshLoadError(fmt::format("mesh '{}' refers to a normal that does not exist", path));
                m.normals.push_back({a.normals[3 * n], a.normals[3 * n + 1], a.normals[3 * n + 2]});
            }
            if (all_uvs) {
                const size_t t = size_t(i.texcoord_index);
                if (2 * t + 1 >= a.texcoords.size())
                    throw MeshLoadError(fmt::format("mesh '{}' refers to a texture coordinate that does not exist", path));
                const Vec2f uv(a.texcoords[2 * t], 1 - a.texcoords[2 * t + 1]);
                if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
                    throw MeshLoadError(fmt::format("mesh '{}' has a non-finite texture coordinate", path));
                m.uvs.push_back(uv);
            }
        }
        return it->second;
    };
    if (!split)
        for (size_t v = 0; v < vertex_count; ++v) m.positions.push_back({a.vertices[3 * v], a.vertices[3 * v + 1], a.vertices[3 * v + 2]});
    for (const tinyobj::shape_t& s : reader.GetShapes()) {
        size_t offset = 0;
        for (const unsigned char count : s.mesh.num_face_vertices) {
            if (count == 3)
                m.triangles.push_back({vertex(s.mesh.indices[offset]), vertex(s.mesh.indices[offset + 1]),
                                       vertex(s.mesh.indices[offset + 2])});
            offset += count;
        }
    }
    if (m.triangles.empty()) throw MeshLoadError(fmt::format("mesh '{}' has no triangles", path));
    for (const Vec3f& n : m.normals)
        if (!is_finite(n)) throw MeshLoadError(fmt::format("mesh '{}' has a non-finite normal", path));
    return m;
}

void transform_mesh(MeshDesc& mesh, const Transform& t) {
    if (t.m == Transform().m) return;
    mesh.to_world = t * mesh.to_world;
    mesh.to_object = mesh.to_world.inverse_affine();
    for (Vec3f& p : mesh.positions) p = Vec3f(t.point(Vec3d(p)));
    for (Vec3f& n : mesh.normals) {
        const Vec3d tn = t.normal(Vec3d(n));
        const double len = length(tn);
        n = len > 0 ? Vec3f(tn / len) : Vec3f(0.0f);
    }
}

void use_face_normals(MeshDesc& mesh) { mesh.normals.clear(); }

void flip_mesh_normals(MeshDesc& mesh) {
    for (auto& tri : mesh.triangles) std::swap(tri[1], tri[2]);
    for (Vec3f& n : mesh.normals) n = -n;
}

}  // namespace pathlab
