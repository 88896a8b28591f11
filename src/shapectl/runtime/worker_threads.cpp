#include <shapectl/runtime/worker_threads.hpp>

#include <memory>
#include <mutex>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

namespace shapectl::runtime {

namespace {
std::mutex limit_mutex;
std::unique_ptr<tbb::global_control> limit;  // the process's one limit, if any
}  // namespace

void limit_worker_threads(int threads) {
  const std::lock_guard lock(limit_mutex);
  limit.reset();
  if (threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(threads));
}

int worker_thread_limit() {
  return static_cast<int>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

void start_worker_threads() {
  const int threads = worker_thread_limit();
  tbb::parallel_for(0, threads, [](int) {});
}

}  // namespace shapectl::runtime
