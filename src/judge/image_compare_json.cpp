#include "judge/image_compare_json.hpp"

namespace pathlab {
namespace {

nlohmann::json statistics_json(const ChannelStatistics& s) {
    return {{"mean_diff", s.mean_diff}, {"mae", s.mae}, {"rmse", s.rmse}, {"relmse", s.relmse}, {"max_abs_diff", s.max_abs_diff}};
}

}  // namespace

nlohmann::json image_difference_json(const ImageDifference& d) {
    nlohmann::json j = {{"width", d.width},
                        {"height", d.height},
                        {"channels", nlohmann::json::array()},
                        {"all", statistics_json(d.all)},
                        {"compared", d.compared},
                        {"nan", {{"a", d.nan_a}, {"b", d.nan_b}}},
                        {"inf", {{"a", d.inf_a}, {"b", d.inf_b}}}};
    for (const ChannelStatistics& c : d.channel) j["channels"].push_back(statistics_json(c));
    return j;
}

}  // namespace pathlab
