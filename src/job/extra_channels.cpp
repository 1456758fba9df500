#include "job/extra_channels.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "cameras/camera.hpp"
#include "samplers/sampler.hpp"

namespace pathlab {

std::vector<ExrChannel> moment_channels(const Film& film) {
    const Image se = film.standard_error();
    std::vector<ExrChannel> out;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        ExrChannel m2{std::string("m2.") + names[c], std::vector<float>(film.pixel_count())};
        ExrChannel var{std::string("var.") + names[c], std::vector<float>(film.pixel_count())};
        for (size_t i = 0; i < film.pixel_count(); ++i) {
            const uint64_t n = film.count(i);
            m2.values[i] = n ? float(film.sum_of_squares(i)[c] / double(n)) : 0.0f;
            var.values[i] = se[i][c] * se[i][c];
        }
        out.push_back(std::move(m2));
        out.push_back(std::move(var));
    }
    return out;
}

std::vector<ExrChannel> aov_channels(const Scene& scene, const std::vector<std::pair<std::string, std::string>>& aovs, int width,
                                     int height, uint64_t samples, uint64_t seed) {
    const size_t pixels = size_t(width) * size_t(height);
    const int n = int(std::clamp<uint64_t>(samples, 1, 64));
    const PerspectiveCamera camera(scene.camera(), width, height);
    // Per aov: its components, summed per pixel.
    std::vector<std::vector<Vec3d>> sums(aovs.size(), std::vector<Vec3d>(pixels, Vec3d(0.0)));
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < width; ++x) {
                const size_t pixel = size_t(y) * size_t(width) + size_t(x);
                for (int k = 0; k < n; ++k) {
                    Sampler sampler(seed, pixel + (uint64_t(1) << 52), uint64_t(k));  // not an integrator's stream
                    const Vec2f j = sampler.next2d();
                    const Ray ray = camera.generate(float(x) + j.x, float(y) + j.y, sampler.next2d());
                    Intersection hit;
                    if (!scene.intersect(ray, hit)) continue;
                    for (size_t a = 0; a < aovs.size(); ++a) {
                        const std::string& kind = aovs[a].second;
                        Vec3d v(0.0);
                        if (kind == "depth") v = Vec3d(double(hit.t) * length(Vec3d(ray.d)));
                        else if (kind == "position") v = Vec3d(hit.p);
                        else if (kind == "sh_normal") v = Vec3d(hit.ns);
                        else if (kind == "geo_normal") v = Vec3d(hit.ng);
                        else if (kind == "albedo") v = Vec3d(diffuse_albedo(scene.material(hit.material)));
                        else if (kind == "uv") v = Vec3d(hit.uv.x, hit.uv.y, 0);
                        sums[a][pixel] += v;
                    }
                }
            }
    });
    std::vector<ExrChannel> out;
    for (size_t a = 0; a < aovs.size(); ++a) {
        const auto& [name, kind] = aovs[a];
        std::vector<std::string> suffixes;
        if (kind == "depth") suffixes = {""};
        else if (kind == "albedo") suffixes = {".R", ".G", ".B"};
        else if (kind == "uv") suffixes = {".U", ".V"};
        else suffixes = {".X", ".Y", ".Z"};
        for (size_t c = 0; c < suffixes.size(); ++c) {
            ExrChannel ch{name + suffixes[c], std::vector<float>(pixels)};
            for (size_t i = 0; i < pixels; ++i) ch.values[i] = float(sums[a][i][int(c)] / n);
            out.push_back(std::move(ch));
        }
    }
    return out;
}

std::vector<ExrChannel> render_aov_channels(const std::vector<std::string>& aovs, const Film& film, const AovFilm* first) {
    const size_t pixels = film.pixel_count();
    std::vector<ExrChannel> out;
    for (const std::string& aov : aovs) {
        // The aov's channels, filled pixel by pixel (the kind decided once, not per value).
        std::vector<ExrChannel> channels;
        for (const std::string& name : aov_channel_names(aov)) channels.push_back({name, std::vector<float>(pixels)});
        if (aov == "variance") {
            for (size_t i = 0; i < pixels; ++i) {
                const double n = double(film.count(i));
                if (n < 2) continue;
                const Vec3d sum = film.sum(i), sumsq = film.sum_of_squares(i);
                for (int c = 0; c < 3; ++c) channels[size_t(c)].values[i] = float(std::max(0.0, (sumsq[c] - sum[c] * sum[c] / n) / (n - 1)));
            }
        } else if (aov == "sample-count") {
            for (size_t i = 0; i < pixels; ++i) channels[0].values[i] = float(film.count(i));
        } else if (first) {
            // The first-vertex components: albedo 0-2, normal 3-5, position 6-8, depth 9 (AovFilm::mean).
            const int base = aov == "albedo" ? 0 : aov == "normal" ? 3 : aov == "position" ? 6 : 9;
            for (size_t c = 0; c < channels.size(); ++c)
                for (size_t i = 0; i < pixels; ++i) channels[c].values[i] = first->mean(i, base + int(c));
        }
        for (ExrChannel& c : channels) out.push_back(std::move(c));
    }
    return out;
}

}  // namespace pathlab
