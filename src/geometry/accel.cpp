#include "geometry/accel.hpp"

#include <embree3/rtcore.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace pathlab {
namespace {

// Embree calls this from C code, so it must not throw; setup calls check the device error.
void embree_error(void*, RTCError code, const char* message) {
    fmt::print(stderr, "Embree error {}: {}\n", int(code), message ? message : "");
}

void throw_on_device_error(RTCDevice device, const char* what) {
    if (const RTCError e = rtcGetDeviceError(device); e != RTC_ERROR_NONE)
        throw std::runtime_error(e == RTC_ERROR_OUT_OF_MEMORY ? fmt::format("Embree ran out of memory to {} (the scene is too large)", what)
                                                              : fmt::format("Embree failed to {} (error {})", what, int(e)));
}

// For a call that returned null (a geometry, a buffer): Embree's error, else a plain failure.
[[noreturn]] void throw_failure(RTCDevice device, const std::string& what) {
    throw_on_device_error(device, what.c_str());
    throw std::runtime_error(fmt::format("Embree could not {}", what));
}

// Nearest root t of |o + t d - c| = r with tmin < t < tmax, in double precision, using the
// numerically stable quadratic form (Haines et al., "Precision Improvements for Ray/Sphere
// Intersection", Ray Tracing Gems, 2019). Returns a negative value when there is none.
double intersect_sphere(const SphereDesc& s, const double o[3], const double d[3], double tmin, double tmax) {
    const double f[3] = {o[0] - s.center.x, o[1] - s.center.y, o[2] - s.center.z};
    const double a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    const double b = -(f[0] * d[0] + f[1] * d[1] + f[2] * d[2]);  // -b/2 of the usual form
    const double r = s.radius;
    const double c = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - r * r;
    // disc/a = r^2 - |f + (b/a) d|^2: avoids the cancellation of b^2 - a c.
    const double k = b / a;
    const double g[3] = {f[0] + k * d[0], f[1] + k * d[1], f[2] + k * d[2]};
    const double disc = a * (r * r - (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]));
    if (disc < 0) return -1;
    const double q = b + std::copysign(std::sqrt(disc), b);
    double t0 = c / q, t1 = q / a;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > tmin && t0 < tmax) return t0;
    if (t1 > tmin && t1 < tmax) return t1;
    return -1;
}

void sphere_bounds(const RTCBoundsFunctionArguments* args) {
    const auto& s = *static_cast<const SphereDesc*>(args->geometryUserPtr);
    RTCBounds* b = args->bounds_o;
    // Pad by a few ulps so float rounding of the bounds never clips the exact sphere.
    const float pad = s.radius * 1e-6f + 1e-6f * (std::abs(s.center.x) + std::abs(s.center.y) + std::abs(s.center.z));
    b->lower_x = s.center.x - s.radius - pad;
    b->lower_y = s.center.y - s.radius - pad;
    b->lower_z = s.center.z - s.radius - pad;
    b->upper_x = s.center.x + s.radius + pad;
    b->upper_y = s.center.y + s.radius + pad;
    b->upper_z = s.center.z + s.radius + pad;
}

void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
    if (args->N != 1 || !args->valid[0]) return;
    const auto& s = *static_cast<const SphereDesc*>(args->geometryUserPtr);
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    const double o[3] = {rh->ray.org_x, rh->ray.org_y, rh->ray.org_z};
    const double d[3] = {rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z};
    const double t = intersect_sphere(s, o, d, rh->ray.tnear, rh->ray.tfar);
    if (t < 0) return;
    rh->ray.tfar = float(t);
    const double sign = s.flip_normals ? -1.0 : 1.0;
    rh->hit.Ng_x = float(sign * (o[0] + t * d[0] - s.center.x));
    rh->hit.Ng_y = float(sign * (o[1] + t * d[1] - s.center.y));
    rh->hit.Ng_z = float(sign * (o[2] + t * d[2] - s.center.z));
    rh->hit.u = rh->hit.v = 0;
    rh->hit.primID = args->primID;
    rh->hit.geomID = args->geomID;
    rh->hit.instID[0] = args->context->instID[0];
}

void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
    if (args->N != 1 || !args->valid[0]) return;
    const auto& s = *static_cast<const SphereDesc*>(args->geometryUserPtr);
    auto* ray = reinterpret_cast<RTCRay*>(args->ray);
    const double o[3] = {ray->org_x, ray->org_y, ray->org_z};
    const double d[3] = {ray->dir_x, ray->dir_y, ray->dir_z};
    if (intersect_sphere(s, o, d, ray->tnear, ray->tfar) >= 0) ray->tfar = -kInf;
}

RTCRay to_embree(const Ray& r, uint32_t mask) {
    RTCRay e{};
    e.org_x = r.o.x, e.org_y = r.o.y, e.org_z = r.o.z;
    e.dir_x = r.d.x, e.dir_y = r.d.y, e.dir_z = r.d.z;
    e.tnear = 0.0f;
    e.tfar = r.tmax;
    e.mask = mask;
    e.flags = 0;
    return e;
}

// Embree chooses its kernels by the CPU (SSE4.2, AVX, AVX2, AVX-512), and they round a hit's
// distance and barycentrics differently in the last bits: the same render would give other bytes
// on another CPU. Pinned to AVX2 wherever the CPU has it (x86-64 CPUs since 2013), so renders,
// checkpoints, merges and MPI ranks agree bit for bit across machines; on older CPUs Embree chooses.
const char* embree_config() {
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") ? "isa=avx2" : nullptr;
}

}  // namespace

Accel::Accel() {
    device_ = rtcNewDevice(embree_config());
    if (!device_) throw std::runtime_error("cannot create an Embree device");
    rtcSetDeviceErrorFunction(device_, embree_error, nullptr);
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    throw_on_device_error(device_, "create a scene");
}

Accel::~Accel() {
    for (RTCScene g : groups_) rtcReleaseScene(g);
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

namespace {

// A triangle mesh's geometry (not committed). Embree returns null geometries and buffers when it
// runs out of memory (a scene of millions of shapes): an error, not a write through null.
RTCGeometry mesh_geometry(RTCDevice device_, const MeshDesc& mesh) {
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!geom) throw_failure(device_, "add a mesh");
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.positions.size()));
    auto* idx = v ? static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(uint32_t), mesh.triangles.size()))
                  : nullptr;
    if (!v || !idx) {
        rtcReleaseGeometry(geom);
        throw_failure(device_, fmt::format("store a mesh of {} triangles", mesh.triangles.size()));
    }
    std::memcpy(v, mesh.positions.data(), mesh.positions.size() * sizeof(Vec3f));
    std::memcpy(idx, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(uint32_t));
    return geom;
}

}  // namespace

uint32_t Accel::add_group(const std::vector<MeshDesc>& meshes) {
    RTCScene group = rtcNewScene(device_);
    rtcSetSceneFlags(group, RTC_SCENE_FLAG_ROBUST);
    groups_.push_back(group);
    for (const MeshDesc& m : meshes) {
        RTCGeometry geom = mesh_geometry(device_, m);
        rtcCommitGeometry(geom);
        rtcAttachGeometry(group, geom);
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(group);
    throw_on_device_error(device_, "build a shapegroup");
    return uint32_t(groups_.size() - 1);
}

uint32_t Accel::add_instance(uint32_t group, const Transform& t) {
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(geom, groups_.at(group));
    float m[12];  // 3x4, row major
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) m[i * 4 + j] = float(t.m[size_t(i)][size_t(j)]);
    rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, m);
    rtcCommitGeometry(geom);
    const uint32_t id = rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    throw_on_device_error(device_, "add an instance");
    return id;
}

uint32_t Accel::add_mesh(const MeshDesc& mesh) {
    RTCGeometry geom = mesh_geometry(device_, mesh);
    rtcSetGeometryMask(geom, mesh.media.index_matched ? kMaskMediumBoundaries : kMaskSurfaces);
    rtcCommitGeometry(geom);
    const uint32_t id = rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    throw_on_device_error(device_, "add a mesh");
    return id;
}

uint32_t Accel::add_sphere(const SphereDesc& sphere) {
    spheres_.push_back(std::make_unique<SphereDesc>(sphere));
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
    if (!geom) throw_failure(device_, "add a sphere");
    rtcSetGeometryUserPrimitiveCount(geom, 1);
    rtcSetGeometryUserData(geom, spheres_.back().get());
    rtcSetGeometryBoundsFunction(geom, sphere_bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, sphere_intersect);
    rtcSetGeometryOccludedFunction(geom, sphere_occluded);
    rtcSetGeometryMask(geom, sphere.media.index_matched ? kMaskMediumBoundaries : kMaskSurfaces);
    rtcCommitGeometry(geom);
    const uint32_t id = rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    throw_on_device_error(device_, "add a sphere");
    return id;
}

void Accel::commit() {
    rtcCommitScene(scene_);
    throw_on_device_error(device_, "build the scene");
}

bool Accel::intersect(const Ray& ray, RawHit& hit, uint32_t mask) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray = to_embree(ray, mask);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit = RawHit{rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0]};
    return true;
}

bool Accel::occluded(const Ray& ray, uint32_t mask) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r = to_embree(ray, mask);
    rtcOccluded1(scene_, &context, &r);
    return r.tfar < 0;
}

}  // namespace pathlab
