// The path tracing loop of pt-mis and pt-mis3, for integrators that continue a path with it
// (ic traces its records' hemisphere rays and its glossy bounces so, volpath renders scenes
// without media with it).
#pragma once

#include "integrators/common/path_rules.hpp"
#include "integrators/common/transport.hpp"
#include "scene/scene.hpp"

namespace pathlab {

// The radiance leaving the surface `hit` towards -dir, without the emission there, estimated as
// pt-mis does from that vertex on (pt-mis3 with `three_rays`), in the colour of a path carrying
// wavelengths wl (common/transport.hpp): for a path that has already made `bounces` bounces (the
// depth limit and Russian roulette count from there). `only_length` >= 0: only paths of that
// many bounces (in all) count. Returns L plus that radiance (added in the order pt-mis adds it).
// Instantiated for RgbWavelengths and SampledWavelengths.
template <class Wl>
ColourAt<Wl> pt_mis_from_hit(const Scene& scene, Intersection hit, Vec3f dir, int bounces, Sampler& sampler, const PathRules& rules, Wl& wl,
                             bool three_rays = false, int only_length = -1, ColourAt<Wl> L = ColourAt<Wl>(0.0f));

// The estimate of a pt-mis pixel sample (pt-mis3's with `three_rays`): the radiance arriving
// along a camera ray, the emission seen directly included (unless rules.hides_emitters(); with
// only_length >= 0, only if that length is 0). pssmlt drives it with a Markov chain's numbers.
template <class Wl>
ColourAt<Wl> pt_mis_camera_radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, const PathRules& rules, Wl& wl,
                                    bool three_rays, int only_length);

}  // namespace pathlab
