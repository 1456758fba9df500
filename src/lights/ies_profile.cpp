#include "lights/ies_profile.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string_view>

#include <fmt/format.h>

#include "core/input_file.hpp"

namespace pathlab {
namespace {

constexpr size_t kMaxFileBytes = size_t(16) << 20;
constexpr int kMaxAngles = 100000;
// Far beyond any luminaire (a searchlight has about 1e9 cd), and far within float's range.
constexpr double kMaxCandela = 1e20;

[[noreturn]] void fail(const std::string& name, int line, const std::string& message) {
    throw IesError(line > 0 ? fmt::format("{}:{}: {}", name, line, message) : fmt::format("{}: {}", name, message));
}

std::string_view trim(std::string_view s) {
    const auto first = s.find_first_not_of(" \t\x1a");
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(" \t\x1a");
    return s.substr(first, last - first + 1);
}

// Shows a token in a message: at most 24 printable characters.
std::string shown(std::string_view t) {
    std::string out;
    for (const char c : t.substr(0, 24)) out += (c >= 32 && c < 127) ? c : '?';
    return t.size() > 24 ? out + "..." : out;
}

struct Token {
    std::string_view text;
    int line;
};

// The numbers after the TILT= line, read in order, each with its line for messages.
class NumberReader {
public:
    NumberReader(std::vector<Token> tokens, const std::string& name, int last_line)
        : tokens_(std::move(tokens)), name_(name), last_line_(last_line) {}

    size_t remaining() const { return tokens_.size() - pos_; }
    int line() const { return pos_ > 0 ? tokens_[pos_ - 1].line : last_line_; }  // of the last number read
    int next_line() const { return pos_ < tokens_.size() ? tokens_[pos_].line : last_line_; }

    double number(const std::string& what) {
        if (pos_ >= tokens_.size()) fail(name_, last_line_, fmt::format("the file ends before the {}", what));
        const Token& t = tokens_[pos_++];
        std::string_view s = t.text;
        if (!s.empty() && s[0] == '+') s.remove_prefix(1);
        double v = 0;
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ec != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(v))
            fail(name_, t.line, fmt::format("expected a number for the {}, found '{}'", what, shown(t.text)));
        return v;
    }
    int integer(const std::string& what, int lo, int hi) {
        const double v = number(what);
        if (v != std::floor(v) || v < lo || v > hi)
            fail(name_, line(), fmt::format("the {} must be a whole number from {} to {}, not {}", what, lo, hi, v));
        return int(v);
    }
    const Token* peek() const { return pos_ < tokens_.size() ? &tokens_[pos_] : nullptr; }

private:
    std::vector<Token> tokens_;
    size_t pos_ = 0;
    const std::string& name_;
    int last_line_;
};

bool near(double a, double b) { return std::abs(a - b) < 1e-6; }

}  // namespace

double IesProfile::candela_scale() const {
    return multiplier * ballast_factor * (version == "LM-63-2002" || version == "LM-63-2019" ? 1.0 : ballast_lamp_factor);
}

std::optional<double> IesProfile::rated_lumens() const {
    if (lumens_per_lamp < 0) return std::nullopt;
    return lamps * lumens_per_lamp * ballast_factor * (version == "LM-63-2002" || version == "LM-63-2019" ? 1.0 : ballast_lamp_factor);
}

IesProfile parse_ies(const std::string& text, const std::string& name) {
    // Lines end with \n, \r\n or \r.
    std::vector<std::string_view> lines;
    const std::string_view all(text);
    for (size_t start = 0; start <= all.size();) {
        size_t end = all.find_first_of("\r\n", start);
        if (end == std::string_view::npos) end = all.size();
        lines.push_back(all.substr(start, end - start));
        if (end == all.size()) break;
        start = end + (all[end] == '\r' && end + 1 < all.size() && all[end + 1] == '\n' ? 2 : 1);
    }
    IesProfile p;
    size_t i = 0;
    const std::string_view first = trim(lines[0]);
    if (first.starts_with("IESNA:LM-63-1995")) p.version = "LM-63-1995", i = 1;
    else if (first.starts_with("IESNA:LM-63-2002")) p.version = "LM-63-2002", i = 1;
    else if (first.starts_with("IESNA91")) p.version = "LM-63-1991", i = 1;
    else if (first.starts_with("IES:LM-63-2019")) p.version = "LM-63-2019", i = 1;
    else if (first.starts_with("IES")) {
        fail(name, 1, fmt::format("unsupported version line '{}'; supported: IESNA:LM-63-1995, IESNA:LM-63-2002 (and IESNA91, "
                                  "IES:LM-63-2019, or none for LM-63-1986)", shown(first)));
    } else {
        p.version = "LM-63-1986";
    }
    // Keyword lines, up to TILT=.
    for (; i < lines.size(); ++i) {
        const std::string_view l = trim(lines[i]);
        if (l.starts_with("TILT=") || l.starts_with("TILT =")) break;
    }
    if (i == lines.size())
        fail(name, int(lines.size()), "the file ends without a TILT= line (is it an IES LM-63 photometric file?)");
    const int tilt_line = int(i) + 1;
    std::string_view tilt = trim(trim(lines[i]).substr(trim(lines[i]).find('=') + 1));
    if (tilt == "NONE") p.tilt = "NONE";
    else if (tilt == "INCLUDE") p.tilt = "INCLUDE";
    else
        fail(name, tilt_line, fmt::format("TILT={} (tilt data in another file) is not supported; use TILT=NONE or TILT=INCLUDE", shown(tilt)));

    std::vector<Token> tokens;
    for (size_t k = i + 1; k < lines.size(); ++k) {
        const std::string_view l = lines[k];
        size_t s = 0;
        while (s < l.size()) {
            s = l.find_first_not_of(" \t,\x1a", s);
            if (s == std::string_view::npos) break;
            size_t e = l.find_first_of(" \t,\x1a", s);
            if (e == std::string_view::npos) e = l.size();
            tokens.push_back({l.substr(s, e - s), int(k) + 1});
            s = e;
        }
    }
    NumberReader r(std::move(tokens), name, int(lines.size()));

    if (p.tilt == "INCLUDE") {
        r.integer("lamp-to-luminaire geometry of TILT=INCLUDE", 1, 3);
        const int n = r.integer("number of tilt angles", 0, kMaxAngles);
        if (size_t(n) * 2 > r.remaining())
            fail(name, int(lines.size()), fmt::format("the file ends in the tilt data ({} angles and factors announced)", n));
        double previous = -1;
        for (int k = 0; k < n; ++k) {
            const double a = r.number("tilt angle");
            if (a < 0 || a > 180 || a <= previous) fail(name, r.line(), fmt::format("tilt angle {} is not increasing within [0, 180]", a));
            previous = a;
        }
        for (int k = 0; k < n; ++k)
            if (r.number("tilt multiplying factor") < 0) fail(name, r.line(), "a tilt multiplying factor is negative");
    }

    p.lamps = r.integer("number of lamps", 1, 1000000);
    p.lumens_per_lamp = r.number("lumens per lamp");
    if (!(p.lumens_per_lamp > 0 || p.lumens_per_lamp == -1))
        fail(name, r.line(), fmt::format("lumens per lamp must be positive (or -1 for absolute photometry), not {}", p.lumens_per_lamp));
    p.multiplier = r.number("candela multiplier");
    if (!(p.multiplier > 0)) fail(name, r.line(), fmt::format("the candela multiplier must be positive, not {}", p.multiplier));
    const int nv = r.integer("number of vertical angles", 2, kMaxAngles);
    const int nh = r.integer("number of horizontal angles", 1, kMaxAngles);
    p.photometric_type = r.integer("photometric type", 1, 3);
    if (p.photometric_type != 1)
        fail(name, r.line(), fmt::format("photometric type {} ({}) is not supported: only type C (1)", p.photometric_type,
                                         p.photometric_type == 2 ? "type B" : "type A"));
    p.units_type = r.integer("units type (1 feet, 2 meters)", 1, 2);
    p.width = r.number("luminous opening's width");
    p.length = r.number("luminous opening's length");
    p.height = r.number("luminous opening's height");
    p.ballast_factor = r.number("ballast factor");
    if (!(p.ballast_factor > 0)) fail(name, r.line(), fmt::format("the ballast factor must be positive, not {}", p.ballast_factor));
    p.ballast_lamp_factor = r.number(p.version == "LM-63-2002" ? "future-use field" : "ballast-lamp photometric factor");
    if (p.version != "LM-63-2002" && p.version != "LM-63-2019" && !(p.ballast_lamp_factor > 0))
        fail(name, r.line(), fmt::format("the ballast-lamp photometric factor must be positive, not {}", p.ballast_lamp_factor));
    p.input_watts = r.number("input watts");

    const size_t needed = size_t(nv) + size_t(nh) + size_t(nv) * size_t(nh);
    if (needed > r.remaining())
        fail(name, int(lines.size()),
             fmt::format("the file ends after {} of the {} numbers its header announces ({} vertical angles, {} horizontal angles and "
                         "{} x {} candela values)",
                         r.remaining(), needed, nv, nh, nv, nh));
    p.vertical.resize(size_t(nv));
    for (int k = 0; k < nv; ++k) {
        const double a = r.number("vertical angle");
        if (a < 0 || a > 180) fail(name, r.line(), fmt::format("vertical angle {} is outside [0, 180] degrees", a));
        if (k > 0 && !(a > p.vertical[size_t(k) - 1]))
            fail(name, r.line(), fmt::format("the vertical angles must increase: {} follows {}", a, p.vertical[size_t(k) - 1]));
        p.vertical[size_t(k)] = a;
    }
    p.horizontal.resize(size_t(nh));
    for (int k = 0; k < nh; ++k) {
        const double a = r.number("horizontal angle");
        if (a < 0 || a > 360) fail(name, r.line(), fmt::format("horizontal angle {} is outside [0, 360] degrees", a));
        if (k > 0 && !(a > p.horizontal[size_t(k) - 1]))
            fail(name, r.line(), fmt::format("the horizontal angles must increase: {} follows {}", a, p.horizontal[size_t(k) - 1]));
        p.horizontal[size_t(k)] = a;
    }
    const double h0 = p.horizontal.front(), h1 = p.horizontal.back();
    const bool symmetric_ok = near(h0, 0) ? (near(h1, 0) || near(h1, 90) || near(h1, 180) || near(h1, 360)) : (near(h0, 90) && near(h1, 270));
    if (!symmetric_ok)
        fail(name, r.line(),
             fmt::format("the horizontal angles of type C photometry run from 0 to 0, 90, 180 or 360 degrees, or from 90 to 270; this "
                         "file's run from {} to {}",
                         h0, h1));
    p.values.resize(size_t(nv) * size_t(nh));
    const double scale = p.candela_scale();
    for (double& v : p.values) {
        v = r.number("candela values");
        if (v < 0) fail(name, r.line(), fmt::format("a negative candela value, {}", v));
        if (!(v * scale <= kMaxCandela))
            fail(name, r.line(), fmt::format("a candela value of {} x {} (multiplier and ballast factors) is beyond {} cd", v, scale, kMaxCandela));
    }
    if (const Token* t = r.peek())
        fail(name, t->line, fmt::format("unexpected '{}' after the {} x {} candela values", shown(t->text), nv, nh));
    return p;
}

IesProfile read_ies_file(const std::string& path) {
    std::string text;
    try {
        text = read_input_file(path, kMaxFileBytes);
    } catch (const InputFileError& e) {
        throw IesError(fmt::format("{}: cannot read the IES file: {}", path, e.what()));
    }
    return parse_ies(text, path);
}

// ---- the distribution ------------------------------------------------------------------------

IesDistribution::IesDistribution(const IesProfile& p) : vertical_(p.vertical) {
    // Expand the horizontal angles to the full circle, each with the file's column it mirrors.
    std::vector<std::pair<double, size_t>> angles;
    const double first = p.horizontal.front(), last = p.horizontal.back();
    for (size_t j = 0; j < p.horizontal.size(); ++j) {
        const double a = p.horizontal[j];
        if (p.horizontal.size() == 1) {
            angles.push_back({0, j});
        } else if (near(first, 90)) {  // 90 ... 270: mirrored about the 90-270 plane, C -> 180 - C
            angles.push_back({a, j});
            angles.push_back({a <= 180 ? 180 - a : 540 - a, j});
        } else if (near(last, 90)) {  // one quadrant
            for (const double m : {a, 180 - a, 180 + a, 360 - a}) angles.push_back({m, j});
        } else if (near(last, 180)) {  // mirrored about the 0-180 plane, C -> 360 - C
            angles.push_back({a, j});
            angles.push_back({360 - a, j});
        } else {
            angles.push_back({a, j});
        }
    }
    // 0 and 360 are the same direction: each end takes the other's column where it is missing.
    std::sort(angles.begin(), angles.end());
    if (!near(angles.front().first, 0)) angles.insert(angles.begin(), {0.0, angles.back().second});
    if (!near(angles.back().first, 360)) angles.push_back({360.0, angles.front().second});
    angles.front().first = 0, angles.back().first = 360;
    std::vector<std::pair<double, size_t>> unique;
    for (const auto& a : angles)
        if (unique.empty() || !near(a.first, unique.back().first)) unique.push_back(a);
    const size_t nv = vertical_.size(), nh = unique.size();
    const double scale = p.candela_scale();
    horizontal_.resize(nh);
    candela_.resize(nh * nv);
    for (size_t h = 0; h < nh; ++h) {
        horizontal_[h] = unique[h].first;
        for (size_t v = 0; v < nv; ++v) candela_[h * nv + v] = float(p.value(unique[h].second, v) * scale);
    }

    // Cells: weight (largest corner) x (solid angle); flux: the exact integral of the interpolant.
    constexpr double kRad = M_PI / 180;
    std::vector<float> weights((nh - 1) * (nv - 1));
    cell_solid_angle_.resize(weights.size());
    double flux = 0;
    for (size_t h = 0; h + 1 < nh; ++h) {
        const double dc = (horizontal_[h + 1] - horizontal_[h]) * kRad;
        for (size_t v = 0; v + 1 < nv; ++v) {
            const double g0 = vertical_[v] * kRad, g1 = vertical_[v + 1] * kRad, dg = g1 - g0;
            const double c00 = grid_value(h, v), c10 = grid_value(h + 1, v), c01 = grid_value(h, v + 1), c11 = grid_value(h + 1, v + 1);
            // cos g0 - cos g1, without the cancellation of a thin cell.
            const double s0 = 2 * std::sin(0.5 * (g0 + g1)) * std::sin(0.5 * dg);
            const double omega = dc * s0;
            const size_t k = h * (nv - 1) + v;
            cell_solid_angle_[k] = float(omega);
            weights[k] = float(std::max({c00, c10, c01, c11}) * omega);
            // Averaged over C the interpolant is a (1 - t) + b t along the cell, t = (g - g0) / dg:
            // its integral is a s_lo + b s_hi with s_hi = int t sin g dg = (sin g0 (cos dg - 1 +
            // dg sin dg) + cos g0 (sin dg - dg cos dg)) / dg and s_lo = s0 - s_hi, both >= 0 (the
            // series of sin dg - dg cos dg for thin cells, where the closed form cancels).
            const double p = dg * std::sin(dg) - 2 * std::sin(0.5 * dg) * std::sin(0.5 * dg);
            const double q = dg < 1e-2 ? dg * dg * dg / 3 - std::pow(dg, 5) / 30 : std::sin(dg) - dg * std::cos(dg);
            const double s_hi = std::clamp((std::sin(g0) * p + std::cos(g0) * q) / dg, 0.0, s0), s_lo = s0 - s_hi;
            const double a = 0.5 * (c00 + c10), b = 0.5 * (c01 + c11);
            flux += dc * (a * s_lo + b * s_hi);
        }
    }
    flux_ = flux;
    cells_ = Distribution1D(std::move(weights));
}

Vec3f IesDistribution::direction(double g, double c) {
    const double gr = g * M_PI / 180, cr = c * M_PI / 180;
    return Vec3f(Vec3d(std::sin(gr) * std::cos(cr), -std::sin(gr) * std::sin(cr), std::cos(gr)));
}

void IesDistribution::angles(const Vec3f& d, double& g, double& c) {
    g = std::acos(std::clamp(double(d.z), -1.0, 1.0)) * (180 / M_PI);
    c = std::atan2(-double(d.y), double(d.x)) * (180 / M_PI);
    if (c < 0) c += 360;
}

size_t IesDistribution::cell_index(double g, double c, bool& inside) const {
    inside = g >= vertical_.front() && g <= vertical_.back();
    const size_t nv = vertical_.size(), nh = horizontal_.size();
    const size_t v = size_t(std::clamp<ptrdiff_t>(std::upper_bound(vertical_.begin(), vertical_.end(), g) - vertical_.begin() - 1, 0,
                                                  ptrdiff_t(nv) - 2));
    const size_t h = size_t(std::clamp<ptrdiff_t>(std::upper_bound(horizontal_.begin(), horizontal_.end(), c) - horizontal_.begin() - 1,
                                                  0, ptrdiff_t(nh) - 2));
    return h * (nv - 1) + v;
}

float IesDistribution::candela(double g, double c) const {
    c = std::fmod(c, 360.0);
    if (c < 0) c += 360;
    bool inside;
    const size_t k = cell_index(g, c, inside);
    if (!inside) return 0.0f;
    const size_t nv = vertical_.size(), h = k / (nv - 1), v = k % (nv - 1);
    const double t = (g - vertical_[v]) / (vertical_[v + 1] - vertical_[v]);
    const double s = std::clamp((c - horizontal_[h]) / (horizontal_[h + 1] - horizontal_[h]), 0.0, 1.0);
    const double lo = (1 - s) * grid_value(h, v) + s * grid_value(h + 1, v);
    const double hi = (1 - s) * grid_value(h, v + 1) + s * grid_value(h + 1, v + 1);
    return float((1 - t) * lo + t * hi);
}

float IesDistribution::candela(const Vec3f& local) const {
    double g, c;
    angles(local, g, c);
    return candela(g, c);
}

std::optional<Vec3f> IesDistribution::sample(Vec2f u, float& pdfW) const {
    float pmf, ux;
    const size_t k = cells_.sample_discrete(u.x, pmf, &ux);
    const size_t nv = vertical_.size(), h = k / (nv - 1), v = k % (nv - 1);
    const double cos0 = std::cos(vertical_[v] * M_PI / 180), cos1 = std::cos(vertical_[v + 1] * M_PI / 180);
    const double cos_g = cos0 - double(ux) * (cos0 - cos1);
    const double c = (horizontal_[h] + double(u.y) * (horizontal_[h + 1] - horizontal_[h])) * M_PI / 180;
    const double sin_g = std::sqrt(std::max(0.0, 1 - cos_g * cos_g));
    const Vec3f d(Vec3d(sin_g * std::cos(c), -sin_g * std::sin(c), cos_g));
    // The density of the direction as pdf() finds it (its cell, even where rounding moved it
    // onto a neighbour's edge).
    pdfW = pdf(d);
    if (!(pdfW > 0)) return std::nullopt;
    return d;
}

float IesDistribution::pdf(const Vec3f& local) const {
    double g, c;
    angles(local, g, c);
    bool inside;
    const size_t k = cell_index(g, c, inside);
    if (!inside || !(cell_solid_angle_[k] > 0)) return 0.0f;
    return cells_.pmf(k) / cell_solid_angle_[k];
}

}  // namespace pathlab
