#include "render/aov_film.hpp"

#include <algorithm>
#include <cstring>

namespace pathlab {

void AovFilm::add(size_t pixel, const FirstVertex& v) {
    Sums& s = sums_[pixel];
    ++s.count;
    if (!v.found) return;
    const float values[kComponents] = {v.albedo.x,   v.albedo.y,   v.albedo.z,   v.normal.x,   v.normal.y,
                                       v.normal.z,   v.position.x, v.position.y, v.position.z, v.depth};
    for (int c = 0; c < kComponents; ++c) s.sum[size_t(c)] += double(values[c]);
}

bool AovFilm::identical(const AovFilm& other) const {
    if (width_ != other.width_ || height_ != other.height_) return false;
    for (size_t i = 0; i < sums_.size(); ++i)
        if (sums_[i].count != other.sums_[i].count ||
            std::memcmp(sums_[i].sum.data(), other.sums_[i].sum.data(), sizeof(double) * kComponents) != 0)
            return false;
    return true;
}

const std::vector<std::string>& aov_names() {
    static const std::vector<std::string> names{"albedo", "normal", "depth", "position", "variance", "sample-count"};
    return names;
}

std::vector<std::string> aov_channel_names(const std::string& aov) {
    if (aov == "albedo") return {"Albedo.R", "Albedo.G", "Albedo.B"};
    if (aov == "normal") return {"N.X", "N.Y", "N.Z"};
    if (aov == "depth") return {"Z"};
    if (aov == "position") return {"P.X", "P.Y", "P.Z"};
    if (aov == "variance") return {"Variance.R", "Variance.G", "Variance.B"};
    if (aov == "sample-count") return {"SampleCount"};
    return {};
}

bool aovs_need_first_vertex(const std::vector<std::string>& aovs) {
    return std::any_of(aovs.begin(), aovs.end(),
                       [](const std::string& a) { return a == "albedo" || a == "normal" || a == "depth" || a == "position"; });
}

}  // namespace pathlab
