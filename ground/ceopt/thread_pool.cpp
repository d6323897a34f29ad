#include "ground/ceopt/thread_pool.hpp"

#include <algorithm>
#include <atomic>

namespace aerie::ceopt {

// One parallel_for call. Workers hold it by shared_ptr, so a worker that wakes late
// finds its own (exhausted) counter, never the next batch's.
struct ThreadPool::Batch {
  const std::function<void(size_t)>* job = nullptr;
  size_t n = 0;
  std::atomic<size_t> next{0};
  size_t done = 0;  // guarded by mutex
  std::mutex mutex;
  std::condition_variable finished;
  std::exception_ptr error;

  void drain() {
    for (size_t i; (i = next.fetch_add(1)) < n;) {
      bool failed;
      {
        std::lock_guard lock(mutex);
        failed = static_cast<bool>(error);
      }
      if (!failed) {
        try {
          (*job)(i);
        } catch (...) {
          std::lock_guard lock(mutex);
          if (!error) error = std::current_exception();
        }
      }
      std::lock_guard lock(mutex);
      if (++done == n) finished.notify_all();
    }
  }
};

ThreadPool::ThreadPool(int threads) {
  const int n = threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  for (int i = 1; i < n; ++i) workers_.emplace_back([this] { work(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::work() {
  std::shared_ptr<Batch> seen;
  for (;;) {
    std::shared_ptr<Batch> batch;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || batch_ != seen; });
      if (stop_) return;
      batch = seen = batch_;
    }
    if (batch) batch->drain();
  }
}

void ThreadPool::parallel_for(size_t n, const std::function<void(size_t)>& f) {
  if (n == 0) return;
  auto batch = std::make_shared<Batch>();
  batch->job = &f;
  batch->n = n;
  {
    std::lock_guard lock(mutex_);
    batch_ = batch;
  }
  wake_.notify_all();
  batch->drain();
  std::unique_lock lock(batch->mutex);
  batch->finished.wait(lock, [&] { return batch->done == n; });
  if (batch->error) std::rethrow_exception(batch->error);
}

}  // namespace aerie::ceopt
