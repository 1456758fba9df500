#include "job/render_identity.hpp"

#include <xxhash.h>

#include <cctype>
#include <fstream>
#include <iterator>
#include <sstream>

#include <fmt/format.h>

#include "job/render_job.hpp"

namespace pathlab {

const std::vector<std::string> kIdentityFields = {"scene", "scene hash", "integrator", "options", "resolution", "seed", "sampler"};
const std::vector<std::string> kMergeFields = {"scene", "scene hash", "integrator", "options", "resolution", "sampler"};

std::string RenderIdentity::value(const std::string& key) const {
    for (const auto& [k, v] : fields)
        if (k == key) return v;
    return "";
}

std::string RenderIdentity::to_text() const {
    std::string s;
    for (const auto& [k, v] : fields) s += k + "=" + v + "\n";
    return s;
}

RenderIdentity RenderIdentity::from_text(const std::string& text) {
    RenderIdentity id;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        const size_t eq = line.find('=');
        if (eq == std::string::npos || eq == 0) continue;
        id.fields.emplace_back(line.substr(0, eq), line.substr(eq + 1));
    }
    return id;
}

std::string RenderIdentity::hash() const {
    const std::string t = to_text();
    return fmt::format("{:016x}", XXH3_64bits(t.data(), t.size()));
}

std::string RenderIdentity::differences(const RenderIdentity& ours, const std::vector<std::string>& keys, const std::string& theirs_name,
                                        const std::string& ours_name) const {
    std::string out;
    for (const std::string& k : keys) {
        const std::string a = value(k), b = ours.value(k);
        if (a != b) out += fmt::format("  {}: {} in {}, {} in {}\n", k, a.empty() ? "(none)" : a, theirs_name, b.empty() ? "(none)" : b, ours_name);
    }
    return out;
}

namespace {

class Hasher {
public:
    Hasher() : state_(XXH3_createState()) { XXH3_64bits_reset(state_); }
    ~Hasher() { XXH3_freeState(state_); }
    Hasher(const Hasher&) = delete;
    Hasher& operator=(const Hasher&) = delete;
    void bytes(const void* p, size_t n) { XXH3_64bits_update(state_, p, n); }
    template <class T>
    void values(const std::vector<T>& v) {
        const uint64_t n = v.size();
        bytes(&n, sizeof n);
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
    void text(const std::string& s) { values(std::vector<char>(s.begin(), s.end())); }
    void floats(std::initializer_list<float> f) {
        for (float x : f) bytes(&x, sizeof x);
    }
    std::string hex() const { return fmt::format("{:016x}", XXH3_64bits_digest(state_)); }

private:
    XXH3_state_t* state_;
};

std::string hex_float(double v) { return fmt::format("{:a}", v); }

}  // namespace

std::string scene_hash(const std::string& file, const SceneDescription& d, const std::string& extra) {
    Hasher h;
    if (!file.empty()) {
        std::ifstream in(file, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        h.text(bytes);
    }
    h.text(extra);
    h.text(d.name);
    h.floats({d.camera.position.x, d.camera.position.y, d.camera.position.z, d.camera.forward.x, d.camera.forward.y,
              d.camera.forward.z, d.camera.up.x, d.camera.up.y, d.camera.up.z, d.camera.fov_degrees});
    // Vec3f, Vec2f and the triangles' index triples have no padding.
    static_assert(sizeof(Vec3f) == 12 && sizeof(Vec2f) == 8 && sizeof(std::array<uint32_t, 3>) == 12);
    for (const MeshDesc& m : d.meshes) {
        h.values(m.positions), h.values(m.normals), h.values(m.uvs), h.values(m.triangles);
        h.bytes(&m.material, sizeof m.material);
        h.floats({m.emission.x, m.emission.y, m.emission.z});
    }
    for (const SphereDesc& s : d.spheres) {
        h.floats({s.center.x, s.center.y, s.center.z, s.radius, s.emission.x, s.emission.y, s.emission.z});
        h.bytes(&s.material, sizeof s.material);
        const uint8_t flip = s.flip_normals;
        h.bytes(&flip, 1);
    }
    const uint64_t counts[2] = {d.materials.size(), d.lights.size()};
    h.bytes(counts, sizeof counts);
    return h.hex();
}

std::string options_text(const IntegratorOptions& o) {
    return fmt::format("max_depth={} rr_depth={} only_length={} mis={} photons={} radius={} alpha={} merging={} connections={} "
                       "ic_rays={} ic_error={} ic_gradients={}",
                       o.max_depth, o.rr_depth, o.only_length, o.mis_power ? "power" : "balance", o.photons, hex_float(o.photon_radius),
                       hex_float(o.photon_alpha), int(o.vcm_merging), int(o.vcm_connections), o.ic_rays, hex_float(o.ic_error),
                       int(o.ic_gradients));
}

std::string metadata_key(const std::string& field) {
    std::string key = "pathlab:";
    bool upper = false;
    for (char c : field) {
        if (c == ' ') upper = true;
        else key += upper ? char(std::toupper(static_cast<unsigned char>(c))) : c, upper = false;
    }
    return key;
}

std::vector<std::pair<std::string, std::string>> render_metadata(const RenderIdentity& identity, const PassSet& passes,
                                                                 uint64_t invalid_samples) {
    std::vector<std::pair<std::string, std::string>> m;
    for (const auto& [k, v] : identity.fields) m.emplace_back(metadata_key(k), v);
    m.emplace_back("pathlab:spp", fmt::format("{}", passes.count()));
    m.emplace_back("pathlab:firstSample", fmt::format("{}", passes.begin()));
    m.emplace_back("pathlab:passes", passes.to_string());
    m.emplace_back("pathlab:invalidSamples", fmt::format("{}", invalid_samples));
    m.emplace_back("pathlab:version", PATHLAB_VERSION);
    return m;
}

RenderIdentity render_identity(RenderJob& job, int width, int height, const std::string& scene_extra) {
    const SceneChoice& c = job.scene_choice();
    const std::string source = c.file.empty() ? (c.builtin ? fmt::format("builtin:{}", *c.builtin) : "") : "";
    RenderIdentity id;
    id.fields = {{"scene", c.name},
                 {"scene hash", scene_hash(c.file, c.description, source + scene_extra)},
                 {"integrator", job.integrator_info().name},
                 {"options", options_text(job.integrator_options())},
                 {"resolution", fmt::format("{}x{}", width, height)},
                 {"seed", fmt::format("{}", job.settings.seed)},
                 {"sampler", job.settings.sampler == SamplerKind::Sobol ? "sobol" : "independent"}};
    return id;
}

}  // namespace pathlab
