#include "scene/scene.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace pathlab {
namespace {

thread_local uint64_t t_rays_traced = 0;

void validate(const SceneDescription& d) {
    const auto check_material = [&](uint32_t m, const std::string& what) {
        if (m >= d.materials.size())
            throw SceneError(fmt::format("{} refers to material {}, but the scene has {} materials", what, m, d.materials.size()));
    };
    for (size_t i = 0; i < d.meshes.size(); ++i) {
        const MeshDesc& m = d.meshes[i];
        const std::string what = fmt::format("mesh '{}'", m.name.empty() ? std::to_string(i) : m.name);
        if (m.triangles.empty()) throw SceneError(what + " has no faces");
        check_material(m.material, what);
        for (const Vec3f& p : m.positions)
            if (!is_finite(p)) throw SceneError(what + " has a NaN or infinite vertex");
        if (!m.normals.empty() && m.normals.size() != m.positions.size())
            throw SceneError(fmt::format("{} has {} normals for {} vertices", what, m.normals.size(), m.positions.size()));
        if (!m.uvs.empty() && m.uvs.size() != m.positions.size())
            throw SceneError(fmt::format("{} has {} texture coordinates for {} vertices", what, m.uvs.size(), m.positions.size()));
        for (const auto& tri : m.triangles)
            for (uint32_t v : tri)
                if (v >= m.positions.size())
                    throw SceneError(fmt::format("{} has a vertex index {} out of range (it has {} vertices)", what, v, m.positions.size()));
        if (!is_finite(m.emission) || min_component(m.emission) < 0)
            throw SceneError(what + " has an invalid emitted radiance");
    }
    for (size_t i = 0; i < d.spheres.size(); ++i) {
        const SphereDesc& s = d.spheres[i];
        const std::string what = fmt::format("sphere {}", i);
        check_material(s.material, what);
        if (!is_finite(s.center) || !(s.radius > 0) || !std::isfinite(s.radius))
            throw SceneError(what + " needs a finite centre and a positive radius");
        if (!is_finite(s.emission) || min_component(s.emission) < 0)
            throw SceneError(what + " has an invalid emitted radiance");
    }
    for (size_t g = 0; g < d.groups.size(); ++g)
        for (const MeshDesc& m : d.groups[g].meshes) {
            const std::string what = fmt::format("mesh '{}' of shapegroup '{}'", m.name, d.groups[g].name);
            if (m.triangles.empty()) throw SceneError(what + " has no faces");
            check_material(m.material, what);
            for (const auto& tri : m.triangles)
                for (uint32_t v : tri)
                    if (v >= m.positions.size()) throw SceneError(what + " has a vertex index out of range");
            if (!m.normals.empty() && m.normals.size() != m.positions.size()) throw SceneError(what + " has a normal count unlike its vertex count");
            if (!m.uvs.empty() && m.uvs.size() != m.positions.size()) throw SceneError(what + " has a uv count unlike its vertex count");
            if (!is_black(m.emission)) throw SceneError(what + " emits light: emitters cannot be instanced");
        }
    for (const InstanceDesc& inst : d.instances)
        if (inst.group >= d.groups.size() || !inst.to_world.is_finite() || !inst.to_world.is_affine_invertible())
            throw SceneError("an instance refers to a missing shapegroup or has a degenerate transform");
    int environments = 0;
    for (const FreeLight& l : d.lights)
        environments += std::holds_alternative<EnvironmentLight>(l) || std::holds_alternative<EnvMapLight>(l);
    if (environments > 1) throw SceneError("a scene can have at most one environment light");
}

}  // namespace

uint64_t Scene::rays_traced_by_this_thread() { return t_rays_traced; }

std::unique_ptr<Scene> Scene::build(const SceneDescription& desc) {
    validate(desc);
    std::unique_ptr<Scene> s(new Scene());
    s->desc_ = desc;
    s->name_ = desc.name;
    s->camera_ = desc.camera;
    s->width_ = desc.width;
    s->height_ = desc.height;
    s->materials_ = desc.materials;

    for (const FreeLight& l : desc.lights) {
        std::visit([&](const auto& light) { s->lights_.emplace_back(light); }, l);
        if (is_environment(s->lights_.back())) s->environment_ = int(s->lights_.size()) - 1;
    }

    Vec3f lo(kInf), hi(-kInf);
    s->face_normals_.reserve(desc.meshes.size());  // stable addresses for the records
    for (size_t i = 0; i < desc.meshes.size(); ++i) {
        const MeshDesc& m = desc.meshes[i];
        const uint32_t id = s->accel_.add_mesh(m);
        if (id >= s->geometry_.size()) s->geometry_.resize(id + 1);
        std::vector<Vec3f> normals(m.triangles.size());
        for (size_t t = 0; t < m.triangles.size(); ++t) {
            const auto& tri = m.triangles[t];
            normals[t] = normalize(cross(m.positions[tri[1]] - m.positions[tri[0]], m.positions[tri[2]] - m.positions[tri[0]]));
        }
        s->face_normals_.push_back(std::move(normals));
        GeometryRecord rec{false, uint32_t(i), -1, &s->desc_.meshes[i], s->face_normals_.back().data()};
        if (!is_black(m.emission)) {
            rec.first_light = int32_t(s->lights_.size());
            for (const auto& t : m.triangles)
                s->lights_.emplace_back(TriangleLight(m.positions[t[0]], m.positions[t[1]], m.positions[t[2]], m.emission));
        }
        s->geometry_[id] = rec;
        for (const Vec3f& p : m.positions) lo = min(lo, p), hi = max(hi, p);
    }
    for (size_t i = 0; i < desc.spheres.size(); ++i) {
        const SphereDesc& sp = desc.spheres[i];
        const uint32_t id = s->accel_.add_sphere(sp);
        if (id >= s->geometry_.size()) s->geometry_.resize(id + 1);
        GeometryRecord rec{true, uint32_t(i), -1};
        if (!is_black(sp.emission)) {
            rec.first_light = int32_t(s->lights_.size());
            s->lights_.emplace_back(SphereLight{sp.center, sp.radius, sp.flip_normals, sp.emission});
        }
        s->geometry_[id] = rec;
        lo = min(lo, sp.center - Vec3f(sp.radius)), hi = max(hi, sp.center + Vec3f(sp.radius));
    }
    for (const ShapeGroupDesc& g : desc.groups) s->accel_.add_group(g.meshes);
    for (size_t i = 0; i < desc.instances.size(); ++i) {
        const InstanceDesc& inst = desc.instances[i];
        const uint32_t id = s->accel_.add_instance(inst.group, inst.to_world);
        if (id >= s->geometry_.size()) s->geometry_.resize(id + 1);
        GeometryRecord rec;
        rec.instance = int32_t(i);
        s->geometry_[id] = rec;
        for (const MeshDesc& m : desc.groups[inst.group].meshes)
            for (const Vec3f& p : m.positions) {
                const Vec3f w(inst.to_world.point(Vec3d(p)));
                lo = min(lo, w), hi = max(hi, w);
            }
    }
    s->accel_.commit();
    if (lo.x <= hi.x) {
        s->center_ = (lo + hi) * 0.5f;
        s->radius_ = std::max(1e-3f, 0.5f * length(hi - lo));
    }

    s->light_distribution_ = LightDistribution(s->lights_, s->scene_sphere());
    return s;
}

bool Scene::has_delta_lights() const {
    return std::any_of(lights_.begin(), lights_.end(), [](const Light& l) { return is_delta_light(l); });
}

bool Scene::has_hittable_emitters() const {
    return std::any_of(lights_.begin(), lights_.end(), [](const Light& l) { return !is_delta_light(l); });
}

bool Scene::intersect(const Ray& ray, Intersection& hit) const {
    ++t_rays_traced;
    RawHit raw;
    if (!accel_.intersect(ray, raw)) return false;
    hit.t = raw.t;
    hit.uv = Vec2f(0.0f, 0.0f);
    if (raw.inst_id != RawHit::kNoInstance) [[unlikely]] {
        instance_hit(raw, hit);
        return true;
    }
    const GeometryRecord& rec = geometry_[raw.geom_id];
    if (rec.is_sphere) {
        const SphereDesc& sp = desc_.spheres[rec.index];
        // Project the hit back onto the sphere in double precision.
        const Vec3d c(sp.center);
        const Vec3d q = Vec3d(ray.o) + Vec3d(ray.d) * double(raw.t) - c;
        const Vec3d n = q / length(q);
        hit.p = Vec3f(c + n * double(sp.radius));
        hit.ng = hit.ns = Vec3f(sp.flip_normals ? -n : n);
        hit.material = sp.material;
        hit.light = rec.first_light;
    } else {
        const MeshDesc& m = *rec.mesh;
        const auto& tri = m.triangles[raw.prim_id];
        const Vec3f &p0 = m.positions[tri[0]], &p1 = m.positions[tri[1]], &p2 = m.positions[tri[2]];
        const float b1 = raw.u, b2 = raw.v, b0 = 1 - b1 - b2;
        hit.p = p0 * b0 + p1 * b1 + p2 * b2;
        hit.ng = rec.face_normals[raw.prim_id];
        hit.ns = hit.ng;
        if (!m.normals.empty()) {
            const Vec3f n = m.normals[tri[0]] * b0 + m.normals[tri[1]] * b1 + m.normals[tri[2]] * b2;
            if (dot(n, n) > 0) hit.ns = normalize(n);
        }
        if (!m.uvs.empty()) hit.uv = m.uvs[tri[0]] * b0 + m.uvs[tri[1]] * b1 + m.uvs[tri[2]] * b2;
        hit.material = m.material;
        hit.light = rec.first_light >= 0 ? rec.first_light + int32_t(raw.prim_id) : -1;
    }
    return true;
}

void Scene::instance_hit(const RawHit& raw, Intersection& hit) const {
    const InstanceDesc& inst = desc_.instances[size_t(geometry_[raw.inst_id].instance)];
    const MeshDesc& m = desc_.groups[inst.group].meshes[raw.geom_id];
    const Transform& t = inst.to_world;
    const bool identity = t.m == Transform().m;  // transform_mesh keeps such a mesh's floats as they are
    const auto place = [&](const Vec3f& v) { return identity ? v : Vec3f(t.point(Vec3d(v))); };
    const auto& tri = m.triangles[raw.prim_id];
    const Vec3f p0 = place(m.positions[tri[0]]), p1 = place(m.positions[tri[1]]), p2 = place(m.positions[tri[2]]);
    const float b1 = raw.u, b2 = raw.v, b0 = 1 - b1 - b2;
    hit.p = p0 * b0 + p1 * b1 + p2 * b2;
    hit.ng = normalize(cross(p1 - p0, p2 - p0));
    hit.ns = hit.ng;
    if (!m.normals.empty()) {
        Vec3f n[3];
        for (int k = 0; k < 3; ++k) {
            if (identity) {
                n[k] = m.normals[tri[size_t(k)]];
                continue;
            }
            const Vec3d tn = t.normal(Vec3d(m.normals[tri[size_t(k)]]));
            const double len = length(tn);
            n[k] = len > 0 ? Vec3f(tn / len) : Vec3f(0.0f);
        }
        const Vec3f ns = n[0] * b0 + n[1] * b1 + n[2] * b2;
        if (dot(ns, ns) > 0) hit.ns = normalize(ns);
    }
    if (!m.uvs.empty()) hit.uv = m.uvs[tri[0]] * b0 + m.uvs[tri[1]] * b1 + m.uvs[tri[2]] * b2;
    hit.material = m.material;
    hit.light = -1;
}

bool Scene::occluded(const Ray& ray) const {
    ++t_rays_traced;
    return accel_.occluded(ray);
}

}  // namespace pathlab
