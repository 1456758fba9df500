// What lights return, shared by every light type (lights/light.hpp lists them).
//
// Two ways of sampling a light:
//  - incident illumination at a reference point p (next-event estimation): a direction wi
//    from p towards the light, the radiance Le arriving along it, and pdfW, the density of wi
//    per unit solid angle. Area lights sample a point by area and convert (pdfW = pdfA d^2 /
//    cos at the light) in one place, area_to_solid_angle.
//  - emission (light paths): an origin and a direction with their densities, pdfA per unit
//    area of the origin and pdfW per unit solid angle of the direction. A light path starts
//    with the throughput Le cos / (pmf pdfA pdfW).
// Delta lights report 1 for the density of their delta part (position of a point light,
// direction of a directional light) and carry the flag that says so: no other strategy can
// produce such a sample, so MIS gives it weight 1.
#pragma once

#include <cstdint>

#include "core/vec.hpp"

namespace pathlab {

enum LightFlags : uint32_t {
    kLightDeltaPosition = 1,   // a point: emission has no area (pdfA is a Dirac coefficient)
    kLightDeltaDirection = 2,  // a single direction (pdfW is a Dirac coefficient)
    kLightInfinite = 4,        // at infinity: seen by rays that escape the scene
    kLightSurface = 8,         // on a shape: found by rays that hit it
};

struct LightSample {
    Vec3f wi;               // unit direction from the reference point towards the light
    float distance = kInf;  // to the sampled point; kInf for lights at infinity
    Vec3f point, normal;    // sampled point and its surface normal (area lights only)
    Rgb Le;                 // radiance arriving along -wi; intensity / d^2 for a point light
    float pdfW = 0;         // solid-angle density of wi (1 for delta lights)
    bool delta = false;
};

struct EmissionSample {
    Vec3f origin;
    Vec3f normal;     // the surface normal at the origin (area lights); the direction otherwise
    Vec3f direction;  // unit direction in which the light travels
    Rgb Le;           // radiance (area, environment), intensity (point), irradiance (directional)
    float cos = 1;    // |normal . direction| for area lights, 1 otherwise
    float pdfA = 0;   // density of the origin per unit area (1 for a delta position)
    float pdfW = 0;   // density of the direction per unit solid angle (1 for a delta direction)
};

struct EmissionPdf {
    float pdfA = 0, pdfW = 0;
};

// The scene's bounding sphere: lights at infinity emit light paths from a disk of this radius
// perpendicular to their direction, placed outside the scene.
struct SceneSphere {
    Vec3f center{0.0f};
    float radius = 1;
};

}  // namespace pathlab
