// The surfel cloud of point-based global illumination (Christensen 2008): the scene's surfaces
// cut into small disks, each with the light its diffuse part reflects.
//
// Placement, view-independent and deterministic: every triangle is cut into k^2 equal triangles
// (its edges in k parts, k = ceil(sqrt(area / target))), every sphere into bands of equal polar
// angle cut into patches of about the target area; target = total area / --pbgi-surfels. Each
// piece becomes a disk at its centroid (on the sphere for spheres) with the piece's exact area
// (radius sqrt(A / pi)) and the shape's normal, so the disks' areas add up to the surface's.
//
// Each surfel has two sides: the front (the shape's normal) and the back. Both occlude; each
// has its own outgoing radiance, the diffusely reflected light rho_d / pi E on the sides a
// Phong material with rho_d > 0 reflects (both for two-sided materials, the front only for
// one-sided ones); other sides and materials (mirrors, glass, conductors, black emitters) are
// black occluders, and the Phong lobe's reflection is not in the cloud (its glossy light is
// missing from the indirect light gathered from it).
#pragma once

#include <cstdint>
#include <vector>

#include "samplers/sampler.hpp"
#include "scene/scene.hpp"

namespace pathlab {

struct Surfel {
    Vec3f p, n;              // centre, unit normal (the front)
    float area = 0, radius = 0;
    Rgb albedo[2] = {Rgb(0.0f), Rgb(0.0f)};    // rho_d of the front and the back (0: the side reflects nothing)
    Rgb direct[2] = {Rgb(0.0f), Rgb(0.0f)};    // the direct light each side reflects (radiance)
    Rgb radiance[2] = {Rgb(0.0f), Rgb(0.0f)};  // what gathers see: direct + the surfel bounces so far
};

// The cloud of about `target` surfels of the scene (at least one per triangle and sphere).
std::vector<Surfel> make_surfels(const Scene& scene, size_t target);

// The direct light each surfel side reflects, rho_d / pi E_direct, each estimated by `samples`
// MIS pairs as pt-mis estimates it (one light sample, one cosine-distributed BSDF sample, balance
// heuristic), with Sampler(seed, surfel stream, k): a pure function of the seed. In parallel.
void light_surfels(const Scene& scene, std::vector<Surfel>& surfels, int samples, uint64_t seed, SamplerKind kind);

}  // namespace pathlab
