#include <shapectl/runtime/heap_settings.hpp>

#include <cstdlib>
#include <malloc.h>

namespace shapectl::runtime {

void keep_freed_heap_memory() {
  if (!std::getenv("MALLOC_MMAP_THRESHOLD_")) mallopt(M_MMAP_THRESHOLD, 64 << 20);
  if (!std::getenv("MALLOC_TRIM_THRESHOLD_")) mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace shapectl::runtime
