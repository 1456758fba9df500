#include "scene/scene.hpp"

#include <algorithm>
#include <cmath>

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
    const auto check_media = [&](const MediumInterface& mi, const std::string& what) {
        for (int32_t m : {mi.interior, mi.exterior})
            if (m < -1 || m >= int32_t(d.media.size()))
                throw SceneError(fmt::format("{} refers to medium {}, but the scene has {} media", what, m, d.media.size()));
    };
    for (size_t i = 0; i < d.meshes.size(); ++i) {
        check_media(d.meshes[i].media, fmt::format("mesh '{}'", d.meshes[i].name.empty() ? std::to_string(i) : d.meshes[i].name));
        if (d.meshes[i].media.index_matched && !is_black(d.meshes[i].emission))
            throw SceneError(fmt::format("mesh '{}' is an index-matched medium boundary and cannot emit", d.meshes[i].name));
    }
    for (size_t i = 0; i < d.spheres.size(); ++i) {
        check_media(d.spheres[i].media, fmt::format("sphere {}", i));
        if (d.spheres[i].media.index_matched && !is_black(d.spheres[i].emission))
            throw SceneError(fmt::format("sphere {} is an index-matched medium boundary and cannot emit", i));
    }
    if (d.camera_medium < -1 || d.camera_medium >= int32_t(d.media.size()))
        throw SceneError(fmt::format("the camera's medium {} is not one of the scene's {} media", d.camera_medium, d.media.size()));
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
    for (Material& m : s->materials_) m.prepare();

    // Light i's spectrum (null: none) from the description's vector `from` at `index`.
    const auto add_spectrum = [&](const std::vector<std::shared_ptr<const EmissionSpectrum>>& from, size_t index) {
        const auto spectrum = index < from.size() ? from[index] : nullptr;
        if (!spectrum) return;
        s->light_spectra_.resize(s->lights_.size());
        s->light_spectra_.back() = spectrum;
    };
    std::vector<int> emitter_of;  // the emitter each light belongs to (the light sampler's uniform choice)
    for (size_t i = 0; i < desc.lights.size(); ++i) {
        std::visit([&](const auto& light) { s->lights_.emplace_back(light); }, desc.lights[i]);
        emitter_of.push_back(int(s->lights_.size()) - 1);
        if (is_environment(s->lights_.back())) s->environment_ = int(s->lights_.size()) - 1;
        add_spectrum(desc.light_spectra, i);
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
        if (m.media.changes_medium() || m.media.index_matched) rec.media = &s->desc_.meshes[i].media;
        if (!is_black(m.emission)) {
            rec.first_light = int32_t(s->lights_.size());
            const Texture* texture = i < desc.mesh_emission_textures.size() ? s->desc_.mesh_emission_textures[i].get() : nullptr;
            if (texture && m.uvs.size() != m.positions.size())
                throw SceneError(fmt::format("mesh {} ('{}') has a textured emitter but no texture coordinates", i, m.name));
            for (const auto& t : m.triangles) {
                TriangleLight light(m.positions[t[0]], m.positions[t[1]], m.positions[t[2]], m.emission);
                if (texture) {
                    light.texture = texture;
                    light.uv0 = m.uvs[t[0]], light.uv1 = m.uvs[t[1]], light.uv2 = m.uvs[t[2]];
                    // Its mean radiance (for its power among lights): 4 x 4 stratified points.
                    Rgb sum(0.0f);
                    for (int a = 0; a < 4; ++a)
                        for (int c = 0; c < 4; ++c)
                            sum += light.radiance_at_barycentric(square_to_uniform_triangle({(a + 0.5f) / 4, (c + 0.5f) / 4}));
                    if (light.area > 0) light.radiance = sum / 16.0f;
                }
                s->lights_.emplace_back(light);
                emitter_of.push_back(rec.first_light);  // the mesh is one emitter
                add_spectrum(desc.mesh_emission_spectra, i);
            }
        }
        s->geometry_[id] = rec;
        for (const Vec3f& p : m.positions) lo = min(lo, p), hi = max(hi, p);
    }
    for (size_t i = 0; i < desc.spheres.size(); ++i) {
        const SphereDesc& sp = desc.spheres[i];
        const uint32_t id = s->accel_.add_sphere(sp);
        if (id >= s->geometry_.size()) s->geometry_.resize(id + 1);
        GeometryRecord rec{true, uint32_t(i), -1};
        if (sp.media.changes_medium() || sp.media.index_matched) rec.media = &s->desc_.spheres[i].media;
        if (!is_black(sp.emission)) {
            rec.first_light = int32_t(s->lights_.size());
            s->lights_.emplace_back(SphereLight{sp.center, sp.radius, sp.flip_normals, sp.emission});
            emitter_of.push_back(int(s->lights_.size()) - 1);
            add_spectrum(desc.sphere_emission_spectra, i);
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
    s->has_media_ = desc.camera_medium >= 0;
    for (const GeometryRecord& rec : s->geometry_) s->has_media_ = s->has_media_ || rec.media;
    s->sealed_.assign(desc.media.size(), 1);
    for (const GeometryRecord& rec : s->geometry_)
        if (rec.media && rec.media->index_matched)
            for (const int32_t m : {rec.media->interior, rec.media->exterior})
                if (m >= 0) s->sealed_[size_t(m)] = 0;
    if (lo.x <= hi.x) {
        s->center_ = (lo + hi) * 0.5f;
        s->radius_ = std::max(1e-3f, 0.5f * length(hi - lo));
    }

    s->light_distribution_ = LightDistribution(s->lights_, s->scene_sphere());
    s->light_sampler_ = LightSampler(s->lights_, s->scene_sphere(), desc.light_sampler, desc.ris_candidates, emitter_of, desc.light_split);
    if (s->has_media_) {
        // A point of each light on its emitting side (the middle of its emission sampling's domain).
        const float offset = 1e-4f * s->radius_;
        for (const Light& l : s->lights_) {
            const auto es = sample_emission(l, {0.5f, 0.5f}, {0.5f, 0.5f}, s->scene_sphere());
            int32_t m = -1;
            if (es) m = s->medium_at((light_flags(l) & kLightSurface) ? es->origin + es->normal * offset : es->origin);
            s->light_media_.push_back(m);
        }
    }
    return s;
}

int32_t Scene::medium_at(const Vec3f& p) const {
    int32_t medium = desc_.camera_medium;
    Ray ray{camera_.position, p - camera_.position, 1.0f};
    for (int crossings = 0; crossings < 1024; ++crossings) {
        Intersection hit;
        const MediumInterface* media = nullptr;
        if (!intersect(ray, hit, kMaskAll, media)) break;
        if (media && media->changes_medium()) medium = media->medium_towards(ray.d, hit.ng);
        const Vec3f from = offset_ray_origin(hit.p, dot(ray.d, hit.ng) >= 0 ? hit.ng : -hit.ng);
        ray = Ray{from, p - from, 1.0f};
    }
    return medium;
}

bool Scene::has_delta_lights() const {
    return std::any_of(lights_.begin(), lights_.end(), [](const Light& l) { return is_delta_light(l); });
}

bool Scene::has_hittable_emitters() const {
    return std::any_of(lights_.begin(), lights_.end(), [](const Light& l) { return !is_delta_light(l); });
}

// The hit record of a raw hit (inlined into both intersect functions).
[[gnu::always_inline]] inline void Scene::fill(const Ray& ray, const RawHit& raw, Intersection& hit) const {
    hit.t = raw.t;
    hit.uv = Vec2f(0.0f, 0.0f);
    hit.geom_id = raw.geom_id;
    hit.prim_id = raw.prim_id;
    if (raw.inst_id != RawHit::kNoInstance) [[unlikely]] {
        instance_hit(raw, hit);
        return;
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
}

bool Scene::intersect(const Ray& ray, Intersection& hit) const {
    ++t_rays_traced;
    RawHit raw;
    if (!accel_.intersect(ray, raw)) return false;
    fill(ray, raw, hit);
    return true;
}

bool Scene::intersect(const Ray& ray, Intersection& hit, uint32_t mask, const MediumInterface*& media) const {
    ++t_rays_traced;
    RawHit raw;
    if (!accel_.intersect(ray, raw, mask)) return false;
    fill(ray, raw, hit);
    media = raw.inst_id == RawHit::kNoInstance ? geometry_[raw.geom_id].media : nullptr;  // instances bound no media
    return true;
}

Scene::SurfaceCoordinates Scene::surface_coordinates(const Intersection& hit) const {
    SurfaceCoordinates c{hit.uv, Vec3f(0.0f), Vec3f(0.0f)};
    if (hit.geom_id == Intersection::kInstanceHit) {
        // An instance's mesh: its interpolated uv, and two tangents of the geometric normal
        // (dp/du of instanced meshes is not computed yet: the hit does not keep the instance).
        const Frame f(hit.ng);
        c.dpdu = f.s;
        c.dpdv = f.t;
        return c;
    }
    const GeometryRecord& rec = geometry_[hit.geom_id];
    if (rec.is_sphere) {
        // Mitsuba 3's sphere: the hit in the sphere's own unit space, theta from its z axis, phi
        // about it from its x axis; uv = (phi / 2 pi, theta / pi).
        const SphereDesc& s = desc_.spheres[rec.index];
        const Vec3d q = (Vec3d(hit.p) - Vec3d(s.center)) / double(s.radius);
        const Vec3d e[3] = {Vec3d(s.axes[0]), Vec3d(s.axes[1]), Vec3d(s.axes[2])};
        const double x = dot(q, e[0]), y = dot(q, e[1]), z = std::clamp(dot(q, e[2]), -1.0, 1.0);
        double phi = std::atan2(y, x);
        if (phi < 0) phi += 2 * M_PI;
        const double theta = std::acos(z), rd = std::hypot(x, y), r = s.radius;
        c.uv = Vec2f(float(phi / (2 * M_PI)), float(theta / M_PI));
        // dp/du = 2 pi r (-y, x, 0), dp/dv = pi r (z cos phi, z sin phi, -rd) in the sphere's axes.
        c.dpdu = Vec3f((e[0] * -y + e[1] * x) * (2 * M_PI * r));
        c.dpdv = rd > 0 ? Vec3f((e[0] * (z * x / rd) + e[1] * (z * y / rd) - e[2] * rd) * (M_PI * r)) : Vec3f(e[0] * (M_PI * r));
        return c;
    }
    const MeshDesc& m = *rec.mesh;
    const auto& tri = m.triangles[hit.prim_id];
    if (!m.attributes.empty()) {  // mesh_attribute textures: the triangle and the hit's barycentrics in it
        const Vec3f e1 = m.positions[tri[1]] - m.positions[tri[0]], e2 = m.positions[tri[2]] - m.positions[tri[0]];
        const Vec3f q = hit.p - m.positions[tri[0]];
        const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), q1 = dot(q, e1), q2 = dot(q, e2);
        const float det = d11 * d22 - d12 * d12;
        const float b1 = det > 0 ? std::clamp((d22 * q1 - d12 * q2) / det, 0.0f, 1.0f) : 0.0f;
        const float b2 = det > 0 ? std::clamp((d11 * q2 - d12 * q1) / det, 0.0f, 1.0f - b1) : 0.0f;
        c.uv.attributes = &m.attributes;
        c.uv.tri = hit.prim_id;
        c.uv.b1 = b1;
        c.uv.b2 = b2;
    }
    if (m.uv_map == UvMap::Disk) {
        // Mitsuba 3's disk: the hit in the unit disk's space in polar coordinates, uv = (r, phi / 2 pi).
        const Vec3d local = m.to_object.point(Vec3d(hit.p));
        const double r = std::hypot(local.x, local.y);
        double phi = std::atan2(local.y, local.x);
        if (phi < 0) phi += 2 * M_PI;
        static_cast<Vec2f&>(c.uv) = Vec2f(float(r), float(phi / (2 * M_PI)));
        const double cs = r > 0 ? local.x / r : 1, sn = r > 0 ? local.y / r : 0;
        c.dpdu = Vec3f(m.to_world.vector({cs, sn, 0}));
        c.dpdv = Vec3f(m.to_world.vector(Vec3d(-sn, cs, 0) * (2 * M_PI * r)));
        return c;
    }
    if (!m.uvs.empty()) {  // (uv itself was interpolated by intersect())
        // p = p0 + dp/du (u - u0) + dp/dv (v - v0) across the triangle.
        const Vec3f dp0 = m.positions[tri[1]] - m.positions[tri[0]], dp1 = m.positions[tri[2]] - m.positions[tri[0]];
        const Vec2f uv0 = m.uvs[tri[0]];
        const Vec2f d0(m.uvs[tri[1]].x - uv0.x, m.uvs[tri[1]].y - uv0.y), d1(m.uvs[tri[2]].x - uv0.x, m.uvs[tri[2]].y - uv0.y);
        const float det = d0.x * d1.y - d0.y * d1.x;
        if (det != 0 && std::isfinite(1 / det)) {
            const float inv = 1 / det;
            c.dpdu = (dp0 * d1.y - dp1 * d0.y) * inv;
            c.dpdv = (dp1 * d0.x - dp0 * d1.x) * inv;
            if (is_finite(c.dpdu) && is_finite(c.dpdv)) return c;
        }
    }
    const Frame f(hit.ng);
    c.dpdu = f.s;
    c.dpdv = f.t;
    return c;
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
    hit.geom_id = Intersection::kInstanceHit;
}

bool Scene::occluded(const Ray& ray) const {
    ++t_rays_traced;
    return accel_.occluded(ray);
}

}  // namespace pathlab
