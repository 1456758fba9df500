// What makes a material vary over a surface: textures bound to its parameters (a reflectance,
// a roughness), and a normal or bump map that tilts its shading frame. A material without them
// (Material::textures null) is the same everywhere: the hot loop's case, untouched by all this.
//
// Resolution at a hit: a textured material's model is copied and each bound parameter set to
// its texture's value at the hit's uv (the model's set_texel(slot, value)), then the model's
// derived values are recomputed (texels_changed()). A texture whose texels all equal a
// constant thus gives exactly the model of that constant.
#pragma once

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
};

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
