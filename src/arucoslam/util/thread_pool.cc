#include "arucoslam/util/thread_pool.h"

#include <stdexcept>

namespace arucoslam {

ThreadPool::ThreadPool(int num_threads) {
  if (num_threads < 1) throw std::invalid_argument("ThreadPool: num_threads must be >= 1");
  workers_.reserve(num_threads - 1);
  for (int i = 1; i < num_threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_ready_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void ThreadPool::ParallelFor(int count, const std::function<void(int)>& body) {
  if (count <= 0) return;
  if (workers_.empty() || count == 1) {
    for (int i = 0; i < count; ++i) body(i);
    return;
  }
  std::lock_guard<std::mutex> loop_lock(loop_mutex_);
  std::unique_lock<std::mutex> lock(mutex_);
  body_ = &body;
  count_ = count;
  next_ = 0;
  running_ = 0;
  error_ = nullptr;
  ++loop_id_;
  work_ready_.notify_all();
  RunIterations(lock);
  loop_done_.wait(lock, [this] { return running_ == 0; });
  body_ = nullptr;
  if (error_) std::rethrow_exception(error_);
}

void ThreadPool::RunIterations(std::unique_lock<std::mutex>& lock) {
  while (next_ < count_ && !error_) {
    const int i = next_++;
    ++running_;
    const std::function<void(int)>& body = *body_;
    lock.unlock();
    std::exception_ptr error;
    try {
      body(i);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    if (error && !error_) error_ = error;
    --running_;
  }
  if (running_ == 0) loop_done_.notify_all();
}

void ThreadPool::WorkerLoop() {
  std::size_t seen_loop = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    work_ready_.wait(lock, [&] { return stop_ || (body_ != nullptr && loop_id_ != seen_loop); });
    if (stop_) return;
    seen_loop = loop_id_;
    RunIterations(lock);
  }
}

}  // namespace arucoslam
