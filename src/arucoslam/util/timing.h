// Stopwatch and TimingStats: wall-clock timing of pipeline stages and their summary
// (median, mean, p95), as printed by `arucoslam run` and written to stats.json.
#pragma once

#include <chrono>
#include <cstddef>
#include <vector>

namespace arucoslam {

class Stopwatch {
 public:
  Stopwatch() : start_(Clock::now()) {}
  void Restart() { start_ = Clock::now(); }
  double ElapsedSeconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
  }
  double ElapsedMilliseconds() const { return 1e3 * ElapsedSeconds(); }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

struct TimingSummary {
  std::size_t count = 0;
  double mean = 0.0;
  double median = 0.0;
  double p95 = 0.0;
  double max = 0.0;
};

// Collects samples (any unit; the caller decides, e.g. milliseconds).
class TimingStats {
 public:
  void Add(double sample) { samples_.push_back(sample); }
  std::size_t Count() const { return samples_.size(); }
  TimingSummary Summarize() const;

 private:
  std::vector<double> samples_;
};

// CPU time consumed so far, milliseconds: by the calling thread, and by the whole process
// (every thread, e.g. OpenCV's pool).
double ThreadCpuMilliseconds();
double ProcessCpuMilliseconds();

// Peak resident set size of this process in bytes (0 where unknown).
std::size_t PeakMemoryBytes();

}  // namespace arucoslam
