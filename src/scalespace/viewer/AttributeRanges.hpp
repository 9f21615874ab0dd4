#pragma once
// What the page needs to colour by a cloud's attribute columns: per column its name, type, min,
// max and 2nd/98th percentiles (a colour bar's robust range), computed once per layer.
#include <nlohmann/json.hpp>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::viewer {

/// One entry per attribute column of `cloud`, in column order: {name, type, min, max, p02, p98}
/// over the finite values (all 0 for a column without any).
nlohmann::json attributeRanges(const PointCloud& cloud);

}  // namespace scalespace::viewer
