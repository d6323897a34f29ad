#pragma once
// A process's heap, as glibc's malloc sees it, and handing back what it holds free.
//
// glibc keeps what a process frees in its arenas, so after a burst (the viewer's images,
// meshes and VTK arrays on three threads; the map's octree before a CLEAR) the RSS follows
// the highest burst so far rather than what is in use: the soak's step-wise RSS growth
// (docs/results/soak.md). malloc_trim(3) returns the free pages of every arena to the kernel.
#include <cstdint>

namespace aerie::util {

struct HeapFigures {
  int64_t in_use_kb = 0;  // allocated and not freed (mallinfo2: uordblks + hblkhd)
  int64_t free_kb = 0;    // freed, still held by malloc's arenas (fordblks)
  int64_t rss_kb = 0;     // resident set of the process (/proc/self/statm)
};

HeapFigures heap_figures();

// malloc_trim(0); returns the resident memory it gave back (kB, RSS before minus after).
int64_t trim_heap();

}  // namespace aerie::util
