#include "job/pass_set.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

namespace pathlab {

PassSet PassSet::range(uint64_t begin, uint64_t end) {
    PassSet s;
    s.insert(begin, end);
    return s;
}

void PassSet::insert(uint64_t begin, uint64_t end) {
    if (begin >= end) return;
    std::vector<PassRange> out;
    out.reserve(ranges_.size() + 1);
    PassRange add{begin, end};
    bool placed = false;
    for (const PassRange& r : ranges_) {
        if (r.end < add.begin) out.push_back(r);
        else if (add.end < r.begin) {
            if (!placed) out.push_back(add), placed = true;
            out.push_back(r);
        } else {
            add.begin = std::min(add.begin, r.begin), add.end = std::max(add.end, r.end);
        }
    }
    if (!placed) out.push_back(add);
    ranges_ = std::move(out);
}

void PassSet::insert(const PassSet& other) {
    for (const PassRange& r : other.ranges_) insert(r.begin, r.end);
}

uint64_t PassSet::count() const {
    uint64_t n = 0;
    for (const PassRange& r : ranges_) n += r.size();
    return n;
}

PassSet PassSet::minus(const PassSet& other) const {
    PassSet out;
    for (PassRange r : ranges_) {
        for (const PassRange& o : other.ranges_) {
            if (o.end <= r.begin || o.begin >= r.end) continue;
            if (o.begin > r.begin) out.ranges_.push_back({r.begin, o.begin});
            r.begin = std::min(r.end, o.end);
        }
        if (r.begin < r.end) out.ranges_.push_back(r);
    }
    return out;
}

bool PassSet::contains(const PassSet& other) const { return other.minus(*this).empty(); }

bool PassSet::intersects(const PassSet& other) const { return minus(other) != *this; }

PassSet PassSet::first(uint64_t n) const {
    PassSet out;
    for (const PassRange& r : ranges_) {
        if (n == 0) break;
        const uint64_t take = std::min(n, r.size());
        out.ranges_.push_back({r.begin, r.begin + take});
        n -= take;
    }
    return out;
}

PassSet PassSet::part(int part, int parts) const {
    const uint64_t n = count(), p = uint64_t(parts), k = uint64_t(part);
    // Part k takes passes [k n / p, (k + 1) n / p) of the set's order, rounded so that the
    // first n mod p parts get one more.
    const auto start = [&](uint64_t j) { return j * (n / p) + std::min(j, n % p); };
    const uint64_t from = start(k), to = start(k + 1);
    PassSet out;
    uint64_t seen = 0;
    for (const PassRange& r : ranges_) {
        const uint64_t lo = std::max(from, seen), hi = std::min(to, seen + r.size());
        if (lo < hi) out.ranges_.push_back({r.begin + (lo - seen), r.begin + (hi - seen)});
        seen += r.size();
    }
    return out;
}

std::string PassSet::to_string() const {
    std::string s;
    for (const PassRange& r : ranges_) {
        if (!s.empty()) s += ',';
        s += r.size() == 1 ? fmt::format("{}", r.begin) : fmt::format("{}-{}", r.begin, r.end - 1);
    }
    return s;
}

std::optional<PassSet> PassSet::parse(const std::string& text) {
    PassSet out;
    const char* p = text.data();
    const char* const end = text.data() + text.size();
    const auto number = [&](uint64_t& v) {
        const auto [next, ec] = std::from_chars(p, end, v);
        if (ec != std::errc() || next == p) return false;
        p = next;
        return true;
    };
    while (p < end) {
        uint64_t a = 0, b = 0;
        if (!number(a)) return std::nullopt;
        b = a;
        if (p < end && *p == '-') {
            ++p;
            if (!number(b) || b < a) return std::nullopt;
        }
        if (b == UINT64_MAX) return std::nullopt;
        if (!out.ranges_.empty() && a <= out.ranges_.back().end) return std::nullopt;  // increasing, apart
        out.ranges_.push_back({a, b + 1});
        if (p < end && *p++ != ',') return std::nullopt;
        if (p == end && text.back() == ',') return std::nullopt;
    }
    return out;
}

}  // namespace pathlab
