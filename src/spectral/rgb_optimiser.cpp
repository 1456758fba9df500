#include "spectral/rgb_optimiser.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include "core/spectrum.hpp"
#include "spectral/sigmoid_polynomial.hpp"

namespace pathlab {
namespace {

// The optimiser's quadrature: 1 nm midpoint rule over [360, 830] nm, weights D65 xyz_bar / N
// with N the same rule's integral of D65 ybar (so a flat reflectance 1 has Y = 1 exactly).
constexpr int kSteps = 470;

struct Quadrature {
    double t[kSteps];           // normalised wavelength (sigmoid_polynomial.hpp)
    double w[3][kSteps];        // D65 (x, y, z)bar h / N
    Vec3d white;                // XYZ of the flat reflectance 1 (CIELAB's white point)
};

const Quadrature& quadrature() {
    static const Quadrature q = [] {
        Quadrature q{};
        const double h = (kCieMaxWavelength - kCieMinWavelength) / kSteps;
        double n = 0;
        for (int k = 0; k < kSteps; ++k) {
            const double l = kCieMinWavelength + (k + 0.5) * h;
            const Vec3d bar = cie1931_xyz_bar(l) * (cie_d65(l) * h);
            q.t[k] = (l - kSigmoidLambdaMin) / kSigmoidLambdaRange;
            for (int c = 0; c < 3; ++c) q.w[c][k] = bar[c];
            n += bar.y;
        }
        q.white = Vec3d(0.0);
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < kSteps; ++k) {
                q.w[c][k] /= n;
                q.white[c] += q.w[c][k];
            }
        return q;
    }();
    return q;
}

// XYZ of the model's reflectance and its derivatives d XYZ / d c (rows: X, Y, Z).
Vec3d model_xyz(const SigmoidCoefficients& c, double (*jac)[3]) {
    const Quadrature& q = quadrature();
    double xyz[3] = {0, 0, 0}, j[3][3] = {};
    for (int k = 0; k < kSteps; ++k) {
        const double t = q.t[k];
        const double x = (c[0] * t + c[1]) * t + c[2];
        const double r = 1 / std::sqrt(1 + x * x);
        const double s = 0.5 + 0.5 * x * r, ds = 0.5 * r * r * r;
        const double d[3] = {ds * t * t, ds * t, ds};
        for (int a = 0; a < 3; ++a) {
            const double w = q.w[a][k];
            xyz[a] += w * s;
            if (jac)
                for (int b = 0; b < 3; ++b) j[a][b] += w * d[b];
        }
    }
    if (jac)
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) jac[a][b] = j[a][b];
    return {xyz[0], xyz[1], xyz[2]};
}

// CIELAB of an XYZ colour relative to `white`, and d Lab / d XYZ.
constexpr double kDelta = 6.0 / 29.0;
double lab_f(double t) { return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3 * kDelta * kDelta) + 4.0 / 29.0; }
double lab_df(double t) {
    return t > kDelta * kDelta * kDelta ? 1 / (3 * std::cbrt(t) * std::cbrt(t)) : 1 / (3 * kDelta * kDelta);
}
Vec3d lab(const Vec3d& xyz, const Vec3d& white, double (*jac)[3]) {
    const double tx = xyz.x / white.x, ty = xyz.y / white.y, tz = xyz.z / white.z;
    const double fx = lab_f(tx), fy = lab_f(ty), fz = lab_f(tz);
    if (jac) {
        const double dx = lab_df(tx) / white.x, dy = lab_df(ty) / white.y, dz = lab_df(tz) / white.z;
        const double m[3][3] = {{0, 116 * dy, 0}, {500 * dx, -500 * dy, 0}, {0, 200 * dy, -200 * dz}};
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) jac[a][b] = m[a][b];
    }
    return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

// Solves the 3x3 system A x = b by Gaussian elimination with partial pivoting; false if singular.
bool solve3(double a[3][3], double b[3], double x[3]) {
    int p[3] = {0, 1, 2};
    for (int col = 0; col < 3; ++col) {
        int best = col;
        for (int r = col + 1; r < 3; ++r)
            if (std::abs(a[p[r]][col]) > std::abs(a[p[best]][col])) best = r;
        std::swap(p[col], p[best]);
        const double piv = a[p[col]][col];
        if (!(std::abs(piv) > 1e-300)) return false;
        for (int r = col + 1; r < 3; ++r) {
            const double f = a[p[r]][col] / piv;
            for (int k = col; k < 3; ++k) a[p[r]][k] -= f * a[p[col]][k];
            b[p[r]] -= f * b[p[col]];
        }
    }
    for (int col = 2; col >= 0; --col) {
        double s = b[p[col]];
        for (int k = col + 1; k < 3; ++k) s -= a[p[col]][k] * x[k];
        x[col] = s / a[p[col]][col];
    }
    return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

struct Eval {
    Vec3d r;           // Lab(model) - Lab(target)
    double j[3][3];    // d r / d c
    double norm2;
};

Eval evaluate(const SigmoidCoefficients& c, const Vec3d& target_lab) {
    const Quadrature& q = quadrature();
    double jx[3][3], jl[3][3];
    const Vec3d xyz = model_xyz(c, jx);
    Eval e;
    e.r = lab(xyz, q.white, jl) - target_lab;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) e.j[a][b] = jl[a][0] * jx[0][b] + jl[a][1] * jx[1][b] + jl[a][2] * jx[2][b];
    e.norm2 = dot(e.r, e.r);
    return e;
}

}  // namespace

RgbFit fit_rgb_reflectance(const Vec3d& rgb, const SigmoidCoefficients& start) {
    const Vec3d target_lab = lab(linear_srgb_to_xyz(rgb), quadrature().white, nullptr);
    RgbFit fit;
    fit.c = start;
    Eval e = evaluate(fit.c, target_lab);
    double mu = 1e-3;  // Levenberg-Marquardt damping, relative to the diagonal of J^T J
    constexpr int kMaxIterations = 64;
    constexpr double kTolerance = 1e-6;  // CIELAB units
    for (; fit.iterations < kMaxIterations && e.norm2 > kTolerance * kTolerance; ++fit.iterations) {
        double jtj[3][3], jtr[3];
        for (int a = 0; a < 3; ++a) {
            jtr[a] = e.j[0][a] * e.r.x + e.j[1][a] * e.r.y + e.j[2][a] * e.r.z;
            for (int b = 0; b < 3; ++b) jtj[a][b] = e.j[0][a] * e.j[0][b] + e.j[1][a] * e.j[1][b] + e.j[2][a] * e.j[2][b];
        }
        bool improved = false;
        for (int attempt = 0; attempt < 16 && !improved; ++attempt) {
            double m[3][3], rhs[3] = {jtr[0], jtr[1], jtr[2]}, step[3];
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) m[a][b] = jtj[a][b] + (a == b ? mu * std::max(jtj[a][a], 1e-12) : 0.0);
            if (!solve3(m, rhs, step)) {
                mu *= 8;
                continue;
            }
            const SigmoidCoefficients next{fit.c[0] - step[0], fit.c[1] - step[1], fit.c[2] - step[2]};
            const Eval en = evaluate(next, target_lab);
            if (en.norm2 < e.norm2) {
                fit.c = next;
                e = en;
                mu = std::max(mu / 4, 1e-9);
                improved = true;
            } else {
                mu *= 8;
            }
        }
        if (!improved) break;  // no step lowers the residual: a local minimum (or black)
    }
    fit.residual = std::sqrt(e.norm2);
    return fit;
}

Vec3d sigmoid_reflectance_rgb(const SigmoidCoefficients& c) { return xyz_to_linear_srgb(model_xyz(c, nullptr)); }

std::vector<float> rgb_table_z_nodes(int res) {
    std::vector<float> z(static_cast<size_t>(res));
    const auto smoothstep = [](double x) { return x * x * (3 - 2 * x); };
    for (int k = 0; k < res; ++k) z[size_t(k)] = float(smoothstep(smoothstep(double(k) / (res - 1))));
    return z;
}

std::vector<float> fit_rgb_table(int res, int threads) {
    const std::vector<float> z = rgb_table_z_nodes(res);
    std::vector<float> table(size_t(3) * res * res * res * 3);
    const auto index = [&](int m, int k, int j, int i) { return (((size_t(m) * res + k) * res + j) * res + i) * 3; };
    const int lines = 3 * res;  // (m, j) pairs; each runs over every i and walks z
    const auto run = [&](int first) {
        for (int line = first; line < lines; line += threads) {
            const int m = line / res, j = line % res;
            for (int i = 0; i < res; ++i) {
                const double x = double(i) / (res - 1), y = double(j) / (res - 1);
                const auto solve_at = [&](int k, SigmoidCoefficients& c) {
                    Vec3d rgb;
                    rgb[m] = z[size_t(k)];
                    rgb[(m + 1) % 3] = x * z[size_t(k)];
                    rgb[(m + 2) % 3] = y * z[size_t(k)];
                    c = fit_rgb_reflectance(rgb, c).c;
                    for (int a = 0; a < 3; ++a) table[index(m, k, j, i) + size_t(a)] = float(c[size_t(a)]);
                };
                const int start = res / 5;
                SigmoidCoefficients c{0, 0, 0};
                for (int k = start; k < res; ++k) solve_at(k, c);
                c = {table[index(m, start, j, i)], table[index(m, start, j, i) + 1], table[index(m, start, j, i) + 2]};
                for (int k = start - 1; k >= 0; --k) solve_at(k, c);
            }
        }
    };
    threads = std::max(1, threads);
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(run, t);
    run(0);
    for (auto& t : pool) t.join();
    return table;
}

}  // namespace pathlab
