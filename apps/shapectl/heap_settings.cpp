#include "heap_settings.hpp"

#include <malloc.h>

namespace shapectl::cli {

void keep_freed_heap_memory() {
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace shapectl::cli
