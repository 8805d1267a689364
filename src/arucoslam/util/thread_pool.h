// ThreadPool: a fixed set of worker threads that, together with the calling thread, run the
// iterations of one loop at a time. Owned by the component that needs it (no global pool).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace arucoslam {

class ThreadPool {
 public:
  // `num_threads` counts the calling thread: 1 starts no worker and runs loops inline.
  // Throws std::invalid_argument when below 1.
  explicit ThreadPool(int num_threads);
  ~ThreadPool();  // joins the workers
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(i) once for every i in [0, count), spread over the workers and the calling
  // thread; iterations are handed out in increasing order to whichever thread is free.
  // Returns when all have finished; rethrows the first exception an iteration threw (the
  // iterations not yet started are then skipped). Calls from several threads run one loop
  // after the other.
  void ParallelFor(int count, const std::function<void(int)>& body);

 private:
  void WorkerLoop();
  // Takes and runs iterations of the current loop until none is left.
  void RunIterations(std::unique_lock<std::mutex>& lock);

  std::mutex loop_mutex_;  // one loop at a time
  std::mutex mutex_;       // guards everything below
  std::condition_variable work_ready_;
  std::condition_variable loop_done_;
  const std::function<void(int)>* body_ = nullptr;
  int count_ = 0;
  int next_ = 0;         // next iteration to hand out
  int running_ = 0;      // iterations started and not finished
  std::size_t loop_id_ = 0;  // increments with every loop, so workers join each loop once
  std::exception_ptr error_;
  bool stop_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace arucoslam
