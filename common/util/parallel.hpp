#pragma once
// fn(i) for i in [0, n) on `jobs` threads, each taking the next index when it is free. fn must
// write only to its own slot: results do not depend on the number of threads.
#include <atomic>
#include <thread>
#include <vector>

namespace aerie::util {

template <class Fn>
void parallel_for(int n, int jobs, Fn fn) {
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next++; i < n; i = next++) fn(i);
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < jobs; ++j) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
}

}  // namespace aerie::util
