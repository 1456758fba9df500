#include "integrators/cache/surfels.hpp"

#include <tbb/parallel_for.h>

#include <cmath>

#include "integrators/common/direct_lighting.hpp"

namespace pathlab {
namespace {

// The diffuse reflectance a surfel of material m has on its front and back.
void set_albedo(Surfel& s, const Material& m) {
    const auto* phong = std::get_if<PhongMaterial>(&m.model);
    if (!phong || is_black(phong->diffuse)) return;
    s.albedo[0] = phong->diffuse;
    if (m.two_sided) s.albedo[1] = phong->diffuse;
}

float triangle_area(const Vec3f& a, const Vec3f& b, const Vec3f& c) { return 0.5f * length(cross(b - a, c - a)); }

// Random-number streams of the surfels' direct light, apart from the pixels' and ic's records'.
uint64_t surfel_stream(size_t surfel, int side) { return uint64_t(2 * surfel + size_t(side)) + (uint64_t(6) << 41); }

}  // namespace

std::vector<Surfel> make_surfels(const Scene& scene, size_t target) {
    const SceneDescription& d = scene.description();
    double total = 0;
    for (const MeshDesc& m : d.meshes)
        for (const auto& t : m.triangles) total += triangle_area(m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]);
    for (const SphereDesc& s : d.spheres) total += 4 * double(kPi) * double(s.radius) * s.radius;
    const double piece = total / double(std::max<size_t>(target, 1));

    std::vector<Surfel> out;
    const auto add = [&](const Vec3f& p, const Vec3f& n, float area, const Material& m) {
        if (!(area > 0)) return;
        Surfel s;
        s.p = p, s.n = n, s.area = area, s.radius = std::sqrt(area / kPi);
        set_albedo(s, m);
        out.push_back(s);
    };
    for (const MeshDesc& m : d.meshes) {
        const Material& material = scene.material(m.material);
        for (const auto& t : m.triangles) {
            const Vec3f &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
            const float area = triangle_area(a, b, c);
            if (!(area > 0)) continue;
            const Vec3f n = normalize(cross(b - a, c - a));  // as Scene's face normals
            const int k = std::max(1, int(std::ceil(std::sqrt(double(area) / piece))));
            const Vec3f e1 = (b - a) / float(k), e2 = (c - a) / float(k);
            const float sub = area / float(k * k);
            // The k^2 pieces: (i, j) upward with corners a + i e1 + j e2, +e1, +e2, and for
            // i + j < k - 1 the downward one beside it.
            for (int i = 0; i < k; ++i)
                for (int j = 0; i + j < k; ++j) {
                    const Vec3f o = a + e1 * float(i) + e2 * float(j);
                    add(o + (e1 + e2) * (1.0f / 3.0f), n, sub, material);
                    if (i + j < k - 1) add(o + (e1 + e2) * (2.0f / 3.0f), n, sub, material);
                }
        }
    }
    for (const SphereDesc& s : d.spheres) {
        const Material& material = scene.material(s.material);
        const double R = s.radius;
        // Bands of equal polar angle about square patches wide, each cut into equal patches.
        const int bands = std::max(1, int(std::ceil(double(kPi) * R / std::sqrt(piece))));
        for (int b = 0; b < bands; ++b) {
            const double t0 = double(kPi) * b / bands, t1 = double(kPi) * (b + 1) / bands;
            const double band_area = 2 * double(kPi) * R * R * (std::cos(t0) - std::cos(t1));
            const int patches = std::max(1, int(std::lround(band_area / piece)));
            // The patch's centroid direction: the mean of cos theta over the band (equal area).
            const double cz = 0.5 * (std::cos(t0) + std::cos(t1)), sz = std::sqrt(std::max(0.0, 1 - cz * cz));
            for (int k = 0; k < patches; ++k) {
                const double phi = 2 * double(kPi) * (k + 0.5) / patches;
                const Vec3f dir(float(sz * std::cos(phi)), float(sz * std::sin(phi)), float(cz));
                add(s.center + dir * s.radius, s.flip_normals ? -dir : dir, float(band_area / patches), material);
            }
        }
    }
    return out;
}

void light_surfels(const Scene& scene, std::vector<Surfel>& surfels, int samples, uint64_t seed, SamplerKind kind) {
    tbb::parallel_for(size_t(0), surfels.size(), [&](size_t i) {
        Surfel& s = surfels[i];
        for (int side = 0; side < 2; ++side) {
            s.direct[side] = Rgb(0.0f);
            if (is_black(s.albedo[side])) continue;
            // A Lambertian surface of the side's albedo, facing the side's way.
            const Material lambert{PhongMaterial{s.albedo[side], Rgb(0.0f), 1.0f}, true};
            ShadingPoint sp;
            sp.material = &lambert;
            sp.p = s.p;
            sp.ng = side == 0 ? s.n : -s.n;
            sp.frame = Frame(sp.ng);
            sp.wi = Vec3f(0, 0, 1);
            Vec3d sum(0.0);
            RgbWavelengths rgb;  // the cloud holds RGB (in spectral mode too)
            for (int k = 0; k < samples; ++k) {
                Sampler sampler(seed, surfel_stream(i, side), uint64_t(k), kind);
                Rgb L = estimate_light_sample(scene, sp, sampler, /*mis=*/true, rgb);
                if (const auto b = lambert.sample(sp, sp.wi, sampler.next2d())) {
                    EmitterHit found;
                    L += estimate_bsdf_sample_mis(scene, sp, *b, b->f, found, rgb);
                }
                sum += Vec3d(L);
            }
            s.direct[side] = Rgb(sum / double(std::max(samples, 1)));
        }
        s.radiance[0] = s.direct[0], s.radiance[1] = s.direct[1];
    });
}

}  // namespace pathlab
