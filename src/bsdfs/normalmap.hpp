// normalmap: a BSDF whose shading normal follows a texture (Mitsuba 3's `normalmap`).
//
// XML: <bsdf type="normalmap"> wraps exactly one BSDF (nested, or <ref id>) and one texture,
// named `normalmap` (nested <texture name="normalmap">, or <ref name="normalmap" id>). Its RGB
// value c in [0, 1]^3 is the normal 2 c - 1 in the tangent frame (s along dp/du, t = n x s, n
// the shading normal; material_textures.hpp). The texture should be read with raw = true
// (normal maps are linear data, not sRGB colours). A normal map of (0.5, 0.5, 1) everywhere is
// the unperturbed frame. It may wrap twosided or be wrapped by it: either way the back of the
// surface is the same tilted surface seen from behind (material.hpp).
#pragma once

#include "core/properties.hpp"

namespace pathlab {

inline const PluginInfo& normalmap_plugin() {
    static const PluginInfo info{"bsdf", "normalmap",
                                 "tilts the shading normal of one nested BSDF by a texture named normalmap (RGB 2c - 1 in the tangent frame)",
                                 {}};
    return info;
}

}  // namespace pathlab
