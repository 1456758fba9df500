// Piecewise-constant distributions, for sampling tabulated functions (environment maps, light
// profiles) in proportion to their values.
//
// Distribution1D: n values f_i >= 0 on n equal cells of [0, 1). Sampled continuously (inverse
// of the cumulative distribution, x uniform inside the chosen cell; density f_i / integral per
// unit length) or discretely (cell i with probability f_i / sum). Distribution2D: nu x nv
// values on the cells of [0, 1)^2, a marginal over the rows and one conditional per row;
// density per unit area f_ij / integral. All-zero (or empty) values are sampled uniformly, so
// that sampling never fails; their densities are then those of the uniform distribution.
// Sums are taken in double; a sample's density is f / integral, never a difference of the
// cumulative table, so pdf() and the density a sample reports are the same number.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

class Distribution1D {
public:
    Distribution1D() = default;
    explicit Distribution1D(std::vector<float> f) : f_(std::move(f)), cdf_(f_.size() + 1) {
        double running = 0;
        cdf_[0] = 0;
        for (size_t i = 0; i < f_.size(); ++i) {
            running += double(std::max(0.0f, f_[i]));
            cdf_[i + 1] = running;
        }
        sum_ = running;
        if (!(sum_ > 0)) {  // nothing to prefer: uniform
            for (size_t i = 0; i < f_.size(); ++i) f_[i] = 1, cdf_[i + 1] = double(i + 1);
            sum_ = double(f_.size());
        }
        for (double& c : cdf_) c /= sum_;
        if (!f_.empty()) cdf_.back() = 1;
    }

    size_t size() const { return f_.size(); }
    float value(size_t i) const { return f_[i]; }
    // The sum of the values (after an all-zero table was made uniform: n).
    double sum() const { return sum_; }
    // The integral of the step function over [0, 1): sum / n.
    double integral() const { return f_.empty() ? 0.0 : sum_ / double(f_.size()); }

    // The cell i with cdf_i <= u < cdf_(i+1) (never a cell of zero probability, for u in [0, 1)).
    size_t find(float u) const {
        const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), double(u));
        const ptrdiff_t i = (it - cdf_.begin()) - 1;
        return size_t(std::clamp<ptrdiff_t>(i, 0, ptrdiff_t(f_.size()) - 1));
    }
    // Discrete: a cell with probability f_i / sum (pmf), and u rescaled to [0, 1) inside it.
    size_t sample_discrete(float u, float& pmf, float* u_remapped = nullptr) const {
        const size_t i = find(u);
        pmf = float(double(f_[i]) / sum_);
        if (u_remapped) {
            const double width = cdf_[i + 1] - cdf_[i];
            *u_remapped = width > 0 ? float(std::min((double(u) - cdf_[i]) / width, 0x1.fffffep-1)) : 0.0f;
        }
        return i;
    }
    float pmf(size_t i) const { return float(double(f_[i]) / sum_); }
    // Continuous: x in [0, 1) with density pdf = f_i / integral, in cell i.
    float sample_continuous(float u, float& pdf, size_t* cell = nullptr) const {
        float du;
        const size_t i = sample_discrete(u, pdf, &du);
        pdf *= float(f_.size());
        if (cell) *cell = i;
        // x in cell i exactly as pdf() finds cells (floor(x n)), whatever the rounding.
        const float n = float(f_.size());
        float x = std::min((float(i) + du) / n, 0x1.fffffep-1f);
        while (x > 0 && size_t(x * n) > i) x = std::nextafter(x, 0.0f);
        while (size_t(x * n) < i) x = std::nextafter(x, 1.0f);
        return x;
    }
    // The density of sample_continuous at x.
    float pdf(float x) const {
        if (f_.empty() || !(x >= 0 && x < 1)) return 0.0f;
        const size_t i = std::min(size_t(x * float(f_.size())), f_.size() - 1);
        return float(double(f_[i]) / sum_ * double(f_.size()));
    }

private:
    std::vector<float> f_;
    std::vector<double> cdf_;
    double sum_ = 0;
};

class Distribution2D {
public:
    Distribution2D() = default;
    // f[v * nu + u]: row v (the second coordinate), column u (the first).
    Distribution2D(const std::vector<float>& f, int nu, int nv) : nu_(nu), nv_(nv) {
        rows_.reserve(size_t(nv));
        std::vector<float> row_sums(static_cast<size_t>(nv));
        for (int v = 0; v < nv; ++v) {
            rows_.emplace_back(std::vector<float>(f.begin() + ptrdiff_t(v) * nu, f.begin() + ptrdiff_t(v + 1) * nu));
            double s = 0;
            for (int u = 0; u < nu; ++u) s += std::max(0.0f, f[size_t(v) * size_t(nu) + size_t(u)]);
            row_sums[size_t(v)] = float(s);
        }
        marginal_ = Distribution1D(std::move(row_sums));
    }

    int width() const { return nu_; }
    int height() const { return nv_; }

    // A point of [0, 1)^2 with its density per unit area; `cell` receives (column, row).
    Vec2f sample_continuous(Vec2f u, float& pdf, int* column = nullptr, int* row = nullptr) const {
        float pdf_v, pdf_u;
        size_t v, c;
        const float y = marginal_.sample_continuous(u.y, pdf_v, &v);
        const float x = rows_[v].sample_continuous(u.x, pdf_u, &c);
        pdf = pdf_v * pdf_u;
        if (column) *column = int(c);
        if (row) *row = int(v);
        return {x, y};
    }
    float pdf(Vec2f p) const {
        if (!(p.x >= 0 && p.x < 1 && p.y >= 0 && p.y < 1) || rows_.empty()) return 0.0f;
        const size_t v = std::min(size_t(p.y * float(nv_)), size_t(nv_ - 1));
        return marginal_.pdf(p.y) * rows_[v].pdf(p.x);
    }
    // The integral of the step function over [0, 1)^2 (the mean of the values).
    double integral() const { return marginal_.integral() / double(std::max(1, nu_)); }

private:
    int nu_ = 0, nv_ = 0;
    std::vector<Distribution1D> rows_;
    Distribution1D marginal_;
};

}  // namespace pathlab
