#pragma once

namespace shapectl::runtime {

// Large blocks (up to 64 MiB) come from the C library's heap, and freed heap memory stays
// mapped for the next block. glibc's defaults map every block from 128 KiB afresh (raising that
// threshold only after such a block is freed) and unmap it on free, so a first solve takes the
// page faults of its Hessians, scatter map and factor twice, and its threads the TLB shootdowns
// of each unmap (docs/benchmarks.md, "session 7": the 12k bar's statics from rest 1.9 ms
// faster, the TetGen frame's 0.8 ms). The process keeps up to 256 MiB it freed.
// MALLOC_MMAP_THRESHOLD_ and MALLOC_TRIM_THRESHOLD_, where set (Dask sets the latter in its
// workers to return memory early), keep their values.
void keep_freed_heap_memory();

}  // namespace shapectl::runtime
