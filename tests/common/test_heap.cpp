// util::heap_figures and util::trim_heap (common/util/heap.hpp) on glibc's heap.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "common/util/heap.hpp"

using namespace aerie;

TEST(Heap, TrimHandsBackTheFreePagesAFragmentedHeapHolds) {
#ifdef __SANITIZE_ADDRESS__
  GTEST_SKIP() << "ASan's allocator replaces glibc's heap";
#else
  // 32 MB in 1 KB blocks, every 64th kept: free() can give none of it back (a block is
  // live in every 64 KB), malloc_trim can give back the whole free pages between them.
  std::vector<char*> blocks(32 * 1024);
  for (auto& b : blocks) {
    b = static_cast<char*>(std::malloc(1024));
    std::memset(b, 1, 1024);
  }
  for (size_t i = 0; i < blocks.size(); ++i)
    if (i % 64) std::free(std::exchange(blocks[i], nullptr));
  const util::HeapFigures held = util::heap_figures();
  EXPECT_GT(held.free_kb, 28 * 1024);
  const int64_t released = util::trim_heap();
  EXPECT_GT(released, 20 * 1024) << "free " << held.free_kb << " kB";
  for (char* b : blocks) std::free(b);
#endif
}
