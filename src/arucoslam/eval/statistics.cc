#include "arucoslam/eval/statistics.h"

#include <algorithm>
#include <cmath>

namespace arucoslam {

ErrorStatistics ComputeErrorStatistics(const std::vector<double>& errors) {
  ErrorStatistics stats;
  if (errors.empty()) return stats;
  const double n = static_cast<double>(errors.size());
  stats.count = errors.size();
  double sum = 0.0;
  for (double e : errors) {
    sum += e;
    stats.sse += e * e;
  }
  stats.mean = sum / n;
  stats.rmse = std::sqrt(stats.sse / n);
  double squared_deviation = 0.0;
  for (double e : errors) squared_deviation += (e - stats.mean) * (e - stats.mean);
  stats.std = std::sqrt(squared_deviation / n);
  const auto [min_it, max_it] = std::minmax_element(errors.begin(), errors.end());
  stats.min = *min_it;
  stats.max = *max_it;
  stats.median = Percentile(errors, 50.0);
  return stats;
}

double Percentile(std::vector<double> values, double percent) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double position =
      std::clamp(percent, 0.0, 100.0) / 100.0 * static_cast<double>(values.size() - 1);
  const std::size_t below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, values.size() - 1);
  const double fraction = position - static_cast<double>(below);
  return values[below] + fraction * (values[above] - values[below]);
}

}  // namespace arucoslam
