// Pieces of test scenes that several tests build: quads, the index-matched fog box that fills the
// course box, a glass ball filled with a medium, and voxel-grid media with a striped pattern of
// extinctions.
#pragma once

#include <array>

#include "bsdfs/material.hpp"
#include "geometry/shape_meshes.hpp"
#include "media/medium.hpp"
#include "media/volume.hpp"
#include "scene/builtin_scenes.hpp"
#include "scene/scene_description.hpp"

namespace pathlab::test {

// A quad centred at c spanned by +-u and +-v, normal along u x v.
inline MeshDesc quad(const Vec3f& c, const Vec3f& u, const Vec3f& v, uint32_t material, Rgb emission = Rgb(0.0f)) {
    MeshDesc m;
    m.positions = {c - u - v, c + u - v, c + u + v, c - u + v};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    m.material = material;
    m.emission = emission;
    return m;
}

// Three spheres on a diffuse floor under a small area light and a dim sky. `sphere_materials`
// are the spheres' materials (indices 2, 3, 4).
inline SceneDescription material_scene(const std::vector<Material>& sphere_materials) {
    SceneDescription d;
    d.name = "materials";
    d.camera = Camera::look_along({0, -4, 1.2f}, {0, 1, -0.3f}, {0, 0, 1}, 36.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(0.0f)), make_phong(Rgb(0.6f))};
    for (const Material& m : sphere_materials) d.materials.push_back(m);
    MeshDesc light;  // 2 x 2 at z = 3, facing down
    light.positions = {{-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}};
    light.triangles = {{0, 2, 1}, {0, 3, 2}};
    light.material = 0;
    light.emission = Rgb(3.0f);
    MeshDesc floor;
    floor.positions = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
    floor.triangles = {{0, 1, 2}, {2, 3, 0}};
    floor.material = 1;
    d.meshes = {light, floor};
    for (size_t i = 0; i < sphere_materials.size(); ++i)
        d.spheres.push_back(SphereDesc{{-1.1f + 1.1f * float(i), 0.2f * float(i), 0.5f}, 0.5f, uint32_t(2 + i)});
    d.lights = {EnvironmentLight{Rgb(0.1f, 0.12f, 0.15f)}};
    return d;
}

// A box filling the course box's inside (a little smaller), an index-matched boundary.
inline MeshDesc fog_box(int32_t medium) {
    MeshDesc m = cube_mesh();
    transform_mesh(m, Transform::translate({0.01, 0.02, 0}) * Transform::scale({1.27, 1.27, 1.27}));
    m.name = "fog";
    m.media.interior = medium;
    m.media.index_matched = true;
    return m;
}

// The course's light box (scene 4) filled with chromatic fog, the camera outside it.
inline SceneDescription light_box_in_fog() {
    SceneDescription d = make_builtin_scene(4);
    d.media.push_back(HomogeneousMedium{Rgb(0.5f, 0.6f, 0.7f), Rgb(0.4f, 0.45f, 0.6f), HgPhase{0.4f}});
    d.meshes.push_back(fog_box(0));
    return d;
}

// Turns the scene's last sphere (the course scenes' blue ball) into glass of index 1.5 filled with
// medium `interior`, medium `exterior` around it.
inline void make_last_sphere_glass(SceneDescription& d, int32_t interior, int32_t exterior) {
    d.materials.push_back(make_dielectric(1.5f));
    SphereDesc& glass = d.spheres.back();
    glass.material = uint32_t(d.materials.size() - 1);
    glass.media.interior = interior;
    glass.media.exterior = exterior;
}

// A grid medium filling [-half, half]^3 whose voxel (x, y, z), channel c, has the extinction
// base + step k, k = (5x + 3y + 7z + 4c) mod levels.
struct StripedGrid {
    std::array<int, 3> res;
    int channels;
    float base, step;
    int levels;
    double half;
    Rgb albedo;
    PhaseFunction phase;
};
inline HeterogeneousMedium striped_grid_medium(const StripedGrid& s) {
    VoxelGrid g;
    g.res = s.res;
    g.channels = s.channels;
    for (int z = 0; z < s.res[2]; ++z)
        for (int y = 0; y < s.res[1]; ++y)
            for (int x = 0; x < s.res[0]; ++x)
                for (int c = 0; c < s.channels; ++c) g.data.push_back(s.base + s.step * float((x * 5 + y * 3 + z * 7 + c * 4) % s.levels));
    HeterogeneousMedium m;
    m.sigma_t = Volume::of_grid(g, Transform::translate({-s.half, -s.half, -s.half}) * Transform::scale({2 * s.half, 2 * s.half, 2 * s.half}));
    m.albedo = Volume::constant_value(s.albedo);
    m.scale = 1;
    m.phase = s.phase;
    m.prepare();
    return m;
}

}  // namespace pathlab::test
