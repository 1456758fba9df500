// What makes a material vary over a surface: textures bound to its parameters (a reflectance,
// a roughness), and a normal or bump map that tilts its shading frame. A material without them
// (Material::textures null) is the same everywhere: the hot loop's case, untouched by all this.
//
// Resolution at a hit: a textured material's model is copied and each bound parameter set to
// its texture's value at the hit's uv (the model's set_texel(slot, value)), then the model's
// derived values are recomputed (texels_changed()). A texture whose texels all equal a
// constant thus gives exactly the model of that constant.
#pragma once

#include <algorithm>
#include <cmath>

#include <memory>
#include <string>
#include <vector>

#include "core/frame.hpp"
#include "textures/texture.hpp"

namespace pathlab {

struct TextureBinding {
    std::string param;      // the parameter's scene-file name, e.g. "reflectance" or "alpha_u"
    int slot = 0;           // the model's parameter it sets (ParamInfo::texture_slot)
    bool scalar = false;    // a float parameter: the texture's scalar value (texture_common.hpp)
    std::shared_ptr<const Texture> texture;
};

// normalmap and bumpmap (normalmap.hpp, bumpmap.hpp).
enum class FramePerturbation : unsigned char { None, NormalMap, BumpMap };

struct MaterialTextures {
    std::vector<TextureBinding> bindings;
    FramePerturbation perturbation = FramePerturbation::None;
    std::shared_ptr<const Texture> perturbation_texture;  // the normal map, or the height field
    float bump_scale = 1;                                 // bumpmap's `scale`
    // Mitsuba 3's normalmap and bumpmap options (true by default there and in scene files here;
    // false for glTF's normal textures). flip_invalid_normals: a perturbed normal n' that the
    // incoming direction wi sees from the other side than the shading normal n is mirrored about
    // n (flip_invalid_normal()); use_shadowing_function: the BSDF is multiplied by
    // bump_shadowing() of the outgoing direction. Both single out one direction, so the BSDF they
    // make is not reciprocal (the light-path integrators refuse it); with either, a direction
    // counts where n and n' see it on one side (Mitsuba's rule), else where ng and n' do.
    bool flip_invalid_normals = false;
    bool shadowing_function = false;
};

// Conty Estevez, Lecocq and Stein 2019, "A Microfacet-Based Shadowing Function to Solve the Bump
// Terminator Problem" (Mitsuba 3's eval_shadow_terminator): cos_p the cosine between the
// perturbed and the unperturbed shading normal, cos_o that of the outgoing direction to the
// unperturbed one; G = 2 / (1 + sqrt(1 + a^2 tan^2 theta_o)) with a^2 = min(tan^2 theta_p / 8, 1).
inline float bump_shadowing(float cos_p, float cos_o) {
    const auto tan2 = [](float c) { return std::max(0.0f, 1 - c * c) / (c * c); };
    const float a2 = std::min(0.125f * tan2(cos_p), 1.0f);
    return 2 / (1 + std::sqrt(1 + a2 * tan2(cos_o)));
}

// flip_invalid_normals: `f` (the perturbed frame) with its normal mirrored about the shading
// normal n when wi (towards where the path came from) sees n and f.n from different sides.
Frame flip_invalid_normal(const Frame& f, const Vec3f& n, const Vec3f& wi);

// The shading frame whose tangent s follows dp/du: s = dp/du made orthogonal to the unit
// shading normal n, t = n x s; Frame(n) where dp/du is zero or along n.
Frame tangent_frame(const Vec3f& n, const Vec3f& dpdu);

// The frame a normal or bump map gives at a hit on its front side: `n` the unit shading normal,
// `ng` the unit geometric normal (on the same side), dp/du and dp/dv the surface's derivatives.
//   normalmap: n' = normalize(2 c - 1) in tangent_frame(n, dp/du), c the texture's RGB value;
//   bumpmap:   with g = scale grad h (h the height texture's scalar value, gradient in uv),
//              n' = normalize(dp'/du x dp'/dv),  dp'/du = dp/du + (g_u - n.dp/du) n  (and v),
//              i.e. the tangents of the surface lifted by h along n, n's own change neglected
//              (Mitsuba 3's bumpmap: only the height's variations matter, not its offset);
// n' turned to the side of ng if it points below; then s' = the tangent s of tangent_frame(n,
// dp/du) made orthogonal to n', and t' = n' x s'. Degenerate inputs (a zero normal, non-finite texels) leave the frame unperturbed.
Frame perturbed_frame(const MaterialTextures& t, const Vec3f& n, const Vec3f& ng, const Vec3f& dpdu, const Vec3f& dpdv,
                      const SurfaceUv& uv);

}  // namespace pathlab
