#include "arucoslam/util/timing.h"

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace arucoslam {

TimingSummary TimingStats::Summarize() const {
  TimingSummary summary;
  summary.count = samples_.size();
  if (samples_.empty()) return summary;
  std::vector<double> sorted = samples_;
  std::sort(sorted.begin(), sorted.end());
  const auto quantile = [&sorted](double q) {
    // Linear interpolation between order statistics (numpy's default).
    const double position = q * static_cast<double>(sorted.size() - 1);
    const std::size_t lower = static_cast<std::size_t>(std::floor(position));
    const std::size_t upper = std::min(lower + 1, sorted.size() - 1);
    const double fraction = position - static_cast<double>(lower);
    return sorted[lower] + fraction * (sorted[upper] - sorted[lower]);
  };
  summary.mean = std::accumulate(sorted.begin(), sorted.end(), 0.0) /
                 static_cast<double>(sorted.size());
  summary.median = quantile(0.5);
  summary.p95 = quantile(0.95);
  summary.max = sorted.back();
  return summary;
}

namespace {

double CpuMilliseconds(clockid_t clock) {
  timespec now{};
  clock_gettime(clock, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

}  // namespace

double ThreadCpuMilliseconds() { return CpuMilliseconds(CLOCK_THREAD_CPUTIME_ID); }
double ProcessCpuMilliseconds() { return CpuMilliseconds(CLOCK_PROCESS_CPUTIME_ID); }

std::size_t PeakMemoryBytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<std::size_t>(usage.ru_maxrss) * 1024;  // ru_maxrss is in KiB on Linux.
}

}  // namespace arucoslam
