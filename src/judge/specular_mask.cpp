#include "judge/specular_mask.hpp"

#include <algorithm>
#include <numeric>

#include "cameras/camera.hpp"

namespace pathlab {

std::vector<uint8_t> specular_first_vertex_mask(const Scene& scene, int width, int height, int samples_per_axis,
                                                bool dilate) {
    const PerspectiveCamera camera(scene.camera(), width, height);
    const size_t w = size_t(width), h = size_t(height);
    std::vector<uint8_t> hit_specular(w * h, 0);
    const int n = std::max(1, samples_per_axis);
    for (size_t y = 0; y < h; ++y)
        for (size_t x = 0; x < w; ++x)
            for (int i = 0; i < n * n && !hit_specular[y * w + x]; ++i) {
                const float sx = float(x) + (float(i % n) + 0.5f) / float(n), sy = float(y) + (float(i / n) + 0.5f) / float(n);
                Intersection hit;
                if (scene.intersect(camera.generate(sx, sy), hit) && (scene.material(hit.material).lobes() & kLobeSpecular))
                    hit_specular[y * w + x] = 1;
            }
    if (!dilate) return hit_specular;
    std::vector<uint8_t> mask(w * h, 0);
    for (size_t y = 0; y < h; ++y)
        for (size_t x = 0; x < w; ++x) {
            if (!hit_specular[y * w + x]) continue;
            for (size_t yy = y > 0 ? y - 1 : 0; yy <= std::min(h - 1, y + 1); ++yy)
                for (size_t xx = x > 0 ? x - 1 : 0; xx <= std::min(w - 1, x + 1); ++xx) mask[yy * w + xx] = 1;
        }
    return mask;
}

size_t count_marked(const std::vector<uint8_t>& mask) {
    return size_t(std::count_if(mask.begin(), mask.end(), [](uint8_t m) { return m != 0; }));
}

}  // namespace pathlab
