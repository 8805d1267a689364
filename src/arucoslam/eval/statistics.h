// ErrorStatistics: the summary evo prints for an error series (rmse, mean, median, std, min,
// max, sse); ComputeErrorStatistics fills it from a list of errors.
#pragma once

#include <vector>

namespace arucoslam {

struct ErrorStatistics {
  std::size_t count = 0;
  double rmse = 0.0;  // sqrt(mean(e^2))
  double mean = 0.0;
  double median = 0.0;  // mean of the two middle values for an even count (numpy's median)
  double std = 0.0;     // population standard deviation (numpy's std, ddof = 0)
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  // sum of e^2
};

// All zero for an empty list.
ErrorStatistics ComputeErrorStatistics(const std::vector<double>& errors);

// Linear-interpolated percentile (numpy's default), `percent` in [0, 100]; 0 when empty.
double Percentile(std::vector<double> values, double percent);

}  // namespace arucoslam
