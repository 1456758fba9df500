// glTF 2.0 -> Mitsuba XML (gltf_scene.hpp). Conventions from the glTF 2.0 specification
// (Khronos, sections "Nodes and Hierarchy", "Cameras", "Materials", "Accessors") and its
// KHR_lights_punctual, KHR_materials_emissive_strength, KHR_materials_transmission and
// KHR_materials_ior extensions; light units as Blender's glTF importer converts them
// (io_scene_gltf2/blender/imp/light.py: W = cd * 4 pi / 683, sun W/m^2 = lux / 683).
#include "scenefile/gltf_scene.hpp"

#include <fmt/format.h>
#include <pugixml.hpp>
#include <tiny_gltf.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

#include "core/transform.hpp"
#include "geometry/mesh_files.hpp"
#include "image/image_io.hpp"

namespace pathlab {

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
// Luminous efficacy with which glTF's photometric light units become radiometric ones.
constexpr double kLumensPerWatt = 683.0;

bool ends_with_ci(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

// Keeps each image's encoded bytes (PNG or JPEG) as they are: the converter copies them, or
// decodes them itself through pathlab's checked readers when it derives an image.
bool keep_encoded_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes, int size,
                        void*) {
    image->image.assign(bytes, bytes + size);
    image->as_is = true;
    return true;
}

std::string percent_decoded(const std::string& uri) {
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uint8_t(uri[i + 1])) && std::isxdigit(uint8_t(uri[i + 2]))) {
            out.push_back(char(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
            i += 2;
        } else {
            out.push_back(uri[i]);
        }
    }
    return out;
}

// Values as the shortest text that reads back as the same float (the loader's precision).
std::string number(double v) { return fmt::format("{}", float(v)); }
std::string triple(double a, double b, double c) { return fmt::format("{}, {}, {}", float(a), float(b), float(c)); }

// A node's local transform: its matrix (column-major) or T * R * S.
Transform local_transform(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) {
        Transform t;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) t.m[size_t(r)][size_t(c)] = n.matrix[size_t(c * 4 + r)];
        return t;
    }
    Transform t, r, s;
    if (n.translation.size() == 3) t = Transform::translate({n.translation[0], n.translation[1], n.translation[2]});
    if (n.rotation.size() == 4) {
        // unit quaternion (x, y, z, w) as a rotation matrix
        double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
        const double len = std::sqrt(x * x + y * y + z * z + w * w);
        if (len > 0) x /= len, y /= len, z /= len, w /= len;
        r.m[0] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0};
        r.m[1] = {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0};
        r.m[2] = {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), 0};
    }
    if (n.scale.size() == 3) s = Transform::scale({n.scale[0], n.scale[1], n.scale[2]});
    return t * r * s;
}

// Whether `count` elements of `element` bytes, `stride` apart from `offset` into a buffer view,
// lie inside the view and the view inside its buffer (no sum can wrap around).
bool inside(const tinygltf::BufferView& v, size_t buffer_size, size_t offset, size_t stride, size_t count, size_t element) {
    if (v.byteLength > buffer_size || v.byteOffset > buffer_size - v.byteLength) return false;
    if (count == 0) return true;
    if (offset > v.byteLength || element > v.byteLength - offset) return false;
    return count - 1 <= (v.byteLength - offset - element) / std::max<size_t>(stride, 1);
}

std::string matrix_text(const Transform& t) {
    std::vector<std::string> v;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) v.push_back(number(t.m[size_t(r)][size_t(c)]));
    return fmt::format("{}", fmt::join(v, " "));
}

class Converter {
public:
    Converter(std::string path, std::string xml_path) : path_(std::move(path)), xml_path_(std::move(xml_path)) {}

    GltfConversion run();

private:
    [[noreturn]] void fail(const std::string& message) const { throw SceneFileError(path_, 0, 0, message); }
    void warn(const std::string& message) {
        if (std::find(out_.warnings.begin(), out_.warnings.end(), message) == out_.warnings.end()) out_.warnings.push_back(message);
    }

    void load();
    void check_extensions();
    void visit(int node, const Transform& parent, std::vector<int>& stack);
    void add_mesh(int node, int mesh, const Transform& to_world);
    std::string material_id(int material, pugi::xml_node first_user);
    void write_material(int material, const std::string& id, pugi::xml_node before);
    const tinygltf::Accessor& accessor(int index, const std::string& what) const;
    const unsigned char* first_element(const tinygltf::Accessor& a, int index, size_t element, size_t& stride, const std::string& what) const;
    std::vector<float> floats(int accessor, int components, const std::string& what, bool allow_normalized) const;
    std::vector<uint32_t> indices(const tinygltf::Primitive& p, size_t vertex_count) const;
    std::string output_path(const std::string& name) const;
    std::string write_file(const std::string& name, const std::string& bytes);
    const tinygltf::Image& texture_image(const tinygltf::TextureInfo& info, const std::string& material, const char* slot);
    void add_bitmap(pugi::xml_node parent, const char* name, const std::string& file, const tinygltf::TextureInfo& info, bool raw);
    std::string image_file(int image_index);
    std::string derived_image(const std::string& name, const tinygltf::Image& image, const std::function<Rgb(const uint8_t*)>& texel);
    Image8 decode(const tinygltf::Image& image) const;
    void add_camera(const tinygltf::Camera& cam, const Transform& to_world);
    void add_default_camera();
    void add_light(int light, const Transform& to_world);
    void add_emission(pugi::xml_node shape, int material, bool has_uv, const std::string& what);

    std::string path_, xml_path_;
    tinygltf::Model model_;
    GltfConversion out_;
    pugi::xml_document doc_;
    pugi::xml_node scene_;
    std::string files_dir_;  // relative to the XML's folder
    std::map<std::pair<int, bool>, std::vector<std::string>> mesh_files_;  // (mesh, mirrored) -> one file per primitive
    std::map<int, std::string> material_ids_;
    std::map<int, std::string> image_files_;
    std::map<int, std::string> emissive_files_;  // by material
    bool have_camera_ = false;
    Vec3d lo_{1e300}, hi_{-1e300};  // the scene's world bounds, for a default camera
};

void Converter::load() {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keep_encoded_image, nullptr);
    std::string err, warn;
    bool ok = false;
    std::error_code ec;
    if (!fs::is_regular_file(path_, ec)) fail("cannot open the glTF file: no such file");
    if (ends_with_ci(path_, ".glb"))
        ok = loader.LoadBinaryFromFile(&model_, &err, &warn, path_);
    else
        ok = loader.LoadASCIIFromFile(&model_, &err, &warn, path_);
    if (!ok || !err.empty()) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        fail(fmt::format("not a readable glTF 2.0 file: {}", err.empty() ? "tinygltf could not parse it" : err));
    }
    for (size_t start = 0; start < warn.size();) {  // tinygltf's own warnings, one per line
        const size_t end = std::min(warn.find('\n', start), warn.size());
        if (end > start) this->warn(warn.substr(start, end - start));
        start = end + 1;
    }
    out_.files.push_back(path_);
    const fs::path dir = fs::path(path_).parent_path();
    const auto external = [&](const std::string& uri) {
        if (!uri.empty() && uri.rfind("data:", 0) != 0) out_.files.push_back((dir / percent_decoded(uri)).string());
    };
    for (const tinygltf::Buffer& b : model_.buffers) external(b.uri);
    for (const tinygltf::Image& i : model_.images) external(i.uri);
}

void Converter::check_extensions() {
    static const std::set<std::string> kSupported = {"KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission",
                                                      "KHR_materials_ior", "KHR_texture_transform"};
    std::vector<std::string> missing;
    for (const std::string& e : model_.extensionsRequired)
        if (!kSupported.count(e)) missing.push_back(e);
    if (!missing.empty())
        fail(fmt::format("the file requires the extension{} {}, which pathlab does not read (it reads {})", missing.size() > 1 ? "s" : "",
                         fmt::join(missing, ", "), fmt::join(kSupported, ", ")));
    for (const std::string& e : model_.extensionsUsed)
        if (!kSupported.count(e)) warn(fmt::format("the extension {} is not read: the scene is rendered without it", e));
}

const tinygltf::Accessor& Converter::accessor(int index, const std::string& what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size()) fail(fmt::format("{}: accessor {} does not exist", what, index));
    return model_.accessors[size_t(index)];
}

// The first of accessor `a`'s (number `index`) elements of `element` bytes in its buffer, and in
// `stride` the bytes from one to the next; fails naming `what` when any lies outside the buffer.
const unsigned char* Converter::first_element(const tinygltf::Accessor& a, int index, size_t element, size_t& stride,
                                              const std::string& what) const {
    if (a.bufferView < 0 || size_t(a.bufferView) >= model_.bufferViews.size())
        fail(fmt::format("{}: buffer view {} does not exist", what, a.bufferView));
    const tinygltf::BufferView& v = model_.bufferViews[size_t(a.bufferView)];
    if (v.buffer < 0 || size_t(v.buffer) >= model_.buffers.size()) fail(fmt::format("{}: buffer {} does not exist", what, v.buffer));
    const std::vector<unsigned char>& data = model_.buffers[size_t(v.buffer)].data;
    stride = v.byteStride ? v.byteStride : element;
    if (!inside(v, data.size(), a.byteOffset, stride, a.count, element))
        fail(fmt::format("{}: accessor {} reaches past the end of its buffer", what, index));
    return data.data() + v.byteOffset + a.byteOffset;
}

std::vector<float> Converter::floats(int index, int components, const std::string& what, bool allow_normalized) const {
    const tinygltf::Accessor& a = accessor(index, what);
    if (a.sparse.isSparse) fail(fmt::format("{}: accessor {} is sparse, which pathlab does not read", what, index));
    const int want_type = components == 2 ? TINYGLTF_TYPE_VEC2 : TINYGLTF_TYPE_VEC3;
    if (a.type != want_type) fail(fmt::format("{}: accessor {} is not a VEC{}", what, index, components));
    size_t component_size = 4;
    if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && allow_normalized && a.normalized)
        component_size = 1;
    else if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && allow_normalized && a.normalized)
        component_size = 2;
    else if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
        fail(fmt::format("{}: accessor {} holds component type {}, not floats{}", what, index, a.componentType,
                         allow_normalized ? " or normalized bytes or shorts" : ""));
    if (a.bufferView < 0) {
        if (a.count > (size_t(1) << 28)) fail(fmt::format("{}: accessor {} claims {} elements", what, index, a.count));
        return std::vector<float>(a.count * size_t(components), 0.0f);  // all zeros, as the spec says
    }
    size_t stride = 0;
    const unsigned char* first = first_element(a, index, component_size * size_t(components), stride, what);
    std::vector<float> out(a.count * size_t(components), 0.0f);
    for (size_t i = 0; i < a.count; ++i)
        for (size_t c = 0; c < size_t(components); ++c) {
            const unsigned char* p = first + i * stride + c * component_size;
            float f = 0;
            if (component_size == 4)
                std::memcpy(&f, p, 4);
            else if (component_size == 1)
                f = float(*p) / 255.0f;
            else
                f = float(uint16_t(p[0] | (p[1] << 8))) / 65535.0f;
            if (!std::isfinite(f)) fail(fmt::format("{}: accessor {} holds a value that is not a finite number", what, index));
            out[i * size_t(components) + c] = f;
        }
    return out;
}

std::vector<uint32_t> Converter::indices(const tinygltf::Primitive& p, size_t vertex_count) const {
    std::vector<uint32_t> out;
    if (p.indices < 0) {
        for (size_t i = 0; i < vertex_count; ++i) out.push_back(uint32_t(i));
        return out;
    }
    const tinygltf::Accessor& a = accessor(p.indices, "indices");
    size_t size = 0;
    switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
        default: fail(fmt::format("indices: accessor {} holds component type {}, not unsigned integers", p.indices, a.componentType));
    }
    if (a.type != TINYGLTF_TYPE_SCALAR || a.bufferView < 0 || size_t(a.bufferView) >= model_.bufferViews.size() || a.sparse.isSparse)
        fail(fmt::format("indices: accessor {} is not a plain list of scalars", p.indices));
    size_t stride = 0;
    const unsigned char* first = first_element(a, p.indices, size, stride, "indices");
    for (size_t i = 0; i < a.count; ++i) {
        const unsigned char* q = first + i * stride;
        uint32_t k = size == 1 ? q[0] : size == 2 ? uint32_t(q[0] | (q[1] << 8)) : uint32_t(q[0] | (q[1] << 8) | (q[2] << 16) | (uint32_t(q[3]) << 24));
        if (k >= vertex_count) fail(fmt::format("indices: accessor {} names vertex {} of {}", p.indices, k, vertex_count));
        out.push_back(k);
    }
    return out;
}

// Where the file `name` of the conversion goes (in the files folder beside the XML).
std::string Converter::output_path(const std::string& name) const {
    return (fs::path(xml_path_).parent_path() / files_dir_ / name).string();
}

std::string Converter::write_file(const std::string& name, const std::string& bytes) {
    write_text_file(output_path(name), bytes);
    return files_dir_ + "/" + name;
}

void Converter::add_mesh(int node, int mesh_index, const Transform& to_world) {
    if (mesh_index < 0 || size_t(mesh_index) >= model_.meshes.size()) fail(fmt::format("node {}: mesh {} does not exist", node, mesh_index));
    const tinygltf::Mesh& mesh = model_.meshes[size_t(mesh_index)];
    // A mirroring transform turns the winding: the spec's front faces are then clockwise.
    const bool mirrored = to_world.determinant() < 0;
    const auto key = std::make_pair(mesh_index, mirrored);
    const bool written = mesh_files_.count(key) > 0;
    std::vector<std::string>& files = mesh_files_[key];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
        const tinygltf::Primitive& p = mesh.primitives[pi];
        const std::string what = fmt::format("mesh {} ('{}') primitive {}", mesh_index, mesh.name, pi);
        const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
            fail(fmt::format("{}: mode {} (points or lines) has no surface to render; pathlab reads triangles, strips and fans", what, mode));
        const auto attribute = [&](const char* name) {
            const auto it = p.attributes.find(name);
            return it == p.attributes.end() ? -1 : it->second;
        };
        if (attribute("POSITION") < 0) fail(fmt::format("{}: no POSITION attribute", what));
        const std::vector<float> pos = floats(attribute("POSITION"), 3, what + " POSITION", false);
        const size_t n = pos.size() / 3;
        for (size_t i = 0; i < n; ++i) {
            const Vec3d w = to_world.point({pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]});
            lo_ = min(lo_, w), hi_ = max(hi_, w);
        }
        if (!written) {
            MeshDesc m;
            m.name = mesh.name;
            for (size_t i = 0; i < n; ++i) m.positions.push_back({pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]});
            if (attribute("NORMAL") >= 0) {
                const std::vector<float> nrm = floats(attribute("NORMAL"), 3, what + " NORMAL", false);
                if (nrm.size() != pos.size()) fail(fmt::format("{}: NORMAL and POSITION have different counts", what));
                for (size_t i = 0; i < n; ++i) m.normals.push_back({nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]});
            }
            if (attribute("TEXCOORD_0") >= 0) {
                const std::vector<float> uv = floats(attribute("TEXCOORD_0"), 2, what + " TEXCOORD_0", true);
                if (uv.size() / 2 != n) fail(fmt::format("{}: TEXCOORD_0 and POSITION have different counts", what));
                // glTF's v runs down the image from its top row, as Mitsuba's uv does: no flip.
                for (size_t i = 0; i < n; ++i) m.uvs.push_back({uv[2 * i], uv[2 * i + 1]});
            }
            const std::vector<uint32_t> idx = indices(p, n);
            const auto triangle = [&](uint32_t a, uint32_t b, uint32_t c) {
                if (a == b || b == c || a == c) return;  // degenerate ones of strips
                m.triangles.push_back(mirrored ? std::array<uint32_t, 3>{a, c, b} : std::array<uint32_t, 3>{a, b, c});
            };
            if (mode == TINYGLTF_MODE_TRIANGLES) {
                if (idx.size() % 3) fail(fmt::format("{}: {} indices are not whole triangles", what, idx.size()));
                for (size_t i = 0; i + 2 < idx.size(); i += 3) triangle(idx[i], idx[i + 1], idx[i + 2]);
            } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                for (size_t i = 0; i + 2 < idx.size(); ++i)
                    i % 2 ? triangle(idx[i + 1], idx[i], idx[i + 2]) : triangle(idx[i], idx[i + 1], idx[i + 2]);
            } else {
                for (size_t i = 1; i + 1 < idx.size(); ++i) triangle(idx[0], idx[i], idx[i + 1]);
            }
            if (m.triangles.empty()) {
                files.push_back("");
                continue;
            }
            files.push_back(write_file(fmt::format("mesh{}-{}{}.serialized", mesh_index, pi, mirrored ? "-mirrored" : ""),
                                       serialized_mesh_bytes(m)));
        }
        if (files[pi].empty()) continue;
        pugi::xml_node shape = scene_.append_child("shape");
        shape.append_attribute("type") = "serialized";
        pugi::xml_node f = shape.append_child("string");
        f.append_attribute("name") = "filename";
        f.append_attribute("value") = files[pi].c_str();
        if (to_world.m != Transform().m) {
            pugi::xml_node t = shape.append_child("transform");
            t.append_attribute("name") = "to_world";
            t.append_child("matrix").append_attribute("value") = matrix_text(to_world).c_str();
        }
        const std::string mat = material_id(p.material, shape);
        pugi::xml_node ref = shape.append_child("ref");
        ref.append_attribute("id") = mat.c_str();
        if (p.material >= 0) add_emission(shape, p.material, attribute("TEXCOORD_0") >= 0, what);
    }
}

// Emission: emissiveFactor times KHR_materials_emissive_strength (times the emissive texture's
// decoded sRGB values), an area emitter radiating from the winding's front side.
void Converter::add_emission(pugi::xml_node shape, int material, bool has_uv, const std::string& what) {
    const tinygltf::Material& m = model_.materials[size_t(material)];
    double strength = 1;
    if (const auto it = m.extensions.find("KHR_materials_emissive_strength"); it != m.extensions.end())
        if (it->second.Has("emissiveStrength")) strength = it->second.Get("emissiveStrength").GetNumberAsDouble();
    const std::vector<double>& f = m.emissiveFactor;
    if (f.size() != 3 || !(f[0] > 0 || f[1] > 0 || f[2] > 0) || !(strength > 0)) return;
    const double k[3] = {f[0] * strength, f[1] * strength, f[2] * strength};
    pugi::xml_node e = shape.append_child("emitter");
    e.append_attribute("type") = "area";
    if (m.emissiveTexture.index < 0) {
        pugi::xml_node r = e.append_child("rgb");
        r.append_attribute("name") = "radiance";
        r.append_attribute("value") = triple(k[0], k[1], k[2]).c_str();
        return;
    }
    const std::string name = m.name.empty() ? fmt::format("{}", material) : m.name;
    if (!has_uv) fail(fmt::format("{}: its material '{}' has an emissive texture but the primitive has no TEXCOORD_0", what, name));
    const tinygltf::Image& image = texture_image(m.emissiveTexture, name, "emissiveTexture");
    auto& file = emissive_files_[material];
    if (file.empty()) {
        if (k[0] == 1 && k[1] == 1 && k[2] == 1)
            file = image_file(model_.textures[size_t(m.emissiveTexture.index)].source);
        else  // the factor times the texture's decoded sRGB values, as a linear image
            file = derived_image(fmt::format("emission-{}.exr", material), image, [&](const uint8_t* t) {
                return Rgb(float(k[0] * decode_srgb8(t[0])), float(k[1] * decode_srgb8(t[1])), float(k[2] * decode_srgb8(t[2])));
            });
    }
    add_bitmap(e, "radiance", file, m.emissiveTexture, /*raw=*/false);
}

// The material's bsdf id; the bsdf is written before its first user.
std::string Converter::material_id(int material, pugi::xml_node first_user) {
    if (const auto it = material_ids_.find(material); it != material_ids_.end()) return it->second;
    if (material >= int(model_.materials.size())) fail(fmt::format("material {} does not exist", material));
    std::string id = material < 0 ? "default-material" : fmt::format("material{}", material);
    if (material >= 0 && !model_.materials[size_t(material)].name.empty()) {
        std::string name;
        for (char c : model_.materials[size_t(material)].name) name.push_back(std::isalnum(uint8_t(c)) || c == '-' || c == '_' ? c : '_');
        id += "-" + name;
    }
    material_ids_[material] = id;
    write_material(material, id, first_user);
    return id;
}

Image8 Converter::decode(const tinygltf::Image& image) const {
    const std::string name = fmt::format("{} image '{}'", path_, image.name.empty() ? image.uri : image.name);
    const std::vector<unsigned char>& b = image.image;
    if (b.empty()) fail(fmt::format("{}: the image could not be read (a missing file?)", name));
    try {
        if (b.size() >= 8 && std::memcmp(b.data(), "\x89PNG\r\n\x1a\n", 8) == 0) return read_png8_from_memory(b.data(), b.size(), name);
        if (b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return read_jpeg8_from_memory(b.data(), b.size(), name);
    } catch (const ImageIoError& e) {
        fail(e.what());
    }
    fail(fmt::format("{}: neither PNG nor JPEG", name));
}

std::string Converter::image_file(int index) {
    if (const auto it = image_files_.find(index); it != image_files_.end()) return it->second;
    const tinygltf::Image& image = model_.images[size_t(index)];
    decode(image);  // refuses what the bitmap reader would refuse, naming the glTF
    const bool png = image.image.size() >= 8 && image.image[0] == 0x89;
    const std::string file = write_file(fmt::format("image{}.{}", index, png ? "png" : "jpg"),
                                        std::string(image.image.begin(), image.image.end()));
    return image_files_[index] = file;
}

std::string Converter::derived_image(const std::string& name, const tinygltf::Image& image, const std::function<Rgb(const uint8_t*)>& texel) {
    const Image8 in = decode(image);
    Image out(in.width, in.height);
    for (int y = 0; y < in.height; ++y)
        for (int x = 0; x < in.width; ++x) out.at(x, y) = texel(&in.rgb[(size_t(y) * size_t(in.width) + size_t(x)) * 3]);
    write_image(out, output_path(name));
    return files_dir_ + "/" + name;
}

const tinygltf::Image& Converter::texture_image(const tinygltf::TextureInfo& info, const std::string& material, const char* slot) {
    if (info.index < 0 || size_t(info.index) >= model_.textures.size())
        fail(fmt::format("material '{}': {} names texture {}, which does not exist", material, slot, info.index));
    const tinygltf::Texture& t = model_.textures[size_t(info.index)];
    if (t.source < 0 || size_t(t.source) >= model_.images.size())
        fail(fmt::format("material '{}': {}'s texture {} has no image (or an image extension pathlab does not read)", material, slot, info.index));
    if (info.texCoord != 0)
        fail(fmt::format("material '{}': {} uses TEXCOORD_{}; pathlab reads the first texture coordinates only", material, slot, info.texCoord));
    if (const auto it = info.extensions.find("KHR_texture_transform"); it != info.extensions.end() && it->second.Has("texCoord") &&
                                                                        it->second.Get("texCoord").GetNumberAsInt() != 0)
        fail(fmt::format("material '{}': {}'s KHR_texture_transform uses TEXCOORD_{}; pathlab reads the first texture coordinates only",
                         material, slot, it->second.Get("texCoord").GetNumberAsInt()));
    return model_.images[size_t(t.source)];
}

void Converter::add_bitmap(pugi::xml_node parent, const char* name, const std::string& file, const tinygltf::TextureInfo& info, bool raw) {
    pugi::xml_node t = parent.append_child("texture");
    t.append_attribute("type") = "bitmap";
    t.append_attribute("name") = name;
    pugi::xml_node f = t.append_child("string");
    f.append_attribute("name") = "filename";
    f.append_attribute("value") = file.c_str();
    const tinygltf::Texture& tex = model_.textures[size_t(info.index)];
    int wrap_s = TINYGLTF_TEXTURE_WRAP_REPEAT, wrap_t = TINYGLTF_TEXTURE_WRAP_REPEAT, mag = -1;
    if (tex.sampler >= 0 && size_t(tex.sampler) < model_.samplers.size()) {
        const tinygltf::Sampler& s = model_.samplers[size_t(tex.sampler)];
        wrap_s = s.wrapS, wrap_t = s.wrapT, mag = s.magFilter;
    }
    const auto wrap_name = [](int w) {
        return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE ? "clamp" : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? "mirror" : "repeat";
    };
    if (wrap_s != wrap_t)
        warn(fmt::format("texture {} wraps s ({}) and t ({}) differently; pathlab's bitmap has one wrap_mode: {} on both", info.index,
                         wrap_name(wrap_s), wrap_name(wrap_t), wrap_name(wrap_s)));
    pugi::xml_node w = t.append_child("string");
    w.append_attribute("name") = "wrap_mode";
    w.append_attribute("value") = wrap_name(wrap_s);
    pugi::xml_node filter = t.append_child("string");
    filter.append_attribute("name") = "filter_type";
    filter.append_attribute("value") = mag == TINYGLTF_TEXTURE_FILTER_NEAREST ? "nearest" : "bilinear";
    // KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, as the bitmap's to_uv.
    if (const auto it = info.extensions.find("KHR_texture_transform"); it != info.extensions.end()) {
        const tinygltf::Value& x = it->second;
        const auto pair = [&](const char* key, double fallback, int i) {
            return x.Has(key) && x.Get(key).IsArray() && x.Get(key).ArrayLen() == 2 ? x.Get(key).Get(i).GetNumberAsDouble() : fallback;
        };
        const double ox = pair("offset", 0, 0), oy = pair("offset", 0, 1), sx = pair("scale", 1, 0), sy = pair("scale", 1, 1);
        const double r = x.Has("rotation") && x.Get("rotation").IsNumber() ? x.Get("rotation").GetNumberAsDouble() : 0.0;
        Transform m;
        m.m[0] = {std::cos(r) * sx, std::sin(r) * sy, 0, ox};
        m.m[1] = {-std::sin(r) * sx, std::cos(r) * sy, 0, oy};
        if (!m.is_finite() || !(std::abs(sx * sy) > 0))
            fail(fmt::format("texture {}: its KHR_texture_transform is not finite or scales by 0", info.index));
        pugi::xml_node tw = t.append_child("transform");
        tw.append_attribute("name") = "to_uv";
        tw.append_child("matrix").append_attribute("value") = matrix_text(m).c_str();
    }
    if (raw) {
        pugi::xml_node r = t.append_child("boolean");
        r.append_attribute("name") = "raw";
        r.append_attribute("value") = "true";
    }
}

void Converter::write_material(int index, const std::string& id, pugi::xml_node before) {
    // glTF's default material: base colour 1, metallic 1, roughness 1.
    static const tinygltf::Material kDefault = [] {
        tinygltf::Material m;
        m.name = "default";
        return m;
    }();
    const tinygltf::Material& m = index < 0 ? kDefault : model_.materials[size_t(index)];
    const std::string name = m.name.empty() ? fmt::format("{}", index) : m.name;
    const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
    if (m.alphaMode != "OPAQUE" && !m.alphaMode.empty())
        warn(fmt::format("material '{}': alphaMode {} is not read; the surface is rendered opaque", name, m.alphaMode));
    if (m.normalTexture.index >= 0 && m.normalTexture.scale != 1.0)
        warn(fmt::format("material '{}': the normal texture's scale {} is not read (1 is used)", name, m.normalTexture.scale));
    double transmission = 0, ior = 0;
    if (const auto it = m.extensions.find("KHR_materials_transmission"); it != m.extensions.end()) {
        if (it->second.Has("transmissionFactor")) transmission = it->second.Get("transmissionFactor").GetNumberAsDouble();
        if (it->second.Has("transmissionTexture")) fail(fmt::format("material '{}': a transmission texture is not read by pathlab", name));
    }
    if (const auto it = m.extensions.find("KHR_materials_ior"); it != m.extensions.end())
        ior = it->second.Has("ior") ? it->second.Get("ior").GetNumberAsDouble() : 1.5;

    // twosided (an opaque surface shades alike from both sides, as in Blender) > normalmap > principled
    pugi::xml_node outer = scene_.insert_child_before("bsdf", before);
    outer.append_attribute("id") = id.c_str();
    pugi::xml_node host = outer;
    if (transmission > 0) {
        host.append_attribute("type") = m.normalTexture.index >= 0 ? "normalmap" : "principled";
    } else {
        host.append_attribute("type") = "twosided";
        host = host.append_child("bsdf");
        host.append_attribute("type") = m.normalTexture.index >= 0 ? "normalmap" : "principled";
    }
    if (m.normalTexture.index >= 0) {
        tinygltf::TextureInfo info;
        info.index = m.normalTexture.index, info.texCoord = m.normalTexture.texCoord, info.extensions = m.normalTexture.extensions;
        texture_image(info, name, "normalTexture");  // checks the texture (its image is copied as it is)
        add_bitmap(host, "normalmap", image_file(model_.textures[size_t(info.index)].source), info, /*raw=*/true);
        // The reciprocal normal map (Mitsuba's flip and shadowing term off), which every integrator renders.
        for (const char* option : {"flip_invalid_normals", "use_shadowing_function"}) {
            pugi::xml_node b = host.append_child("boolean");
            b.append_attribute("name") = option;
            b.append_attribute("value") = "false";
        }
        host = host.append_child("bsdf");
        host.append_attribute("type") = "principled";
    }
    const auto add_float = [&](const char* param, double v) {
        pugi::xml_node f = host.append_child("float");
        f.append_attribute("name") = param;
        f.append_attribute("value") = number(v).c_str();
    };
    const std::vector<double>& c = pbr.baseColorFactor;
    if (pbr.baseColorTexture.index >= 0) {
        const tinygltf::Image& image = texture_image(pbr.baseColorTexture, name, "baseColorTexture");
        const int source = model_.textures[size_t(pbr.baseColorTexture.index)].source;
        if (c[0] == 1 && c[1] == 1 && c[2] == 1) {
            add_bitmap(host, "base_color", image_file(source), pbr.baseColorTexture, /*raw=*/false);
        } else {  // the factor times the texture's decoded sRGB values, as a linear image
            const std::string file = derived_image(fmt::format("base-color-{}.exr", index), image, [&](const uint8_t* t) {
                return Rgb(float(c[0] * decode_srgb8(t[0])), float(c[1] * decode_srgb8(t[1])), float(c[2] * decode_srgb8(t[2])));
            });
            add_bitmap(host, "base_color", file, pbr.baseColorTexture, /*raw=*/false);
        }
    } else {
        pugi::xml_node r = host.append_child("rgb");
        r.append_attribute("name") = "base_color";
        r.append_attribute("value") = triple(c[0], c[1], c[2]).c_str();
    }
    if (pbr.metallicRoughnessTexture.index >= 0) {
        // roughness in the green channel, metallic in the blue, each times its factor
        const tinygltf::Image& image = texture_image(pbr.metallicRoughnessTexture, name, "metallicRoughnessTexture");
        for (const auto& [param, channel, factor] : {std::tuple{"metallic", 2, pbr.metallicFactor}, std::tuple{"roughness", 1, pbr.roughnessFactor}}) {
            const std::string file = derived_image(fmt::format("{}-{}.exr", param, index), image, [&, channel = channel, factor = factor](const uint8_t* t) {
                return Rgb(float(factor * (t[channel] / 255.0)));
            });
            add_bitmap(host, param, file, pbr.metallicRoughnessTexture, /*raw=*/true);
        }
    } else {
        add_float("metallic", pbr.metallicFactor);
        add_float("roughness", pbr.roughnessFactor);  // glTF's roughness is Disney's: alpha = roughness^2
    }
    if (transmission > 0) add_float("spec_trans", transmission);
    if (ior > 0) add_float("eta", ior);
}

void Converter::add_camera(const tinygltf::Camera& cam, const Transform& node) {
    const bool ortho = cam.type == "orthographic";
    if (cam.type != "perspective" && !ortho)
        fail(fmt::format("camera '{}' is {}; glTF cameras are perspective or orthographic", cam.name, cam.type.empty() ? "of no type" : cam.type));
    const tinygltf::PerspectiveCamera& p = cam.perspective;
    const tinygltf::OrthographicCamera& o = cam.orthographic;
    if (!ortho && !(p.yfov > 0 && p.yfov < kPi)) fail(fmt::format("camera '{}': yfov {} is not between 0 and pi", cam.name, p.yfov));
    if (ortho && !(o.xmag > 0 && o.ymag > 0 && std::isfinite(o.xmag) && std::isfinite(o.ymag)))
        fail(fmt::format("camera '{}': xmag {} and ymag {} must be positive", cam.name, o.xmag, o.ymag));
    // glTF's camera looks down -z with +y up and +x right; Mitsuba's down +z with +x left: turn
    // it half a turn about y. Only the rotation and translation of the node count (no scale).
    Transform t = node;
    for (int c = 0; c < 3; ++c) {
        double len = 0;
        for (int r = 0; r < 3; ++r) len += t.m[size_t(r)][size_t(c)] * t.m[size_t(r)][size_t(c)];
        len = std::sqrt(len);
        if (!(len > 0)) fail(fmt::format("camera '{}': its node's transform has a zero scale", cam.name));
        for (int r = 0; r < 3; ++r) t.m[size_t(r)][size_t(c)] /= len;
    }
    t = t * Transform::scale({-1, 1, -1});
    const int width = 640;
    const double aspect = ortho ? o.xmag / o.ymag : p.aspectRatio;
    const int height = aspect > 0 ? std::max(1, int(std::lround(width / aspect))) : 480;
    pugi::xml_node s = scene_.append_child("sensor");
    s.append_attribute("type") = ortho ? "orthographic" : "perspective";
    if (ortho) {
        // Mitsuba's orthographic sensor sees camera-space x in [-1, 1] and y in [-1/a, 1/a] (a the
        // film's aspect, here xmag / ymag), scaled by to_world: xmag on both axes.
        t = t * Transform::scale({o.xmag, o.xmag, 1});
    } else {
        pugi::xml_node fov = s.append_child("float");
        fov.append_attribute("name") = "fov";
        fov.append_attribute("value") = number(p.yfov * 180.0 / kPi).c_str();
        pugi::xml_node axis = s.append_child("string");
        axis.append_attribute("name") = "fov_axis";
        axis.append_attribute("value") = "y";
    }
    pugi::xml_node tw = s.append_child("transform");
    tw.append_attribute("name") = "to_world";
    tw.append_child("matrix").append_attribute("value") = matrix_text(t).c_str();
    pugi::xml_node film = s.append_child("film");
    film.append_attribute("type") = "hdrfilm";
    for (const auto& [name, value] : {std::pair{"width", width}, std::pair{"height", height}}) {
        pugi::xml_node i = film.append_child("integer");
        i.append_attribute("name") = name;
        i.append_attribute("value") = value;
    }
    film.append_child("rfilter").append_attribute("type") = "box";
    have_camera_ = true;
}

void Converter::add_default_camera() {
    if (!(lo_.x <= hi_.x)) fail("the scene has no camera and no mesh to frame");
    warn("the scene has no camera: pathlab frames its bounds from +z (yfov 39.6 degrees, Blender's 50 mm lens)");
    const Vec3d centre = (lo_ + hi_) * 0.5;
    const double radius = length(hi_ - lo_) * 0.5;
    const double fov = 39.6 * kPi / 180;
    tinygltf::Camera cam;
    cam.name = "default";
    cam.type = "perspective";
    cam.perspective.yfov = fov;
    cam.perspective.aspectRatio = 4.0 / 3.0;
    add_camera(cam, Transform::translate(centre + Vec3d(0, 0, 1.1 * radius / std::sin(fov / 2))));
}

void Converter::add_light(int index, const Transform& node) {
    const auto lights = model_.extensions.find("KHR_lights_punctual");
    if (lights == model_.extensions.end() || !lights->second.Has("lights") || !lights->second.Get("lights").IsArray() ||
        index < 0 || size_t(index) >= lights->second.Get("lights").ArrayLen())
        fail(fmt::format("KHR_lights_punctual: light {} does not exist", index));
    const tinygltf::Value& l = lights->second.Get("lights").Get(index);
    const auto num = [&](const tinygltf::Value& v, const char* key, double fallback) {
        return v.Has(key) && v.Get(key).IsNumber() ? v.Get(key).GetNumberAsDouble() : fallback;
    };
    const std::string type = l.Has("type") ? l.Get("type").Get<std::string>() : "";
    const std::string name = l.Has("name") ? l.Get("name").Get<std::string>() : fmt::format("{}", index);
    double color[3] = {1, 1, 1};
    if (l.Has("color") && l.Get("color").IsArray() && l.Get("color").ArrayLen() == 3)
        for (int i = 0; i < 3; ++i) color[i] = l.Get("color").Get(i).GetNumberAsDouble();
    const double watts = num(l, "intensity", 1.0) / kLumensPerWatt;  // W/sr (point, spot) or W/m^2 (directional)
    const std::string value = triple(color[0] * watts, color[1] * watts, color[2] * watts);
    const Vec3d position = node.point({0, 0, 0});
    const Vec3d direction = normalize(node.vector({0, 0, -1}));  // glTF lights shine down their -z
    pugi::xml_node e = scene_.append_child("emitter");
    const auto add = [&](const char* tag, const char* param, const std::string& v) {
        pugi::xml_node x = e.append_child(tag);
        x.append_attribute("name") = param;
        x.append_attribute("value") = v.c_str();
    };
    if (type == "point") {
        e.append_attribute("type") = "point";
        add("point", "position", triple(position.x, position.y, position.z));
        add("rgb", "intensity", value);
    } else if (type == "directional") {
        e.append_attribute("type") = "directional";
        add("vector", "direction", triple(direction.x, direction.y, direction.z));
        add("rgb", "irradiance", value);
    } else if (type == "spot") {
        // Mitsuba's spot falls off linearly in angle between beam_width and cutoff_angle; glTF's
        // recommended falloff is smooth in cos theta between the same two cones.
        const tinygltf::Value spot = l.Has("spot") ? l.Get("spot") : tinygltf::Value();
        const double outer = num(spot, "outerConeAngle", kPi / 4), inner = num(spot, "innerConeAngle", 0);
        if (!(inner >= 0 && inner < outer && outer <= kPi / 2))
            fail(fmt::format("spot light '{}': cone angles inner {} and outer {} are not 0 <= inner < outer <= pi/2", name, inner, outer));
        e.append_attribute("type") = "spot";
        add("rgb", "intensity", value);
        add("float", "cutoff_angle", number(outer * 180 / kPi));
        add("float", "beam_width", number(inner * 180 / kPi));
        const Vec3d up = std::abs(direction.y) < 0.9 ? Vec3d(0, 1, 0) : Vec3d(1, 0, 0);
        pugi::xml_node tw = e.append_child("transform");
        tw.append_attribute("name") = "to_world";
        pugi::xml_node la = tw.append_child("lookat");
        la.append_attribute("origin") = triple(position.x, position.y, position.z).c_str();
        const Vec3d target = position + direction;
        la.append_attribute("target") = triple(target.x, target.y, target.z).c_str();
        la.append_attribute("up") = triple(up.x, up.y, up.z).c_str();
    } else {
        fail(fmt::format("light '{}' has type '{}'; KHR_lights_punctual's types are point, spot and directional", name, type));
    }
}

void Converter::visit(int index, const Transform& parent, std::vector<int>& stack) {
    if (index < 0 || size_t(index) >= model_.nodes.size()) fail(fmt::format("node {} does not exist", index));
    if (std::find(stack.begin(), stack.end(), index) != stack.end()) fail(fmt::format("node {} is its own ancestor", index));
    const tinygltf::Node& n = model_.nodes[size_t(index)];
    const Transform to_world = parent * local_transform(n);
    if (!to_world.is_finite()) fail(fmt::format("node {} ('{}'): its transform is not finite", index, n.name));
    if (n.mesh >= 0) {
        if (!to_world.is_affine_invertible()) fail(fmt::format("node {} ('{}'): its transform is not invertible", index, n.name));
        add_mesh(index, n.mesh, to_world);
    }
    if (n.camera >= 0 && !have_camera_) {
        if (size_t(n.camera) >= model_.cameras.size()) fail(fmt::format("node {}: camera {} does not exist", index, n.camera));
        add_camera(model_.cameras[size_t(n.camera)], to_world);
    }
    if (const auto it = n.extensions.find("KHR_lights_punctual"); it != n.extensions.end() && it->second.Has("light"))
        add_light(it->second.Get("light").GetNumberAsInt(), to_world);
    stack.push_back(index);
    for (int c : n.children) visit(c, to_world, stack);
    stack.pop_back();
}

GltfConversion Converter::run() {
    load();
    check_extensions();
    files_dir_ = fs::path(xml_path_).stem().string() + "_files";
    scene_ = doc_.append_child("scene");
    scene_.append_attribute("version") = "3.0.0";
    pugi::xml_node comment = scene_.append_child(pugi::node_comment);
    comment.set_value(fmt::format(" converted by pathlab from {} (docs/scene-files.md, \"glTF scenes\") ", fs::path(path_).filename().string()).c_str());
    if (model_.scenes.empty()) fail("the file has no scene");
    const int scene = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (size_t(scene) >= model_.scenes.size()) fail(fmt::format("the default scene {} does not exist", scene));
    std::vector<int> stack;
    for (int n : model_.scenes[size_t(scene)].nodes) visit(n, Transform(), stack);
    if (!have_camera_) add_default_camera();
    scene_.insert_move_after(scene_.child("sensor"), comment);  // the comment, the sensor, the rest
    std::ostringstream text;
    doc_.save(text, "    ");
    write_text_file(xml_path_, text.str());
    return out_;
}

}  // namespace

bool is_gltf_path(const std::string& path) { return ends_with_ci(path, ".gltf") || ends_with_ci(path, ".glb"); }

GltfConversion convert_gltf_scene(const std::string& gltf_path, const std::string& xml_path) {
    try {
        return Converter(gltf_path, xml_path).run();
    } catch (const ImageIoError& e) {
        throw SceneFileError(gltf_path, 0, 0, fmt::format("converting to {}: {}", xml_path, e.what()));
    } catch (const MeshLoadError& e) {
        throw SceneFileError(gltf_path, 0, 0, fmt::format("converting to {}: {}", xml_path, e.what()));
    }
}

SceneDescription load_gltf_scene(const std::string& path, const SceneDefines& defines, SceneFileInputs* inputs) {
    std::string pattern = (fs::temp_directory_path() / "pathlab-gltf-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw SceneFileError(path, 0, 0, fmt::format("cannot make a temporary folder in {}", fs::temp_directory_path().string()));
    struct Remove {
        std::string dir;
        ~Remove() {
            std::error_code ec;
            fs::remove_all(dir, ec);
        }
    } remove{pattern};
    const std::string xml = (fs::path(pattern) / (fs::path(path).stem().string() + ".xml")).string();
    const GltfConversion c = convert_gltf_scene(path, xml);
    for (const std::string& w : c.warnings) fmt::print(stderr, "pathlab: warning: {}: {}\n", path, w);
    SceneFileInputs converted;
    SceneDescription d;
    try {
        d = load_scene_file(xml, defines, &converted);
    } catch (const SceneFileError& e) {
        throw SceneFileError(path, 0, 0, fmt::format("its conversion to XML does not load (a pathlab bug; `pathlab convert` writes it): {}", e.what()));
    }
    if (inputs) {
        inputs->parameters = converted.parameters;
        inputs->files = c.files;
    }
    return d;
}

}  // namespace pathlab
