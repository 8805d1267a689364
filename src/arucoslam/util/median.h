// The median of a set of values: the upper of the two middle ones for an even count (no
// averaging), 0 for none. Takes its argument by value: nth_element reorders it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace arucoslam {

inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace arucoslam
