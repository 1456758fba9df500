// compare's statistics as JSON, one form for `pathlab compare --json` and the Python module's
// pathlab.compare (so both give the same numbers under the same names).
#pragma once

#include <nlohmann/json.hpp>

#include "judge/image_compare.hpp"

namespace pathlab {

// {"width", "height", "channels": [R, G, B], "all", "compared", "nan": {"a", "b"}, "inf": {"a", "b"}},
// each statistics object {"mean_diff", "mae", "rmse", "relmse", "max_abs_diff"}.
nlohmann::json image_difference_json(const ImageDifference& d);

}  // namespace pathlab
