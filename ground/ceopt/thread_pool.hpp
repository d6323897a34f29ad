#pragma once
// A fixed pool of std::threads that runs an index loop in parallel: the candidates of
// one CE iteration. Work is handed out by an atomic counter; results go to per-index
// slots, so they do not depend on the number of threads.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace aerie::ceopt {

class ThreadPool {
 public:
  explicit ThreadPool(int threads = 0);  // 0 = all cores (std::thread::hardware_concurrency)
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  // Calls f(i) for i in [0, n) on the pool (the caller works too) and waits. The first
  // exception thrown by f is rethrown here once the batch has stopped.
  void parallel_for(size_t n, const std::function<void(size_t)>& f);
  int size() const { return static_cast<int>(workers_.size()) + 1; }

 private:
  struct Batch;
  void work();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::shared_ptr<Batch> batch_;
  bool stop_ = false;
};

}  // namespace aerie::ceopt
