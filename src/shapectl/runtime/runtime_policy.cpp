#include <shapectl/runtime/runtime_policy.hpp>

#include <mutex>
#include <optional>

#include <shapectl/runtime/blas_threads.hpp>
#include <shapectl/runtime/heap_settings.hpp>
#include <shapectl/runtime/worker_threads.hpp>

namespace shapectl::runtime {

namespace {
std::mutex applied_mutex;
std::optional<RuntimeSettings> applied;  // the last apply_runtime_policy's settings
}  // namespace

void apply_runtime_policy(const RuntimeSettings& settings) {
  const std::lock_guard lock(applied_mutex);
  // OpenBLAS first: its pool may be stopped, which must happen before TBB's threads call BLAS.
  if (settings.blas_idle_timeout > 0) set_blas_idle_timeout(settings.blas_idle_timeout);
  set_blas_threads(settings.blas_threads);
  if (settings.keep_freed_heap) keep_freed_heap_memory();
  if (!applied || applied->threads != settings.threads) limit_worker_threads(settings.threads);
  if (settings.start_threads) start_worker_threads();
  applied = settings;
}

void ensure_runtime_policy() {
  {
    const std::lock_guard lock(applied_mutex);
    if (applied) return;
  }
  apply_runtime_policy(settings_from_environment());
}

RuntimeSettings applied_runtime_settings() {
  const std::lock_guard lock(applied_mutex);
  return applied.value_or(RuntimeSettings{});
}

}  // namespace shapectl::runtime
