#pragma once
// The process-wide tuning shapectl runs with: thread counts, OpenBLAS's idle threads, the C
// library's heap. Each setting, why, and what it measured: docs/runtime.md.
// runtime_policy.hpp applies them; every program that runs the solvers does so at its start
// (the CLI and so `serve`, the server, the Python module at import, each Dask worker).

namespace shapectl::runtime {

struct RuntimeSettings {
  // TBB's worker threads, all parallel loops of the process (tbb::global_control); 0: one per
  // core. A Dask worker sets its own thread count: workers sharing a machine then do not each
  // start a thread per core.
  int threads = 0;
  // OpenBLAS's threads; 0: chosen per factorization (blas_threads.hpp: one, or one per core for
  // wide bands and large CHOLMOD factorizations); n > 0: n for every call.
  int blas_threads = 0;
  // OPENBLAS_THREAD_TIMEOUT: an idle OpenBLAS pool thread spins 2^n cycles before it sleeps
  // (OpenBLAS: 2^28, ~0.1 s, after every threaded call, taking a core from TBB's kernels, the
  // GUI and a robot link); 4: it sleeps at once. 0: OpenBLAS's own, as it loaded.
  int blas_idle_timeout = 4;
  // Large blocks (to 64 MiB) from the heap, and up to 256 MiB of freed heap kept mapped for the
  // next solve, not unmapped and faulted in again (heap_settings.hpp). false: the heap is left
  // as it is.
  bool keep_freed_heap = true;
  // TBB's workers started now, not inside the first solve and its time.
  bool start_threads = true;

  bool operator==(const RuntimeSettings&) const = default;
};

// The defaults above, where the environment does not say otherwise: SHAPECTL_THREADS gives
// `threads`; OPENBLAS_NUM_THREADS and OPENBLAS_THREAD_TIMEOUT give `blas_threads` and
// `blas_idle_timeout` as OpenBLAS read them when it loaded (a child of a process that applied
// the policy inherits its OPENBLAS_THREAD_TIMEOUT). glibc's
// MALLOC_MMAP_THRESHOLD_ and MALLOC_TRIM_THRESHOLD_ win over `keep_freed_heap` (heap_settings).
// InputError for a SHAPECTL_THREADS that is not a whole number >= 0.
RuntimeSettings settings_from_environment();

}  // namespace shapectl::runtime
