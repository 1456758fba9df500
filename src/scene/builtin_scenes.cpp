#include "scene/builtin_scenes.hpp"

#include <array>

namespace pathlab {
namespace {

// Box corners c0..c7 (npgr010-scenes.md, "The box").
constexpr std::array<Vec3f, 8> kBox = {{
    {-1.27029f, 1.30455f, -1.28002f}, {1.28975f, 1.30455f, -1.28002f},
    {1.28975f, 1.30455f, 1.28002f},   {-1.27029f, 1.30455f, 1.28002f},
    {-1.27029f, -1.25549f, -1.28002f}, {1.28975f, -1.25549f, -1.28002f},
    {1.28975f, -1.25549f, 1.28002f},  {-1.27029f, -1.25549f, 1.28002f},
}};
// Light box corners l0..l7 (scenes 4 and 5).
constexpr std::array<Vec3f, 8> kLightBox = {{
    {-0.25f, 0.25f, 1.26002f}, {0.25f, 0.25f, 1.26002f}, {0.25f, 0.25f, 1.28002f}, {-0.25f, 0.25f, 1.28002f},
    {-0.25f, -0.25f, 1.26002f}, {0.25f, -0.25f, 1.26002f}, {0.25f, -0.25f, 1.28002f}, {-0.25f, -0.25f, 1.28002f},
}};

using Tri = std::array<uint32_t, 3>;

// A mesh made of triangles over a corner table; the winding gives the normal.
MeshDesc make_mesh(std::string name, const std::array<Vec3f, 8>& corners, std::vector<Tri> tris, uint32_t material,
                   Rgb emission = Rgb(0.0f)) {
    MeshDesc m;
    m.name = std::move(name);
    m.positions.assign(corners.begin(), corners.end());
    m.triangles = std::move(tris);
    m.material = material;
    m.emission = emission;
    return m;
}

enum Mat : uint32_t { kEmitter = 0, kFloor = 2, kGreen = 3, kRed = 4, kBackWall = 5, kYellowBall = 6, kBlueBall = 7 };

// Materials 0-7. The glossy set halves the diffuse reflectance and adds the Phong lobe.
std::vector<Material> course_materials(bool glossy) {
    const float half = glossy ? 0.5f : 1.0f;
    const auto mat = [&](Rgb rho_d, float rho_s, float n) {
        return make_phong(rho_d * half, Rgb(glossy ? rho_s : 0.0f), n);
    };
    const float w = 0.803922f;
    return {
        make_phong(Rgb(0.0f)),                                   // 0: emitter triangle A
        make_phong(Rgb(0.0f)),                                   // 1: emitter triangle B
        mat(Rgb(w), 0.5f, 90),                                   // 2: floor, plain ceiling
        mat(Rgb(0.156863f, w, 0.172549f), 0.5f, 90),             // 3: left wall, green
        mat(Rgb(w, 0.152941f, 0.152941f), 0.5f, 90),             // 4: right wall, red
        mat(Rgb(w), 0.5f, 90),                                   // 5: back wall, light-box sides
        mat(Rgb(w, w, 0.152941f), 0.7f, 200),                    // 6: left sphere, yellow
        mat(Rgb(0.152941f, 0.152941f, w), 0.7f, 600),            // 7: right sphere, blue
    };
}

enum class LightKind { Point, Ceiling, LightBox, Environment };

SceneDescription make_course_scene(const BuiltinSceneInfo& info, LightKind light, bool glossy) {
    SceneDescription d;
    d.name = info.name;
    d.width = d.height = 512;
    // The course gives the forward direction (0.00688625, 0.998505, -0.0542161); the target is
    // position + forward rounded to float, so scene files (which use look-at) reproduce it exactly.
    d.camera = Camera::look_at({-0.0439815f, -4.12529f, 0.222539f}, {-0.0370952487f, -3.1267848f, 0.168322891f},
                               {3.73896e-4f, 0.0542148f, 0.998529f}, 45.0f, FovAxis::EachAxis);
    d.materials = course_materials(glossy);
    // The scene files' ids (scenes/N-*.xml), for differentiable parameters; the emitter's
    // black BSDF has none (nothing to differentiate: paths end there).
    d.material_ids = {"", "", "floor", "green", "red", "back", "yellow", "blue"};

    d.meshes.push_back(make_mesh("floor", kBox, {{0, 4, 5}, {5, 1, 0}}, kFloor));
    d.meshes.push_back(make_mesh("left wall", kBox, {{3, 7, 4}, {4, 0, 3}}, kGreen));
    d.meshes.push_back(make_mesh("right wall", kBox, {{1, 5, 6}, {6, 2, 1}}, kRed));
    d.meshes.push_back(make_mesh("back wall", kBox, {{0, 1, 2}, {2, 3, 0}}, kBackWall));
    if (light == LightKind::Ceiling) {  // radiance 1.21, hard-coded by the course (not from a power)
        d.meshes.push_back(make_mesh("ceiling light", kBox, {{2, 6, 7}, {7, 3, 2}}, kEmitter, Rgb(1.21f)));
        d.meshes.back().id = "light";
    } else {
        d.meshes.push_back(make_mesh("ceiling", kBox, {{2, 6, 7}, {7, 3, 2}}, kFloor));
    }

    if (light == LightKind::LightBox) {
        d.meshes.push_back(make_mesh("light box sides", kLightBox,
                                     {{0, 2, 1}, {2, 0, 3}, {3, 4, 7}, {4, 3, 0}, {1, 6, 5}, {6, 1, 2}, {4, 5, 6}, {6, 7, 4}},
                                     kBackWall));
        d.meshes.push_back(make_mesh("light box bottom", kLightBox, {{0, 5, 4}, {5, 0, 1}}, kEmitter, Rgb(31.831f)));
        d.meshes.back().id = "light";
    }

    d.spheres.push_back(SphereDesc{{-0.5388500f, 0.0245301f, -0.7800200f}, 0.5f, kYellowBall, false});
    d.spheres.push_back(SphereDesc{{0.5583100f, 0.6645401f, -0.7800200f}, 0.5f, kBlueBall, false});

    if (light == LightKind::Point) d.lights.emplace_back(PointLight{{0.0f, -0.5f, 1.0f}, Rgb(50.0f / (4.0f * kPi))});
    if (light == LightKind::Environment)  // the course's raw colour, no sRGB decoding
        d.lights.emplace_back(EnvironmentLight{Rgb(135.0f / 255.0f, 206.0f / 255.0f, 250.0f / 255.0f)});
    if (!d.lights.empty()) d.light_ids = {"light"};
    return d;
}

}  // namespace

const std::vector<BuiltinSceneInfo>& builtin_scenes() {
    static const std::vector<BuiltinSceneInfo> scenes = {
        {0, "point-diffuse", "ws_p_sdwd", "point light (50 W), diffuse walls and spheres"},
        {1, "point-glossy", "ws_p_sdsgwdwg", "point light (50 W), glossy walls and spheres"},
        {2, "ceiling-diffuse", "ws_c_sdwd", "whole ceiling emits (L = 1.21), diffuse"},
        {3, "ceiling-glossy", "ws_c_sdsgwdwg", "whole ceiling emits (L = 1.21), glossy"},
        {4, "box-diffuse", "ws_b_sdwd", "small light box under the ceiling (25 W), diffuse"},
        {5, "box-glossy", "ws_b_sdsgwdwg", "small light box under the ceiling (25 W), glossy"},
        {6, "env-diffuse", "ws_e_sdwd", "constant sky-blue environment through the open front, diffuse"},
        {7, "env-glossy", "ws_e_sdsgwdwg", "constant sky-blue environment through the open front, glossy"},
    };
    return scenes;
}

std::optional<int> find_builtin_scene(const std::string& key) {
    for (const BuiltinSceneInfo& s : builtin_scenes())
        if (key == std::to_string(s.index) || key == s.name || key == s.acronym ||
            key == std::to_string(s.index) + "_" + s.acronym)
            return s.index;
    return std::nullopt;
}

SceneDescription make_builtin_scene(int index) {
    const BuiltinSceneInfo& info = builtin_scenes().at(size_t(index));
    static constexpr LightKind kinds[4] = {LightKind::Point, LightKind::Ceiling, LightKind::LightBox, LightKind::Environment};
    return make_course_scene(info, kinds[index / 2], index % 2 == 1);
}

}  // namespace pathlab
