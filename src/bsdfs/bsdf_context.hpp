// What a BSDF is told about the point it scatters at: the shading context.
//
// The transport mode says which quantity the path carries. Camera paths carry radiance; light
// paths (light tracer, BDPT's light subpaths, photons) carry importance, and scatter with the
// adjoint BSDF f*(wi, wo) = f(wo, wi) (Veach's thesis, ch. 5), where wi is always the direction
// the path arrived from. Two things differ between the modes:
//  - refraction: radiance keeps L / eta^2 invariant, so the radiance BSDF of a transmission
//    carries the factor eta_wi^2 / eta_wo^2 that importance does not; in importance mode a
//    transmission is scaled by (eta_wo / eta_wi)^2 (which equals f(wo, wi) / f(wi, wo), the
//    generalised reciprocity of refraction);
//  - shading normals: the adjoint of a BSDF evaluated with a shading normal ns differs from
//    the BSDF by |wi.ns| |wo.ng| / (|wi.ng| |wo.ns|) (Veach, eq. 5.19), and directions whose
//    sides differ for ns and ng are refused (they would leak light through the surface).
// In radiance mode neither applies and the models are evaluated as they are.
#pragma once

#include "core/frame.hpp"
#include "core/vec.hpp"
#include "textures/mesh_attribute.hpp"

namespace pathlab {

enum class TransportMode : unsigned char { Radiance, Importance };

struct BsdfContext {
    Vec3f p;                  // the hit point
    SurfaceUv uv;             // surface coordinates, (0, 0) where the shape has none; a mesh's attributes at the hit
    Frame frame;              // shading frame: n the shading normal, s the tangent, t the bitangent
    Vec3f ng;                 // unit geometric normal, on the side of frame.n
    Vec3f ns{};               // unit shading normal before a normal or bump map (0: not known)
    TransportMode mode = TransportMode::Radiance;
    bool reverse_pdf = false;  // sample() also fills BsdfSample::pdf_rev
};

}  // namespace pathlab
