// The extra EXR channels a scene file's integrator asks for: moment (the second moment of the
// samples per pixel and the variance of the mean) and aov (what the first surface seen is); and
// --aovs, the auxiliary images from the render's own samples (render/aov_film.hpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "image/image_io.hpp"
#include "render/aov_film.hpp"
#include "render/film.hpp"
#include "scene/scene.hpp"

namespace pathlab {

// m2.R, m2.G, m2.B: the mean of the squared samples (sum of squares / count); var.R, ...: the
// variance of the pixel's mean (the square of Film::standard_error).
std::vector<ExrChannel> moment_channels(const Film& film);

// The aovs (name, kind), kinds depth (distance along the camera ray), position, sh_normal,
// geo_normal (unit world vectors), albedo (the diffuse reflectance) and uv, each averaged over
// `samples` (1 to 64) jittered camera rays per pixel (box filter; 0 where the ray escapes).
// Deterministic: the rays are a pure function of (seed, pixel, sample).
std::vector<ExrChannel> aov_channels(const Scene& scene, const std::vector<std::pair<std::string, std::string>>& aovs, int width,
                                     int height, uint64_t samples, uint64_t seed);

// --aovs (names from aov_names(), in the order given): the first-vertex images from `first`
// (needed unless only variance and sample-count are asked for) and the others from the film:
// variance, the unbiased variance of one sample of the pixel ((sum of squares - n mean^2) /
// (n - 1); 0 with one sample), and sample-count, its samples.
std::vector<ExrChannel> render_aov_channels(const std::vector<std::string>& aovs, const Film& film, const AovFilm* first);

}  // namespace pathlab
