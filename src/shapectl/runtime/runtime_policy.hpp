#pragma once
// The one place process-wide tuning is applied (docs/runtime.md): the CLI's main, the server,
// the Python module's import and each Dask worker (shapectl.batch) call it; nothing restarts
// the program to set a variable.
#include <shapectl/runtime/runtime_settings.hpp>

namespace shapectl::runtime {

// Applies every setting. Applying the same settings again changes nothing (OpenBLAS's pool is
// restarted only for a new idle timeout); other settings replace the earlier ones. Call it
// before other threads use BLAS: a new idle timeout stops OpenBLAS's pool (blas_threads.hpp).
void apply_runtime_policy(const RuntimeSettings& settings);

// The environment's settings (settings_from_environment), unless the process has applied
// settings already: for the server and the Python module, which may run inside a program that
// chose its own.
void ensure_runtime_policy();

// The settings applied last (the defaults before any).
RuntimeSettings applied_runtime_settings();

}  // namespace shapectl::runtime
