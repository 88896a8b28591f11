// shapectl.configure_runtime and shapectl.runtime_settings: the process-wide tuning
// (docs/runtime.md), applied at import with the environment's settings (module.cpp).
#include <shapectl/runtime/blas_threads.hpp>
#include <shapectl/runtime/runtime_policy.hpp>
#include <shapectl/runtime/worker_threads.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {
int count_from(const std::optional<Integer>& given, int applied, const char* name, int smallest) {
  if (!given) return applied;
  if (given->value < smallest)
    throw InputError("configure_runtime", name, "an int >= " + std::to_string(smallest),
                     given->value);
  return given->value;
}

py::dict runtime_settings() {
  const runtime::RuntimeSettings s = runtime::applied_runtime_settings();
  py::dict d;
  d["threads"] = s.threads;
  d["blas_threads"] = s.blas_threads;
  d["blas_idle_timeout"] = s.blas_idle_timeout;
  d["keep_freed_heap"] = s.keep_freed_heap;
  d["start_threads"] = s.start_threads;
  // What the libraries report now.
  d["tbb_thread_limit"] = runtime::worker_thread_limit();
  d["openblas_threads"] = runtime::current_blas_threads();
  d["openblas_idle_timeout"] = runtime::current_blas_idle_timeout();
  return d;
}

py::dict configure_runtime(std::optional<Integer> threads, std::optional<Integer> blas_threads,
                           std::optional<Integer> blas_idle_timeout,
                           std::optional<bool> keep_freed_heap, std::optional<bool> start_threads) {
  runtime::RuntimeSettings s = runtime::applied_runtime_settings();
  s.threads = count_from(threads, s.threads, "threads", 0);
  s.blas_threads = count_from(blas_threads, s.blas_threads, "blas_threads", 0);
  s.blas_idle_timeout = count_from(blas_idle_timeout, s.blas_idle_timeout, "blas_idle_timeout", 0);
  if (s.blas_idle_timeout > 30)
    throw InputError("configure_runtime", "blas_idle_timeout", "an int from 0 to 30",
                     s.blas_idle_timeout);
  s.keep_freed_heap = keep_freed_heap.value_or(s.keep_freed_heap);
  s.start_threads = start_threads.value_or(s.start_threads);
  {
    py::gil_scoped_release release;
    runtime::apply_runtime_policy(s);
  }
  return runtime_settings();
}
}  // namespace

void bind_runtime(py::module_& m) {
  m.def("configure_runtime", &configure_runtime, py::kw_only(), py::arg("threads") = py::none(),
        py::arg("blas_threads") = py::none(), py::arg("blas_idle_timeout") = py::none(),
        py::arg("keep_freed_heap") = py::none(), py::arg("start_threads") = py::none(),
        "Applies the process-wide tuning (docs/runtime.md); settings not given keep their "
        "value. Importing shapectl applied the environment's (SHAPECTL_THREADS, "
        "OPENBLAS_NUM_THREADS, OPENBLAS_THREAD_TIMEOUT). threads: TBB's worker threads, 0 one per "
        "core; blas_threads: OpenBLAS's, 0 chosen per factorization; blas_idle_timeout: log2 of "
        "the cycles an idle OpenBLAS thread spins (4 sleeps at once; 0 leaves OpenBLAS as it is); "
        "keep_freed_heap: mallopt thresholds that keep freed memory for the next solve; "
        "start_threads: TBB's workers started now. Call it before other threads use BLAS. "
        "Returns runtime_settings().");
  m.def("runtime_settings", &runtime_settings,
        "The tuning applied last (threads, blas_threads, blas_idle_timeout, keep_freed_heap, "
        "start_threads) and what the libraries report now (tbb_thread_limit, openblas_threads, "
        "openblas_idle_timeout).");
}

}  // namespace shapectl::python
