#include "common/util/heap.hpp"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>

namespace aerie::util {
namespace {

int64_t rss_kb() {
  std::ifstream statm("/proc/self/statm");
  int64_t size_pages = 0, resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return 0;
  return resident_pages * (sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace

HeapFigures heap_figures() {
  const struct mallinfo2 m = mallinfo2();
  return {static_cast<int64_t>((m.uordblks + m.hblkhd) / 1024), static_cast<int64_t>(m.fordblks / 1024), rss_kb()};
}

int64_t trim_heap() {
  const int64_t before = rss_kb();
  malloc_trim(0);
  return std::max<int64_t>(0, before - rss_kb());
}

void map_large_blocks(size_t threshold_bytes) { mallopt(M_MMAP_THRESHOLD, static_cast<int>(threshold_bytes)); }

}  // namespace aerie::util
