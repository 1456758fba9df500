// An irradiance record (Ward, Rubinstein and Clear 1988) and the hemisphere gather that makes
// one: M x N rays stratified in the cosine-weighted hemisphere (sin^2 theta_j in [j/M, (j+1)/M),
// phi_k in [2 pi k/N, 2 pi (k+1)/N)), the indirect irradiance E = pi/(MN) sum L_jk, the harmonic
// mean distance to what the rays hit, and Ward and Heckbert's (1992) gradients:
//   rotational     grad_r E = pi/(MN) sum_k v_k sum_j tan(theta_jk) L_jk, v_k the tangent
//                  direction at phi_k + pi/2, so that E(n') ~ E + (n x n') . grad_r;
//   translational  grad_t E = sum_k [ u_k (2 pi/N) sum_{j>=1} sin(t_j-) cos^2(t_j-) / min(r_jk, r_j-1,k) (L_jk - L_j-1,k)
//                                   + v_k- sum_j (sin t_j+ - sin t_j-) / min(r_jk, r_j,k-1) (L_jk - L_j,k-1) ],
//                  t_j- = asin(sqrt(j/M)), t_j+ = asin(sqrt((j+1)/M)), u_k the direction at the
//                  cell's azimuth, v_k- perpendicular to the boundary at 2 pi k/N: the projected
//                  solid angle a cell boundary sweeps as the point moves, times the radiance
//                  difference across it (derived here with the boundary points at the nearer
//                  distance, as Ward and Heckbert do), so that E(x') ~ E + (x' - x) . grad_t.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "core/frame.hpp"
#include "core/vec.hpp"
#include "samplers/sampler.hpp"

namespace pathlab {

struct IrradianceRecord {
    Vec3f p, n;          // where, and the shading normal there
    Rgb E{0.0f};         // indirect irradiance
    float R = 0;         // validity radius: the harmonic mean distance, clamped
    float harmonic = 0;  // the harmonic mean distance itself
    Vec3f grad_r[3], grad_t[3];  // per colour channel
    uint32_t pixel = 0;  // the pixel whose first hit placed it
};

// The gather at p with frame `frame` (normal frame.n): radiance(world direction, distance&) gives
// the radiance arriving from that direction (0 for none) and the distance to what it hit
// (infinity for nothing).
template <typename Radiance>
IrradianceRecord gather_record(const Vec3f& p, const Frame& frame, int M, int N, Sampler& sampler, Radiance&& radiance) {
    IrradianceRecord rec;
    rec.p = p;
    rec.n = frame.n;
    const float inf = std::numeric_limits<float>::infinity();
    thread_local std::vector<Rgb> L;
    thread_local std::vector<float> dist;
    L.assign(size_t(M) * size_t(N), Rgb(0.0f));
    dist.assign(size_t(M) * size_t(N), inf);
    const auto at = [N](int j, int k) { return size_t(j) * size_t(N) + size_t((k + N) % N); };
    Vec3f grad_r[3] = {Vec3f(0.0f), Vec3f(0.0f), Vec3f(0.0f)};
    double inverse_distances = 0;
    Rgb sum(0.0f);
    for (int j = 0; j < M; ++j)
        for (int k = 0; k < N; ++k) {
            const Vec2f u = sampler.next2d();
            const float sin2 = (float(j) + u.x) / float(M), sin_t = std::sqrt(sin2), cos_t = std::sqrt(std::max(0.0f, 1 - sin2));
            const float phi = 2 * kPi * (float(k) + u.y) / float(N);
            const Vec3f local(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
            float d = inf;
            const Rgb Li = radiance(frame.to_world(local), d);
            L[at(j, k)] = Li;
            dist[at(j, k)] = d;
            sum += Li;
            if (d < inf && d > 0) inverse_distances += 1.0 / double(d);
            const Vec3f v(-std::sin(phi), std::cos(phi), 0.0f);
            const float tan_t = cos_t > 1e-4f ? sin_t / cos_t : sin_t / 1e-4f;
            for (int c = 0; c < 3; ++c) grad_r[c] += v * (tan_t * Li[c]);
        }
    const float norm = kPi / float(M * N);
    rec.E = sum * norm;
    rec.harmonic = inverse_distances > 0 ? float(double(M * N) / inverse_distances) : inf;
    Vec3f grad_t[3] = {Vec3f(0.0f), Vec3f(0.0f), Vec3f(0.0f)};
    for (int k = 0; k < N; ++k) {
        const float phi_c = 2 * kPi * (float(k) + 0.5f) / float(N), phi_b = 2 * kPi * float(k) / float(N);
        const Vec3f u_k(std::cos(phi_c), std::sin(phi_c), 0.0f), v_k(-std::sin(phi_b), std::cos(phi_b), 0.0f);
        for (int j = 0; j < M; ++j) {
            // The boundary at theta_j- with the cell below (j - 1, k).
            if (j > 0) {
                const float r = std::min(dist[at(j, k)], dist[at(j - 1, k)]);
                if (r < inf && r > 0) {
                    const float s2 = float(j) / float(M), c = (2 * kPi / float(N)) * std::sqrt(s2) * (1 - s2) / r;
                    for (int ch = 0; ch < 3; ++ch) grad_t[ch] += u_k * (c * (L[at(j, k)][ch] - L[at(j - 1, k)][ch]));
                }
            }
            // The boundary at phi_k- with the cell (j, k - 1).
            const float r = std::min(dist[at(j, k)], dist[at(j, k - 1)]);
            if (r < inf && r > 0) {
                const float c = (std::sqrt(float(j + 1) / float(M)) - std::sqrt(float(j) / float(M))) / r;
                for (int ch = 0; ch < 3; ++ch) grad_t[ch] += v_k * (c * (L[at(j, k)][ch] - L[at(j, k - 1)][ch]));
            }
        }
    }
    for (int c = 0; c < 3; ++c) {
        rec.grad_r[c] = frame.to_world(grad_r[c] * norm);
        rec.grad_t[c] = frame.to_world(grad_t[c]);
    }
    return rec;
}

}  // namespace pathlab
