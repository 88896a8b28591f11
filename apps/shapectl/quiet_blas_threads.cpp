#include "quiet_blas_threads.hpp"

#include <cstdlib>
#include <unistd.h>

namespace shapectl::cli {

void restart_with_quiet_blas_threads(char** argv) {
  // Setting it in-process is too late (OpenBLAS has read it), and an ELF pre-initialisation
  // function is too early (libc's start-up resets the environment after it).
  if (std::getenv("OPENBLAS_THREAD_TIMEOUT")) return;
  if (setenv("OPENBLAS_THREAD_TIMEOUT", "4", 1) != 0) return;
  execv("/proc/self/exe", argv);  // returns only on failure
}

}  // namespace shapectl::cli
