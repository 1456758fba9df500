// Hand-built paths in a small scene with diffuse, glossy and mirror quads and an area, point or
// environment light, their strategies' densities written out from their definitions (not taken
// from the subpath code), and the subpaths bdpt (or vcm) would have traced for each strategy:
// what the MIS tests (test_bdpt_mis.cpp, test_vcm_mis.cpp) check the weights against.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include "integrators/bidir/bdpt.hpp"
#include "scene_helpers.hpp"

namespace pathlab::test {
namespace {

constexpr uint32_t kDiffuse = 0, kGlossy = 1, kMirror = 2, kLight = 3;

enum class LightKind { Area, Point, Environment };

SceneDescription scene(LightKind light) {
    SceneDescription d;
    d.name = "mis";
    d.camera = Camera::look_at({0, -4, 1.5f}, {0, 0, 0.5f}, {0, 0, 1}, 60, FovAxis::X);
    d.width = d.height = 64;
    d.materials = {make_phong(Rgb(0.6f)), make_phong(Rgb(0.2f), Rgb(0.5f), 20), make_mirror(Rgb(0.9f)), make_phong(Rgb(0.0f))};
    d.meshes.push_back(quad({0, 0, 0}, {3, 0, 0}, {0, 3, 0}, kDiffuse));                           // floor, normal +z
    d.meshes.push_back(quad({0, 2.5f, 1.5f}, {3, 0, 0}, {0, 0, 1.5f}, kDiffuse));                  // back wall, normal -y
    d.meshes.push_back(quad({1.2f, 1.0f, 0.8f}, {0, 0, 0.6f}, {0, 0.6f, 0}, kGlossy));             // glossy, normal -x
    d.meshes.push_back(quad({-1.2f, 1.0f, 0.8f}, {0, 0.6f, 0}, {0, 0, 0.6f}, kMirror));            // mirror, normal +x
    if (light == LightKind::Area) d.meshes.push_back(quad({0, 0.5f, 2.5f}, {0.5f, 0, 0}, {0, -0.5f, 0}, kLight, Rgb(6.0f)));  // normal -z
    if (light == LightKind::Point) d.lights.push_back(PointLight{{0.3f, 0.4f, 2.2f}, Rgb(8.0f)});
    if (light == LightKind::Environment) d.lights.push_back(EnvironmentLight{Rgb(0.8f)});
    if (light != LightKind::Area) d.lights.push_back(PointLight{{-2, -2, 3}, Rgb(1.0f)});  // a second light, for the pmf
    return d;
}

// A full path x_0 (the pinhole), x_1, ..., x_k as real hits of the scene: what the test
// builds subpaths from. The last point is on a light (area: a hit on the emitter; point: its
// position; environment: a direction).
struct FullPath {
    std::vector<Vec3f> p;
    std::vector<Intersection> hit;  // hit[j] for the surface points
    LightKind light = LightKind::Area;
    int light_index = -1;
    Vec3f env_dir;
    std::string problem;  // why the path could not be built as asked (empty: it was)
};

// Where a segment of a hand-built path goes: towards a point that it must hit, or (after a
// mirror) along the mirror's reflection.
struct Aim {
    Aim() = default;
    Aim(const Vec3f& p) : point(p) {}  // NOLINT: implicit, for the paths' lists
    std::optional<Vec3f> point;
};
const Aim kReflect{};

class MisHarness {
public:
    explicit MisHarness(LightKind kind, BdptFaults faults = {})
        : desc_(scene(kind)), scene_(Scene::build(desc_)), camera_(scene_->camera(), 64, 64),
          ctx_{*scene_, camera_, 64, 64, 1, SamplerKind::Independent, 32}, kind_(kind), balance_(IntegratorOptions{}, faults),
          power_(power_options(), faults) {}

    // Traces from the pinhole through each aim in turn (each must hit its point, and the camera
    // must see the first); for point and environment lights the light end is added after.
    FullPath build(const std::vector<Aim>& aims, const Vec3f& env_dir = {}) const {
        FullPath f;
        f.light = kind_;
        f.p.push_back(camera_.position());
        f.hit.push_back({});
        if (!aims.front().point || !camera_.connect(*aims.front().point)) f.problem = "the camera does not see the first point";
        Ray ray{camera_.position(), normalize(*aims.front().point - camera_.position()), kInf};
        for (size_t j = 0; j < aims.size(); ++j) {
            Intersection h;
            if (!scene_->intersect(ray, h)) {
                f.problem = "segment " + std::to_string(j) + " hits nothing";
                return f;
            }
            if (aims[j].point && length(h.p - *aims[j].point) > 1e-3f)
                f.problem = "segment " + std::to_string(j) + " hits the wrong surface";
            f.p.push_back(h.p);
            f.hit.push_back(h);
            if (j + 1 == aims.size()) break;
            const ShadingPoint sp = make_shading_point(*scene_, h, ray.d);
            const Vec3f next = aims[j + 1].point ? normalize(*aims[j + 1].point - h.p) : reflect(-ray.d, sp.ng);
            ray = spawn_ray(h.p, sp.ng, next);
        }
        if (kind_ == LightKind::Area) {
            if (f.hit.back().light < 0) f.problem = "the last point is not on the light";
            f.light_index = f.hit.back().light;
        } else if (kind_ == LightKind::Point) {
            f.p.push_back(std::get<PointLight>(scene_->lights()[0]).position);
            f.hit.push_back({});
            f.light_index = 0;
        } else {
            f.env_dir = normalize(env_dir);
            f.p.push_back(f.p.back() + f.env_dir);
            f.hit.push_back({});
            f.light_index = scene_->environment_light();
        }
        return f;
    }

    // ---- the densities, from their definitions ---------------------------------------------
    bool specular(const FullPath& f, int j) const {
        return j > 0 && j < k(f) && scene_->material(f.hit[size_t(j)].material).is_delta();
    }
    int k(const FullPath& f) const { return int(f.p.size()) - 1; }
    // Area density at x_to of a direction chosen at x_from with solid-angle density pdfW.
    float area(const FullPath& f, float pdfW, int from, int to) const {
        if (to == k(f) && kind_ == LightKind::Environment) return pdfW;
        if (to == k(f) && kind_ == LightKind::Point) {
            const Vec3f d = f.p[size_t(to)] - f.p[size_t(from)];
            return pdfW / dot(d, d);
        }
        const Vec3f d = f.p[size_t(to)] - f.p[size_t(from)];
        return pdfW * std::abs(dot(f.hit[size_t(to)].ng, normalize(d))) / dot(d, d);
    }
    Vec3f dir(const FullPath& f, int from, int to) const {
        if (to == k(f) && kind_ == LightKind::Environment) return f.env_dir;
        if (from == k(f) && kind_ == LightKind::Environment) return -f.env_dir;
        return normalize(f.p[size_t(to)] - f.p[size_t(from)]);
    }
    // The BSDF density at x_j of going on to x_next, having come from x_prev.
    float bsdf_density(const FullPath& f, int prev, int j, int next) const {
        // A Dirac lobe: its coefficient (the selection probability, 1 for the mirror) as a
        // solid-angle density, converted to area at x_next: the delta itself is common to every
        // strategy that can make the path, so it cancels from the heuristic, and the cosines and
        // distances stay (the VCM report's specular vertices).
        if (specular(f, j)) return area(f, 1.0f, j, next);
        const ShadingPoint sp = make_shading_point(*scene_, f.hit[size_t(j)], -dir(f, j, prev));
        return area(f, sp.material->pdf(sp.frame.to_local(dir(f, j, prev)), sp.frame.to_local(dir(f, j, next))), j, next);
    }
    // Light sampling's density of the light end (x_k).
    float light_origin(const FullPath& f) const {
        const float pmf = scene_->emitter_pmf(f.light_index);
        if (kind_ == LightKind::Point) return pmf;
        if (kind_ == LightKind::Environment) return pmf / (4 * kPi);
        return pmf / std::get<TriangleLight>(scene_->lights()[size_t(f.light_index)]).area;
    }
    // The light's density of emitting from x_k towards x_{k-1}.
    float light_emission(const FullPath& f) const {
        const int n = k(f);
        if (kind_ == LightKind::Environment) {
            const float R = scene_->scene_sphere().radius;
            return std::abs(dot(f.hit[size_t(n - 1)].ng, f.env_dir)) / (kPi * R * R);
        }
        if (kind_ == LightKind::Point) return area(f, 1 / (4 * kPi), n, n - 1);
        const Vec3f nl = f.hit[size_t(n)].ng;
        return area(f, std::max(0.0f, dot(nl, dir(f, n, n - 1))) / kPi, n, n - 1);
    }
    // The density of the whole path under strategy (s, t), t = k + 1 - s.
    double strategy_density(const FullPath& f, int s) const {
        const int n = k(f), t = n + 1 - s;
        double p = 1;
        for (int j = 1; j < t; ++j)  // camera side: x_1 .. x_{t-1}
            p *= j == 1 ? area(f, camera_.pdf_direction(dir(f, 0, 1)), 0, 1) : bsdf_density(f, j - 2, j - 1, j);
        for (int i = 0; i < s; ++i) {  // light side: x_k, x_{k-1}, ..., x_{k-s+1}
            const int j = n - i;
            p *= i == 0 ? light_origin(f) : i == 1 ? light_emission(f) : bsdf_density(f, j + 2, j + 1, j);
        }
        return p;
    }
    bool valid(const FullPath& f, int s) const {
        const int n = k(f), t = n + 1 - s;
        if (s + t == 2) return s == 0;
        if (s == 0) return kind_ != LightKind::Point;
        if (t == 1) return !specular(f, 1) && n >= 2;
        return !specular(f, t - 1) && !specular(f, t);
    }
    double direct_weight(const FullPath& f, int s, bool power) const {
        const auto h = [power](double x) { return power ? x * x : x; };
        double sum = 0;
        for (int i = 0; i <= k(f); ++i)
            if (valid(f, i)) sum += h(strategy_density(f, i));
        return h(strategy_density(f, s)) / sum;
    }

    // ---- the subpaths bdpt would have traced for strategy (s, t) --------------------------------
    PathVertex<RgbTransport> vertex(const FullPath& f, int j, bool camera_side) const {
        PathVertex<RgbTransport> v;
        const int n = k(f);
        if (j == 0 && camera_side) {
            v.kind = VertexKind::Camera;
            v.p = f.p[0];
            return v;
        }
        if (j == n && (!camera_side || kind_ != LightKind::Area)) {
            v.kind = VertexKind::Light;
            v.light = f.light_index;
            v.p = f.p[size_t(n)];
            v.infinite = kind_ == LightKind::Environment;
            v.dir = f.env_dir;
            v.delta_light = kind_ == LightKind::Point;
            if (kind_ == LightKind::Area) v.n = v.emitter_n = f.hit[size_t(n)].ng;
            return v;
        }
        // A surface point, reached from x_{j-1} (camera side) or x_{j+1} (light side).
        const int from = camera_side ? j - 1 : j + 1;
        v.kind = VertexKind::Surface;
        v.sp = make_shading_point(*scene_, f.hit[size_t(j)], -dir(f, j, from),
                                  camera_side ? TransportMode::Radiance : TransportMode::Importance);
        v.p = f.p[size_t(j)];
        v.n = v.sp.ng;
        v.emitter_n = f.hit[size_t(j)].ng;
        v.light = f.hit[size_t(j)].light;
        v.delta = specular(f, j);
        return v;
    }
    // Subpaths with the densities their random walks record (pdf_fwd from the predecessor,
    // pdf_rev from the successor on the same subpath); the vertices at the new edge get NaN,
    // which bdpt must overwrite. Their running MIS quantities are made as bdpt's subpaths make
    // them, for the heuristic (power) and the merging strategies vm.
    void subpaths(const FullPath& f, int s, std::vector<PathVertex<RgbTransport>>& light, std::vector<PathVertex<RgbTransport>>& camera,
                  bool power = false, const MergeMis* vm = nullptr) const {
        const int n = k(f), t = n + 1 - s;
        camera.clear(), light.clear();
        for (int j = 0; j < t; ++j) {
            PathVertex<RgbTransport> v = vertex(f, j, true);
            v.pdf_fwd = j == 0 ? 1 : j == 1 ? area(f, camera_.pdf_direction(dir(f, 0, 1)), 0, 1) : bsdf_density(f, j - 2, j - 1, j);
            v.pdf_rev = j + 2 <= t - 1 ? bsdf_density(f, j + 2, j + 1, j) : NAN;
            if (j == t - 1 || (j == t - 2 && t >= 2)) v.pdf_rev = NAN;
            camera.push_back(v);
        }
        for (int i = 0; i < s; ++i) {
            const int j = n - i;
            PathVertex<RgbTransport> v = vertex(f, j, false);
            v.pdf_fwd = i == 0 ? light_origin(f) : i == 1 ? light_emission(f) : bsdf_density(f, j + 2, j + 1, j);
            v.pdf_rev = i + 2 <= s - 1 ? bsdf_density(f, j - 2, j - 1, j) : NAN;
            if (i >= s - 2) v.pdf_rev = NAN;
            light.push_back(v);
        }
        set_running_mis(light.data(), int(light.size()), /*light_side=*/true, MisRules(power, vm));
        set_running_mis(camera.data(), int(camera.size()), /*light_side=*/false, MisRules(power, vm));
    }
    PathVertex<RgbTransport> sampled_end(const FullPath& f, int s) const {
        if (s == 1) {
            PathVertex<RgbTransport> v = vertex(f, k(f), false);
            v.pdf_fwd = light_origin(f);
            return v;
        }
        return vertex(f, 0, true);
    }

    const Bdpt<RgbTransport>& bdpt(bool power) const { return power ? power_ : balance_; }
    LightKind kind() const { return kind_; }
    const RenderContext& ctx() const { return ctx_; }

private:
    SceneDescription desc_;
    std::unique_ptr<Scene> scene_;
    PerspectiveCamera camera_;
    RenderContext ctx_;
    LightKind kind_;
    Bdpt<RgbTransport> balance_, power_;

    static IntegratorOptions power_options() {
        IntegratorOptions o;
        o.mis_power = true;
        return o;
    }
};

// The floor point from which a ray reflected by the mirror plane x = -1.2 at m reaches q.
Vec3f floor_point_reflected_to(const Vec3f& m, const Vec3f& q) {
    const Vec3f image(-2.4f - q.x, q.y, q.z);  // q mirrored in the plane
    const Vec3f d = m - image;
    return m + d * (m.z / -d.z);
}

struct NamedPath {
    std::string name;
    FullPath path;
};

// The hand-built paths the MIS tests check, for the harness's light: diffuse, glossy and mirror
// vertices; with the point light, specular-diffuse-specular paths (camera-mirror-floor-point)
// that only merging can make.
inline std::vector<NamedPath> hand_built_paths(const MisHarness& h) {
    const Vec3f a(0.2f, 0.4f, 0.0f), b(-0.4f, 2.5f, 1.0f), on_glossy(1.2f, 1.1f, 0.7f), low_mirror(-1.2f, 0.6f, 0.3f);
    switch (h.kind()) {
        case LightKind::Area: {
            const Vec3f on_light(0.1f, 0.45f, 2.5f), on_mirror(-1.2f, 1.0f, 0.8f);
            return {{"camera-floor-light", h.build({a, on_light})},
                    {"camera-floor-glossy-light", h.build({a, on_glossy, on_light})},
                    {"camera-floor-wall-light", h.build({a, b, on_light})},
                    {"camera-glossy-floor-wall-light", h.build({on_glossy, a, b, on_light})},
                    {"camera-light", h.build({on_light})},  // the light seen directly
                    {"camera-floor-mirror-light", h.build({floor_point_reflected_to(on_mirror, on_light), on_mirror, kReflect})},
                    // A vertical mirror cannot send light from the floor back down: mirrors seen first.
                    {"camera-mirror-floor-light", h.build({low_mirror, kReflect, on_light})},
                    {"camera-mirror-floor-wall-light", h.build({low_mirror, kReflect, b, on_light})}};
        }
        case LightKind::Point:
            return {{"camera-floor-point", h.build({a})},
                    {"camera-floor-glossy-point", h.build({a, on_glossy})},
                    {"camera-mirror-floor-point", h.build({low_mirror, kReflect})},
                    {"camera-mirror-floor-wall-point", h.build({low_mirror, kReflect, b})}};
        case LightKind::Environment:
            return {{"camera-floor-sky", h.build({a}, {0.2f, 0.1f, 1.0f})},
                    {"camera-floor-glossy-sky", h.build({a, on_glossy}, {-1.0f, 0.2f, 0.5f})},
                    {"camera-mirror-floor-sky", h.build({low_mirror, kReflect}, {0.1f, 0.3f, 1.0f})}};
    }
    return {};
}

}  // namespace
}  // namespace pathlab::test
