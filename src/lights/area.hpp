// area: the emitter of a shape (<shape> ... <emitter type="area">): a one-sided Lambertian
// emitter of radiance L on the side of the shape's normal, power pi L A. The shape's triangles
// become TriangleLights (triangle.hpp), an exact sphere a SphereLight (sphere.hpp). L may be a
// texture (<texture name="radiance">, read by read_shape.cpp) on a mesh with texture coordinates.
#pragma once

#include "core/properties.hpp"
#include "core/vec.hpp"

namespace pathlab {

inline const PluginInfo& area_plugin() {
    static const PluginInfo info{"emitter", "area", "the emitter of a shape (only inside a <shape>): one-sided, Lambertian",
                                 {{"radiance", ParamType::Rgb, "1",
                                   "radiance L on the side of the shape's normal (power pi L A); a texture needs a mesh with uv", "", 0}}};
    return info;
}
inline Rgb read_area_radiance(Properties& p) { return p.get_rgb("radiance"); }

}  // namespace pathlab
