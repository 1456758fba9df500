// The pixels that a light tracer leaves black by design: those whose first surface seen from
// the camera has a specular (Dirac) lobe (mirrors, glass, the coating of plastic), through
// which no light path can connect to a pinhole. Found by tracing samples_per_axis^2 stratified
// camera rays per pixel; with `dilate` the 8 neighbours of such a pixel are marked too, so a
// sliver of a specular surface that the rays missed still marks its pixel.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.hpp"

namespace pathlab {

std::vector<uint8_t> specular_first_vertex_mask(const Scene& scene, int width, int height, int samples_per_axis = 4,
                                                bool dilate = true);
size_t count_marked(const std::vector<uint8_t>& mask);

}  // namespace pathlab
