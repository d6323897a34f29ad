#pragma once
// A process's heap, as glibc's malloc sees it, and handing back what it holds free.
//
// glibc keeps what a process frees in its arenas, so after a burst (the viewer's images,
// meshes and VTK arrays on three threads; the map's octree before a CLEAR) the RSS follows
// the highest burst so far rather than what is in use: the soak's step-wise RSS growth
// (docs/results/soak.md). malloc_trim(3) returns the free pages of every arena to the kernel.
#include <cstddef>
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

// glibc raises its mmap threshold to the largest block freed so far (up to 32 MB), so after
// one burst every later image, mesh or octree array of that size is carved from the arenas
// and its pages stay there when it is freed. A fixed threshold (mallopt M_MMAP_THRESHOLD,
// which turns the raising off) maps each block above it on its own and unmaps it on free.
// For the long-running ground nodes (aerie-map, aerie-viewer).
void map_large_blocks(size_t threshold_bytes = 128 * 1024);

}  // namespace aerie::util
